// posefilter/prepared_frame.h — a depth frame prepared once for the filter, shared by every
// estimate of that frame.
//
// What the filter derives from a frame's depth image and camera alone is computed once, when
// the frame is prepared, and never changes after (docs/ARCHITECTURE.md, "The filter's state"):
// the frame's checks (ValidateScene) and, with FilterOptions::support.plane, the support
// surfaces (FindSupportSurfaces: the table, the floor, shelf boards, walls) and the depth with
// their pixels taken out. What belongs to one object — its instance mask and its pose seeds —
// comes with each estimate (ObjectInput, posefilter/filter.h), which applies it to the prepared
// frame without finding the surfaces again. A PreparedFrame is immutable: any number of
// estimates, on any number of threads, may share it (held by std::shared_ptr<const ...>).
//
//   auto frame = PrepareFrame(SceneInput{depth, camera}, options);     // once per frame
//   for (const Object& o : objects)                                     // posefilter/filter.h
//     results.push_back(EstimatePose(*frame, {o.mask, o.seeds}, *o.model, prior, o.cls, options));
//   RunScenePass(*frame, prior, scene_objects, options);                // posefilter/scene_pass.h
//
// The results are those of EstimatePose(SceneInput{depth, camera, mask, seeds}, ...), bit for
// bit. An estimate whose options disagree with the frame's support.plane prepares the frame
// again for itself (the same numbers as an estimate on the SceneInput).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "posefilter/filter.h"
#include "posefilter/filter_options.h"
#include "posefilter/support_plane.h"

namespace posefilter {

namespace filter {
struct PreparedScene;  // the scene an estimate scores against (src/filter/scene_prep.h)
}  // namespace filter

class PreparedFrame {
 public:
  // Use PrepareFrame.
  PreparedFrame(SceneInput frame, bool support_plane, std::shared_ptr<const filter::PreparedScene> scene);

  // The frame as given: depth (camera z, metres, 0 = missing) and camera; no mask, no seeds.
  const SceneInput& frame() const { return frame_; }
  // Whether it was prepared with FilterOptions::support.plane (its support surfaces found).
  bool support_plane() const { return support_plane_; }
  // Every support surface and structure patch (camera frame); empty without support_plane.
  const SupportSurfaces& surfaces() const;
  // Internal (src/filter/scene_prep.h): the scene every estimate of the frame without a mask
  // or seeds scores against, shared by them.
  const std::shared_ptr<const filter::PreparedScene>& scene() const { return scene_; }

 private:
  SceneInput frame_;
  bool support_plane_ = false;
  std::shared_ptr<const filter::PreparedScene> scene_;
};

// Prepares `frame` (depth and camera; its mask and seeds must be empty: they are an object's,
// ObjectInput) for estimates with `options` (valid, FilterOptions::IsValid; only support.plane
// matters here). Throws Error naming `what` on an invalid frame (ValidateScene), a mask or
// seeds in it, and on invalid options.
std::shared_ptr<const PreparedFrame> PrepareFrame(const SceneInput& frame, const FilterOptions& options = {},
                                                  const std::string& what = "scene");

// How many frames this process has prepared so far (PrepareFrame, and estimates on a SceneInput
// or on a frame prepared with another support.plane, which prepare their own), counted once
// each.
std::uint64_t FramesPrepared();

}  // namespace posefilter
