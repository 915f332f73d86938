// src/filter/driver.cc — the host-side driver steps every engine shares (driver.h): the
// annealing schedule, pixel levels and set sizes, the run-ending test, restarts, adopting a
// polished pose, the polish entry point of the hw engine, and the no-initial-mass error.
#include "filter/driver.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "filter/filter_context.h"
#include "filter/polish.h"
#include "filter/scene_prep.h"
#include "posefilter/mesh_simplify.h"

namespace posefilter::filter {

bool ParseEngine(const std::string& name, Engine* out) {
  if (name == "reference") *out = Engine::kReference;
  else if (name == "cpu") *out = Engine::kCpu;
  else if (name == "hw") *out = Engine::kHw;
  else return false;
  return true;
}

int AnnealIterations(const FilterOptions& options) {
  return options.anneal_start_m > options.inlier.thr1_m ? int(std::lround(options.anneal_fraction * options.max_iterations))
                                                         : 0;
}

int FineFactor(const FilterOptions& options, const Prior& prior, int cls, const prior::VolumeCache& volumes,
               const Camera& camera, double diameter) {
  if (!options.adaptive_resolution) return 1;
  int best = -1;
  double best_p = 0;
  for (int c = 0; c < prior.layout.CellCount(); ++c)
    if (volumes.Valid(c) && prior.Prob(c, cls) > best_p) best = c, best_p = prior.Prob(c, cls);
  if (best < 0) return 1;
  const double z = std::max((camera.base_to_camera * volumes.Get(best).Centre()).z(), options.near_m);
  const double px = diameter * std::max(camera.fx, camera.fy) / z;
  return std::clamp(int(std::ceil(px / (1.25 * options.max_window_px))), 1, 4);
}

int CoarseMeshFaces(int faces, int subsample) {
  return std::max(kCoarseMinFaces, faces / (subsample * subsample));
}

int FineParticles(const FilterOptions& options) {
  const int n = int(std::lround(options.fine_particle_fraction * options.num_particles));
  return std::min(options.num_particles, std::max(options.num_elite + 1, n));
}

double AnnealedThreshold(const FilterOptions& options, int it, int anneal_its) {
  if (it >= anneal_its) return options.inlier.thr1_m;
  return options.anneal_start_m * std::pow(options.inlier.thr1_m / options.anneal_start_m, double(it) / anneal_its);
}

bool RunEnds(const FilterOptions& options, int it, int anneal_its, const std::vector<double>& best_weights,
             bool* converged) {
  const bool final_threshold = it >= anneal_its;
  if (final_threshold && best_weights[it] >= options.confidence) *converged = true;
  const int k = options.stall_iterations;
  const bool stalled = k > 0 && it - k >= anneal_its && best_weights[it] - best_weights[it - k] < options.stall_gain;
  return *converged || stalled || it + 1 == options.max_iterations;
}

EstimateResult RunRestarts(const FilterOptions& options, const ProgressFn& progress, const RunFn& run) {
  Rng rng(options.seed);
  EstimateResult best;
  for (int k = 0; k < options.restarts; ++k) {
    Rng run_rng = options.restarts == 1 ? rng : rng.Split();
    const int offset = k * options.max_iterations;
    const double best_w = best.weight;  // of the runs before this one
    const ProgressFn run_progress = progress ? ProgressFn([&progress, offset, best_w](int it, double w) {
      progress(offset + it, std::max(w, best_w));
    }) : ProgressFn();
    EstimateResult r = run(run_rng, run_progress);
    FilterStats total = best.stats;
    total += r.stats;
    const int iterations = best.iterations + r.iterations;
    std::vector<double> history = best.best_weight_history, times = best.iteration_ms;
    history.insert(history.end(), r.best_weight_history.begin(), r.best_weight_history.end());
    times.insert(times.end(), r.iteration_ms.begin(), r.iteration_ms.end());
    const bool converged = best.converged || r.converged;
    if (k == 0 || r.weight > best.weight) best = std::move(r);
    best.stats = total;
    best.iterations = iterations;
    best.best_weight_history = std::move(history);
    best.iteration_ms = std::move(times);
    best.converged = converged;
  }
  return best;
}

void AdoptPose(EstimateResult* result, const Camera& camera, const PolishResult& p, double confidence) {
  result->pose_base = p.pose;
  result->T_cam_obj = camera.base_to_camera * PoseToTransform(p.pose);
  result->cell = p.cell;
  result->weight = p.weight;
  result->converged = result->converged || p.weight >= confidence;
}

PolishResult PolishPoses(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                         const FilterOptions& options, const std::vector<PolishSeed>& seeds, FilterStats* stats) {
  if (seeds.empty()) throw Error("polish: no seed pose");
  FilterOptions o = options;
  o.engine = "cpu";  // the host's float weighing
  Mesh lod;
  const PreparedScene prep = PrepareScene(scene, o);
  Context ctx = BuildContext(prep, MeshAtLod(mesh, o.lod_max_faces, &lod), prior, cls, o, false);
  std::vector<Particle> ps(seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if (seeds[i].cell < 0 || seeds[i].cell >= prior.layout.CellCount()) throw Error("polish: seed cell index out of range");
    ps[i].pose = seeds[i].pose;
    ps[i].cell = seeds[i].cell;
  }
  FilterStats local;
  const Particle best = Polish(ctx, ps, stats ? stats : &local);
  return {best.pose, best.cell, best.weight};
}

Error NoInitialMassError(const Prior& prior, int cls, const FilterOptions& options) {
  int with_mass = 0;
  for (int c = 0; c < prior.layout.CellCount(); ++c) with_mass += prior.Prob(c, cls) > 0;
  std::ostringstream os;
  if (with_mass == 0) {
    os << "the prior holds no probability mass for class '" << prior.classes[std::size_t(cls)] << "'";
    return Error(os.str());
  }
  os << "no prior cell of class '" << prior.classes[std::size_t(cls)] << "' has both probability and valid depth ("
     << with_mass << " cell(s) have probability, but none of their boxes holds "
     << options.heuristics.min_valid_pixels << " depth samples in (0, " << options.heuristics.max_depth_m
     << "] m): check the depth scale (--depth-scale or depth_scale=, metres per depth unit) and that the prior was made "
        "for this depth image";
  return Error(os.str());
}

}  // namespace posefilter::filter
