// The particle filter, `reference` engine (SPEC §6; thesis §2.2, §7.4–7.6, App. B).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <array>
#include <map>
#include <sstream>

#include "filter/cdf_sampler.h"
#include "filter/diffusion.h"
#include "filter/online_sorter.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/rng.h"

namespace posefilter {
namespace {

using filter::Particle;

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}



// Counts valid depth pixels in any rectangle in O(1) (summed-area table of the valid mask).
class ValidDepthCounter {
 public:
  explicit ValidDepthCounter(const DepthImage& d) : w_(d.width + 1), sat_(std::size_t(d.width + 1) * (d.height + 1), 0) {
    for (int v = 0; v < d.height; ++v) {
      long row = 0;
      for (int u = 0; u < d.width; ++u) {
        row += d.at(u, v) > 0 ? 1 : 0;
        sat_[std::size_t(v + 1) * w_ + (u + 1)] = sat_[std::size_t(v) * w_ + (u + 1)] + row;
      }
    }
  }
  long Count(const PixelRect& r) const {
    auto at = [&](int u, int v) { return sat_[std::size_t(v) * w_ + u]; };
    return at(r.u0 + r.width, r.v0 + r.height) - at(r.u0, r.v0 + r.height) -
           at(r.u0 + r.width, r.v0) + at(r.u0, r.v0);
  }

