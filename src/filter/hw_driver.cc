// src/filter/hw_driver.cc — the `hw` engine's host driver (host side of the C simulation;
// docs/HARDWARE.md §4), beside the float engines' driver: converts the inputs into the
// fixed-point memories of the architecture and runs the top functions of src/hw/top.h iteration
// by iteration (the thesis's control loop) as the engine's runs (filter/engine.h); ProfileHw also
// models the cycles (src/hw/cycle_model.h). The kernels themselves are in src/hw/.
//
// Host / hardware split (docs/HARDWARE.md "Driver"):
//   * host, float, once per run: heuristic volumes (ComputeHeuristics, as the reference
//     engine), per-cell windows (the reference's CellWindow incl. the minimum window of one
//     object diameter), hypothesis labels for the region cap, the inlier-threshold schedule —
//     the set-up shared with the float engines comes from src/filter/host_setup.h;
//   * hardware (C simulation of the kernels): initialisation, transformation, rasterization and
//     scoring, weight merging, sorting, resampling, diffusion — every per-particle step;
//   * host, float, after the runs (polish.steps > 0): the final polish of the runs' best
//     particles (filter::PolishPoses, the float engines' polish with the cpu weighing).
// The prior is a float Prior (any of the three kinds of docs/ALGORITHM.md §2); its class
// probabilities are rounded into the prob_t memory (ρ of eq. 7.4 [ALGORITHM.md]) — the hw post-process kernel runs
// only in ProfileHw, on a raw pyramid, for its cycles.
// The kernels carry HLS pragmas (meaningless to g++) and loop labels (synthesis reports).
#pragma GCC diagnostic ignored "-Wunknown-pragmas"
#pragma GCC diagnostic ignored "-Wunused-label"

#include <algorithm>
#include <functional>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include "core/mesh_scale.h"
#include "core/option_check.h"
#include "filter/driver.h"
#include "filter/engine.h"
#include "filter/host_setup.h"
#include "filter/hw_weigh.h"
#include "filter/scene_prep.h"
#include "hw/cycle_model.h"
#include "hw/latency.h"
#include "hw/postprocess.h"
#include "hw/top.h"
#include "posefilter/error.h"
#include "posefilter/hw_engine.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/option_table.h"
#include "posefilter/rng.h"

