// The particle filter, `reference` engine (thesis §2.2, §7.4–7.6, App. B; docs/ALGORITHM.md §4–9).
#include <omp.h>

#include <algorithm>
#include <numeric>
#include <chrono>
#include <cmath>
#include <array>
#include <map>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "core/threads.h"
#include "filter/cdf_sampler.h"
#include "filter/diffusion.h"
#include "filter/online_sorter.h"
#include "filter/scene_prep.h"
#include "filter/driver.h"
#include "prior/volume_cache.h"
#include "render/cpu_kernel.h"
#include "render/scene_normals.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/hw_engine.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/rng.h"
#include "posefilter/stable_poses.h"

namespace posefilter {
namespace {

using filter::Particle;

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The particle's window (thesis §7.5.3; docs/ALGORITHM.md §5): the cell's box centred on the box
// centre, each side at least min_side (the object's projected diameter, so a box smaller than
// the object cannot truncate its rendering) and at most max_px, then shifted ("saturated") to
// lie inside the image.
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
// points along most — the 24 rotations of a cube, so a quarter or half turn changes the bin
// (0 … 23).
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

// One pixel level: the scoring scene on every factor-th pixel of every factor-th row (pixel
// (i, j) is the full image's (factor·i, factor·j); fx, fy, cx, cy divided by factor), its
// N_depth table (of the support depth), its scene normals (computed tile by tile where ICP
// weighings render), and the mesh weighed there (empty: the context's mesh) with its face
// planes for the cpu kernel's back-face pre-cull (render/face_planes.h; empty for the
// reference engine).
struct Level {
  int factor = 1;
  SceneInput scene{};
  render::ValidDepthSat valid_depth{};
  mutable render::SceneNormalTiles normals{};
  Mesh mesh{};
  render::FacePlanes face_planes{};
};

// Everything one run needs that does not change between iterations.
struct Context {
  const SceneInput& scene;
  const Mesh& mesh;
  const Prior& prior;
  int cls;
  const FilterOptions& opt;
  prior::VolumeCache volumes{};      // heuristic volume per cell (base frame), computed on demand
  // Window per cell, computed on demand by PrepareCell (from the serial steps only).
  mutable std::vector<PixelRect> windows{};
  InlierParams inlier{};             // this iteration's inlier thresholds (annealed)
  std::vector<int> hypothesis{};     // niching: cells sharing one decoded box share an id
  int hypothesis_count = 0;
  std::array<Eigen::Vector3d, 8> bbox_corners{};  // the model's bounding box, object frame, m
  // The box the polish turns the model in (object frame): its axes (columns, right-handed),
  // centre and half extents along them. The axis-aligned bounding box, or the box along the
  // vertices' principal axes when that one is at least 10 % smaller (an elongated model
  // drawn at an angle to its own axes, as the YCB scissors).
  Eigen::Matrix3d box_axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d box_centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_half = Eigen::Vector3d::Zero();
  render::CpuTarget cpu_target = render::CpuTarget::kPortable;  // FilterOptions::cpu_isa, resolved
  // One scratch memory per worker thread (cpu kernel; holds the reference's too), kept from
  // one weighing round to the next so that its buffers are allocated and touched once.
  mutable std::vector<render::CpuWorkspace> workspaces{};
  // The pixel levels particles are weighed on (docs/ALGORITHM.md, "Pixel levels"): the fine
  // level (every fine.factor-th pixel of every fine.factor-th row; 1 = every pixel, more for
  // objects larger than max_window_px pixels, FilterOptions::adaptive_resolution) for the
  // answer's weighings, and the coarse level (factor fine.factor · anneal_subsample) for the
  // annealing iterations; `coarse` selects the level of the moment. Windows are full-image
  // pixel rectangles, mapped to the level's grid when weighed.
  Level fine{};
  Level coarse_level{};
  bool coarse = false;
  double diameter = 0;  // the mesh's, metres (cell windows)
  // Contact prior (FilterOptions::contact): the support plane (camera frame) and the mesh's
  // convex-hull vertices (object frame, metres); empty when the prior is off or no plane.
  SupportPlane plane{};
  std::vector<Eigen::Vector3d> hull{};
  // The mesh's stable poses (FilterOptions::stable_start); empty without a support plane. A
  // stable start stands on the point of the plane below the centre of its cell's visible
  // surface: surface_volumes are the heuristic volumes without the depth extension.
  std::vector<StablePose> stable{};
  prior::VolumeCache surface_volumes{};
  Eigen::Vector3d com_obj = Eigen::Vector3d::Zero();  // the mesh's centre of mass, object frame
  mutable std::vector<std::uint8_t> window_ready{};  // per cell: windows[c] is set
};

// Computes cell c's heuristic volume and window if not done yet (on demand because a run uses
// a few hundred of a pyramid's thousands of cells). Not thread-safe: the serial steps call it, and
// WeighAll calls it for its particles' cells before its parallel loop.
void PrepareCell(const Context& ctx, int c) {
  if (ctx.window_ready[std::size_t(c)]) return;
  // The object's diameter in pixels at the depth of the cell's volume centre.
  const Camera& cam = ctx.scene.camera;
  const double z_cam = ctx.volumes.Valid(c) ? (cam.base_to_camera * ctx.volumes.Get(c).Centre()).z() : 1.0;
  const double min_side = ctx.opt.min_window_diameters * ctx.diameter * cam.fx / std::max(z_cam, ctx.opt.near_m);
  ctx.windows[std::size_t(c)] =
      CellWindow(ctx.prior.boxes[std::size_t(c)], min_side, ctx.opt.max_window_px * ctx.fine.factor, cam.width, cam.height);
  ctx.window_ready[std::size_t(c)] = 1;
}

// The window a particle is weighed in (ours, FilterOptions::grow_window): its cell's window
// grown, axis by axis, to contain the projection of the model's bounding box at the
// particle's pose (T = object → camera), clipped to the image. An axis whose grown extent
// would exceed max(max_window_px, the cell window's) keeps the cell window's extent, as does
// a pose with a corner behind the near plane. Without growing, a pose that fits the scene but
// hangs out of a jittered detection box loses its outside pixels to a pose that does not.
PixelRect ParticleWindow(const Context& ctx, const Eigen::Isometry3d& T, int cell) {
  const PixelRect& w = ctx.windows[cell];
  if (!ctx.opt.grow_window) return w;
  const Camera& cam = ctx.scene.camera;
  double u_lo = 1e30, u_hi = -1e30, v_lo = 1e30, v_hi = -1e30;
  for (const Eigen::Vector3d& c : ctx.bbox_corners) {
    const Eigen::Vector3d p = T * c;
    if (p.z() < ctx.opt.near_m) return w;
    const double u = cam.fx * p.x() / p.z() + cam.cx, v = cam.fy * p.y() / p.z() + cam.cy;
    u_lo = std::min(u_lo, u);
    u_hi = std::max(u_hi, u);
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
  }
  auto grow = [](int lo, int size, double p_lo, double p_hi, int limit, int cap, int* out_lo, int* out_size) {
    const long a = std::max(0L, std::min(long(lo), long(std::floor(p_lo))));
    const long b = std::min(long(limit), std::max(long(lo) + size, long(std::ceil(p_hi)) + 1));
    if (b - a > std::max(cap, size)) return;  // keep the cell window's extent
    *out_lo = int(a);
    *out_size = int(b - a);
  };
  PixelRect r = w;
  const int cap = ctx.opt.max_window_px * ctx.fine.factor;  // full-image pixels
  grow(w.u0, w.width, u_lo, u_hi, cam.width, cap, &r.u0, &r.width);
  grow(w.v0, w.height, v_lo, v_hi, cam.height, cap, &r.v0, &r.height);
  return r;
}

// Listing 7.5: x, y at the volume centre, z uniform in [z_min, z_max]; angles uniform in ±π.
// Or (ours, FilterOptions::stable_start, with a support plane): resting on the plane in one of
// the mesh's stable poses (drawn by probability), turned by a uniform yaw about the plane's
// normal, its centre of mass above the point of the plane below the centre of the cell's
// visible surface (the volume without the depth extension), moved away from the camera along
// the plane by a uniform fraction of the object's radius.
Particle NewParticle(const Context& ctx, int cell, Rng& rng) {
  const Volume& vol = ctx.volumes.Get(cell);
  Particle p;
  p.cell = cell;
  const Eigen::Vector3d c = vol.Centre();
  const double u_start = rng.Uniform();
  if (!ctx.stable.empty() && u_start < ctx.opt.stable_start) {
    const double u_pose = rng.Uniform(), yaw = rng.Uniform(-M_PI, M_PI), back = rng.Uniform();
    std::size_t k = 0;
    for (double acc = ctx.stable[0].probability; k + 1 < ctx.stable.size() && u_pose >= acc;)
      acc += ctx.stable[++k].probability;
    const Eigen::Isometry3d& C = ctx.scene.camera.base_to_camera;
    const Eigen::Vector3d centre = C * ctx.surface_volumes.Get(cell).Centre();
    const Eigen::Vector3d n = ctx.plane.normal;
    Eigen::Isometry3d T_cam_table = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d ex = n.unitOrthogonal();
    T_cam_table.linear() << ex, n.cross(ex), n;
    // The visible surface's foot, moved away from the camera along the plane by up to the
    // object's radius: the object lies behind what the camera sees of it (and an occluder in
    // the box pulls the surface's centre towards the camera).
    Eigen::Vector3d away = centre - n * n.dot(centre);
    if (away.norm() > 1e-9) away.normalize();
    T_cam_table.translation() = centre - ctx.plane.Height(centre) * n + back * 0.5 * ctx.diameter * away;
    const Eigen::Isometry3d T_cam_obj =
        T_cam_table * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * ctx.stable[k].T_table_obj;
    p.pose = TransformToPose(C.inverse() * T_cam_obj);
    return p;
  }
  p.pose.x = c.x();
  p.pose.y = c.y();
  p.pose.z = rng.Uniform(vol.min.z(), vol.max.z());
  p.pose.roll = rng.Uniform(-M_PI, M_PI);
  p.pose.pitch = rng.Uniform(-M_PI, M_PI);
  p.pose.yaw = rng.Uniform(-M_PI, M_PI);
  return p;
}

// The pixel level weighings use at the moment (Context::coarse), its scene and its normals.
const Level& CurrentLevel(const Context& ctx) { return ctx.coarse ? ctx.coarse_level : ctx.fine; }
const SceneInput& LevelScene(const Context& ctx) { return CurrentLevel(ctx).scene; }
render::SceneNormalTiles& LevelNormals(const Context& ctx) { return CurrentLevel(ctx).normals; }

// Particle p's transform object → camera (FT without P).
Eigen::Isometry3d CameraFromObject(const Context& ctx, const Particle& p) {
  return ctx.scene.camera.base_to_camera * PoseToTransform(p.pose);
}

// The window a particle at T (object → camera) in `cell` is weighed in: ParticleWindow, on
// the pixel grid of the current level.
PixelRect WeighWindow(const Context& ctx, const Eigen::Isometry3d& T, int cell) {
  const PixelRect w = ParticleWindow(ctx, T, cell);
  const int s = CurrentLevel(ctx).factor;
  if (s == 1) return w;
  // The level's pixels i whose full-resolution pixel s·i lies in [u0, u1): ceil(u0 / s) ≤ i < ceil(u1 / s).
  auto up = [s](int a) { return (a + s - 1) / s; };  // a ≥ 0: windows lie inside the image
  const int u0 = up(w.u0), u1 = up(w.u0 + w.width);
  const int v0 = up(w.v0), v1 = up(w.v0 + w.height);
  return PixelRect{u0, v0, u1 - u0, v1 - v0};
}

// The contact prior's penalty of a pose T (object → camera): FilterOptions::contact times the
// fraction of contact_span_m by which the lowest hull point floats above, or sinks below, the
// support plane beyond contact_tolerance_m (0 without a plane).
double ContactPenalty(const Context& ctx, const Eigen::Isometry3d& T) {
  if (ctx.hull.empty()) return 0.0;
  double lowest = 1e30;
  for (const Eigen::Vector3d& v : ctx.hull) lowest = std::min(lowest, ctx.plane.Height(T * v));
  const double off = std::fabs(lowest) - ctx.opt.contact_tolerance_m;
  return off > 0 ? ctx.opt.contact * std::min(1.0, off / ctx.opt.contact_span_m) : 0.0;
}

// Weight of eq. 7.4 for one particle; `ws` is the calling worker's own scratch memory. With
// `icp`, the kernel also sums the ICP normal equations (scene normals passed); the weight
// does not depend on it.
double Weigh(const Context& ctx, const Particle& p, bool icp, render::CpuWorkspace* ws, ScoreKernelResult* out) {
  const Eigen::Isometry3d T = CameraFromObject(ctx, p);
  const Level& level = CurrentLevel(ctx);
  const SceneInput& scene = level.scene;
  const Mesh& mesh = level.mesh.faces.empty() ? ctx.mesh : level.mesh;
  ScoreKernelParams k = MakeKernelParams(mesh, T, scene.camera);
  k.near_m = float(ctx.opt.near_m);
  k.window = WeighWindow(ctx, T, p.cell);
  k.depth = scene.depth.data.data();
  k.depth_width = scene.depth.width;
  k.depth_height = scene.depth.height;
  k.inlier = ctx.inlier;
  k.zbuffer = ctx.opt.zbuffer;
  k.align_band_m = float(ctx.opt.align_band_m);
  k.edge_band_m = float(ctx.opt.edge_band_m);
  k.scene_normals = icp ? LevelNormals(ctx).data() : nullptr;
  const render::FacePlanes* planes = &level.face_planes;
  *out = ctx.opt.engine == "cpu" ? render::ScoreCpuWith(ctx.cpu_target, k, ws, planes) : ScoreReference(k, &ws->reference);
  const double I = out->inlier_sum;
  // Without a z-buffer fragments may overlap, so each ratio is capped at 1.
  const std::int64_t n_raster = ctx.opt.occlusion_aware ? out->n_raster - out->n_occluded : out->n_raster;
  const double r_raster = n_raster > 0 ? std::min(1.0, I / double(n_raster)) : 0.0;
  const long nd = long(level.valid_depth.Count(k.window));
  const double r_depth = nd > 0 ? std::min(1.0, I / double(nd)) : 0.0;
  const double rho = ctx.prior.Prob(p.cell, ctx.cls);
  const double r_edge = out->n_edge > 0 ? double(out->n_edge_continued) / double(out->n_edge) : 0.0;
  return std::max(0.0, ctx.opt.alpha * r_raster + ctx.opt.beta * r_depth + ctx.opt.gamma * rho - ctx.opt.delta * r_edge -
                           ContactPenalty(ctx, T));
}

// Weighs every particle not yet scored (threads over particles; each owns a workspace);
// `icp`: also solve each one's ICP step (the kIcpStep move's input).
void WeighAll(const Context& ctx, std::vector<Particle>& ps, FilterStats* stats, bool icp = false) {
  const int n = int(ps.size());
  std::int64_t faces_total = 0, faces_front = 0, fragments = 0, weighings = 0;
  const int threads = WorkerThreads(ctx.opt.threads);
  if (int(ctx.workspaces.size()) < threads) ctx.workspaces.resize(std::size_t(threads));
  for (const Particle& p : ps) PrepareCell(ctx, p.cell);  // the windows the workers read
  if (icp) {  // the scene normals under the windows of the ICP weighings
    std::vector<PixelRect> windows;
    for (const Particle& p : ps)
      if (!p.scored) windows.push_back(WeighWindow(ctx, CameraFromObject(ctx, p), p.cell));
    const SceneInput& scene = LevelScene(ctx);
    LevelNormals(ctx).Prepare(scene.depth, scene.camera, windows, ctx.opt.threads);
  }
#pragma omp parallel num_threads(threads) reduction(+ : faces_total, faces_front, fragments, weighings)
  {
    render::CpuWorkspace& ws = ctx.workspaces[std::size_t(omp_get_thread_num())];  // this worker's own
#pragma omp for schedule(dynamic, 4)
    for (int i = 0; i < n; ++i) {
      if (ps[i].scored) continue;
      ScoreKernelResult r;
      ps[i].weight = Weigh(ctx, ps[i], icp, &ws, &r);
      ps[i].depth_offset = r.depth_diff_count > 0 ? r.depth_diff_sum / double(r.depth_diff_count) : 0.0;
      ps[i].icp_valid = icp && filter::SolveIcpStep(r, &ps[i].icp_step);
      ps[i].icp_known = icp;
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
  if (engine != "cpu" && engine != "reference" && engine != "hw")
    return fail("engine must be 'cpu', 'reference' or 'hw' (got '" + engine + "')");
  if (cpu_isa != "auto") {
    render::CpuTarget t;
    if (!render::ParseCpuTarget(cpu_isa, &t))
      return fail("cpu_isa must be 'auto', 'avx512', 'avx2' or 'portable' (got '" + cpu_isa + "')");
    if (!render::CpuTargetSupported(t)) {
      std::string supported;
      for (render::CpuTarget c : render::SupportedCpuTargets())
        supported += std::string(supported.empty() ? "" : ", ") + render::CpuTargetName(c);
      return fail("cpu_isa '" + cpu_isa + "' is not supported by this CPU or build (supported: " + supported + ")");
    }
  }
  if (num_particles < 2 || num_particles > 1'000'000) return fail("num_particles must be in [2, 1000000]");
  if (max_iterations < 1 || max_iterations > 100'000) return fail("max_iterations must be in [1, 100000]");
  if (!(confidence > 0 && confidence <= 1)) return fail("confidence must be in (0, 1]");
  for (double v : {alpha, beta, gamma})
    if (!(v >= 0 && v <= 1)) return fail("alpha, beta, gamma must each be in [0, 1]");
  if (std::fabs(alpha + beta + gamma - 1) > 1e-6) return fail("alpha + beta + gamma must equal 1");
  if (!(inlier.thr1_m > 0 && std::isfinite(inlier.thr1_m))) return fail("inlier threshold must be > 0");
  if (!(inlier.hard_thr_m > 0 && std::isfinite(inlier.hard_thr_m))) return fail("hard inlier threshold must be > 0");
  if (!(anneal_start_m >= 0 && std::isfinite(anneal_start_m))) return fail("anneal_start_m must be >= 0");
  if (!(anneal_fraction >= 0 && anneal_fraction <= 1)) return fail("anneal_fraction must be in [0, 1]");
  if (anneal_subsample < 1 || anneal_subsample > 4) return fail("anneal_subsample must be in [1, 4]");
  if (!(min_window_diameters >= 0 && min_window_diameters <= 4)) return fail("min_window_diameters must be in [0, 4]");
  if (max_window_px < 8) return fail("max_window_px must be >= 8");
  if (!(near_m > 0 && std::isfinite(near_m))) return fail("near_m must be > 0");
  if (num_elite < 0 || num_elite >= num_particles) return fail("num_elite must be in [0, num_particles)");
  if (!(fine_particle_fraction > 0 && fine_particle_fraction <= 1))
    return fail("fine_particle_fraction must be in (0, 1]");
  if (!(resample_pool > 0 && resample_pool <= 1)) return fail("resample_pool must be in (0, 1]");
  if (!(region_cap > 0 && region_cap <= 1)) return fail("region_cap must be in (0, 1]");
  if (!(rotation_cap > 0 && rotation_cap <= 1)) return fail("rotation_cap must be in (0, 1]");
  if (!(delta >= 0 && delta <= 1)) return fail("delta must be in [0, 1]");
  if (!(contact >= 0 && contact <= 1)) return fail("contact must be in [0, 1]");
  if (!(stable_start >= 0 && stable_start <= 1)) return fail("stable_start must be in [0, 1]");
  if (!(contact_tolerance_m >= 0 && std::isfinite(contact_tolerance_m))) return fail("contact_tolerance_m must be >= 0");
  if (!(contact_span_m > 0 && std::isfinite(contact_span_m))) return fail("contact_span_m must be > 0");
  if (!(edge_band_m > 0 && std::isfinite(edge_band_m))) return fail("edge_band_m must be > 0");
  if (!(align_band_m > 0 && std::isfinite(align_band_m))) return fail("align_band_m must be > 0");
  if (init_oversample < 1 || init_oversample > 64) return fail("init_oversample must be in [1, 64]");
  if (restarts < 1 || restarts > 100) return fail("restarts must be in [1, 100]");
  if (stall_iterations < 0 || stall_iterations > 1000) return fail("stall_iterations must be in [0, 1000]");
  if (!(stall_gain >= 0 && stall_gain <= 1)) return fail("stall_gain must be in [0, 1]");
  if (lod_max_faces != 0 && lod_max_faces < kMinSimplifyFaces) return fail("lod_max_faces must be 0 (full mesh) or >= 4");
  if (polish_steps < 0 || polish_steps > 100) return fail("polish_steps must be in [0, 100]");
  if (polish_seeds < 1 || polish_seeds > 1000) return fail("polish_seeds must be in [1, 1000]");
  if (polish_climbers < 0 || polish_climbers > 1000) return fail("polish_climbers must be in [0, 1000]");
  if (polish_keep < 1 || polish_keep > 100000) return fail("polish_keep must be in [1, 100000]");
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
  if (threads < 0 || threads > MaxWorkerThreads())
    return fail("threads must be in [0, " + std::to_string(MaxWorkerThreads()) +
                "] (0 = all cores; at most 4 per hardware thread)");
  std::string h;
  if (!heuristics.IsValid(&h)) return fail("heuristics: " + h);
  return true;
}

namespace {

// Plausible scene and object sizes (metres): what a depth camera sees, and objects between a
// thousandth and ten times the scene's median depth across.
constexpr double kMinPlausibleDepthM = 0.01, kMaxPlausibleDepthM = 100;
constexpr double kMinObjectToDepth = 1e-3, kMaxObjectToDepth = 10;

// The median of the depth image's valid (> 0) pixels, metres; 0 when there is none.
double MedianValidDepth(const DepthImage& d) {
  std::vector<float> z;
  z.reserve(d.data.size());
  for (float v : d.data)
    if (v > 0) z.push_back(v);
  if (z.empty()) return 0;
  auto mid = z.begin() + std::ptrdiff_t(z.size() / 2);
  std::nth_element(z.begin(), mid, z.end());
  return *mid;
}

}  // namespace

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
  // A depth scale off by 1000 (millimetres read as metres, or the reverse) puts the scene
  // kilometres or millimetres away; no depth camera sees that.
  const double median = MedianValidDepth(d);
  if (!(median >= kMinPlausibleDepthM && median <= kMaxPlausibleDepthM)) {
    std::ostringstream os;
    os << what << ": the median depth is " << median << " m, outside the [" << kMinPlausibleDepthM << ", "
       << kMaxPlausibleDepthM << "] m of a depth camera: wrong depth scale (metres per PNG unit)?";
    throw Error(os.str());
  }
  if (!scene.mask.empty()) {
    if (scene.mask.size() != d.data.size()) {
      std::ostringstream os;
      os << what << ": the mask holds " << scene.mask.size() << " pixels but the image " << d.data.size();
      throw Error(os.str());
    }
    if (std::none_of(scene.mask.begin(), scene.mask.end(), [](std::uint8_t m) { return m != 0; }))
      throw Error(what + ": the mask is empty (no pixel of the object)");
  }
}

SceneInput SubsampleScene(const SceneInput& scene, int factor) {
  if (factor < 1) throw Error("SubsampleScene: factor must be >= 1 (got " + std::to_string(factor) + ")");
  const int s = factor;
  SceneInput out;
  Camera& c = out.camera;
  c = scene.camera;
  c.width = (scene.camera.width + s - 1) / s;
  c.height = (scene.camera.height + s - 1) / s;
  c.fx /= s;  // u = fx·x/z + cx at full resolution is s times the coarse u
  c.fy /= s;
  c.cx /= s;
  c.cy /= s;
  const DepthImage& d = scene.depth;
  out.depth = DepthImage((d.width + s - 1) / s, (d.height + s - 1) / s);
  for (int j = 0; j < out.depth.height; ++j)
    for (int i = 0; i < out.depth.width; ++i) out.depth.at(i, j) = d.at(s * i, s * j);
  return out;
}

namespace {

// Checks the inputs and precomputes volumes, windows and N_depth for every cell.
// `runs`: the context will run the filter (EstimatePose), so it also gets the coarse level
// of the annealing iterations; weighing given poses and the polish need only every pixel.
// `prep` (PrepareScene's, already validated) must outlive the context: the context scores
// against prep.scoring and reads volumes and N_depth from prep.support.
Context BuildContext(const filter::PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                     const FilterOptions& options, bool runs) {
  std::string why;
  if (!options.IsValid(&why)) throw Error("invalid filter option: " + why);
  if (!mesh.IsValid(&why)) throw Error("mesh '" + mesh.name + "': " + why);
  const SceneInput& scene = prep.scoring;
  if (cls < 0 || cls >= int(prior.classes.size())) throw Error("class index out of range for the prior");
  if (prior.layout.image_width != scene.camera.width || prior.layout.image_height != scene.camera.height)
    throw Error("prior was made for a different image size than the camera's");

  Context ctx{.scene = scene, .mesh = mesh, .prior = prior, .cls = cls, .opt = options, .inlier = options.inlier};
  // cpu_isa names a supported variant or is "auto" (options were validated).
  if (!render::ParseCpuTarget(options.cpu_isa, &ctx.cpu_target)) ctx.cpu_target = render::BestCpuTarget();
  const double diameter = mesh.Diameter();
  ctx.diameter = diameter;
  // Catches mesh unit mistakes (a millimetre mesh read as metres, or the reverse).
  const double median_depth = MedianValidDepth(prep.support);
  if (!(diameter >= kMinObjectToDepth * median_depth && diameter <= kMaxObjectToDepth * median_depth)) {
    std::ostringstream os;
    os << "mesh '" << mesh.name << "' is " << diameter << " m across, implausible in a scene whose median depth is "
       << median_depth << " m (objects of " << kMinObjectToDepth * median_depth << " to "
       << kMaxObjectToDepth * median_depth
       << " m are accepted): are the mesh units right? (the unit scale, --unit-scale: 0.001 for a millimetre mesh, 1 for metres)";
    throw Error(os.str());
  }
  HeuristicOptions hopt = options.heuristics;
  if (hopt.depth_extension_m == 0) hopt.depth_extension_m = 0.5 * diameter;
  ctx.volumes = prior::VolumeCache(prep.support, scene.camera, prior.boxes, hopt, options.threads);
  const int cells = prior.layout.CellCount();
  // A pixel level of the given factor: the scene, N_depth table and normals subsampled, and
  // (factor > 1, anneal_simplify) the mesh simplified to faces / factor² faces (at least
  // kCoarseMinFaces; a mesh meshoptimizer cannot bring to the budget is weighed as it is).
  auto make_level = [&](int factor) {
    Level l;
    l.factor = factor;
    l.scene = factor > 1 ? SubsampleScene(scene, factor) : scene;
    const DepthImage support = factor > 1 ? SubsampleScene(SceneInput{prep.support, scene.camera}, factor).depth : prep.support;
    l.valid_depth = render::ValidDepthSat(support.data.data(), support.width, support.height);
    l.normals = render::SceneNormalTiles(support.width, support.height);
    if (factor > 1 && options.anneal_simplify) {
      const int budget = filter::CoarseMeshFaces(int(mesh.faces.size()), factor);
      if (int(mesh.faces.size()) > budget) {
        try {
          l.mesh = SimplifyMesh(mesh, budget);
        } catch (const Error&) {
        }
      }
    }
    // The cpu engine's pre-cull table: of the same arrays every weighing's parameters point at.
    if (options.engine == "cpu")
      l.face_planes = render::BuildFacePlanes(
          MakeKernelParams(l.mesh.faces.empty() ? mesh : l.mesh, Eigen::Isometry3d::Identity(), scene.camera));
    return l;
  };
  ctx.fine = make_level(filter::FineFactor(options, prior, cls, ctx.volumes, scene.camera, diameter));
  if (runs && options.anneal_subsample > 1 && filter::AnnealIterations(options) > 0)
    ctx.coarse_level = make_level(ctx.fine.factor * options.anneal_subsample);
  if (prep.plane.found) ctx.plane = prep.plane;
  if (options.contact > 0 && prep.plane.found) {
    std::vector<Eigen::Vector3d> pts;
    for (const auto& v : mesh.vertices) pts.push_back(v.cast<double>());
    ctx.hull = ComputeConvexHull(pts, "mesh '" + mesh.name + "'").vertices;
  }
  if (runs && options.stable_start > 0 && prep.plane.found) {
    ctx.stable = ComputeStablePoses(mesh);
    if (!ctx.stable.empty())
      ctx.com_obj = ctx.stable[0].T_table_obj.inverse() * Eigen::Vector3d(0, 0, ctx.stable[0].com_height_m);
    HeuristicOptions surface = hopt;
    surface.depth_extension_m = 0;
    ctx.surface_volumes = prior::VolumeCache(prep.support, scene.camera, prior.boxes, surface, options.threads);
  }
  const Eigen::Vector3d lo = mesh.Min().cast<double>(), hi = mesh.Max().cast<double>();
  for (int i = 0; i < 8; ++i)
    ctx.bbox_corners[i] = Eigen::Vector3d(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  ctx.box_centre = 0.5 * (lo + hi);
  ctx.box_half = 0.5 * (hi - lo);
  {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& v : mesh.vertices) mean += v.cast<double>();
    mean /= double(mesh.vertices.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& v : mesh.vertices) cov += (v.cast<double>() - mean) * (v.cast<double>() - mean).transpose();
    Eigen::Matrix3d A = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
    if (A.determinant() < 0) A.col(2) = -A.col(2);
    Eigen::Vector3d plo = Eigen::Vector3d::Constant(1e30), phi = Eigen::Vector3d::Constant(-1e30);
    for (const auto& v : mesh.vertices) {
      const Eigen::Vector3d q = A.transpose() * v.cast<double>();
      plo = plo.cwiseMin(q);
      phi = phi.cwiseMax(q);
    }
    if ((phi - plo).prod() < 0.9 * (hi - lo).prod() && A.allFinite()) {
      ctx.box_axes = A;
      ctx.box_centre = A * (0.5 * (plo + phi));
      ctx.box_half = 0.5 * (phi - plo);
    }
  }
  ctx.windows.resize(cells);  // PrepareCell fills them in as cells are used
  ctx.window_ready.assign(std::size_t(cells), 0);
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
  Mesh lod;  // the mesh rendered at options.lod_max_faces (unused at 0: the full mesh)
  const filter::PreparedScene prep = filter::PrepareScene(scene, options);
  const Context ctx = BuildContext(prep, MeshAtLod(mesh, options.lod_max_faces, &lod), prior, cls, options, false);
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
// `leaders` receives the best particle of each (hypothesis, orientation bin) niche of the
// final set, best first, at most FilterOptions::polish_seeds of them.
EstimateResult RunFilter(Context& ctx, const std::vector<double>& cell_mass, Rng& rng, const ProgressFn& progress,
                         std::vector<Particle>* leaders) {
  EstimateResult res;
  const FilterOptions& options = ctx.opt;
  const SceneInput& scene = ctx.scene;
  const filter::DiffusionContext diffusion(scene.camera, ctx.prior.layout, ctx.volumes, options, &ctx.plane,
                                           0.5 * (ctx.bbox_corners[0] + ctx.bbox_corners[7]));
  // Coarse-to-fine inlier threshold: thr1 falls geometrically from anneal_start_m to its
  // final value over the first anneal_fraction of the iterations, weighed on the coarse pixel
  // grid while it does (anneal_subsample > 1). Sets the threshold and the pixel grid of
  // iteration `it`; returns true when either changed (weights measured before are stale).
  const int anneal_its = filter::AnnealIterations(options);
  auto set_threshold = [&](int it) {
    const float thr = float(filter::AnnealedThreshold(options, it, anneal_its));
    const bool changed = thr != ctx.inlier.thr1_m;
    ctx.inlier.thr1_m = thr;
    ctx.inlier.hard_thr_m = float(options.inlier.hard_thr_m * thr / options.inlier.thr1_m);
    // Never the run's last possible iteration: its weights are the answer's.
    const bool coarse = ctx.coarse_level.factor > 1 && it < anneal_its && it + 1 < options.max_iterations;
    const bool level_changed = coarse != ctx.coarse;
    ctx.coarse = coarse;
    return changed || level_changed;
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
    if (set_threshold(it))
      for (auto& p : current) p.scored = false;
    // 2. Weigh.
    WeighAll(ctx, current, &res.stats);
    // 3. Sort online as the weights arrive.
    const int Nc = int(current.size());
    filter::OnlineSorter sorter(Nc);
    for (int i = 0; i < Nc; ++i) sorter.Insert(current[i].weight, i);
    const auto& ranked = sorter.sorted();
    best = current[ranked[0].index];
    res.best_weight_history.push_back(best.weight);
    res.iterations = it + 1;
    // 4. Converged, stalled or out of iterations: the last set is already weighed; report its best.
    if (filter::RunEnds(options, it, anneal_its, res.best_weight_history, &res.converged)) {
      std::set<std::pair<int, int>> niches;
      for (int j = 0; j < Nc && int(niches.size()) < options.polish_seeds; ++j) {
        const Particle& p = current[ranked[j].index];
        if (niches.insert({ctx.hypothesis[p.cell], RotationBin(p.pose)}).second) leaders->push_back(p);
      }
      res.iteration_ms.push_back(MsSince(t_iter));
      if (progress) progress(it, best.weight);
      break;
    }
    // 5. Resample: the pool is the best particles in rank order, at most region_cap·pool of
    // them from one hypothesis and rotation_cap·pool from one hypothesis and orientation
    // (niching: a false detection or a wrong orientation that fits coarsely early on cannot
    // take the whole set); the elite is the head of the pool, the rest is drawn from
    // the pool's CDF (threshold tracker) and diffused.
    const int pool_size = std::max(std::max(options.num_elite, 1), int(std::lround(options.resample_pool * Nc)));
    const int cap = std::max(1, int(std::ceil(options.region_cap * pool_size)));
    const int rot_cap = std::max(1, int(std::ceil(options.rotation_cap * pool_size)));
    std::vector<int> pool;  // indices into `ranked`
    pool.reserve(pool_size);
    std::vector<int> per_hypothesis(ctx.hypothesis_count, 0);
    std::map<std::pair<int, int>, int> per_orientation;
    for (int j = 0; j < Nc && int(pool.size()) < pool_size; ++j) {
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
    // 6. Diffuse. A child that drew the ICP move waits until its parent's ICP step is known:
    // the parents in question are weighed once more with the ICP sums (same weight), then
    // the move is applied. The move draws no random numbers, so the streams are unchanged.
    std::map<int, std::vector<int>> icp_children;  // parent index in `current` → children j
    // The next set's size: N, or once annealing is over the fine set (FineParticles).
    const int n_next = anneal_its > 0 && it + 1 >= anneal_its ? filter::FineParticles(options) : N;
    next.resize(n_next);
    for (int j = elite; j < n_next; ++j) {
      const int parent = ranked[pool[resampler.Sample(1.0 - rng.Uniform())]].index;
      next[j] = current[parent];
      const Move move = diffusion.PickMove(rng.Uniform());
      if (move == Move::kIcpStep && !next[j].icp_known) {
        icp_children[parent].push_back(j);
        continue;
      }
      filter::ApplyMove(diffusion, move, &next[j], best.weight, rng);
    }
    if (!icp_children.empty()) {
      std::vector<Particle> parents;
      for (const auto& [parent, children] : icp_children) {
        parents.push_back(current[parent]);
        parents.back().scored = false;
      }
      WeighAll(ctx, parents, &res.stats, /*icp=*/true);
      int k = 0;
      for (const auto& [parent, children] : icp_children) {
        for (int j : children) {
          next[j] = parents[k];
          filter::ApplyMove(diffusion, Move::kIcpStep, &next[j], best.weight, rng);
        }
        ++k;
      }
    }
    res.stats.resample_cdf_reads += resampler.reads();
    res.stats.resample_cdf_reads_linear += resampler.reads_linear();
    std::swap(current, next);
    res.iteration_ms.push_back(MsSince(t_iter));
    if (progress) progress(it, best.weight);
  }

  res.pose_base = best.pose;
  res.T_cam_obj = CameraFromObject(ctx, best);
  res.weight = best.weight;
  res.cell = best.cell;
  return res;
}

}  // namespace

namespace {

// The 24 rotations of a cube (signed permutation matrices with determinant +1).
std::vector<Eigen::Matrix3d> CubeRotations() {
  std::vector<Eigen::Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) R(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (R.determinant() > 0) out.push_back(R);
    }
  return out;  // identity first: perms[0] with signs 0
}

// Final polish (ours, FilterOptions::polish_steps): every seed, and with polish_turns each
// seed turned about the centre c of the model's box (Context::box_axes) by the 23 other
// rotations of a cube in the box's frame
// (T' = T·[R_k | c − R_k·c], so the object stays where it is), takes polish_steps ICP steps
// (the kIcpStep move solved from its own last weighing) at the final inlier threshold. A
// turned copy whose translation is a little off can thus settle before it is compared, which
// the filter's own quarter-turn move cannot do (its copies are outweighed at once). Returns
// the best weighed particle seen, or the best seed if nothing beats it.
Particle Polish(Context& ctx, const std::vector<Particle>& seeds, FilterStats* stats) {
  const FilterOptions& o = ctx.opt;
  ctx.inlier = o.inlier;  // final thresholds, every pixel, the full mesh
  ctx.coarse = false;
  const Eigen::Vector3d centre = ctx.box_centre;
  const Eigen::Matrix3d& A = ctx.box_axes;
  std::vector<Eigen::Matrix3d> turns = CubeRotations();
  if (!o.polish_turns) turns.resize(1);
  // Pivots: a turn about the centre, and (polish_pivots) the same turn followed by the shift
  // that puts a corner of the turned box where that corner of the seed's box was — a turn
  // about an edge or corner, as when an object tips over onto another face. Half extents e
  // and, turned, e' = |R|·e; corner σ ∈ {±1}³ moves the centre by σ∘(e − e') (box frame).
  // Turns that keep the box (e' = e) need no shift. The turns R are the cube's in the box's
  // frame: A·R·Aᵀ in the object frame.
  const Eigen::Vector3d half = ctx.box_half;
  std::vector<Particle> cands;
  for (const Particle& s : seeds)
    for (const Eigen::Matrix3d& R : turns) {
      const Eigen::Vector3d diff = half - R.cwiseAbs() * half;
      const int pivots = o.polish_pivots && diff.norm() > 1e-6 ? 9 : 1;
      const Eigen::Matrix3d R_obj = A * R * A.transpose();
      for (int k = 0; k < pivots; ++k) {
        Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
        turn.linear() = R_obj;
        turn.translation() = centre - R_obj * centre;
        if (k > 0) {
          const Eigen::Vector3d sigma((k - 1) & 1 ? 1.0 : -1.0, (k - 1) & 2 ? 1.0 : -1.0, (k - 1) & 4 ? 1.0 : -1.0);
          turn.translation() += A * sigma.cwiseProduct(diff);
        }
        Particle p = s;
        p.pose = TransformToPose(PoseToTransform(s.pose) * turn);
        p.scored = false;
        cands.push_back(p);
      }
    }
  // Stable re-search (polish_stable, with a support plane): each seed's centre of mass
  // dropped onto the plane, and the object standing there in each of its stable poses of at
  // least 1 % probability (at most 8), turned about the plane's normal in 24 steps of 15°: an
  // answer in the wrong stable pose, or the right one turned or flipped, gets the right one.
  if (o.polish_stable && !ctx.stable.empty()) {
    const Eigen::Isometry3d& C = ctx.scene.camera.base_to_camera;
    const Eigen::Vector3d n = ctx.plane.normal, ex = n.unitOrthogonal();
    for (const Particle& s : seeds) {
      const Eigen::Vector3d com = C * PoseToTransform(s.pose) * ctx.com_obj;
      Eigen::Isometry3d T_cam_table = Eigen::Isometry3d::Identity();
      T_cam_table.linear() << ex, n.cross(ex), n;
      T_cam_table.translation() = com - ctx.plane.Height(com) * n;
      for (std::size_t k = 0; k < std::min<std::size_t>(ctx.stable.size(), 8); ++k) {
        if (ctx.stable[k].probability < 0.01) break;  // most probable first
        for (int j = 0; j < 24; ++j) {
          const Eigen::Isometry3d T = T_cam_table * Eigen::AngleAxisd(j * M_PI / 12, Eigen::Vector3d::UnitZ()) *
                                      ctx.stable[k].T_table_obj;
          Particle p = s;
          p.pose = TransformToPose(C.inverse() * T);
          p.scored = false;
          cands.push_back(p);
        }
      }
    }
  }
  // With pivots, weigh every copy once and polish only the best polish_keep of them.
  if ((o.polish_pivots || o.polish_stable) && int(cands.size()) > o.polish_keep) {
    WeighAll(ctx, cands, stats, /*icp=*/true);
    std::partial_sort(cands.begin(), cands.begin() + o.polish_keep, cands.end(),
                      [](const Particle& a, const Particle& b) { return a.weight > b.weight; });
    cands.resize(o.polish_keep);
  }
  const filter::DiffusionContext diffusion(ctx.scene.camera, ctx.prior.layout, ctx.volumes, o, &ctx.plane, centre);
  Rng unused(0);  // the ICP move draws no random numbers
  std::vector<Particle> path_best(cands.size());  // best weighed state of each candidate
  for (auto& p : path_best) p.weight = -1;
  for (int step = 0; step <= o.polish_steps; ++step) {
    WeighAll(ctx, cands, stats, /*icp=*/true);
    for (std::size_t i = 0; i < cands.size(); ++i)
      if (cands[i].weight > path_best[i].weight) path_best[i] = cands[i];
    if (step == o.polish_steps) break;
    for (Particle& p : cands) filter::ApplyMove(diffusion, Move::kIcpStep, &p, p.weight, unused);
  }
  std::sort(path_best.begin(), path_best.end(), [](const Particle& a, const Particle& b) { return a.weight > b.weight; });

  // Pattern search (compass search) on the weight itself from the best candidates: each
  // round tries ±step along three axes and ±angle about them through the model centre, moves
  // to the best improvement, and halves step and angle when none improves; the ICP steps
  // align surfaces, this also aligns the outline (N_depth, edges). The axes are the support
  // plane's (two in the plane, its normal) where one was found — an object resting on the
  // table then slides and turns on it, the moves that align the outline of a thin or flat
  // object, which point-to-plane ICP on its top face cannot — else the camera's.
  const Eigen::Isometry3d& C = ctx.scene.camera.base_to_camera;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns, camera frame
  if (ctx.plane.found) {
    const Eigen::Vector3d n = ctx.plane.normal, e1 = n.unitOrthogonal();
    axes << e1, n.cross(e1), n;
  }
  struct Climber {
    Particle p;
    double step_m = 0.01, angle_rad = 0.1;
  };
  std::vector<Climber> climbers;
  for (int i = 0; i < std::min(int(path_best.size()), o.polish_climbers); ++i) climbers.push_back({path_best[i]});
  for (int round = 0; round < 24; ++round) {
    std::vector<Particle> trials;
    std::vector<int> owner;
    for (int c = 0; c < int(climbers.size()); ++c) {
      const Climber& cl = climbers[c];
      if (cl.step_m < 0.0005) continue;
      const Eigen::Isometry3d T_cam = C * PoseToTransform(cl.p.pose);
      const Eigen::Vector3d pc = T_cam * centre;
      for (int dof = 0; dof < 6; ++dof)
        for (double sign : {-1.0, 1.0}) {
          Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
          if (dof < 3) {
            D.translation() = sign * cl.step_m * axes.col(dof);
          } else {
            D.linear() = Eigen::AngleAxisd(sign * cl.angle_rad, axes.col(dof - 3)).toRotationMatrix();
            D.translation() = pc - D.linear() * pc;
          }
          Particle t = cl.p;
          t.pose = TransformToPose(C.inverse() * D * T_cam);
          t.scored = false;
          trials.push_back(t);
          owner.push_back(c);
        }
    }
    if (trials.empty()) break;
    WeighAll(ctx, trials, stats);
    std::vector<int> best_trial(climbers.size(), -1);
    for (int i = 0; i < int(trials.size()); ++i) {
      const int c = owner[i];
      const double ref = best_trial[c] < 0 ? climbers[c].p.weight : trials[best_trial[c]].weight;
      if (trials[i].weight > ref) best_trial[c] = i;
    }
    for (int c = 0; c < int(climbers.size()); ++c) {
      Climber& cl = climbers[c];
      if (cl.step_m < 0.0005) continue;
      if (best_trial[c] >= 0) {
        cl.p = trials[best_trial[c]];
      } else {
        cl.step_m *= 0.5;
        cl.angle_rad *= 0.5;
      }
    }
  }
  Particle best = path_best.front();
  for (const Climber& cl : climbers)
    if (cl.p.weight > best.weight) best = cl.p;
  return best;
}

}  // namespace

namespace filter {

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

}  // namespace filter

EstimateResult EstimatePose(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress) {
  if (options.engine == "hw") return EstimatePoseHw(scene, mesh, prior, cls, options, progress);  // src/hw/engine.cc
  const auto t_start = Clock::now();
  Mesh lod;  // the mesh rendered at options.lod_max_faces (unused at 0: the full mesh)
  const filter::PreparedScene prep = filter::PrepareScene(scene, options);
  Context ctx = BuildContext(prep, MeshAtLod(mesh, options.lod_max_faces, &lod), prior, cls, options, true);
  // A cell without a heuristic volume cannot host a particle (App. B: check_pose()).
  std::vector<double> cell_mass(prior.layout.CellCount(), 0.0);
  for (int c = 0; c < prior.layout.CellCount(); ++c)
    if (ctx.volumes.Valid(c)) cell_mass[c] = prior.Prob(c, cls);
  if (!(std::accumulate(cell_mass.begin(), cell_mass.end(), 0.0) > 0))
    throw filter::NoInitialMassError(prior, cls, options);

  // Independent runs (restarts), each with its own random stream; the best weight wins.
  std::vector<Particle> run_bests;  // seeds of the final polish
  EstimateResult best = filter::RunRestarts(options, progress, [&](Rng& rng, const ProgressFn& run_progress) {
    return RunFilter(ctx, cell_mass, rng, run_progress, &run_bests);
  });
  if (options.polish_steps > 0) {
    const Particle p = Polish(ctx, run_bests, &best.stats);
    if (p.weight > best.weight) filter::AdoptPose(&best, scene.camera, {p.pose, p.cell, p.weight}, options.confidence);
  }
  best.obj = mesh.name;
  best.time_ms = MsSince(t_start);
  return best;
}

}  // namespace posefilter
