// src/filter/scene_pass.cc — RunScenePass (posefilter/scene_pass.h): the per-object estimates
// settled best first against a z-buffer of the objects settled before them.
#include "posefilter/scene_pass.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>

#include "filter/scene_prep.h"
#include "posefilter/error.h"
#include "posefilter/option_table.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/render.h"

namespace posefilter {

std::vector<ScenePassResult> RunScenePass(const SceneInput& scene, const Prior& prior, const std::vector<SceneObject>& objects,
                                          const FilterOptions& options, const ScenePassOptions& pass) {
  std::string why;
  if (!pass.IsValid(&why)) throw Error("invalid scene pass option: " + why);
  ThrowIfInvalid(options, OptionNaming::kField);
  ValidateScene(scene, "scene pass");
  if (!scene.mask.empty() || !scene.seeds.empty()) throw Error("scene pass: the scene must hold no mask and no seeds");
  // The frame prepared once for every weighing and re-estimate (checked above).
  SceneInput input{scene.depth, scene.camera};
  auto prep = std::make_shared<const filter::PreparedScene>(filter::FrameScene(input, options.support.plane));
  return RunScenePass(PreparedFrame(std::move(input), options.support.plane, std::move(prep)), prior, objects, options,
                      pass);
}

std::vector<ScenePassResult> RunScenePass(const PreparedFrame& frame, const Prior& prior,
                                          const std::vector<SceneObject>& objects, const FilterOptions& options,
                                          const ScenePassOptions& pass) {
  using Clock = std::chrono::steady_clock;
  std::string why;
  if (!pass.IsValid(&why)) throw Error("invalid scene pass option: " + why);
  ThrowIfInvalid(options, OptionNaming::kField);
  const SceneInput& scene = frame.frame();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (!objects[i].mesh) throw Error("scene pass: object " + std::to_string(i) + " has no mesh");
    if (objects[i].cls < 0 || objects[i].cls >= int(prior.classes.size()))
      throw Error("scene pass: object " + std::to_string(i) + "'s class index is out of range");
  }
  const Camera& cam = scene.camera;
  const DepthImage& z = scene.depth;
  std::vector<std::size_t> order(objects.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return objects[a].estimate.weight > objects[b].estimate.weight; });

  // The objects settled so far, rendered with one z-buffer, and the pixels they explain (mask 0).
  DepthImage settled(cam.width, cam.height, 0.f);
  ObjectInput masked{std::vector<std::uint8_t>(z.data.size(), 1)};
  std::vector<ScenePassResult> out(objects.size());
  for (std::size_t idx : order) {
    const auto t0 = Clock::now();
    const SceneObject& obj = objects[idx];
    ScenePassResult& r = out[idx];
    r.estimate = obj.estimate;
    const std::vector<std::pair<Pose6, int>> hyp = {{obj.estimate.pose_base, obj.estimate.cell}};
    // The caller's prepared model, or the mesh prepared for each call (only what it reads).
    auto weigh = [&](const ObjectInput& in, const std::vector<std::pair<Pose6, int>>& poses) {
      return obj.model ? WeighPoses(frame, in, *obj.model, prior, obj.cls, options, poses)[0]
                       : WeighPoses(frame, in, *obj.mesh, prior, obj.cls, options, poses)[0];
    };
    // With a level of detail by size (render.lod_face_px) the estimate weighed its mesh at its
    // most probable cell's stride; the pose is weighed again, unmasked, at the stride of its own
    // depth, the one every weighing below uses, so that the drop compares one mesh.
    const bool by_size = options.render.lod_face_px > 0;
    r.weight_alone = by_size ? weigh(ObjectInput{}, hyp) : obj.estimate.weight;
    const bool any_free = std::find(masked.mask.begin(), masked.mask.end(), 1) != masked.mask.end();
    r.weight_masked = !any_free ? 0.0 : weigh(masked, hyp);
    if (any_free && r.weight_alone - r.weight_masked > pass.conflict_drop) {
      // Better estimates explain this one's pixels: look again where they leave room.
      FilterOptions o = options;
      o.seed = options.seed ^ (0x9E3779B97F4A7C15ull * (idx + 1));
      r.reestimated = true;
      try {
        const EstimateResult e = obj.model ? EstimatePose(frame, masked, *obj.model, prior, obj.cls, o)
                                           : EstimatePose(frame, masked, *obj.mesh, prior, obj.cls, o);
        const double e_weight = by_size ? weigh(masked, {{e.pose_base, e.cell}}) : e.weight;
        if (e_weight > r.weight_masked) {
          r.estimate = e;
          r.weight_masked = e_weight;
          r.replaced = true;
        }
      } catch (const Error&) {
        // No cell of the class holds free depth: the per-object pose stays.
      }
      r.estimate.obj = obj.estimate.obj;
    }
    // Settle it: its surface takes the pixels it explains from the objects after it.
    RenderDepth(*obj.mesh, r.estimate.T_cam_obj, cam, &settled);
    for (std::size_t p = 0; p < settled.data.size(); ++p)
      if (settled.data[p] > 0 && z.data[p] > 0 && std::fabs(settled.data[p] - z.data[p]) < pass.band_m) masked.mask[p] = 0;
    r.time_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }
  return out;
}

}  // namespace posefilter
