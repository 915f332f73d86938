// filter/estimate_scene.cc — one frame's objects: per-object estimates, then the joint scene
// pass over those of the shared prior (posefilter/estimate_scene.h).
#include "posefilter/estimate_scene.h"

#include "core/option_check.h"
#include "posefilter/error.h"

namespace posefilter {

bool EstimateSceneOptions::IsValid(std::string* why) const {
  if (pass_min_objects < 1)
    return Fail(why, "pass_min_objects must be >= 1 (got " + std::to_string(pass_min_objects) + ")");
  std::string p;
  if (!pass.IsValid(&p)) return Fail(why, "pass: " + p);
  return true;
}

std::vector<SceneEstimate> EstimateScene(const SceneInput& scene, const Prior& prior,
                                         const std::vector<SceneEstimateObject>& objects, const FilterOptions& filter,
                                         const EstimateSceneOptions& options, const SceneEstimateFn& on_estimate) {
  std::string why;
  if (!options.IsValid(&why)) throw Error("invalid scene estimate option: " + why);
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (!objects[i].mesh) throw Error("estimate scene: object " + std::to_string(i) + " has no mesh");
  std::vector<SceneEstimate> out(objects.size());
  SceneInput input{scene.depth, scene.camera};
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const SceneEstimateObject& obj = objects[i];
    SceneEstimate& est = out[i];
    input.mask = obj.mask;
    input.seeds = obj.seeds;
    FilterOptions o = filter;
    if (obj.seed) o.seed = *obj.seed;
    const Prior& p = obj.own_prior ? *obj.own_prior : prior;
    try {
      est.alone = obj.model ? EstimatePose(input, *obj.model, p, obj.cls, o, obj.progress)
                            : EstimatePose(input, *obj.mesh, p, obj.cls, o, obj.progress);
      est.alone.obj = obj.mesh->name;
      est.particles = std::move(est.alone.particle_history);
      est.alone.particle_history.clear();
      est.result = est.alone;
      est.estimated = true;
    } catch (const Error& e) {
      if (!options.keep_going) throw;
      est.error = e.what();
    }
    if (on_estimate) on_estimate(i, est);
  }
  std::vector<SceneObject> shared;
  std::vector<std::size_t> index;  // shared[k] is objects[index[k]]
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (out[i].estimated && !objects[i].own_prior) {
      shared.push_back({objects[i].mesh, objects[i].cls, out[i].alone, objects[i].model});
      index.push_back(i);
    }
  if (!options.scene_pass || int(shared.size()) < options.pass_min_objects) return out;
  FilterOptions o = filter;
  if (options.pass_seed) o.seed = *options.pass_seed;
  const std::vector<ScenePassResult> passed =
      RunScenePass(SceneInput{scene.depth, scene.camera}, prior, shared, o, options.pass);
  for (std::size_t k = 0; k < passed.size(); ++k) {
    SceneEstimate& est = out[index[k]];
    est.passed = true;
    est.pass = passed[k];
    if (passed[k].replaced) {
      est.result = passed[k].estimate;
      est.result.iterations += est.alone.iterations;
    }
    est.result.time_ms = est.alone.time_ms + passed[k].time_ms;
    est.result.obj = est.alone.obj;
  }
  return out;
}

}  // namespace posefilter