 private:
  int w_;
  std::vector<long> sat_;
};

// The particle's window (§7.5.3, SPEC §6.2): the cell's box centred on the box centre, each
// side at least min_side (the object's projected diameter, so a box smaller than the object
// cannot truncate its rendering) and at most max_px, then shifted ("saturated") to lie inside
// the image.
PixelRect CellWindow(const Box& box, double min_side, int max_px, int image_w, int image_h) {
  PixelRect r;
  r.width = std::clamp(int(std::lround(std::max(box.w, min_side))), 1, std::min(max_px, image_w));
  r.height = std::clamp(int(std::lround(std::max(box.h, min_side))), 1, std::min(max_px, image_h));
  r.u0 = std::clamp(int(std::lround(box.cx - 0.5 * r.width)), 0, image_w - r.width);
  r.v0 = std::clamp(int(std::lround(box.cy - 0.5 * r.height)), 0, image_h - r.height);
  return r;
}

// Coarse orientation class of a pose for niching: which signed axis of the base frame the
// object's z axis points along most (6) × which of the 4 remaining signed axes its x axis
// points along most — the 24 rotations of a cube, so a quarter or half turn changes the bin.
constexpr int kRotationBins = 24;
int RotationBin(const Pose6& pose) {
  const Eigen::Matrix3d R = PoseToTransform(pose).linear();
  auto signed_axis = [](const Eigen::Vector3d& v, int exclude) {
    int best = exclude == 0 ? 1 : 0;
    for (int a = 0; a < 3; ++a)
      if (a != exclude && std::fabs(v[a]) > std::fabs(v[best])) best = a;
    return std::pair<int, int>{best, v[best] < 0 ? 1 : 0};
  };
  const auto [za, zs] = signed_axis(R.col(2), -1);
  const auto [xa, xs] = signed_axis(R.col(0), za);
  const int x_slot = (xa > za ? xa - 1 : xa);  // 0 or 1 among the two axes left
  return (za * 2 + zs) * 4 + x_slot * 2 + xs;
}

// Everything one run needs that does not change between iterations.
struct Context {
  const SceneInput& scene;
  const Mesh& mesh;
  const Prior& prior;
  int cls;
  const FilterOptions& opt;
  std::vector<Volume> volumes;       // heuristic volume per cell (base frame)
  std::vector<PixelRect> windows;    // window per cell
  std::vector<long> n_depth;         // valid depth pixels per window
  InlierParams inlier;               // this iteration's inlier thresholds (annealed)
  std::vector<float> normals;        // scene normals, 3 per pixel, camera frame (0 = none)
  std::vector<int> hypothesis;       // niching: cells sharing one decoded box share an id
  int hypothesis_count = 0;
};

// Listing 7.5: x, y at the volume centre, z uniform in [z_min, z_max]; angles uniform in ±π.
Particle NewParticle(const Context& ctx, int cell, Rng& rng) {
  const Volume& vol = ctx.volumes[cell];
  Particle p;
  p.cell = cell;
  const Eigen::Vector3d c = vol.Centre();
  p.pose.x = c.x();
  p.pose.y = c.y();
  p.pose.z = rng.Uniform(vol.min.z(), vol.max.z());
  p.pose.roll = rng.Uniform(-M_PI, M_PI);
  p.pose.pitch = rng.Uniform(-M_PI, M_PI);
  p.pose.yaw = rng.Uniform(-M_PI, M_PI);
  return p;
}

// Weight of eq. 7.4 for one particle; `ws` is the calling worker's own scratch memory.
double Weigh(const Context& ctx, const Particle& p, RenderWorkspace* ws, ScoreKernelResult* out) {
  const Camera& cam = ctx.scene.camera;
  const Eigen::Isometry3d T = cam.base_to_camera * PoseToTransform(p.pose);  // FT without P
  ScoreKernelParams k = MakeKernelParams(ctx.mesh, T, cam);
  k.near_m = float(ctx.opt.near_m);
  k.window = ctx.windows[p.cell];
  k.depth = ctx.scene.depth.data.data();
  k.depth_width = ctx.scene.depth.width;
  k.depth_height = ctx.scene.depth.height;
  k.inlier = ctx.inlier;
  k.zbuffer = ctx.opt.zbuffer;
  k.align_band_m = float(ctx.opt.align_band_m);
  k.edge_band_m = float(ctx.opt.edge_band_m);
  k.scene_normals = ctx.normals.data();
  *out = ScoreReference(k, ws);
  const double I = out->inlier_sum;
  // Without a z-buffer fragments may overlap, so each ratio is capped at 1.
  const std::int64_t n_raster = ctx.opt.occlusion_aware ? out->n_raster - out->n_occluded : out->n_raster;
  const double r_raster = n_raster > 0 ? std::min(1.0, I / double(n_raster)) : 0.0;
  const long nd = ctx.n_depth[p.cell];
  const double r_depth = nd > 0 ? std::min(1.0, I / double(nd)) : 0.0;
  const double rho = ctx.prior.Prob(p.cell, ctx.cls);
  const double r_edge = out->n_edge > 0 ? double(out->n_edge_continued) / double(out->n_edge) : 0.0;
  return std::max(0.0, ctx.opt.alpha * r_raster + ctx.opt.beta * r_depth + ctx.opt.gamma * rho - ctx.opt.delta * r_edge);
}

// Weighs every particle not yet scored (threads over particles; each owns a workspace).
void WeighAll(const Context& ctx, std::vector<Particle>& ps, FilterStats* stats) {
  const int n = int(ps.size());
  std::int64_t faces_total = 0, faces_front = 0, fragments = 0, weighings = 0;
  const int threads = ctx.opt.threads > 0 ? ctx.opt.threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads) reduction(+ : faces_total, faces_front, fragments, weighings)
  {
    RenderWorkspace ws;
#pragma omp for schedule(dynamic, 4)
    for (int i = 0; i < n; ++i) {
      if (ps[i].scored) continue;
      ScoreKernelResult r;
      ps[i].weight = Weigh(ctx, ps[i], &ws, &r);
      ps[i].depth_offset = r.depth_diff_count > 0 ? r.depth_diff_sum / double(r.depth_diff_count) : 0.0;
      ps[i].icp_valid = filter::SolveIcpStep(r, &ps[i].icp_step);
      ps[i].scored = true;
      faces_total += r.faces_total;
      faces_front += r.faces_front;
      fragments += r.n_raster;
      ++weighings;
    }
  }
  stats->faces_total += faces_total;
  stats->faces_front += faces_front;
  stats->fragments += fragments;
  stats->weighings += weighings;
}

}  // namespace

