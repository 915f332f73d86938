// apps/view_cli.h — the viewer page (posefilter/view.h) as the commands write it: `view`,
// `estimate --view`, `demo --view` and `run-dataset --view-dir` (docs/VIEWER.md).
#pragma once

#include <string>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/scene_io.h"
#include "posefilter/view.h"

namespace posefilter::cli {

// One frame and what was estimated on it.
struct FrameView {
  std::string title;
  const SceneInput* scene = nullptr;        // depth (metres) and camera
  const RgbImage* rgb = nullptr;            // the point cloud's colours, or nullptr (depth shading)
  std::vector<const Mesh*> meshes;          // one per result, same order
  std::vector<ObjectResult> results;
  std::vector<std::vector<ParticleSet>> particles;  // one per result (or empty: none recorded)
  std::vector<GtObject> gt;                 // ground truth of the frame (may be empty)
  bool support_plane = true;                // draw the support plane the filter finds
};

// Throws posefilter::Error naming `option` when this build has no viewer (libjs-three was not
// found when it was configured); commands call it before any work.
void RequireViewer(const std::string& option);

// Writes the page of `frame` to `path` atomically. Each result is paired with the ground truth
// of its class (of several of one class, the nearest unused one by translation).
void WriteFrameView(const FrameView& frame, const std::string& path);

}  // namespace posefilter::cli
