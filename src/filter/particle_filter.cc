// The particle filter of the float engines, `reference`, `cpu` and `gpu` (thesis §2.2, §7.4–7.6,
// App. B; docs/ALGORITHM.md §4–9): the context set-up (BuildContext), the weighing of particles
// (WeighAll, WeighPoses: kernel parameters and weights here, the kernel behind the engine's
// ParticleWeigher, engine_weigh.h), one run of the filter (RunFilter) and the float engines'
// EngineRuns (engine.h), whose final polish is polish.cc. EstimatePose, the driver every engine
// shares, is in driver.cc; the options' checks in option_table.cc.
#include <algorithm>
#include <numeric>
#include <cmath>
#include <array>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "core/mesh_scale.h"
#include "core/threads.h"
#include "filter/cdf_sampler.h"
#include "filter/diffusion.h"
#include "filter/driver.h"
#include "filter/engine.h"
#include "filter/engine_registry.h"
#include "filter/engine_weigh.h"
#include "filter/filter_context.h"
#include "filter/host_setup.h"
#include "filter/model_lod.h"
#include "filter/online_sorter.h"
#include "filter/polish.h"
#include "filter/scene_prep.h"
#include "prior/volume_cache.h"
#include "render/cpu_kernel.h"
#include "render/scene_normals.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/option_table.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/prepared_model.h"
#include "posefilter/rng.h"
#include "posefilter/stable_poses.h"