bool FilterOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (engine != "reference") return fail("engine must be 'reference' (got '" + engine + "')");
  if (num_particles < 2 || num_particles > 1'000'000) return fail("num_particles must be in [2, 1000000]");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(confidence > 0 && confidence <= 1)) return fail("confidence must be in (0, 1]");
  for (double v : {alpha, beta, gamma})
    if (!(v >= 0 && v <= 1)) return fail("alpha, beta, gamma must each be in [0, 1]");
  if (std::fabs(alpha + beta + gamma - 1) > 1e-6) return fail("alpha + beta + gamma must equal 1");
  if (!(inlier.thr1_m > 0 && std::isfinite(inlier.thr1_m))) return fail("inlier threshold must be > 0");
  if (!(inlier.hard_thr_m > 0 && std::isfinite(inlier.hard_thr_m))) return fail("hard inlier threshold must be > 0");
  if (!(anneal_start_m >= 0 && std::isfinite(anneal_start_m))) return fail("anneal_start_m must be >= 0");
  if (!(anneal_fraction >= 0 && anneal_fraction <= 1)) return fail("anneal_fraction must be in [0, 1]");
  if (!(min_window_diameters >= 0 && min_window_diameters <= 4)) return fail("min_window_diameters must be in [0, 4]");
  if (max_window_px < 8) return fail("max_window_px must be >= 8");
  if (!(near_m > 0 && std::isfinite(near_m))) return fail("near_m must be > 0");
  if (num_elite < 0 || num_elite >= num_particles) return fail("num_elite must be in [0, num_particles)");
  if (!(resample_pool > 0 && resample_pool <= 1)) return fail("resample_pool must be in (0, 1]");
  if (!(region_cap > 0 && region_cap <= 1)) return fail("region_cap must be in (0, 1]");
  if (!(rotation_cap > 0 && rotation_cap <= 1)) return fail("rotation_cap must be in (0, 1]");
  if (!(delta >= 0 && delta <= 1)) return fail("delta must be in [0, 1]");
  if (!(edge_band_m > 0 && std::isfinite(edge_band_m))) return fail("edge_band_m must be > 0");
  if (!(align_band_m > 0 && std::isfinite(align_band_m))) return fail("align_band_m must be > 0");
  if (init_oversample < 1 || init_oversample > 64) return fail("init_oversample must be in [1, 64]");
  if (restarts < 1 || restarts > 100) return fail("restarts must be in [1, 100]");
  if (tracker_bins < 1 || tracker_bins > 4096) return fail("tracker_bins must be in [1, 4096]");
  if (!(sigma_t0_m >= 0 && std::isfinite(sigma_t0_m))) return fail("sigma_t0_m must be >= 0");
  if (!(sigma_r0_rad >= 0 && std::isfinite(sigma_r0_rad))) return fail("sigma_r0_rad must be >= 0");
  if (!(min_sigma_fraction >= 0 && min_sigma_fraction <= 1)) return fail("min_sigma_fraction must be in [0, 1]");
  double total = 0;
  for (double p : move_probabilities) {
    if (!(p >= 0 && std::isfinite(p))) return fail("move probabilities must be finite and >= 0");
    total += p;
  }
  if (!(total > 0)) return fail("at least one move probability must be > 0");
  if (threads < 0) return fail("threads must be >= 0");
  std::string h;
  if (!heuristics.IsValid(&h)) return fail("heuristics: " + h);
  return true;
}

