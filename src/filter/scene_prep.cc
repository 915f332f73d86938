// src/filter/scene_prep.cc — support-plane removal and mask shift of the scored depth
// (scene_prep.h), and the prepared frame that shares the first between estimates
// (posefilter/prepared_frame.h).
#include "filter/scene_prep.h"

#include <algorithm>
#include <atomic>
#include <sstream>

#include "posefilter/error.h"
#include "posefilter/option_table.h"

namespace posefilter {
namespace {

std::atomic<std::uint64_t> frames_prepared{0};

}  // namespace

namespace filter {

PreparedScene FrameScene(const SceneInput& frame, bool support_plane) {
  PreparedScene p;
  p.scoring.camera = frame.camera;
  p.scoring.depth = frame.depth;
  std::vector<float>& z = p.scoring.depth.data;
  if (support_plane) {
    p.surfaces = FindSupportSurfaces(frame.depth, frame.camera);
    if (p.surfaces.supports > 0) p.plane = p.surfaces.patches[0].plane;
    const std::vector<int> on = SupportSurfacePixels(frame.depth, frame.camera, p.surfaces);
    for (std::size_t i = 0; i < z.size(); ++i)
      if (on[i] && z[i] > 0) {
        z[i] = 0;
        ++p.plane_pixels;
      }
  }
  p.valid_pixels = frame.depth.CountValid();
  p.support = p.scoring.depth;
  ++frames_prepared;
  return p;
}

PreparedScene WithObject(PreparedScene p, const std::vector<std::uint8_t>& mask, const std::vector<PoseSeed>& seeds,
                         const FilterOptions& options) {
  p.scoring.seeds = seeds;
  if (!mask.empty()) {
    std::vector<float>& z = p.scoring.depth.data;
    // Further than any inlier ramp (2·thr1 at the annealing's start) and the align and edge
    // bands reach: a fragment on a shifted pixel is never an inlier, never aligned to it.
    const double thr = std::max(options.anneal.start_m, double(options.score.inlier.thr1_m));
    p.mask_shift_m = 2 * std::max({2 * thr, options.diffusion.align_band_m, options.score.edge_band_m});
    for (std::size_t i = 0; i < z.size(); ++i) {
      if (mask[i]) continue;
      p.support.data[i] = 0;
      // A pixel nearer than the shift stays valid with a tiny depth: in front of everything.
      if (z[i] > 0) z[i] = std::max(z[i] - float(p.mask_shift_m), 1e-3f);
    }
  }
  return p;
}

PreparedScene PrepareScene(const SceneInput& scene, const FilterOptions& options, const std::string& what) {
  ValidateScene(scene, what);
  return WithObject(FrameScene(SceneInput{scene.depth, scene.camera}, options.support.plane), scene.mask, scene.seeds,
                    options);
}

std::shared_ptr<const PreparedScene> SceneFor(const PreparedFrame& frame, const ObjectInput& object,
                                              const FilterOptions& options, const std::string& what) {
  ValidateObjectInput(object.mask, object.seeds, frame.frame().depth.data.size(), what);
  const bool same = frame.support_plane() == options.support.plane;
  if (same && object.mask.empty() && object.seeds.empty()) return frame.scene();
  return std::make_shared<const PreparedScene>(WithObject(
      same ? *frame.scene() : FrameScene(frame.frame(), options.support.plane), object.mask, object.seeds, options));
}

}  // namespace filter

PreparedFrame::PreparedFrame(SceneInput frame, bool support_plane, std::shared_ptr<const filter::PreparedScene> scene)
    : frame_(std::move(frame)), support_plane_(support_plane), scene_(std::move(scene)) {}

const SupportSurfaces& PreparedFrame::surfaces() const { return scene_->surfaces; }

std::shared_ptr<const PreparedFrame> PrepareFrame(const SceneInput& frame, const FilterOptions& options,
                                                  const std::string& what) {
  ThrowIfInvalid(options, OptionNaming::kField);
  if (!frame.mask.empty() || !frame.seeds.empty())
    throw Error(what + ": a prepared frame holds no mask and no seeds (they are an object's: ObjectInput)");
  ValidateScene(frame, what);
  SceneInput input{frame.depth, frame.camera};
  auto scene = std::make_shared<const filter::PreparedScene>(filter::FrameScene(input, options.support.plane));
  return std::make_shared<const PreparedFrame>(std::move(input), options.support.plane, std::move(scene));
}

std::uint64_t FramesPrepared() { return frames_prepared.load(); }

}  // namespace posefilter