namespace posefilter {
namespace {

using filter::BuildContext;
using filter::Clock;
using filter::Context;
using filter::Level;
using filter::MsSince;
using filter::Particle;
using filter::RunState;
using filter::Scratch;
using filter::WeighBatch;
using filter::WeighAll;

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

// Computes cell c's heuristic volume and window into the scratch if not done yet (on demand
// because a run uses a few hundred of a pyramid's thousands of cells). The serial steps call
// it: WeighAll for its particles' cells before its parallel loop.
void PrepareCell(const Context& ctx, Scratch& scratch, int c) {
  if (scratch.window_ready[std::size_t(c)]) return;
  // The object's diameter in pixels at the depth of the cell's volume centre; the window's
  // cap grows with the fine level's pixel stride (a window of that many pixels of the level).
  const Camera& cam = ctx.scene().camera;
  const double min_side =
      filter::MinWindowSide(ctx.opt, ctx.model->diameter, cam, ctx.volumes.Valid(c) ? &ctx.volumes.Get(c) : nullptr);
  scratch.windows[std::size_t(c)] = filter::CellWindow(ctx.prior->boxes[std::size_t(c)], min_side,
                                                       ctx.opt.render.max_window_px * ctx.fine().factor, cam.width, cam.height);
  scratch.window_ready[std::size_t(c)] = 1;
}

// The window a particle is weighed in (ours, FilterOptions::render.grow_window): its cell's window
// grown, axis by axis, to contain the projection of the model's bounding box at the
// particle's pose (T = object → camera), clipped to the image. An axis whose grown extent
// would exceed max(max_window_px, the cell window's) keeps the cell window's extent, as does
// a pose with a corner behind the near plane. Without growing, a pose that fits the scene but
// hangs out of a jittered detection box loses its outside pixels to a pose that does not.
PixelRect ParticleWindow(const Context& ctx, const Scratch& scratch, const Eigen::Isometry3d& T, int cell) {
  const PixelRect& w = scratch.windows[std::size_t(cell)];
  if (!ctx.opt.render.grow_window) return w;
  const Camera& cam = ctx.scene().camera;
  double u_lo = 1e30, u_hi = -1e30, v_lo = 1e30, v_hi = -1e30;
  for (const Eigen::Vector3d& c : ctx.model->bbox_corners) {
    const Eigen::Vector3d p = T * c;
    if (p.z() < ctx.opt.render.near_m) return w;
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
  const int cap = ctx.opt.render.max_window_px * ctx.fine().factor;  // full-image pixels
  grow(w.u0, w.width, u_lo, u_hi, cam.width, cap, &r.u0, &r.width);
  grow(w.v0, w.height, v_lo, v_hi, cam.height, cap, &r.v0, &r.height);
  return r;
}

// Listing 7.5 [ALGORITHM.md]: x, y at the volume centre, z uniform in [z_min, z_max]; angles uniform in ±π.
// Or (ours, FilterOptions::support.stable_start, with a support plane): resting on the plane in one of
// the mesh's stable poses (drawn by probability), turned by a uniform yaw about the plane's
// normal, its centre of mass above the point of the plane below the centre of the cell's
// visible surface (the volume without the depth extension), moved away from the camera along
// the plane by a uniform fraction of the object's radius.
Particle NewParticle(const Context& ctx, int cell, Rng& rng) {
  const Volume& vol = ctx.volumes.Get(cell);
  // The support below the centre of the cell's visible surface (none: the start of Listing 7.5 [ALGORITHM.md]).
  const SupportPlane* below = ctx.stable.empty() ? nullptr
                                                 : PlaneBelow(ctx, ctx.scene().camera.base_to_camera * ctx.surface_volumes.Get(cell).Centre());
  Particle p;
  p.cell = cell;
  const Eigen::Vector3d c = vol.Centre();
  const double u_start = rng.Uniform();
  // A seeded start: the first seed_start of u_start's range (only where there are seeds).
  const double seeded = ctx.seeds.empty() ? 0.0 : ctx.opt.seed_start;
  if (u_start < seeded) {
    const double u_seed = rng.Uniform() * ctx.seed_cdf.back();
    const std::size_t k = std::size_t(std::upper_bound(ctx.seed_cdf.begin(), ctx.seed_cdf.end(), u_seed) - ctx.seed_cdf.begin());
    const auto& [pose, seed_cell] = ctx.seeds[std::min(k, ctx.seeds.size() - 1)];
    p.pose = pose;
    p.cell = seed_cell;
    return p;
  }
  if (below && u_start - seeded < ctx.opt.support.stable_start * (1 - seeded)) {
    const double u_pose = rng.Uniform(), yaw = rng.Uniform(-M_PI, M_PI), back = rng.Uniform();
    std::size_t k = 0;
    for (double acc = ctx.stable[0].probability; k + 1 < ctx.stable.size() && u_pose >= acc;)
      acc += ctx.stable[++k].probability;
    const Eigen::Isometry3d& C = ctx.scene().camera.base_to_camera;
    const Eigen::Vector3d centre = C * ctx.surface_volumes.Get(cell).Centre();
    const Eigen::Vector3d n = below->normal;
    Eigen::Isometry3d T_cam_table = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d ex = n.unitOrthogonal();
    T_cam_table.linear() << ex, n.cross(ex), n;
    // The visible surface's foot, moved away from the camera along the plane by up to the
    // object's radius: the object lies behind what the camera sees of it (and an occluder in
    // the box pulls the surface's centre towards the camera).
    Eigen::Vector3d away = centre - n * n.dot(centre);
    if (away.norm() > 1e-9) away.normalize();
    T_cam_table.translation() = centre - below->Height(centre) * n + back * 0.5 * ctx.model->diameter * away;
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

// The pixel level weighings use at the moment (RunState::level).
const Level& CurrentLevel(const Context& ctx, const RunState& run) { return ctx.levels[run.level]; }

// Particle p's transform object → camera (FT without P).
Eigen::Isometry3d CameraFromObject(const Context& ctx, const Particle& p) {
  return ctx.scene().camera.base_to_camera * PoseToTransform(p.pose);
}

// The window a particle at T (object → camera) in `cell` is weighed in: ParticleWindow, on
// the pixel grid of the current level.
PixelRect WeighWindow(const Context& ctx, const RunState& run, const Scratch& scratch, const Eigen::Isometry3d& T,
                      int cell) {
  const PixelRect w = ParticleWindow(ctx, scratch, T, cell);
  const int s = CurrentLevel(ctx, run).factor;
  if (s == 1) return w;
  // The level's pixels i whose full-resolution pixel s·i lies in [u0, u1): ceil(u0 / s) ≤ i < ceil(u1 / s).
  auto up = [s](int a) { return (a + s - 1) / s; };  // a ≥ 0: windows lie inside the image
  const int u0 = up(w.u0), u1 = up(w.u0 + w.width);
  const int v0 = up(w.v0), v1 = up(w.v0 + w.height);
  return PixelRect{u0, v0, u1 - u0, v1 - v0};
}

// The contact prior's penalty of a pose T (object → camera): FilterOptions::support.contact times the
// fraction of contact_span_m by which the lowest hull point floats above, or sinks below, the
// support plane beyond contact_tolerance_m (0 without a plane).
double ContactPenalty(const Context& ctx, const Eigen::Isometry3d& T) {
  if (ctx.hull.empty()) return 0.0;
  const SupportPlane* below = PlaneBelow(ctx, T * ctx.model->box_centre);  // the object's own support
  if (!below) return 0.0;
  double lowest = 1e30;
  for (const Eigen::Vector3d& v : ctx.hull) lowest = std::min(lowest, below->Height(T * v));
  const double off = std::fabs(lowest) - ctx.opt.support.contact_tolerance_m;
  return off > 0 ? ctx.opt.support.contact * std::min(1.0, off / ctx.opt.support.contact_span_m) : 0.0;
}

// The kernel parameters of particle p at T (object → camera) on the current level; `icp`:
// with the level's scene normals.
ScoreKernelParams ParticleParams(const Context& ctx, const RunState& run, const Scratch& scratch, const Particle& p,
                                 const Eigen::Isometry3d& T, bool icp) {
  const Level& level = CurrentLevel(ctx, run);
  const SceneInput& scene = level.scene;
  ScoreKernelParams k = MakeKernelParams(*level.mesh, T, scene.camera);
  k.near_m = float(ctx.opt.render.near_m);
  k.window = WeighWindow(ctx, run, scratch, T, p.cell);
  k.depth = scene.depth.data.data();
  k.depth_width = scene.depth.width;
  k.depth_height = scene.depth.height;
  k.inlier = run.inlier;
  k.zbuffer = ctx.opt.render.zbuffer;
  k.align_band_m = float(ctx.opt.diffusion.align_band_m);
  k.edge_band_m = float(ctx.opt.score.edge_band_m);
  k.scene_normals = icp ? scratch.normals[run.level].data() : nullptr;
  return k;
}

// Weight of eq. 7.4 [ALGORITHM.md] of particle p at T (object → camera) from its kernel result on the
// current level, whose window is `window`.
double WeightFromScore(const Context& ctx, const RunState& run, const Particle& p, const Eigen::Isometry3d& T,
                       const PixelRect& window, const ScoreKernelResult* out) {
  const Level& level = CurrentLevel(ctx, run);
  const double I = out->inlier_sum;
  // Without a z-buffer fragments may overlap, so each ratio is capped at 1.
  const std::int64_t n_raster = ctx.opt.score.occlusion_aware ? out->n_raster - out->n_occluded : out->n_raster;
  const double r_raster = n_raster > 0 ? std::min(1.0, I / double(n_raster)) : 0.0;
  const long nd = long(level.valid_depth.Count(window));
  const double r_depth = nd > 0 ? std::min(1.0, I / double(nd)) : 0.0;
  const double rho = ctx.prior->Prob(p.cell, ctx.cls);
  const double r_edge = out->n_edge > 0 ? double(out->n_edge_continued) / double(out->n_edge) : 0.0;
  return std::max(0.0, ctx.opt.score.alpha * r_raster + ctx.opt.score.beta * r_depth + ctx.opt.score.gamma * rho - ctx.opt.score.delta * r_edge -
                           ContactPenalty(ctx, T));
}

// Records a weighing's result in its particle (WeighAll adds its counters to the statistics).
void Record(Particle& p, double weight, const ScoreKernelResult& r, bool icp) {
  p.weight = weight;
  p.depth_offset = r.depth_diff_count > 0 ? r.depth_diff_sum / double(r.depth_diff_count) : 0.0;
  p.icp_valid = icp && filter::SolveIcpStep(r, &p.icp_step);
  p.icp_known = icp;
  p.scored = true;
}

}  // namespace

namespace filter {

const SupportSurfaces& Context::surfaces() const {
  static const SupportSurfaces kNone{};
  return prep->plane.found ? prep->surfaces : kNone;
}

RunState FinalRunState(const Context& ctx) { return RunState{ctx.opt.score.inlier, kFineLevel}; }

Scratch MakeScratch(const Context& ctx) {
  Scratch s;
  for (int l = 0; l < 2; ++l) {
    const Level& level = ctx.levels[std::size_t(l)];
    if (l == kCoarseLevel && !ctx.has_coarse()) break;
    s.normals[std::size_t(l)] = render::SceneNormalTiles(level.scene.depth.width, level.scene.depth.height);
  }
  const std::size_t cells = std::size_t(ctx.prior->layout.CellCount());
  s.windows.resize(cells);  // PrepareCell fills them in as cells are used
  s.window_ready.assign(cells, 0);
  s.weigher = ctx.engine->make_weigher(ctx);
  return s;
}

void WeighAll(const Context& ctx, const RunState& run, Scratch& scratch, std::vector<Particle>& ps, FilterStats* stats,
              bool icp) {
  const int n = int(ps.size());
  const int threads = WorkerThreads(ctx.opt.threads);
  for (const Particle& p : ps) PrepareCell(ctx, scratch, p.cell);  // the windows the workers read
  if (icp) {  // the scene normals under the windows of the ICP weighings
    std::vector<PixelRect> windows;
    for (const Particle& p : ps)
      if (!p.scored) windows.push_back(WeighWindow(ctx, run, scratch, CameraFromObject(ctx, p), p.cell));
    const SceneInput& scene = CurrentLevel(ctx, run).scene;
    scratch.normals[run.level].Prepare(scene.depth, scene.camera, windows, ctx.opt.threads);
  }
  // The batch: every unscored particle's transform and kernel parameters, in particle order.
  std::vector<int> idx;
  for (int i = 0; i < n; ++i)
    if (!ps[std::size_t(i)].scored) idx.push_back(i);
  if (idx.empty()) return;
  const int m = int(idx.size());
  std::vector<Eigen::Isometry3d> poses(std::size_t(m), Eigen::Isometry3d::Identity());
  std::vector<ScoreKernelParams> params(static_cast<std::size_t>(m));
  ParallelFor(threads, m, 4, [&](int, int j) {
    const Particle& p = ps[std::size_t(idx[std::size_t(j)])];
    poses[std::size_t(j)] = CameraFromObject(ctx, p);
    params[std::size_t(j)] = ParticleParams(ctx, run, scratch, p, poses[std::size_t(j)], icp);
  });
  // The engine's weigher scores them (engine_weigh.h); each weight is the particle's own.
  std::vector<ScoreKernelResult> results;
  const WeighBatch batch{run.level, CurrentLevel(ctx, run).face_planes, icp, ctx.opt.threads};
  scratch.weigher->Score(batch, params, &results);
  ParallelFor(threads, m, 4, [&](int, int j) {
    const std::size_t k = std::size_t(j);
    Particle& p = ps[std::size_t(idx[k])];
    Record(p, WeightFromScore(ctx, run, p, poses[k], params[k].window, &results[k]), results[k], icp);
  });
  // The counters, summed in particle order.
  for (const ScoreKernelResult& r : results) {
    stats->faces_total += r.faces_total;
    stats->faces_front += r.faces_front;
    stats->fragments += r.n_raster;
    ++stats->weighings;
  }
}

}  // namespace filter

namespace {

// Plausible scene and object sizes (metres): what a depth camera sees, and objects between a
// thousandth and ten times the scene's median depth across.
constexpr double kMinPlausibleDepthM = 0.01, kMaxPlausibleDepthM = 100;


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
  if (!MedianValidDepthWithin(d, kMinPlausibleDepthM, kMaxPlausibleDepthM)) {
    const double median = MedianValidDepth(d);
    std::ostringstream os;
    os << what << ": the median depth is " << median << " m, outside the [" << kMinPlausibleDepthM << ", "
       << kMaxPlausibleDepthM << "] m of a depth camera: wrong depth scale (metres per PNG unit)?";
    throw Error(os.str());
  }
  filter::ValidateObjectInput(scene.mask, scene.seeds, d.data.size(), what);
}

void filter::ValidateObjectInput(const std::vector<std::uint8_t>& mask, const std::vector<PoseSeed>& seeds,
                                 std::size_t pixels, const std::string& what) {
  if (!mask.empty()) {
    if (mask.size() != pixels) {
      std::ostringstream os;
      os << what << ": the mask holds " << mask.size() << " pixels but the image " << pixels;
      throw Error(os.str());
    }
    if (std::none_of(mask.begin(), mask.end(), [](std::uint8_t m) { return m != 0; }))
      throw Error(what + ": the mask is empty (no pixel of the object)");
  }
  for (std::size_t k = 0; k < seeds.size(); ++k)
    if (!seeds[k].T_cam_obj.matrix().allFinite() || !(seeds[k].score > 0 && std::isfinite(seeds[k].score)))
      throw Error(what + ": pose seed " + std::to_string(k) + " is not finite or has no positive score");
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

namespace filter {

Context BuildContext(std::shared_ptr<const PreparedScene> prep_ptr, std::shared_ptr<const ModelLod> model,
                     const Prior& prior, int cls, const FilterOptions& options, bool runs,
                     const std::vector<Pose6>* poses) {
  const PreparedScene& prep = *prep_ptr;  // options: checked by the caller (ThrowIfInvalid)
  const Mesh& mesh = model->lod;
  const SceneInput& scene = prep.scoring;
  if (cls < 0 || cls >= int(prior.classes.size())) throw Error("class index out of range for the prior");
  if (prior.layout.image_width != scene.camera.width || prior.layout.image_height != scene.camera.height)
    throw Error("prior was made for a different image size than the camera's");

  Context ctx;
  ctx.prep = std::move(prep_ptr);
  ctx.model = std::move(model);
  ctx.prior = &prior;
  ctx.cls = cls;
  ctx.opt = options;
  // cpu_isa names a supported variant or is "auto" (options were validated).
  ctx.engine = filter::FindEngine(options.engine);
  if (ctx.engine == nullptr) throw Error("unknown engine '" + options.engine + "'");
  if (!render::ParseCpuTarget(options.cpu_isa, &ctx.cpu_target)) ctx.cpu_target = render::BestCpuTarget();
  // An engine that weighs this context and cannot run here (no Vulkan device, ...): before any set-up.
  if (std::string why; ctx.engine->float_filter && !ctx.engine->available(&why)) throw Error(why);
  const ModelLod& m = *ctx.model;
  const double diameter = m.diameter;
  CheckMeshScale(mesh.name, diameter, prep.support);
  const HeuristicOptions hopt = VolumeOptions(options, diameter);
  ctx.volumes = prior::VolumeCache(prep.support, scene.camera, prior.boxes, hopt, options.threads);
  const int cells = prior.layout.CellCount();
  // The mesh stride of render.lod_face_px (1 when off): from the class's most probable cell, or
  // from the nearest of the given poses.
  int mesh_factor = 1;
  if (poses == nullptr) {
    mesh_factor = filter::MeshFactor(options, prior, cls, ctx.volumes, scene.camera, diameter, int(mesh.faces.size()));
  } else {
    double z_near = std::numeric_limits<double>::infinity();
    for (const Pose6& p : *poses)
      z_near = std::min(z_near, (scene.camera.base_to_camera * PoseToTransform(p) * m.box_centre).z());
    if (std::isfinite(z_near))
      mesh_factor = filter::MeshFactorAt(options, scene.camera, diameter, int(mesh.faces.size()), z_near);
  }
  // A pixel level of the given factor: the scene and N_depth table subsampled, and (factor > 1,
  // anneal_simplify) the model's mesh simplified to faces / factor² faces (at least
  // kCoarseMinFaces; a mesh meshoptimizer cannot bring to the budget is weighed as it is), or
  // to faces / mesh_factor² where that is fewer.
  auto make_level = [&](int factor) {
    Level l;
    l.factor = factor;
    l.scene = factor > 1 ? SubsampleScene(scene, factor) : scene;
    const DepthImage support = factor > 1 ? SubsampleScene(SceneInput{prep.support, scene.camera}, factor).depth : prep.support;
    l.valid_depth = render::ValidDepthSat(support.data.data(), support.width, support.height);
    l.mesh = &mesh;
    l.face_planes = &m.face_planes;
    const int mesh_stride = std::max(options.anneal.simplify ? factor : 1, mesh_factor);
    if (mesh_stride > 1) {
      const int budget = filter::CoarseMeshFaces(int(mesh.faces.size()), mesh_stride);
      if (int(mesh.faces.size()) > budget) {
        const CoarseMesh* coarse = m.Coarse(budget);
        if (!coarse) throw Error("internal: mesh '" + mesh.name + "' was not prepared for this coarse level");
        if (coarse->simplified) l.mesh = &coarse->mesh, l.face_planes = &coarse->face_planes;
      }
    }
    return l;
  };
  ctx.levels[kFineLevel] = make_level(filter::FineFactor(options, prior, cls, ctx.volumes, scene.camera, diameter));
  if (runs && options.anneal.subsample > 1 && filter::AnnealIterations(options) > 0)
    ctx.levels[kCoarseLevel] = make_level(ctx.fine().factor * options.anneal.subsample);
  if (options.support.contact > 0 && prep.plane.found) {
    if (!m.hull_error.empty()) throw Error(m.hull_error);
    ctx.hull = m.hull;
  }
  if (runs && options.support.stable_start > 0 && prep.plane.found) {
    if (!m.stable_error.empty()) throw Error(m.stable_error);
    ctx.stable = m.stable;
    HeuristicOptions surface = hopt;
    surface.depth_extension_m = 0;
    ctx.surface_volumes = prior::VolumeCache(prep.support, scene.camera, prior.boxes, surface, options.threads);
  }
  // Hypotheses for niching: every cell labelled, unbounded (a cell no detection reaches
  // keeps its anchor box, and a label of its own).
  HypothesisLabeller labeller;
  ctx.hypothesis.resize(cells);
  for (int c = 0; c < cells; ++c) ctx.hypothesis[c] = labeller.Label(prior.boxes[c]);
  ctx.hypothesis_count = labeller.count();
  // Pose seeds: each in the cell of the class's highest probability (then the finest level)
  // whose anchor holds the projected box centre and whose volume is valid.
  if (runs && options.seed_start > 0) {
    const Eigen::Isometry3d base_from_cam = scene.camera.base_to_camera.inverse();
    for (const PoseSeed& seed : scene.seeds) {
      const Eigen::Vector3d centre = seed.T_cam_obj * m.box_centre;
      if (!(centre.z() > 0)) continue;
      const Eigen::Vector2d px = scene.camera.Project(centre);
      int best = -1;
      for (int c = 0; c < cells; ++c) {
        const Box a = prior.layout.AnchorBox(c);
        if (std::fabs(px.x() - a.cx) > 0.5 * a.w || std::fabs(px.y() - a.cy) > 0.5 * a.h) continue;
        if (best >= 0 && prior.Prob(c, cls) < prior.Prob(best, cls)) continue;
        if (ctx.volumes.Valid(c)) best = c;
      }
      if (best < 0) continue;
      ctx.seeds.push_back({TransformToPose(base_from_cam * seed.T_cam_obj), best});
      ctx.seed_cdf.push_back((ctx.seed_cdf.empty() ? 0.0 : ctx.seed_cdf.back()) + seed.score);
    }
  }
  return ctx;
}

}  // namespace filter

namespace {

// WeighPoses on the prepared scene and the model's level of detail.
std::vector<double> WeighPreparedPoses(std::shared_ptr<const filter::PreparedScene> prep,
                                       std::shared_ptr<const filter::ModelLod> lod, const Prior& prior, int cls,
                                       const FilterOptions& options,
                                       const std::vector<std::pair<Pose6, int>>& hypotheses) {
  std::vector<Pose6> poses;
  for (const auto& h : hypotheses) poses.push_back(h.first);
  const Context ctx = BuildContext(std::move(prep), std::move(lod), prior, cls, options, false, &poses);
  std::vector<Particle> ps(hypotheses.size());
  for (std::size_t i = 0; i < hypotheses.size(); ++i) {
    if (hypotheses[i].second < 0 || hypotheses[i].second >= prior.layout.CellCount())
      throw Error("WeighPoses: cell index out of range");
    ps[i].pose = hypotheses[i].first;
    ps[i].cell = hypotheses[i].second;
  }
  FilterStats stats;
  Scratch scratch = filter::MakeScratch(ctx);
  WeighAll(ctx, filter::FinalRunState(ctx), scratch, ps, &stats);
  std::vector<double> w(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) w[i] = ps[i].weight;
  return w;
}

}  // namespace

std::vector<double> WeighPoses(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                               const FilterOptions& options, const std::vector<std::pair<Pose6, int>>& hypotheses) {
  ThrowIfInvalid(options, OptionNaming::kField);
  auto prep = std::make_shared<const filter::PreparedScene>(filter::PrepareScene(scene, options));
  auto lod = filter::LodFor(nullptr, mesh, options, false, prep->plane.found);
  return WeighPreparedPoses(std::move(prep), std::move(lod), prior, cls, options, hypotheses);
}

std::vector<double> WeighPoses(const SceneInput& scene, const PreparedModel& model, const Prior& prior, int cls,
                               const FilterOptions& options, const std::vector<std::pair<Pose6, int>>& hypotheses) {
  ThrowIfInvalid(options, OptionNaming::kField);
  auto prep = std::make_shared<const filter::PreparedScene>(filter::PrepareScene(scene, options));
  auto lod = filter::LodFor(&model, model.mesh(), options, false, prep->plane.found);
  return WeighPreparedPoses(std::move(prep), std::move(lod), prior, cls, options, hypotheses);
}

std::vector<double> WeighPoses(const PreparedFrame& frame, const ObjectInput& object, const PreparedModel& model,
                               const Prior& prior, int cls, const FilterOptions& options,
                               const std::vector<std::pair<Pose6, int>>& hypotheses) {
  ThrowIfInvalid(options, OptionNaming::kField);
  auto prep = filter::SceneFor(frame, object, options);
  auto lod = filter::LodFor(&model, model.mesh(), options, false, prep->plane.found);
  return WeighPreparedPoses(std::move(prep), std::move(lod), prior, cls, options, hypotheses);
}

std::vector<double> WeighPoses(const PreparedFrame& frame, const ObjectInput& object, const Mesh& mesh,
                               const Prior& prior, int cls, const FilterOptions& options,
                               const std::vector<std::pair<Pose6, int>>& hypotheses) {
  ThrowIfInvalid(options, OptionNaming::kField);
  auto prep = filter::SceneFor(frame, object, options);
  auto lod = filter::LodFor(nullptr, mesh, options, false, prep->plane.found);
  return WeighPreparedPoses(std::move(prep), std::move(lod), prior, cls, options, hypotheses);
}

namespace {

// One run of the filter (initialisation to convergence) on a prepared context.
// `leaders` receives the best particle of each (hypothesis, orientation bin) niche of the
// final set, best first, at most FilterOptions::polish.seeds of them.
EstimateResult RunFilter(const Context& ctx, Scratch& scratch, const std::vector<double>& cell_mass, Rng& rng,
                         const ProgressFn& progress, std::vector<Particle>* leaders) {
  EstimateResult res;
  const FilterOptions& options = ctx.opt;
  const SceneInput& scene = ctx.scene();
  const std::array<Eigen::Vector3d, 8>& corners = ctx.model->bbox_corners;
  const filter::DiffusionContext diffusion(scene.camera, ctx.prior->layout, ctx.volumes, options, &ctx.plane(),
                                           0.5 * (corners[0] + corners[7]), &ctx.surfaces());
  RunState run;  // this run's thresholds and pixel level, set per iteration
  // Coarse-to-fine inlier threshold: thr1 falls geometrically from anneal_start_m to its
  // final value over the first anneal_fraction of the iterations, weighed on the coarse pixel
  // grid while it does (anneal_subsample > 1). Sets the threshold and the pixel grid of
  // iteration `it`; returns true when either changed (weights measured before are stale).
  const int anneal_its = filter::AnnealIterations(options);
  auto set_threshold = [&](int it) {
    const float thr = float(filter::AnnealedThreshold(options, it, anneal_its));
    const bool changed = thr != run.inlier.thr1_m;
    run.inlier.thr1_m = thr;
    run.inlier.hard_thr_m = filter::ScaledHardThreshold<float>(options.score.inlier, thr);
    // Never the run's last possible iteration: its weights are the answer's.
    const bool coarse = ctx.has_coarse() && it < anneal_its && it + 1 < options.stop.max_iterations;
    const bool level_changed = coarse != (run.level == filter::kCoarseLevel);
    run.level = coarse ? filter::kCoarseLevel : filter::kFineLevel;
    return changed || level_changed;
  };
  run.inlier = options.score.inlier;
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
      WeighAll(ctx, run, scratch, drawn, &res.stats);
      filter::OnlineSorter sorter(M);
      for (int i = 0; i < M; ++i) sorter.Insert(drawn[i].weight, i);
      for (int i = 0; i < N; ++i) current[i] = drawn[sorter.sorted()[i].index];
    } else {
      current = drawn;
    }
  }

  Particle best;
  for (int it = 0; it < options.stop.max_iterations; ++it) {
    const auto t_iter = Clock::now();
    if (set_threshold(it))
      for (auto& p : current) p.scored = false;
    // 2. Weigh.
    WeighAll(ctx, run, scratch, current, &res.stats);
    // 3. Sort online as the weights arrive.
    const int Nc = int(current.size());
    filter::OnlineSorter sorter(Nc);
    for (int i = 0; i < Nc; ++i) sorter.Insert(current[i].weight, i);
    const auto& ranked = sorter.sorted();
    best = current[ranked[0].index];
    res.best_weight_history.push_back(best.weight);
    res.iterations = it + 1;
    if (options.record_particles) {  // the set as weighed, best first
      ParticleSet& set = res.particle_history.emplace_back();
      set.iteration = it;
      for (const auto& r : ranked) {
        set.poses.push_back(current[r.index].pose);
        set.weights.push_back(current[r.index].weight);
      }
    }
    // 4. Converged, stalled or out of iterations: the last set is already weighed; report its best.
    if (filter::RunEnds(options, it, anneal_its, res.best_weight_history, &res.converged)) {
      std::set<std::pair<int, int>> niches;
      for (int j = 0; j < Nc && int(niches.size()) < options.polish.seeds; ++j) {
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
    const int pool_size = filter::ResamplePoolSize(options, Nc);
    const int cap = filter::NicheCap(options.niches.region_cap, pool_size);
    const int rot_cap = filter::NicheCap(options.niches.rotation_cap, pool_size);
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
      WeighAll(ctx, run, scratch, parents, &res.stats, /*icp=*/true);
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

// The float engines' runs: one context (levels, volumes, hypotheses) and one scratch (windows,
// the weigher, normals) serve every run and the final polish; each run keeps its own RunState.
class FloatEngine final : public filter::EngineRuns {
 public:
  FloatEngine(const std::shared_ptr<const filter::PreparedScene>& prep, std::shared_ptr<const filter::ModelLod> model,
              const Prior& prior, int cls, const FilterOptions& options)
      : ctx_(BuildContext(prep, std::move(model), prior, cls, options, true)), scratch_(filter::MakeScratch(ctx_)) {
    // A cell without a heuristic volume cannot host a particle (App. B: check_pose()).
    cell_mass_.assign(std::size_t(prior.layout.CellCount()), 0.0);
    for (int c = 0; c < prior.layout.CellCount(); ++c)
      if (ctx_.volumes.Valid(c)) cell_mass_[std::size_t(c)] = prior.Prob(c, cls);
    if (!(std::accumulate(cell_mass_.begin(), cell_mass_.end(), 0.0) > 0))
      throw filter::NoInitialMassError(prior, cls, options, prep.get());
  }

  EstimateResult Run(Rng& rng, const ProgressFn& progress) override {
    return RunFilter(ctx_, scratch_, cell_mass_, rng, progress, &run_bests_);
  }

  filter::PolishResult PolishRuns(FilterStats* stats) override {
    const Particle p = filter::Polish(ctx_, scratch_, run_bests_, stats);
    return {p.pose, p.cell, p.weight};
  }

 private:
  const Context ctx_;
  Scratch scratch_;
  std::vector<double> cell_mass_;
  std::vector<Particle> run_bests_;  // seeds of the final polish, from every run
};

}  // namespace

namespace filter {

std::unique_ptr<EngineRuns> MakeFloatEngine(const std::shared_ptr<const PreparedScene>& prep, std::shared_ptr<const ModelLod> model,
                                            const Prior& prior, int cls, const FilterOptions& options) {
  return std::make_unique<FloatEngine>(prep, std::move(model), prior, cls, options);
}

}  // namespace filter

}  // namespace posefilter