void ValidateScene(const SceneInput& scene, const std::string& what) {
  std::string why;
  if (!scene.camera.IsValid(&why)) throw Error(what + ": invalid camera: " + why);
  const DepthImage& d = scene.depth;
  if (d.width != scene.camera.width || d.height != scene.camera.height) {
    std::ostringstream os;
    os << what << ": depth image is " << d.width << "x" << d.height << " but the camera is "
       << scene.camera.width << "x" << scene.camera.height;
    throw Error(os.str());
  }
  if (d.data.size() != std::size_t(d.width) * d.height) throw Error(what + ": depth buffer size mismatch");
  std::size_t valid = 0;
  for (float z : d.data) {
    if (!std::isfinite(z) || z < 0) throw Error(what + ": depth holds NaN, inf or negative values");
    valid += z > 0;
  }
  if (valid == 0) throw Error(what + ": depth image has no valid pixel (all zero)");
}

namespace {

// Checks the inputs and precomputes volumes, windows and N_depth for every cell.
Context BuildContext(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                     const FilterOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw Error("invalid filter option: " + why);
  if (!mesh.IsValid(&why)) throw Error("mesh '" + mesh.name + "': " + why);
  ValidateScene(scene, "scene");
  if (cls < 0 || cls >= int(prior.classes.size())) throw Error("class index out of range for the prior");
  if (prior.layout.image_width != scene.camera.width || prior.layout.image_height != scene.camera.height)
    throw Error("prior was made for a different image size than the camera's");

  Context ctx{scene, mesh, prior, cls, options, {}, {}, {}, options.inlier, ComputeSceneNormals(scene.depth, scene.camera), {}, 0};
  const double diameter = mesh.Diameter();
  HeuristicOptions hopt = options.heuristics;
  if (hopt.depth_extension_m == 0) hopt.depth_extension_m = 0.5 * diameter;
  ctx.volumes = ComputeHeuristics(scene.depth, scene.camera, prior.boxes, hopt);
  const int cells = prior.layout.CellCount();
  const ValidDepthCounter counter(scene.depth);
  ctx.windows.resize(cells);
  ctx.n_depth.resize(cells);
  for (int c = 0; c < cells; ++c) {
    // The object's diameter in pixels at the depth of the cell's volume centre.
    const double z_cam = ctx.volumes[c].valid ? (scene.camera.base_to_camera * ctx.volumes[c].Centre()).z() : 1.0;
    const double min_side = options.min_window_diameters * diameter * scene.camera.fx / std::max(z_cam, options.near_m);
    ctx.windows[c] = CellWindow(prior.boxes[c], min_side, options.max_window_px, scene.camera.width, scene.camera.height);
    ctx.n_depth[c] = counter.Count(ctx.windows[c]);
  }
  // Hypotheses for niching: cells whose decoded boxes agree to the pixel share one (all the
  // cells a detection covers carry its box; a cell no detection reaches keeps its anchor).
  std::map<std::array<long, 4>, int> ids;
  ctx.hypothesis.resize(cells);
  for (int c = 0; c < cells; ++c) {
    const Box& b = prior.boxes[c];
    const std::array<long, 4> key = {std::lround(b.cx), std::lround(b.cy), std::lround(b.w), std::lround(b.h)};
    ctx.hypothesis[c] = ids.emplace(key, int(ids.size())).first->second;
  }
  ctx.hypothesis_count = int(ids.size());
  return ctx;
}

}  // namespace

std::vector<double> WeighPoses(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                               const FilterOptions& options, const std::vector<std::pair<Pose6, int>>& hypotheses) {
  const Context ctx = BuildContext(scene, mesh, prior, cls, options);
  std::vector<Particle> ps(hypotheses.size());
  for (std::size_t i = 0; i < hypotheses.size(); ++i) {
    if (hypotheses[i].second < 0 || hypotheses[i].second >= prior.layout.CellCount())
      throw Error("WeighPoses: cell index out of range");
    ps[i].pose = hypotheses[i].first;
    ps[i].cell = hypotheses[i].second;
  }
  FilterStats stats;
  WeighAll(ctx, ps, &stats);
  std::vector<double> w(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) w[i] = ps[i].weight;
  return w;
}