namespace posefilter {
namespace {

using namespace posefilter::hw;
static_assert(kHwMaxParticles == kMaxParticles && kHwMaxWindowPx == kMaxWindow, "posefilter/hw_engine.h's limits");
using filter::Clock;
using filter::MsSince;

// Host → fixed point, rounded to nearest and saturated (the kernels' types truncate by default).
xyz_t ToXyz(double v) { return xyz_t(ap_fixed<13, 3, AP_RND, AP_SAT>(v)); }
depth_t ToDepth(double z) {
  if (!(z > 0)) return depth_t(0);
  return depth_t(ap_ufixed<12, 2, AP_RND, AP_SAT>(std::min(z, 4.0)));  // clipped to 4 m (Table 7.1 [HARDWARE.md])
}
prob_t ToProb(double p) { return prob_t(ap_ufixed<8, 0, AP_RND, AP_SAT>(std::clamp(p, 0.0, 1.0))); }
dist_t ToDist(double m) { return dist_t(ap_ufixed<24, 4, AP_RND, AP_SAT>(m)); }

// The thesis pyramid (15×20, 30×40, 60×80) is compile-time in the kernels.
void CheckLayout(const PyramidLayout& layout) {
  if (layout.CellCount() != kNumCells || layout.levels.size() != 3)
    throw Error("hw engine: the prior must use the thesis pyramid (15x20, 30x40, 60x80 = 6300 cells)");
  const int rows[3] = {15, 30, 60}, cols[3] = {20, 40, 80};
  for (int l = 0; l < 3; ++l)
    if (layout.levels[l].rows != rows[l] || layout.levels[l].cols != cols[l])
      throw Error("hw engine: prior level " + std::to_string(l) + " must be " + std::to_string(rows[l]) + "x" +
                  std::to_string(cols[l]) + " (thesis pyramid)");
}

// The mesh as the hardware stores it: ≤ kMaxVertices vertices, ≤ kMaxFaces faces (§7.1).
Mesh HardwareMesh(const Mesh& mesh, int lod_max_faces) {
  Mesh lod;
  Mesh m = MeshAtLod(mesh, lod_max_faces, &lod);
  int budget = std::min<int>(kMaxFaces, int(m.faces.size()));
  for (int attempt = 0; attempt < 12 && (int(m.vertices.size()) > kMaxVertices || int(m.faces.size()) > kMaxFaces);
       ++attempt) {
    m = SimplifyMesh(mesh, budget);
    budget = std::max(kMinSimplifyFaces, int(budget * 0.85));
  }
  if (int(m.vertices.size()) > kMaxVertices || int(m.faces.size()) > kMaxFaces)
    throw Error("mesh '" + mesh.name + "': cannot be reduced to the hw engine's 1024 vertices / 2048 faces");
  for (const auto& v : m.vertices)
    for (int k = 0; k < 3; ++k)
      if (!(std::fabs(v[k]) < 4.0))
        throw Error("mesh '" + mesh.name + "': a vertex lies outside the hw engine's +-4 m (fixed<13,3>)");
  return m;
}

// The float engines' window of a cell (filter::CellWindow, src/filter/host_setup.h: the box
// centred, each side ≥ min_side and ≤ max_px, shifted into the image) in the window memory's
// fields: u0, v0 of 10 bits, width, height of 8 bits (max_px ≤ kMaxWindow = 200 fits).
Window CellWindowHw(const Box& box, double min_side, int max_px, int image_w, int image_h) {
  const PixelRect r = filter::CellWindow(box, min_side, max_px, image_w, image_h);
  Window win;
  win.u0 = r.u0;
  win.v0 = r.v0;
  win.width = r.width;
  win.height = r.height;
  return win;
}

Pose6 SampleToPose(const Sample& s) {
  Pose6 p;
  p.x = s.x.to_double();
  p.y = s.y.to_double();
  p.z = s.z.to_double();
  p.roll = s.roll.to_double();
  p.pitch = s.pitch.to_double();
  p.yaw = s.yaw.to_double();
  return p;
}

// The hardware's memories and parameters for one (scene, mesh, prior, class, options).
struct HwMemories {
  depth_t depth[kImageHeight * kImageWidth];
  xyz_t vmem[3][kMaxVertices];
  face_t tri_mem[kMaxFaces];
  prob_t init_prob[kNumCells][1];     // CDF input (power-of-two scaled, see Load)
  class_sum_t init_sum;
  prob_t class_prob[kNumCells];       // ρ of eq. 7.4 [ALGORITHM.md] (unscaled)
  HeuristicVolume volumes[kNumCells];
  Window cell_windows[kNumCells];
  hypothesis_t hypothesis[kNumCells];
  Sample samples[2][kMaxParticles];   // ping-pong sample memories
  weight_t sorted_w[kMaxParticles];
  particle_index_t sorted_idx[kMaxParticles];
  RasterCoreOutput stats[kMaxParticles];
  depth_off_t offsets[kMaxParticles];  // side-band of the set just weighed: mean z_s − z_r
};

// Per modelled iteration: what ProfileHw accumulates.
struct IterationProfile {
  CycleTrace weigh, update;           // traces of the real tops (M = run cores)
  std::vector<ParticleWork> work;     // per particle (one-particle raster core calls)
  std::vector<Window> windows;        // per particle
};

// The hw engine's weighing (hw_weigh.h): the C model's weigh region, HwWeighTopCores.
class HwCModelWeigh final : public filter::HwWeighStrategy {
 public:
  void Weigh(int cores, int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
             const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
             const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
             const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles], particle_index_t sorted_idx[kMaxParticles],
             RasterCoreOutput stats[kMaxParticles], depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts,
             CycleTrace* trace) override {
    HwWeighTopCores(cores, n, cfg, samples, cell_windows, class_prob, depth, vmem, tri_mem, sorted_w, sorted_idx, stats,
                    offsets, dd_counts, trace);
  }
};

// The C model's weighing, shared (it holds no state).
filter::HwWeighStrategy& CModelWeighing() {
  static HwCModelWeigh weigh;
  return weigh;
}

class HwRunner {
 public:
  // `prep`: filter::PrepareScene's (validated): the depth memory holds prep.scoring, the
  // heuristic volumes come from prep.support. It must outlive the runner.
  HwRunner(const filter::PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls, const FilterOptions& opt)
      : prep_(prep), prior_(prior), cls_(cls), opt_(opt), mem_(new HwMemories) {
    Load(mesh);
  }

  int num_vertices() const { return num_vertices_; }
  int num_faces() const { return cfg_.num_faces; }
  HwMemories& mem() { return *mem_; }
  const WeighConfig& config() const { return cfg_; }
  std::string mesh_name;
  // The weighing each iteration runs (by default the C model's, HwCModelWeigh); not owned.
  void SetWeigh(filter::HwWeighStrategy* weigh) { weigh_ = weigh; }

