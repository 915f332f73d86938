// src/filter/engine.h — the one interface every engine's runs implement behind EstimatePose.
//
// EstimatePose (driver.cc) validates the options and prepares the scene once (scene_prep.h),
// looks FilterOptions::engine up in the engine registry (engine_registry.h), has the engine's
// row make its runs from the shared host set-up (host_setup.h), runs options.restarts of them
// (RunRestarts) and ends with the engine's final polish (polish.h). An engine's runs supply
// only what differs:
//   - Run: one run of the filter, initialisation to convergence, on a given random stream;
//   - PolishRuns: the final polish of what its runs found.
// Two levels: the float engines (`reference`, `cpu`, `gpu`) share one EngineRuns, the float
// filter (particle_filter.cc), and differ only in the ParticleWeigher it weighs each batch with
// (engine_weigh.h); the `hw` and `rtl` engines run whole runs of their own (hw_driver.cc, the
// C-simulated hardware), and differ only in the HwWeighStrategy those runs weigh with
// (hw_weigh.h: the C model, or the Verilated RTL). docs/ARCHITECTURE.md, "Engines".
#pragma once

#include <memory>
#include <string>

#include "filter/driver.h"
#include "filter/model_lod.h"
#include "filter/scene_prep.h"
#include "posefilter/filter.h"
#include "posefilter/rng.h"

namespace posefilter::filter {

class EngineRuns {
 public:
  virtual ~EngineRuns() = default;
  // One run from initialisation to convergence on `rng`; `progress` (may be empty) sees
  // (iteration within the run, best weight of the run so far). Remembers what the final
  // polish starts from.
  virtual EstimateResult Run(Rng& rng, const ProgressFn& progress) = 0;
  // The final polish (options.polish.steps > 0) of what the runs so far found: the best pose
  // and its float weight (eq. 7.4 [ALGORITHM.md] at the final inlier threshold); counters into *stats.
  virtual PolishResult PolishRuns(FilterStats* stats) = 0;
  // Whether the polished pose is the answer even when its weight is below the runs' best: the
  // hw engine's runs weigh in fixed point, which the float weight does not compare with.
  virtual bool PolishReplacesRuns() const { return false; }
};

// The engine's runs for one estimate on the prepared scene (PrepareScene, with the same
// options). The float engines share the scene and the mesh's level of detail (LodFor, holding
// what their options read); `prior` outlives the result. The hw engine takes the mesh itself
// (it makes its own hardware mesh); `prep`, `mesh` and `prior` outlive its result. Throws
// Error on inputs the engine cannot take.
std::unique_ptr<EngineRuns> MakeFloatEngine(const std::shared_ptr<const PreparedScene>& prep,
                                            std::shared_ptr<const ModelLod> model, const Prior& prior, int cls,
                                            const FilterOptions& options);  // particle_filter.cc
std::unique_ptr<EngineRuns> MakeHwEngine(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                         const FilterOptions& options);  // hw_driver.cc
// Whether this build has the hw engine (CMake option POSEFILTER_HW; hw_driver.cc), else *why
// (may be null) says why not (hw_engine_none.cc, where MakeHwEngine throws that reason).
bool HwEngineBuilt(std::string* why);

}  // namespace posefilter::filter
