// Host-side steps shared by every engine (bodies in src/filter/driver.cc, beside EstimatePose):
// the annealing schedule, restarts and the final polish (the engines themselves:
// src/filter/engine_registry.h). The
// float engines use them in src/filter/particle_filter.cc; the hw engine's host driver
// (src/filter/hw_driver.cc) uses them around the C-simulated hardware runs.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/pose.h"
#include "posefilter/rng.h"
#include "filter/scene_prep.h"
#include "prior/volume_cache.h"

namespace posefilter::filter {

// Coarse-to-fine schedule (FilterOptions::anneal.start_m, anneal_fraction): the number of
// iterations whose inlier threshold is above its final value (0 = annealing off), and the
// threshold thr1 of iteration `it` (metres), falling geometrically from anneal_start_m.
int AnnealIterations(const FilterOptions& options);
double AnnealedThreshold(const FilterOptions& options, int it, int anneal_its);
// The face budget of the mesh weighed on the coarse pixel grid (FilterOptions::anneal.simplify)
// for a mesh of `faces` faces: faces / subsample², at least kCoarseMinFaces. A mesh with no
// more faces than that is weighed as it is.
inline constexpr int kCoarseMinFaces = 256;
int CoarseMeshFaces(int faces, int subsample);

// The pixel stride of the fine level (FilterOptions::render.adaptive_resolution): the smallest s in
// [1, 4] with D / s ≤ 1.25 · max_window_px, D = diameter · max(fx, fy) / z the object's
// projected diameter in pixels at the depth z of the volume centre of the class's most
// probable cell (1 when adaptive_resolution is off or no cell has a volume). Objects larger
// than the window in the image are then weighed on every s-th pixel of every s-th row, in
// windows s times as large, so the window holds the whole object.
int FineFactor(const FilterOptions& options, const Prior& prior, int cls, const prior::VolumeCache& volumes,
               const Camera& camera, double diameter);
// The mesh stride of the levels (FilterOptions::render.lod_face_px): the smallest m in [1, 4]
// with faces / m² ≤ D² / lod_face_px, D the projected diameter of FineFactor (1 when
// lod_face_px is 0 or no cell has a volume). A level of pixel stride s weighs the mesh of
// CoarseMeshFaces(faces, max(s, m)) faces (with anneal.simplify; max(1, m) without), so the
// faces of a small object in the image are at most about one per lod_face_px pixels of D².
int MeshFactor(const FilterOptions& options, const Prior& prior, int cls, const prior::VolumeCache& volumes,
               const Camera& camera, double diameter, int faces);
// The same stride for an object whose centre is z_m metres in front of the camera.
int MeshFactorAt(const FilterOptions& options, const Camera& camera, double diameter, int faces, double z_m);

// The set size once annealing is over (FilterOptions::fine_particle_fraction):
// round(fine_particle_fraction · num_particles), at least num_elite + 1, at most num_particles.
int FineParticles(const FilterOptions& options);

// Whether a run ends after iteration it (0-based) with these best weights so far (one per
// iteration): at the final threshold (it ≥ anneal_its) the best weight reached
// options.stop.confidence (*converged is set), or it rose by less than stall_gain over the last
// stall_iterations iterations (stall_iterations > 0), or it was the last iteration.
bool RunEnds(const FilterOptions& options, int it, int anneal_its, const std::vector<double>& best_weights,
             bool* converged);

// One run of an engine's filter, from initialisation to convergence, on the given random
// stream, reporting (iteration within the run, best weight) to the given progress callback.
using RunFn = std::function<EstimateResult(Rng& rng, const ProgressFn& progress)>;

// Runs options.restarts independent runs, each on its own random stream split from
// options.seed (one run: the seed's stream itself), and merges them: statistics and
// iteration counts add up, the per-iteration histories are concatenated, the run with the
// highest weight provides the pose. `progress` (may be empty) sees the iterations counted
// over all runs and the best weight any run has reached at the final inlier threshold (NaN
// before one has; ProgressFn, posefilter/filter.h). The runs after the second are skipped
// where the first two agree (RunsAgree).
EstimateResult RunRestarts(const FilterOptions& options, const ProgressFn& progress, const RunFn& run);

// Whether two runs' results found one optimum: their best poses' origins lie within
// stop.restart_agree_m (metres; 0: never) and their weights within stop.restart_agree_weight.
bool RunsAgree(const StopOptions& stop, const EstimateResult& a, const EstimateResult& b);

// A pose to polish: object → base, and the prior cell it is weighed with (its window, ρ).
struct PolishSeed {
  Pose6 pose;
  int cell = -1;
};

struct PolishResult {
  Pose6 pose;          // object → base
  int cell = -1;
  double weight = 0;   // eq. 7.4 [ALGORITHM.md] at the final inlier threshold, float (cpu engine) weighing
};

// Makes `p` the result's answer: pose, object → camera transform, cell and weight; the result
// counts as converged once the weight reaches `confidence`.
void AdoptPose(EstimateResult* result, const Camera& camera, const PolishResult& p, double confidence);

// The final polish of FilterOptions::polish (ALGORITHM.md §9) of the given seeds on the prepared
// scene, every weighing by the float `cpu` engine whatever options.engine says; options valid
// (CheckOptions). Returns the best weighed pose (a seed itself counts). Throws Error on a cell
// out of range or an empty seed list.
PolishResult PolishPoses(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                         const FilterOptions& options, const std::vector<PolishSeed>& seeds,
                         FilterStats* stats);

// The Error every engine throws when no cell of class `cls` holds both prior probability and
// a heuristic volume (valid depth inside its box): it names the class and either says the
// prior has no mass for it at all, or gives the number of cells with probability and the usual
// causes of their boxes holding no usable depth (a wrong depth scale, another image's prior).
// With `prep`, when the support plane took (nearly) every depth reading, it says that instead:
// a wall or floor filling the view leaves nothing standing on the plane.
Error NoInitialMassError(const Prior& prior, int cls, const FilterOptions& options,
                         const PreparedScene* prep = nullptr);

}  // namespace posefilter::filter