  // One run (initialisation to convergence). `on_iteration` (may be empty) is called after
  // each weighing with the iteration index and whether a trace was requested for it.
  using Hook = std::function<void(int it, int cur, CycleTrace* weigh, CycleTrace* update, bool last)>;
  EstimateResult Run(Rng& rng, const ProgressFn& progress, CycleTrace* init_trace, const std::function<bool(int)>& trace_it,
                     const Hook& hook) {
    EstimateResult res;
    HwMemories& m = *mem_;
    const int N = opt_.num_particles;
    // Seeds of every LFSR of the run from the host's stream (zero → the LFSR's default).
    InitGenerators gen;
    gen.sampling.Seed(unsigned(rng.NextU64()));
    gen.z.Seed(unsigned(rng.NextU64()));
    gen.roll.Seed(unsigned(rng.NextU64()));
    gen.pitch.Seed(unsigned(rng.NextU64()));
    gen.yaw.Seed(unsigned(rng.NextU64()));
    Lfsr18 resample_rng(unsigned(rng.NextU64()));
    DiffusionRng diffusion_rng(std::uint32_t(rng.NextU64()));
    InitOptions iopt;  // tracker on, LFSR leap on (docs/HARDWARE.md)
    InitReport report;
    if (init_trace) init_trace->Clear();
    {
      const ScopedTopTrace traced(init_trace);
      HwInitTop(m.init_prob, m.init_sum, m.volumes, gen, iopt, m.samples[0], N, report);
    }
    res.stats.init_cdf_reads = std::int64_t(report.counters.reads.to_uint64());
    res.stats.init_cdf_reads_linear = std::int64_t(report.counters.reads_linear.to_uint64());

    // Coarse-to-fine inlier threshold (host schedule, as the reference engine).
    const int anneal_its = filter::AnnealIterations(opt_);
    int cur = 0;
    Sample best{};
    double best_w = 0;
    CycleTrace* weigh_trace = nullptr;
    CycleTrace* update_trace = nullptr;
    std::unique_ptr<CycleTrace> wt, ut;
    if (trace_it) {
      wt.reset(new CycleTrace);
      ut.reset(new CycleTrace);
    }
    for (int it = 0; it < opt_.stop.max_iterations; ++it) {
      const auto t_iter = Clock::now();
      SetThreshold(filter::AnnealedThreshold(opt_, it, anneal_its));
      const bool traced = trace_it && trace_it(it);
      weigh_trace = traced ? wt.get() : nullptr;
      update_trace = traced ? ut.get() : nullptr;
      if (weigh_trace) weigh_trace->Clear();
      if (update_trace) update_trace->Clear();
      DepthDistributionCounts dd;
      weigh_->Weigh(cfg_.num_cores, N, cfg_, m.samples[cur], m.cell_windows, m.class_prob, m.depth, m.vmem, m.tri_mem,
                    m.sorted_w, m.sorted_idx, m.stats, m.offsets, &dd, weigh_trace);
      for (int p = 0; p < N; ++p) {
        res.stats.faces_total += m.stats[p].faces_total.to_int();
        res.stats.faces_front += m.stats[p].faces_front.to_int();
        res.stats.fragments += std::int64_t(m.stats[p].n_raster.to_uint64());
      }
      res.stats.weighings += N;
      best = m.samples[cur][m.sorted_idx[0].to_int()];
      best_w = m.sorted_w[0].to_double();
      res.best_weight_history.push_back(best_w);
      res.iterations = it + 1;
      const bool last = filter::RunEnds(opt_, it, anneal_its, res.best_weight_history, &res.converged);
      if (!last) {
        ResampleCounters rc;
        // w_best = the sorter's first output; the sample memory on both of its read ports.
        const ScopedTopTrace traced(update_trace);
        HwUpdateTop(m.sorted_w, m.sorted_idx, m.sorted_w[0], m.samples[cur], m.samples[cur], m.offsets, m.hypothesis, rprm_,
                    resample_rng, dprm_, m.volumes, diffusion_rng, m.samples[1 - cur], &rc);
        res.stats.resample_cdf_reads += rc.cdf_reads;
        res.stats.resample_cdf_reads_linear += rc.cdf_reads_linear;
      }
      if (hook) hook(it, cur, weigh_trace, update_trace, last);
      if (!last) cur = 1 - cur;
      res.iteration_ms.push_back(MsSince(t_iter));
      if (progress) progress(it, best_w);
      if (last) break;
    }
    weigh_->EndRun(&res.stats);
    res.pose_base = SampleToPose(best);
    res.T_cam_obj = prep_.scoring.camera.base_to_camera * PoseToTransform(res.pose_base);
    res.weight = best_w;
    res.cell = best.cell.to_int();
    return res;
  }

  void SetThreshold(double thr) {
    cfg_.raster.thr1 = ToDist(thr);
    cfg_.raster.inv_thr1 = inv_thr_t(ap_ufixed<20, 12, AP_RND, AP_SAT>(1.0 / cfg_.raster.thr1.to_double()));
    // In double (thr is), unlike the float engines' float: the result is rounded to dist_t.
    cfg_.raster.hard_thr = ToDist(filter::ScaledHardThreshold<double>(opt_.score.inlier, thr));
    std::string why;
    if (!RasterParamsAreValid(cfg_.raster, &why)) throw Error("hw engine: inlier threshold: " + why);
  }

