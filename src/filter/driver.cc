// src/filter/driver.cc — EstimatePose, the one driver of every engine (engine.h; the engine's
// row of engine_registry.h makes its runs), and the host-side steps the engines share
// (driver.h): the annealing schedule, pixel levels and set sizes, the run-ending test,
// restarts, adopting a polished pose, the polish of given seeds, and the no-initial-mass error.
#include "filter/driver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "filter/engine.h"
#include "filter/engine_registry.h"
#include "filter/filter_context.h"
#include "filter/host_setup.h"
#include "filter/model_lod.h"
#include "filter/polish.h"
#include "filter/scene_prep.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/option_table.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/prepared_model.h"

namespace posefilter::filter {

int AnnealIterations(const FilterOptions& options) {
  return options.anneal.start_m > options.score.inlier.thr1_m ? int(std::lround(options.anneal.fraction * options.stop.max_iterations))
                                                         : 0;
}

namespace {

// The object's projected diameter in pixels, diameter · max(fx, fy) / z, at the depth z of the
// volume centre of the class's most probable cell with a volume; 0 when no cell has one.
double ProjectedDiameterPx(const FilterOptions& options, const Prior& prior, int cls, const prior::VolumeCache& volumes,
                           const Camera& camera, double diameter) {
  int best = -1;
  double best_p = 0;
  for (int c = 0; c < prior.layout.CellCount(); ++c)
    if (volumes.Valid(c) && prior.Prob(c, cls) > best_p) best = c, best_p = prior.Prob(c, cls);
  if (best < 0) return 0;
  const double z = std::max((camera.base_to_camera * volumes.Get(best).Centre()).z(), options.render.near_m);
  return diameter * std::max(camera.fx, camera.fy) / z;
}

// render.lod_face_px's mesh stride for an object px pixels across (1 when px is not positive):
// faces / m² ≤ px² / lod_face_px  ⇔  m ≥ sqrt(faces · lod_face_px) / px, m in [1, 4].
int StrideForDiameterPx(const FilterOptions& options, int faces, double px) {
  if (!(px > 0)) return 1;
  return std::clamp(int(std::ceil(std::sqrt(double(faces) * options.render.lod_face_px) / px)), 1, 4);
}

}  // namespace

int FineFactor(const FilterOptions& options, const Prior& prior, int cls, const prior::VolumeCache& volumes,
               const Camera& camera, double diameter) {
  if (!options.render.adaptive_resolution) return 1;
  const double px = ProjectedDiameterPx(options, prior, cls, volumes, camera, diameter);
  if (!(px > 0)) return 1;
  return std::clamp(int(std::ceil(px / (1.25 * options.render.max_window_px))), 1, 4);
}

int MeshFactor(const FilterOptions& options, const Prior& prior, int cls, const prior::VolumeCache& volumes,
               const Camera& camera, double diameter, int faces) {
  if (!(options.render.lod_face_px > 0)) return 1;
  return StrideForDiameterPx(options, faces, ProjectedDiameterPx(options, prior, cls, volumes, camera, diameter));
}

int MeshFactorAt(const FilterOptions& options, const Camera& camera, double diameter, int faces, double z_m) {
  if (!(options.render.lod_face_px > 0)) return 1;
  return StrideForDiameterPx(options, faces, diameter * std::max(camera.fx, camera.fy) / std::max(z_m, options.render.near_m));
}

int CoarseMeshFaces(int faces, int subsample) {
  return std::max(kCoarseMinFaces, faces / (subsample * subsample));
}

int FineParticles(const FilterOptions& options) {
  const int n = int(std::lround(options.fine_particle_fraction * options.num_particles));
  return std::min(options.num_particles, std::max(options.num_elite + 1, n));
}

double AnnealedThreshold(const FilterOptions& options, int it, int anneal_its) {
  if (it >= anneal_its) return options.score.inlier.thr1_m;
  return options.anneal.start_m * std::pow(options.score.inlier.thr1_m / options.anneal.start_m, double(it) / anneal_its);
}

bool RunEnds(const FilterOptions& options, int it, int anneal_its, const std::vector<double>& best_weights,
             bool* converged) {
  const bool final_threshold = it >= anneal_its;
  if (final_threshold && best_weights[it] >= options.stop.confidence) *converged = true;
  const int k = options.stop.stall_iterations;
  const bool stalled = k > 0 && it - k >= anneal_its && best_weights[it] - best_weights[it - k] < options.stop.stall_gain;
  return *converged || stalled || it + 1 == options.stop.max_iterations;
}

bool RunsAgree(const StopOptions& stop, const EstimateResult& a, const EstimateResult& b) {
  const Eigen::Vector3d d(a.pose_base.x - b.pose_base.x, a.pose_base.y - b.pose_base.y, a.pose_base.z - b.pose_base.z);
  return stop.restart_agree_m > 0 && d.norm() < stop.restart_agree_m &&
         std::fabs(a.weight - b.weight) < stop.restart_agree_weight;
}

EstimateResult RunRestarts(const FilterOptions& options, const ProgressFn& progress, const RunFn& run) {
  Rng rng(options.seed);
  EstimateResult best;
  // The best weight any run has reached at the final inlier threshold (NaN: none yet). Weights
  // of annealing iterations are measured at a looser threshold and are not comparable.
  const int anneal_its = AnnealIterations(options);
  double final_best = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < options.restarts; ++k) {
    Rng run_rng = options.restarts == 1 ? rng : rng.Split();
    const int offset = k * options.stop.max_iterations;
    const ProgressFn run_progress =
        progress ? ProgressFn([&progress, &final_best, offset, anneal_its](int it, double w) {
          if (it >= anneal_its && !(w <= final_best)) final_best = w;
          progress(offset + it, final_best);
        })
                 : ProgressFn();
    EstimateResult r = run(run_rng, run_progress);
    // The first two runs found one optimum: further runs would most likely find it again.
    const bool agree = k == 1 && RunsAgree(options.stop, best, r);
    FilterStats total = best.stats;
    total += r.stats;
    const int iterations = best.iterations + r.iterations;
    std::vector<double> history = best.best_weight_history, times = best.iteration_ms;
    history.insert(history.end(), r.best_weight_history.begin(), r.best_weight_history.end());
    times.insert(times.end(), r.iteration_ms.begin(), r.iteration_ms.end());
    std::vector<ParticleSet> particles = std::move(best.particle_history);
    for (ParticleSet& set : r.particle_history) {
      set.run = k;
      particles.push_back(std::move(set));
    }
    const bool converged = best.converged || r.converged;
    if (k == 0 || r.weight > best.weight) best = std::move(r);
    best.stats = total;
    best.iterations = iterations;
    best.best_weight_history = std::move(history);
    best.iteration_ms = std::move(times);
    best.particle_history = std::move(particles);
    best.converged = converged;
    if (agree) break;
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

PolishResult PolishPoses(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                         const FilterOptions& options, const std::vector<PolishSeed>& seeds, FilterStats* stats) {
  if (seeds.empty()) throw Error("polish: no seed pose");
  FilterOptions o = options;
  o.engine = "cpu";  // the host's float weighing
  // The caller's scene, borrowed for this call (an owner-less pointer: nothing to free).
  const std::shared_ptr<const PreparedScene> borrowed(std::shared_ptr<void>(), &prep);
  const Context ctx = BuildContext(borrowed, LodFor(nullptr, mesh, o, false, prep.plane.found), prior, cls, o, false);
  std::vector<Particle> ps(seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if (seeds[i].cell < 0 || seeds[i].cell >= prior.layout.CellCount()) throw Error("polish: seed cell index out of range");
    ps[i].pose = seeds[i].pose;
    ps[i].cell = seeds[i].cell;
  }
  FilterStats local;
  Scratch scratch = MakeScratch(ctx);
  const Particle best = Polish(ctx, scratch, ps, stats ? stats : &local);
  return {best.pose, best.cell, best.weight};
}

Error NoInitialMassError(const Prior& prior, int cls, const FilterOptions& options, const PreparedScene* prep) {
  int with_mass = 0;
  for (int c = 0; c < prior.layout.CellCount(); ++c) with_mass += prior.Prob(c, cls) > 0;
  std::ostringstream os;
  if (with_mass == 0) {
    os << "the prior holds no probability mass for class '" << prior.classes[std::size_t(cls)] << "'";
    return Error(os.str());
  }
  // 90 % or more of the readings on one plane: the plane, not the scale, emptied the boxes.
  if (prep != nullptr && prep->plane.found && prep->valid_pixels > 0 &&
      double(prep->plane_pixels) >= 0.9 * double(prep->valid_pixels)) {
    os << "no prior cell of class '" << prior.classes[std::size_t(cls)] << "' has valid depth off the support plane: "
       << std::lround(100.0 * double(prep->plane_pixels) / double(prep->valid_pixels))
       << " % of the depth readings lie on one plane (a wall or floor filling the view?), which is removed as the "
          "surface objects stand on, so nothing is left to estimate; --no-support-plane (support_plane=False) keeps it";
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

namespace posefilter {

namespace {

// EstimatePose on a prepared scene with the mesh's prepared model (null: prepared on the fly
// for the float engines); options checked, t_start the call's start.
EstimateResult EstimateOn(const std::shared_ptr<const filter::PreparedScene>& prep, const PreparedModel* model, const Mesh& mesh,
                          const Prior& prior, int cls, const FilterOptions& options, const ProgressFn& progress,
                          filter::Clock::time_point t_start) {
  const Camera camera = prep->scoring.camera;
  // A known name (checked above); the row makes the engine's runs.
  const filter::EngineRow* engine = filter::FindEngine(options.engine);
  const std::unique_ptr<filter::EngineRuns> runs =
      engine->make_runs(filter::EngineInputs{prep, model, mesh, prior, cls, options});
  // Independent runs (restarts), each with its own random stream; the best weight wins.
  EstimateResult best = filter::RunRestarts(options, progress, [&](Rng& rng, const ProgressFn& run_progress) {
    return runs->Run(rng, run_progress);
  });
  if (options.polish.steps > 0) {
    const filter::PolishResult p = runs->PolishRuns(&best.stats);
    if (runs->PolishReplacesRuns() || p.weight > best.weight) filter::AdoptPose(&best, camera, p, options.stop.confidence);
  }
  best.obj = mesh.name;
  best.time_ms = filter::MsSince(t_start);
  return best;
}

// EstimatePose on a scene: prepared for this estimate.
EstimateResult Estimate(const SceneInput& scene, const PreparedModel* model, const Mesh& mesh, const Prior& prior,
                        int cls, const FilterOptions& options, const ProgressFn& progress) {
  const auto t_start = filter::Clock::now();
  ThrowIfInvalid(options, OptionNaming::kField);
  auto prep = std::make_shared<const filter::PreparedScene>(filter::PrepareScene(scene, options));
  return EstimateOn(prep, model, mesh, prior, cls, options, progress, t_start);
}

// EstimatePose on a prepared frame and an object's mask and seeds.
EstimateResult EstimateFrame(const PreparedFrame& frame, const ObjectInput& object, const PreparedModel* model,
                             const Mesh& mesh, const Prior& prior, int cls, const FilterOptions& options,
                             const ProgressFn& progress) {
  const auto t_start = filter::Clock::now();
  ThrowIfInvalid(options, OptionNaming::kField);
  return EstimateOn(filter::SceneFor(frame, object, options), model, mesh, prior, cls, options, progress, t_start);
}

}  // namespace

EstimateResult EstimatePose(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress) {
  return Estimate(scene, nullptr, mesh, prior, cls, options, progress);
}

EstimateResult EstimatePose(const SceneInput& scene, const PreparedModel& model, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress) {
  return Estimate(scene, &model, model.mesh(), prior, cls, options, progress);
}

EstimateResult EstimatePose(const PreparedFrame& frame, const ObjectInput& object, const PreparedModel& model,
                            const Prior& prior, int cls, const FilterOptions& options, const ProgressFn& progress) {
  return EstimateFrame(frame, object, &model, model.mesh(), prior, cls, options, progress);
}

EstimateResult EstimatePose(const PreparedFrame& frame, const ObjectInput& object, const Mesh& mesh, const Prior& prior,
                            int cls, const FilterOptions& options, const ProgressFn& progress) {
  return EstimateFrame(frame, object, nullptr, mesh, prior, cls, options, progress);
}

}  // namespace posefilter