namespace {

// One run of the filter (initialisation to convergence) on a prepared context.
EstimateResult RunFilter(Context& ctx, const std::vector<double>& cell_mass, Rng& rng, const ProgressFn& progress) {
  EstimateResult res;
  const FilterOptions& options = ctx.opt;
  const SceneInput& scene = ctx.scene;
  const filter::DiffusionContext diffusion(scene.camera, ctx.prior.layout, ctx.volumes, options);
  // Coarse-to-fine inlier threshold: thr1 falls geometrically from anneal_start_m to its
  // final value over the first anneal_fraction of the iterations. Sets the threshold of
  // iteration `it`; returns true when it changed (weights measured before are stale).
  const int anneal_its = options.anneal_start_m > options.inlier.thr1_m
                             ? int(std::lround(options.anneal_fraction * options.max_iterations)) : 0;
  auto set_threshold = [&](int it) {
    float thr = options.inlier.thr1_m;
    if (it < anneal_its)
      thr = float(options.anneal_start_m * std::pow(options.inlier.thr1_m / options.anneal_start_m, double(it) / anneal_its));
    const bool changed = thr != ctx.inlier.thr1_m;
    ctx.inlier.thr1_m = thr;
    ctx.inlier.hard_thr_m = float(options.inlier.hard_thr_m * thr / options.inlier.thr1_m);
    return changed;
  };
  ctx.inlier = options.inlier;
  set_threshold(0);  // the oversampled start is weighed with the first iteration's threshold

  // 1. Initialisation: importance sampling of the prior's cells (§7.4).
  const int N = options.num_particles;
  std::vector<Particle> current(N), next(N);  // the two ping-pong sample memories
  {
    filter::CdfSampler init(cell_mass, options.tracker_bins);  // throws if no mass
    // Oversampled start (ours): draw init_oversample·N particles, weigh them all and keep
    // the best N as the first set — more starting rotations for the same set size.
    const int M = N * options.init_oversample;
    std::vector<Particle> drawn(M);
    for (int i = 0; i < M; ++i) drawn[i] = NewParticle(ctx, init.Sample(1.0 - rng.Uniform()), rng);
    res.stats.init_cdf_reads = init.reads();
    res.stats.init_cdf_reads_linear = init.reads_linear();
    if (options.init_oversample > 1) {
      WeighAll(ctx, drawn, &res.stats);
      filter::OnlineSorter sorter(M);
      for (int i = 0; i < M; ++i) sorter.Insert(drawn[i].weight, i);
      for (int i = 0; i < N; ++i) current[i] = drawn[sorter.sorted()[i].index];
    } else {
      current = drawn;
    }
  }

  Particle best;
  for (int it = 0; it < options.max_iterations; ++it) {
    const auto t_iter = Clock::now();
    const bool annealing = it < anneal_its;
    if (set_threshold(it))
      for (auto& p : current) p.scored = false;
    // 2. Weigh.
    WeighAll(ctx, current, &res.stats);
    // 3. Sort online as the weights arrive.
    filter::OnlineSorter sorter(N);
    for (int i = 0; i < N; ++i) sorter.Insert(current[i].weight, i);
    const auto& ranked = sorter.sorted();
    best = current[ranked[0].index];
    res.best_weight_history.push_back(best.weight);
    res.iterations = it + 1;
    // 4. Converged, or out of iterations: the last set is already weighed; report its best.
    if (!annealing && best.weight >= options.confidence) res.converged = true;
    if (res.converged || it + 1 == options.max_iterations) {
      res.iteration_ms.push_back(MsSince(t_iter));
      if (progress) progress(it, best.weight);
      break;
    }
    // 5. Resample: the pool is the best particles in rank order, at most region_cap·pool of
    // them from one hypothesis and rotation_cap·pool from one hypothesis and orientation
    // (niching: a false detection or a wrong orientation that fits coarsely early on cannot
    // take the whole set); the elite is the head of the pool, the rest is drawn from
    // the pool's CDF (threshold tracker) and diffused.
    const int pool_size = std::max(std::max(options.num_elite, 1), int(std::lround(options.resample_pool * N)));
    const int cap = std::max(1, int(std::ceil(options.region_cap * pool_size)));
    const int rot_cap = std::max(1, int(std::ceil(options.rotation_cap * pool_size)));
    std::vector<int> pool;  // indices into `ranked`
    pool.reserve(pool_size);
    std::vector<int> per_hypothesis(ctx.hypothesis_count, 0);
    std::map<std::pair<int, int>, int> per_orientation;
    for (int j = 0; j < N && int(pool.size()) < pool_size; ++j) {
      const Particle& p = current[ranked[j].index];
      const int h = ctx.hypothesis[p.cell];
      if (per_hypothesis[h] >= cap) continue;
      int& o = per_orientation[{h, RotationBin(p.pose)}];
      if (o >= rot_cap) continue;
      ++per_hypothesis[h];
      ++o;
      pool.push_back(j);
    }
    std::vector<double> pool_w(pool.size());
    for (std::size_t j = 0; j < pool.size(); ++j) pool_w[j] = ranked[pool[j]].weight;
    if (pool_w[0] <= 0) std::fill(pool_w.begin(), pool_w.end(), 1.0);  // nothing matched yet
    filter::CdfSampler resampler(pool_w, options.tracker_bins);
    const int elite = std::min<int>(options.num_elite, int(pool.size()));
    for (int j = 0; j < elite; ++j) next[j] = current[ranked[pool[j]].index];
    for (int j = elite; j < N; ++j) {
      next[j] = current[ranked[pool[resampler.Sample(1.0 - rng.Uniform())]].index];
      // 6. Diffuse.
      filter::Diffuse(diffusion, &next[j], best.weight, rng);
    }
    res.stats.resample_cdf_reads += resampler.reads();
    res.stats.resample_cdf_reads_linear += resampler.reads_linear();
    std::swap(current, next);
    res.iteration_ms.push_back(MsSince(t_iter));
    if (progress) progress(it, best.weight);
  }

  res.pose_base = best.pose;
  res.T_cam_obj = scene.camera.base_to_camera * PoseToTransform(best.pose);
  res.weight = best.weight;
  res.cell = best.cell;
  return res;
}

}  // namespace