 private:
  void Load(const Mesh& mesh_in) {
    HwMemories& m = *mem_;
    const FilterOptions& o = opt_;
    std::string why;
    // The options were validated (ValidateFilterOptions checks the hardware's limits too).
    if (!mesh_in.IsValid(&why)) throw Error("mesh '" + mesh_in.name + "': " + why);
    const Camera& cam = prep_.scoring.camera;
    if (cam.width > kImageWidth || cam.height > kImageHeight)
      throw Error("hw engine: image " + std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                  " exceeds the hardware's 640x480");
    if (cls_ < 0 || cls_ >= int(prior_.classes.size())) throw Error("class index out of range for the prior");
    if (prior_.layout.image_width != cam.width || prior_.layout.image_height != cam.height)
      throw Error("prior was made for a different image size than the camera's");
    CheckLayout(prior_.layout);

    // Model memory (Listing 7.1 [HARDWARE.md]).
    const Mesh mesh = HardwareMesh(mesh_in, o.render.lod_max_faces);
    mesh_name = mesh_in.name;
    num_vertices_ = int(mesh.vertices.size());
    for (int i = 0; i < num_vertices_; ++i)
      for (int k = 0; k < 3; ++k) m.vmem[k][i] = ToXyz(mesh.vertices[i][k]);
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
      m.tri_mem[f] = PackFace(mesh.faces[f][0], mesh.faces[f][1], mesh.faces[f][2]);
    cfg_.num_faces = int(mesh.faces.size());
    cfg_.num_cores = kMaxRasterCores;  // results do not depend on M (tested)
    cfg_.img_width = cam.width;
    cfg_.img_height = cam.height;
    // Per-particle window growth (ours, as the reference's grow_window): the hardware mesh's
    // bounding box (of the quantized vertices, so it contains every vertex exactly).
    cfg_.grow_window = o.render.grow_window ? 1 : 0;
    cfg_.max_window = o.render.max_window_px;
    {
      double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
      for (int i = 0; i < num_vertices_; ++i)
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], m.vmem[k][i].to_double());
          hi[k] = std::max(hi[k], m.vmem[k][i].to_double());
        }
      for (int c = 0; c < 8; ++c)
        for (int k = 0; k < 3; ++k) cfg_.bbox[c][k] = ToXyz((c >> k) & 1 ? hi[k] : lo[k]);
    }

    // Depth memory: clipped to 4 m, rounded to ufixed<12,2> (Table 7.1 [HARDWARE.md]).
    for (int v = 0; v < cam.height; ++v)
      for (int u = 0; u < cam.width; ++u) m.depth[v * cam.width + u] = ToDepth(prep_.scoring.depth.at(u, v));

    // Camera: P (intrinsics) and C (eq. 6.9 [ALGORITHM.md]).
    auto intr = [](double v) { return intr_t(ap_ufixed<28, 12, AP_RND, AP_SAT>(v)); };
    if (!(cam.fx < 4095 && cam.fy < 4095 && cam.cx >= 0 && cam.cx < 4095 && cam.cy >= 0 && cam.cy < 4095))
      throw Error("hw engine: camera intrinsics must lie in [0, 4095) px (ufixed<28,12>)");
    cfg_.cam.fx = intr(cam.fx);
    cfg_.cam.fy = intr(cam.fy);
    cfg_.cam.cx = intr(cam.cx);
    cfg_.cam.cy = intr(cam.cy);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        cfg_.cam.rot[3 * r + c] = trig_t(ap_fixed<18, 2, AP_RND, AP_SAT>(cam.base_to_camera.linear()(r, c)));
      const double t = cam.base_to_camera.translation()[r];
      if (!(std::fabs(t) < 8)) throw Error("hw engine: camera translation must lie within +-8 m (fixed<24,4>)");
      cfg_.cam.trans[r] = ctrans_t(ap_fixed<24, 4, AP_RND, AP_SAT>(t));
    }

    // Raster and merger parameters.
    RasterParams& rp = cfg_.raster;
    rp = DefaultRasterParams();
    rp.zbuffer = o.render.zbuffer ? 1 : 0;
    rp.hard = o.score.inlier.hard ? 1 : 0;
    rp.align_band = ToDist(o.diffusion.align_band_m);
    rp.edge_band = ToDist(o.score.edge_band_m);
    rp.near_plane = ToDist(o.render.near_m);
    SetThreshold(o.score.inlier.thr1_m);
    WeightParams& wp = cfg_.weight;
    auto coef = [](double v) { return coef_t(ap_ufixed<16, 1, AP_RND, AP_SAT>(v)); };
    wp.alpha = coef(o.score.alpha);
    wp.beta = coef(o.score.beta);
    wp.gamma = coef(std::max(0.0, 1.0 - wp.alpha.to_double() - wp.beta.to_double()));
    wp.delta = coef(o.render.zbuffer ? o.score.delta : 0.0);  // edge samples exist only in z-buffer mode
    wp.occlusion_aware = o.score.occlusion_aware ? 1 : 0;
    if (!WeightParamsAreValid(wp, &why)) throw Error("hw engine: weight coefficients: " + why);

    // Per-cell memories: heuristic volumes, windows, probabilities, hypotheses.
    // The diameter is the input mesh's (the float engines take their level-of-detail mesh's).
    const double diameter = mesh_in.Diameter();
    CheckMeshScale(mesh_in.name, diameter, prep_.support);
    const HeuristicOptions hopt = filter::VolumeOptions(o, diameter);
    const std::vector<Volume> volumes = ComputeHeuristics(prep_.support, cam, prior_.boxes, hopt, o.threads);
    double max_p = 0;
    // Hypothesis labels (region cap) differ from the float engines' on purpose: 8-bit labels
    // (kMaxHypotheses), label 0 = every cell without mass / beyond 255 boxes, so only cells
    // with mass are labelled, from 1.
    filter::HypothesisLabeller labeller(/*first=*/1, /*max_labels=*/kMaxHypotheses - 1, /*overflow=*/0);
    for (int c = 0; c < kNumCells; ++c) {
      const Volume& vol = volumes[c];
      HeuristicVolume& hv = m.volumes[c];
      bool valid = vol.valid;
      for (int k = 0; k < 3 && valid; ++k) valid = std::fabs(vol.min[k]) < 4 && std::fabs(vol.max[k]) < 4;
      if (valid) {
        hv.x_min = ToXyz(vol.min.x());
        hv.y_min = ToXyz(vol.min.y());
        hv.z_min = ToXyz(vol.min.z());
        hv.x_max = ToXyz(vol.max.x());
        hv.y_max = ToXyz(vol.max.y());
        hv.z_max = ToXyz(vol.max.z());
      } else {  // inverted: "no volume" for the diffusion's cell moves
        hv.x_min = hv.y_min = hv.z_min = ToXyz(1);
        hv.x_max = hv.y_max = hv.z_max = ToXyz(0);
      }
      // No pixel levels in the hw engine: the cap is max_window_px itself.
      const double min_side = filter::MinWindowSide(o, diameter, cam, vol.valid ? &vol : nullptr);
      m.cell_windows[c] = CellWindowHw(prior_.boxes[c], min_side, o.render.max_window_px, cam.width, cam.height);
      const double p = valid ? prior_.Prob(c, cls_) : 0.0;
      m.class_prob[c] = ToProb(prior_.Prob(c, cls_));
      max_p = std::max(max_p, p);
      // Hypothesis labels (region cap): cells with mass whose decoded boxes agree share one.
      m.hypothesis[c] = p > 0 ? labeller.Label(prior_.boxes[c]) : 0;
    }
    if (!(max_p > 0))
      throw filter::NoInitialMassError(prior_, cls_, o, &prep_);
    // CDF input: the probabilities scaled by 2^k so the largest is in [1/2, 1) — eq. 7.3 [ALGORITHM.md] is
    // scale-invariant, and small probabilities (a uniform prior's 1/6300) survive prob_t.
    const double scale = std::ldexp(1.0, -int(std::floor(std::log2(max_p))) - 1);
    class_sum_t sum = 0;
    for (int c = 0; c < kNumCells; ++c) {
      const double p = (m.volumes[c].x_min <= m.volumes[c].x_max) ? prior_.Prob(c, cls_) : 0.0;
      m.init_prob[c][0] = ToProb(p * scale);
      sum = sum + m.init_prob[c][0];
    }
    m.init_sum = sum;

    // Resampling (§7.5.4) and diffusion (§7.6) parameters.
    rprm_.num_particles = o.num_particles;
    // The float engines' pool of a set of N (no fine sets here), bounded by the sample memory's N.
    rprm_.pool_size = std::min(o.num_particles, filter::ResamplePoolSize(o, o.num_particles));
    rprm_.num_elite = std::min(o.num_elite, rprm_.pool_size);
    // The caps' register encodes "no cap" (a fraction of 1) as 0, where the float engines use
    // a cap of the whole pool; below 1 both use filter::NicheCap.
    rprm_.region_cap = o.niches.region_cap < 1 ? filter::NicheCap(o.niches.region_cap, rprm_.pool_size) : 0;
    // Ours: the reference's rotation cap (niching per hypothesis and orientation bin); 1 = off.
    rprm_.rotation_cap = o.niches.rotation_cap < 1 ? filter::NicheCap(o.niches.rotation_cap, rprm_.pool_size) : 0;
    std::string cwhy;
    if (!rprm_.IsValid(&cwhy)) throw Error("hw engine: resampling: " + cwhy);
    double prob[kNumHwMoves] = {};
    for (int k = 0; k < kNumThesisMoves; ++k) prob[k] = o.diffusion.move_probabilities[k];
    prob[kHwQuarterRoll] = o.diffusion.move_probabilities[int(Move::kQuarterTurn)];
    prob[kHwAlignDepth] = o.diffusion.move_probabilities[int(Move::kAlignDepth)];
    // The ICP move is not modelled: its probability is spread over the rest by the
    // normalisation below.
    if (!SetMoveProbabilities(&dprm_, prob, &cwhy))
      throw Error("hw engine: move probabilities: " + cwhy +
                  " (the hw engine models moves 0-12, the quarter turn and align depth)");
    {
      double rot[9], trans[3];
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) rot[3 * r + c] = cam.base_to_camera.linear()(r, c);
        trans[r] = cam.base_to_camera.translation()[r];
      }
      if (!SetAlignDepthCamera(&dprm_, rot, trans, &cwhy)) throw Error("hw engine: align-depth move: " + cwhy);
    }
    auto sigma = [](double v, const char* name) {
      if (!(v < 4)) throw Error(std::string("hw engine: ") + name + " must be < 4 (ufixed<18,2>)");
      return sigma_t(ap_ufixed<18, 2, AP_RND, AP_SAT>(v));
    };
    dprm_.sigma_t0 = sigma(o.diffusion.sigma_t0_m, "sigma_t0_m");
    dprm_.sigma_r0 = sigma(o.diffusion.sigma_r0_rad, "sigma_r0_rad");
    dprm_.min_fraction = weight_t(ap_ufixed<18, 1, AP_RND, AP_SAT>(o.diffusion.min_sigma_fraction));
    // σ floor of one LSB (ours) whenever the options ask for a σ floor at all: the reference's
    // 0.05·1 cm = 0.5 mm is half an xyz_t LSB. min_sigma_fraction = 0 → the thesis's decay.
    dprm_.sigma_floor_lsb = o.diffusion.min_sigma_fraction > 0 ? 1 : 0;
    if (!dprm_.IsValid(&cwhy)) throw Error("hw engine: diffusion: " + cwhy);
  }

  const filter::PreparedScene& prep_;  // scoring: the depth memory's image; support: the volumes'
  const Prior& prior_;
  int cls_;
  FilterOptions opt_;
  std::unique_ptr<HwMemories> mem_;
  WeighConfig cfg_{};
  ResampleParams rprm_;
  DiffusionParams dprm_{};
  int num_vertices_ = 0;
  filter::HwWeighStrategy* weigh_ = &CModelWeighing();
};

