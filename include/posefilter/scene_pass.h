// posefilter/scene_pass.h — the joint scene pass: after each object has been estimated on its
// own, the estimates are rendered together and each object is re-weighed (and, where another
// estimate explains its pixels, re-estimated) against the pixels no better estimate explains.
//
// Per object, best weight first (docs/ALGORITHM.md, "Scene pass"):
//   1. render every estimate into one depth image with a z-buffer across objects (a pixel
//      belongs to the nearest estimated surface), and call a pixel *explained* by object j when
//      j's surface is the nearest there and lies within band_m of the measured depth;
//   2. the object's mask is every pixel not explained by an object already settled (higher
//      weight first); its current pose is weighed against that mask (SceneInput::mask: masked-
//      out pixels are neither inliers nor in N_depth, and hide what lies behind them);
//   3. when that weight falls short of the object's own by more than conflict_drop (a better
//      estimate claims its pixels: two estimates on one object), the object is estimated again
//      on the masked scene, and the new pose replaces the old one where it weighs more there;
//   4. the object is settled: its pixels are taken from the objects after it.
// Units: metres; poses object → camera. Deterministic given the options' seed.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/filter_options.h"
#include "posefilter/mesh.h"
#include "posefilter/option_rows.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/prepared_model.h"
#include "posefilter/prior.h"

namespace posefilter {

struct ScenePassOptions {
  // A pixel is explained by an estimate whose rendered depth lies within this of the measured
  // depth, metres, > 0.
  double band_m = 0.01;
  // Re-estimate an object whose weight, with the pixels better estimates explain masked out,
  // is this much below its own weight (eq. 7.4 [ALGORITHM.md] units), (0, 1].
  double conflict_drop = 0.1;
  bool IsValid(std::string* why) const;
};

// ScenePassOptions' fields as rows (posefilter/option_rows.h): CLI flag, Python keyword, range,
// help. IsValid checks the ranges of these rows.
std::span<const OptionInfo> ScenePassOptionTable();

// One estimated object of the scene: its mesh (metres), its class in the prior, the
// per-object estimate (EstimatePose's result with the same scene, prior and options), and
// optionally the mesh prepared once (PrepareModel of *mesh, shared with the per-object
// estimate; null: the pass's weighing and re-estimate prepare the mesh for themselves).
struct SceneObject {
  const Mesh* mesh = nullptr;
  int cls = 0;
  EstimateResult estimate;
  std::shared_ptr<const PreparedModel> model = nullptr;
};

struct ScenePassResult {
  EstimateResult estimate;      // the object's estimate after the pass (T_cam_obj, pose_base, cell)
  // Its weight before the pass: the per-object estimate's (with render.lod_face_px, its pose
  // weighed again in the whole frame, at the stride of its own depth).
  double weight_alone = 0;
  double weight_masked = 0;     // its weight against the pixels better estimates leave it
  bool reestimated = false;     // step 3 ran
  bool replaced = false;        // step 3's pose replaced the per-object one
  double time_ms = 0;           // the pass's wall time for this object
};

// The pass over `objects` (results in the objects' order). `scene` must not hold a mask or
// seeds; `options` are those of the per-object estimates (the re-estimates use them, with a
// seed derived from options.seed and the object's index). Throws Error on invalid options,
// a null mesh, a class out of range, or an invalid scene.
std::vector<ScenePassResult> RunScenePass(const SceneInput& scene, const Prior& prior, const std::vector<SceneObject>& objects,
                                          const FilterOptions& options, const ScenePassOptions& pass = {});
// The same on a frame prepared once (PrepareFrame, posefilter/prepared_frame.h, with the
// options' support.plane): its weighings and re-estimates share the frame's support surfaces
// instead of finding them again. The same results, bit for bit.
std::vector<ScenePassResult> RunScenePass(const PreparedFrame& frame, const Prior& prior,
                                          const std::vector<SceneObject>& objects, const FilterOptions& options,
                                          const ScenePassOptions& pass = {});

}  // namespace posefilter
