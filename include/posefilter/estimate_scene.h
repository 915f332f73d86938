// posefilter/estimate_scene.h — the estimates of one frame's objects: each object estimated on
// its own (EstimatePose, posefilter/filter.h), then the joint scene pass over those that share
// the frame's prior (RunScenePass, posefilter/scene_pass.h).
//
// An object with a prior of its own (a mask's instance) is estimated with it and its mask and
// does not join the pass; an object of the shared prior may carry pose seeds (the stage 1's,
// posefilter/stage1.h). The pass runs on the frame without mask or seeds, with the options'
// seed (or pass_seed), when at least pass_min_objects objects of the shared prior have an
// estimate. Units: metres; poses object → camera. Deterministic given the seeds.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/filter_options.h"
#include "posefilter/mesh.h"
#include "posefilter/prepared_model.h"
#include "posefilter/prior.h"
#include "posefilter/scene_pass.h"

namespace posefilter {

// One object of the frame.
struct SceneEstimateObject {
  const Mesh* mesh = nullptr;                          // metres; named
  std::shared_ptr<const PreparedModel> model = nullptr;  // PrepareModel(*mesh), optional (estimate and pass use it)
  int cls = -1;                                        // its class index in its prior
  const Prior* own_prior = nullptr;                    // null: the frame's shared prior
  std::vector<std::uint8_t> mask;                      // with own_prior: its instance's pixels (SceneInput::mask)
  std::vector<PoseSeed> seeds;                         // its pose seeds (SceneInput::seeds)
  std::optional<std::uint64_t> seed;                   // its estimate's seed (default: the options' seed)
  ProgressFn progress = nullptr;                       // its estimate's progress (EstimatePose)
};

struct EstimateSceneOptions {
  bool scene_pass = true;     // run the joint scene pass
  // The pass runs when at least this many objects of the shared prior have an estimate, ≥ 1.
  int pass_min_objects = 2;
  std::optional<std::uint64_t> pass_seed;  // the pass's seed (default: the filter options' seed)
  ScenePassOptions pass;
  // An object whose estimate throws Error is reported (SceneEstimate::error) and left out
  // instead of the Error ending the call.
  bool keep_going = false;
  bool IsValid(std::string* why) const;
};

// What became of one object.
struct SceneEstimate {
  bool estimated = false;       // false: keep_going caught `error`
  std::string error;
  EstimateResult alone;         // the per-object estimate (its particle_history moved to `particles`)
  std::vector<ParticleSet> particles;  // the per-object estimate's recorded particle sets
  bool passed = false;          // the scene pass weighed it
  ScenePassResult pass;         // its result (when passed)
  // The object's final estimate: `alone`, or where the pass replaced it the pass's estimate
  // with the iterations of both; time_ms is the per-object estimate's plus the pass's (which
  // holds its re-estimate's); obj is the mesh's name; particle_history only the re-estimate's
  // (the per-object sets are in `particles`).
  EstimateResult result;
};

// Called after each object's own estimate (or its caught error), before the next one: the
// object's index and what it gave so far (`result` = `alone`).
using SceneEstimateFn = std::function<void(std::size_t, const SceneEstimate&)>;

// Estimates `objects` on `scene` (its mask and seeds are ignored; each object's are used)
// with `prior` as the shared prior and `filter` as the options, then the scene pass. Results
// in the objects' order. Throws Error on invalid options, a null mesh, and (without
// keep_going) the estimates' errors.
std::vector<SceneEstimate> EstimateScene(const SceneInput& scene, const Prior& prior,
                                         const std::vector<SceneEstimateObject>& objects, const FilterOptions& filter,
                                         const EstimateSceneOptions& options = {},
                                         const SceneEstimateFn& on_estimate = nullptr);

}  // namespace posefilter