// The hw engine's runs (filter/engine.h): the hardware's memories are loaded once, each run
// starts the C-simulated hardware from its own seeds.
class HwEngine final : public filter::EngineRuns {
 public:
  HwEngine(const filter::PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls, const FilterOptions& options,
           std::unique_ptr<filter::HwWeighStrategy> weigh)
      : prep_(prep), mesh_(mesh), prior_(prior), cls_(cls), options_(options), runner_(prep, mesh, prior, cls, options),
        weigh_(std::move(weigh)) {
    runner_.SetWeigh(weigh_.get());
  }

  EstimateResult Run(Rng& rng, const ProgressFn& progress) override {
    EstimateResult r = runner_.Run(rng, progress, nullptr, nullptr, nullptr);
    seeds_.push_back({r.pose_base, r.cell});
    return r;
  }
  // Host side (ours, not hardware): the final polish of the runs' best particles with the
  // float weighing, as the float engines end.
  filter::PolishResult PolishRuns(FilterStats* stats) override {
    return filter::PolishPoses(prep_, mesh_, prior_, cls_, options_, seeds_, stats);
  }
  bool PolishReplacesRuns() const override { return true; }

 private:
  const filter::PreparedScene& prep_;
  const Mesh& mesh_;
  const Prior& prior_;
  int cls_;
  FilterOptions options_;
  HwRunner runner_;
  std::unique_ptr<filter::HwWeighStrategy> weigh_;  // the C model's (hw) or the RTL's (rtl)
  std::vector<filter::PolishSeed> seeds_;  // each run's best particle
};

}  // namespace