EstimateResult EstimatePose(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress) {
  const auto t_start = Clock::now();
  Context ctx = BuildContext(scene, mesh, prior, cls, options);
  // A cell without a heuristic volume cannot host a particle (App. B: check_pose()).
  std::vector<double> cell_mass(prior.layout.CellCount(), 0.0);
  for (int c = 0; c < prior.layout.CellCount(); ++c)
    if (ctx.volumes[c].valid) cell_mass[c] = prior.Prob(c, cls);

  // Independent runs (restarts), each with its own random stream; the best weight wins.
  Rng rng(options.seed);
  EstimateResult best;
  for (int run = 0; run < options.restarts; ++run) {
    Rng run_rng = options.restarts == 1 ? rng : rng.Split();
    const int offset = run * options.max_iterations;
    const ProgressFn run_progress = progress ? ProgressFn([&](int it, double w) {
      progress(offset + it, std::max(w, best.weight));
    }) : ProgressFn();
    EstimateResult r = RunFilter(ctx, cell_mass, run_rng, run_progress);
    FilterStats total = best.stats;
    total += r.stats;
    const int iterations = best.iterations + r.iterations;
    std::vector<double> history = best.best_weight_history, times = best.iteration_ms;
    history.insert(history.end(), r.best_weight_history.begin(), r.best_weight_history.end());
    times.insert(times.end(), r.iteration_ms.begin(), r.iteration_ms.end());
    if (run == 0 || r.weight > best.weight) best = std::move(r);
    best.stats = total;
    best.iterations = iterations;
    best.best_weight_history = std::move(history);
    best.iteration_ms = std::move(times);
  }
  best.obj = mesh.name;
  best.time_ms = MsSince(t_start);
  return best;
}

}  // namespace posefilter