namespace filter {

bool HwEngineBuilt(std::string*) { return true; }

std::unique_ptr<EngineRuns> MakeHwEngine(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                         const FilterOptions& options) {
  return std::make_unique<HwEngine>(prep, mesh, prior, cls, options, std::make_unique<HwCModelWeigh>());
}

std::unique_ptr<EngineRuns> MakeHwEngineWith(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                             const FilterOptions& options, std::unique_ptr<HwWeighStrategy> weigh) {
  return std::make_unique<HwEngine>(prep, mesh, prior, cls, options, std::move(weigh));
}

}  // namespace filter

bool HwProfileOptions::IsValid(std::string* why) const {
  if (cores.empty()) return Fail(why, "cores must not be empty");
  for (int c : cores)
    if (c < 1 || c > kMaxRasterCores) return Fail(why, "cores must each be in [1, 10]");
  if (!(clock_mhz > 0 && std::isfinite(clock_mhz))) return Fail(why, "clock_mhz must be > 0");
  if (profile_every < 1) return Fail(why, "profile_every must be >= 1");
  return true;
}

namespace {

// Post-process cycles on a raw pyramid, padded to the thesis's 21 classes (missing classes get
// the most negative logit, so their probabilities are ≈ 0 and the cycles are the thesis's).
double PostProcessCycles(const std::vector<float>& raw, const PyramidLayout& layout) {
  const int nc = layout.num_classes;
  if (raw.size() != std::size_t(kNumCells) * (nc + 5))
    throw Error("hw-report: raw pyramid holds " + std::to_string(raw.size()) + " values, expected " +
                std::to_string(std::size_t(kNumCells) * (nc + 5)));
  std::vector<float> padded(std::size_t(kNumCells) * (kNumClasses + 5), -32.0f);
  for (int c = 0; c < kNumCells; ++c) {
    for (int j = 0; j < std::min(nc, kNumClasses); ++j) padded[std::size_t(c) * 26 + j] = raw[std::size_t(c) * (nc + 5) + j];
    for (int k = 0; k < 5; ++k) padded[std::size_t(c) * 26 + 21 + k] = raw[std::size_t(c) * (nc + 5) + nc + k];
  }
  PyramidLayout l21 = layout;
  l21.num_classes = kNumClasses;
  const PostProcessParams prm = PostProcessParamsFor(l21, 200);
  hls::stream<raw_t> in("pp_raw");
  RawPyramidToStream(padded, kNumClasses, in);
  struct PpOut {
    prob_t prob[kNumCells][kNumClasses];
    CellBox boxes[kNumCells];
    Window windows[kNumCells];
    class_sum_t sums[kNumClasses];
    CycleTrace trace;
  };
  std::unique_ptr<PpOut> o(new PpOut);
  PostProcess<kNumClasses>(in, prm, o->prob, o->boxes, o->windows, o->sums, &o->trace);
  return double(ModuleTotal(o->trace, ""));
}

}  // namespace

HwProfile ProfileHw(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls, const FilterOptions& options,
                    const HwProfileOptions& popt) {
  std::string why;
  if (!popt.IsValid(&why)) throw Error("hw-report: invalid profile option: " + why);
  ThrowIfInvalid(options, OptionNaming::kField);
  FilterOptions opt = options;
  opt.restarts = 1;
  const filter::PreparedScene prep = filter::PrepareScene(scene, opt);
  HwRunner runner(prep, mesh, prior, cls, opt);
  HwMemories& m = runner.mem();
  const int N = opt.num_particles;
  HwProfile prof;
  prof.num_particles = N;
  prof.num_vertices = runner.num_vertices();
  prof.num_faces = runner.num_faces();
  prof.clock_mhz = popt.clock_mhz;
  if (!popt.raw_pyramid.empty()) prof.postprocess_cycles = PostProcessCycles(popt.raw_pyramid, prior.layout);

  const int K = int(popt.cores.size());
  std::vector<HwCoreModel> acc(K);
  std::vector<std::map<std::string, std::pair<double, double>>> module_acc(K);  // cycles, memory
  std::vector<std::vector<std::string>> module_order(K);
  std::vector<double> iteration_cycles_sum(K, 0.0), first_iteration(K, 0.0);
  int modelled = 0, iterations = 0;
  double window_area = 0;
  std::unique_ptr<CycleTrace> one(new CycleTrace);
  std::unique_ptr<CycleTrace> vm_trace(new CycleTrace);
  std::unique_ptr<depth_t[]> depth_mem(new depth_t[kImageHeight * kImageWidth]);  // DistributeDepth's copy
  double last_model_iteration[16] = {};

  auto hook = [&](int it, int cur, CycleTrace* weigh, CycleTrace* update, bool last) {
    ++iterations;
    if (!weigh) {  // not modelled: count the last modelled iteration's cycles for the average
      for (int k = 0; k < K; ++k) iteration_cycles_sum[k] += last_model_iteration[k];
      return;
    }
    ++modelled;
    const Sample* samples = m.samples[cur];
    // Per particle: the raster core's work, from a one-particle run of the same top.
    std::vector<ParticleWork> work(N);
    std::vector<Window> windows(N);
    WeighConfig cfg1 = runner.config();
    cfg1.num_cores = 1;
    ft_t pc[kFtElements];
    ProjectionTimesCamera(cfg1.cam, pc);
    for (int p = 0; p < N; ++p) {
      Sample s1[kMaxParticles];
      s1[0] = samples[p];
      weight_t w1[kMaxParticles];
      particle_index_t i1[kMaxParticles];
      RasterCoreOutput st1[kMaxParticles];
      depth_off_t off1[kMaxParticles];
      DepthDistributionCounts dd1;
      one->Clear();
      HwWeighTop<1>(1, cfg1, s1, m.cell_windows, m.class_prob, m.depth, m.vmem, m.tri_mem, w1, i1, st1, off1, &dd1,
                    one.get());
      work[p] = ParticleWorkFromTrace(*one);
      windows[p] = ParticleWindowHw(samples[p], m.cell_windows[samples[p].cell.to_int()], cfg1, pc);
      window_area += double(windows[p].width.to_int()) * windows[p].height.to_int();
    }
    // M-independent modules of the weigh region, from the real top's trace.
    const auto weigh_modules = ModuleCycles(*weigh);
    auto module_cycles = [&](const std::string& name) {
      for (const auto& [mod, c] : weigh_modules)
        if (mod == name) return double(c);
      return 0.0;
    };
    // Head, before the first round: the depth distributor and the FT chain start when
    // GatherSampleInfo has returned (its windows and sample copy are ping-pong buffers), so its
    // whole time (the window memory's burst, then one particle per II) and the FT chain's fill.
    // The vertex multiplier's model bursts run beside it (below, per M).
    const double gather = double(ModuleTotal(*weigh, "sample_info") + ModuleDepth(*weigh, "ft_chain") +
                                 ModuleDepth(*weigh, "ft_distributor"));
    // The merger copies ρ on chip before its first particle: it cannot finish before that copy
    // and its N particles at II 3.
    const double merger_floor =
        double(ModuleTotal(*weigh, "weight_merger")) - double(ModuleDepth(*weigh, "weight_merger"));
    // Tail after the last round: the merger's last particle (II 3 + depth), the sorter chain's
    // latency and its drain, the glue kernels' depths.
    const double tail = double(kWmParticlesII + ModuleDepth(*weigh, "weight_merger") + ModuleDepth(*weigh, "weight_split") +
                               ModuleDepth(*weigh, "stats") + kSortCells) +
                        double(ModuleTotal(*weigh, "sorter")) - double(LoopTrips(*weigh, "sorter", "SORT_INSERT"));
    const double update_cycles = update ? double(ModuleTotal(*update, "resample") + ModuleTotal(*update, "diffusion")) : 0.0;
    for (int k = 0; k < K; ++k) {
      const int M = popt.cores[k];
      // Depth distributor per round (its per-round cycles) and the vertex multiplier for M.
      std::vector<std::uint64_t> round_fill;
      double dd_cycles = 0, dd_load = 0, dd_memory = 0, reads_shared = 0, reads_unshared = 0;
      for (int first = 0; first < N; first += M) {
        const int active = std::min(M, N - first);
        hls::stream<Window> info[kMaxRasterCores];
        hls::stream<depth_t> dep[kMaxRasterCores];
        DepthDistributionCounts cnt;
        one->Clear();
        DistributeDepth(active, M, windows.data() + first, m.depth, runner.config().img_width,
                        runner.config().img_height, depth_mem.get(), info, dep, &cnt, one.get());
        for (int c = 0; c < active; ++c) {
          while (!info[c].empty()) info[c].read();
          while (!dep[c].empty()) dep[c].read();
        }
        // The depth image's copy on chip happens once per weighing, before the first round
        // (in the head below), not per round.
        const std::uint64_t load = LoopTotal(*one, "depth_distributor", "DD_DEPTH_LOAD");
        round_fill.push_back(ModuleTotal(*one, "depth_distributor") - load);
        dd_cycles += double(round_fill.back());
        dd_load = double(load);
        dd_memory = double(ModuleMemory(*one, "depth_distributor"));
        reads_shared += double(cnt.reads_shared.to_uint64());
        reads_unshared += double(cnt.reads_unshared.to_uint64());
      }
      double vm_cycles = 0, vm_load = 0, vm_memory = 0;
      {
        hls::stream<Vertex> vout[kMaxRasterCores];
        vm_trace->Clear();
        // One round suffices for the stream contents; the cycles scale with the rounds.
        VertexMultiplier(std::min(N, M), M, runner.num_faces(), m.vmem, m.tri_mem, vout, vm_trace.get());
        for (int c = 0; c < M; ++c)
          while (!vout[c].empty()) vout[c].read();
        const int rounds = (N + M - 1) / M;
        vm_load = double(ModuleTotal(*vm_trace, "vertex_multiplier")) -
                  double(LoopTrips(*vm_trace, "vertex_multiplier", "VM_VERTICES")) - kVmVerticesDepth;
        vm_memory = double(ModuleMemory(*vm_trace, "vertex_multiplier"));
        vm_cycles = vm_load + double(LoopTrips(*vm_trace, "vertex_multiplier", "VM_VERTICES")) * rounds + kVmVerticesDepth;
      }
      // The cores start when the depth distributor has its depth copy (it starts after
      // GatherSampleInfo) and the vertex multiplier its model copy (it starts at once).
      const double head = std::max(gather + dd_load, vm_load + kVmVerticesDepth);
      // Busiest core: Σ over its particles of fill + compute.
      double busiest = 0;
      for (int c = 0; c < M; ++c) {
        double s = 0;
        for (int p = c; p < N; p += M) s += double(work[p].fill + work[p].Compute());
        busiest = std::max(busiest, s);
      }
      const double rounds_cycles = double(ComposeRounds(work, round_fill, M));
      const double weigh_cycles = head + std::max(rounds_cycles, merger_floor) + tail;
      HwCoreModel& a = acc[k];
      a.cores = M;
      a.depth_distribution_cycles += dd_cycles;
      a.weigh_cycles += weigh_cycles;
      a.update_cycles += update_cycles;
      a.iteration_cycles += weigh_cycles + update_cycles;
      a.depth_reads_shared += reads_shared;
      a.depth_reads_unshared += reads_unshared;
      const double iter = weigh_cycles + update_cycles;
      last_model_iteration[k] = iter;
      iteration_cycles_sum[k] += iter;
      if (it == 0) first_iteration[k] = iter;
      auto add = [&](const std::string& name, double c, double memory) {
        if (!module_acc[k].count(name)) module_order[k].push_back(name);
        module_acc[k][name].first += c;
        module_acc[k][name].second += memory;
        a.memory_cycles += memory;
      };
      for (const auto& [mod, c] : weigh_modules) {
        if (mod == "raster_core") add(mod, busiest, 0);
        else if (mod == "depth_distributor") add(mod, dd_load + dd_cycles, dd_memory);
        else if (mod == "vertex_multiplier") add(mod, vm_cycles, vm_memory);
        else add(mod, module_cycles(mod), double(ModuleMemory(*weigh, mod)));
      }
      if (update)
        for (const auto& [mod, c] : ModuleCycles(*update)) add(mod, double(c), double(ModuleMemory(*update, mod)));
    }
    (void)last;
  };
  auto trace_it = [&](int it) { return it == 0 || it % popt.profile_every == 0; };
  std::unique_ptr<CycleTrace> init_trace(new CycleTrace);
  Rng rng(opt.seed);
  prof.result = runner.Run(rng, nullptr, init_trace.get(), trace_it, hook);
  prof.result.obj = mesh.name;
  prof.iterations = iterations;
  prof.modelled_iterations = modelled;
  prof.init_cycles = double(DataflowLatency(*init_trace));
  for (const auto& [mod, c] : ModuleCycles(*init_trace))
    prof.init_modules.push_back({mod, double(c), double(ModuleMemory(*init_trace, mod))});
  const FilterStats& st = prof.result.stats;
  prof.init_reads = double(st.init_cdf_reads) / N;
  prof.init_reads_linear = double(st.init_cdf_reads_linear) / N;
  const double draws = double(std::max(1, iterations - 1)) * (N - std::min(opt.num_elite, N));
  prof.resample_reads = double(st.resample_cdf_reads) / draws;
  prof.resample_reads_linear = double(st.resample_cdf_reads_linear) / draws;
  prof.faces_total = double(st.faces_total);
  prof.faces_front = double(st.faces_front);
  prof.mean_window_area = modelled > 0 ? window_area / (double(modelled) * N) : 0;
  for (int k = 0; k < K; ++k) {
    HwCoreModel a = acc[k];
    const double d = std::max(1, modelled);
    a.depth_distribution_cycles /= d;
    a.weigh_cycles /= d;
    a.update_cycles /= d;
    a.iteration_cycles /= d;
    a.depth_reads_shared /= d;
    a.depth_reads_unshared /= d;
    a.first_iteration_cycles = prof.postprocess_cycles + prof.init_cycles + first_iteration[k];
    a.average_iteration_cycles =
        (iteration_cycles_sum[k] + prof.postprocess_cycles + prof.init_cycles) / std::max(1, iterations);
    a.memory_cycles /= d;
    for (const auto& name : module_order[k])
      a.modules.push_back({name, module_acc[k][name].first / d, module_acc[k][name].second / d});
    prof.models.push_back(a);
  }
  return prof;
}

}  // namespace posefilter
