// tests/hw/rtl/weigh_pipeline_cosim.cc — co-simulation of the RTL weighing pipeline
// (src/hw/rtl/weigh_pipeline.sv: FT distributor, vertex multiplier, depth distributor, M raster
// cores, weight merger; verilated with --assert) against the C model's processes of
// HwWeighTop<M> (src/hw/top.h): DistributeFT, VertexMultiplier, DistributeDepth, RasterCore per
// core and MergeWeights, run in sequence over unbounded streams. Per call every output word —
// weight (weight_t raw), particle index and the forwarded RasterCoreOutput — and the depth
// distributor's two read counters must be bit-identical.
//
// Calls: each has one mesh (a torus or a mesh file, ≤ 1024 vertices and ≤ 2048 faces), a depth
// image, n particles (random poses around one object position, so the windows of a round
// overlap, plus scattered ones), random raster parameters (both z-buffer modes, soft and hard
// inlier) and random weight parameters (α, β, γ, δ, occlusion-aware), random cells and class
// probabilities.
//
// Cycles: the first pass per call offers every input word as soon as it is due and holds
// out_ready at 1; its cycles (first clock of the call → last output word) are compared with the
// cycle model of the same call: the longer of the image copy (img_width·img_height) and the
// model copy (1024 + num_faces) plus ComposeRounds (src/hw/cycle_model.h) of the particles'
// ParticleWork and the rounds' distributor cycles, recorded by the C model, or the merger's ρ
// copy and II (6300 + 3·n) if that is longer; Σ RTL / Σ model cycles over the calls must lie in
// [0.9, R] (R = --max-ratio, default 1.1). Further passes (--bubbles K, seeds seed + 1 … seed + K) replay the
// calls with random bubbles on every interface: a stream whose next word is due raises valid
// with probability 1 − rate per clock and holds it and its data until the handshake; out_ready
// is 1 with probability 1 − rate. Every pass must be bit-exact.
//
// Usage: weigh_pipeline_cosim [calls (default 4)] [particles per call (default 23)] [seed]
//            [--bubbles K] [--rate R] [--set torus|torus-small|mesh=FILE[:SCALE]]
//            [--image WxH] [--max-window S] [--max-ratio R] [--violate-handshake]
//   --set torus-small (default) a 128-face torus; torus: the 2048-face torus; mesh=FILE a PLY/OBJ
//                      file × SCALE, simplified to ≤ 2048 faces and ≤ 1024 vertices
//   --image WxH        depth image size (default 160x120; ≤ 640x480)
//   --max-window S     largest window side (default 48; ≤ 200)
//   --max-ratio R      upper bound of Σ RTL / Σ model cycles (default 1.1)
//   --violate-handshake  in the bubble passes, the inputs drop valid before ready (an illegal
//                      source): the input handshake assertions must fire (counted instead of
//                      stopping the run); exit 0 only if they did
#include <algorithm>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "Vweigh_pipeline.h"
#include "hw/cycle_model.h"
#include "hw/distributor.h"
#include "hw/fx_math.h"
#include "hw/raster_core.h"
#include "hw/transform.h"
#include "hw/weight_merger.h"
#include "posefilter/mesh.h"
#include "posefilter/mesh_simplify.h"
#include "verilated.h"

#ifndef WP_CORES
#error "WP_CORES (the verilated model's M) must be defined"
#endif

namespace {

using namespace posefilter::hw;
constexpr int M = WP_CORES;

struct MeshData {
  std::vector<std::array<double, 3>> v;  // metres
  std::vector<std::array<int, 3>> f;
};

MeshData TorusMesh(double R, double r, int nu, int nv) {
  MeshData m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv;
      m.v.push_back({(R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a), r * std::sin(b)});
    }
  auto id = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.f.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.f.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// A mesh file × scale, simplified until it fits the vertex multiplier's memories.
MeshData FileMesh(const std::string& path, double scale) {
  const posefilter::Mesh loaded = posefilter::LoadMesh(path, scale);
  posefilter::Mesh m = loaded;
  for (int budget = kMaxFaces; int(m.faces.size()) > kMaxFaces || int(m.vertices.size()) > kMaxVertices;
       budget -= 16)
    m = posefilter::SimplifyMesh(loaded, budget);
  MeshData d;
  for (const auto& v : m.vertices) d.v.push_back({double(v.x()), double(v.y()), double(v.z())});
  for (const auto& f : m.faces) d.f.push_back({int(f[0]), int(f[1]), int(f[2])});
  return d;
}

// One call of the pipeline: everything on its input streams and its parameters.
struct Call {
  int n = 0, num_faces = 0, img_w = 0, img_h = 0;
  std::vector<uint16_t> depth;                 // img_h × img_w, raw F10
  std::vector<std::array<int, 4>> win;         // u0, v0, width, height
  std::vector<std::array<int64_t, 12>> ft;     // raw F22
  std::vector<uint64_t> vwords;                // kMaxVertices words {x, y, z} (13 bits each)
  std::vector<uint32_t> fwords;                // num_faces words (3 × 10-bit indices)
  std::vector<uint8_t> prob;                   // kNumCells, raw F8
  std::vector<int> cell;                       // per particle
  int zbuffer, hard;
  uint32_t thr1, inv_thr1, hard_thr, align_band, edge_band, near_plane;
  uint32_t alpha, beta, gamma, delta, occl;
};

struct OutWord {
  uint32_t weight, index;
  std::array<uint32_t, 10> stats;  // 314-bit word as 10 × 32 bits, LSB first
  bool operator==(const OutWord& o) const { return weight == o.weight && index == o.index && stats == o.stats; }
};

struct Result {
  std::vector<OutWord> out;
  uint64_t reads_shared = 0, reads_unshared = 0;
};

// The 314-bit core word (weight_merger.sv's layout), LSB first in 32-bit words.
std::array<uint32_t, 10> PackStats(const RasterCoreOutput& o) {
  std::array<uint32_t, 10> w{};
  int pos = 0;
  auto put = [&](uint64_t v, int bits) {
    for (int b = 0; b < bits; ++b, ++pos)
      if ((v >> b) & 1) w[size_t(pos / 32)] |= 1u << (pos % 32);
  };
  put(o.faces_total.to_uint64(), 12);
  put(o.faces_front.to_uint64(), 12);
  put(o.n_edge_continued.to_uint64(), 32);
  put(o.n_edge.to_uint64(), 32);
  put(o.depth_diff_count.to_uint64(), 32);
  put(uint64_t(RawSigned(o.depth_diff_sum).to_int64()), 56);
  put(o.n_depth.to_uint64(), 32);
  put(o.n_occluded.to_uint64(), 32);
  put(o.n_raster.to_uint64(), 32);
  put(RawUnsigned(o.inlier_sum).to_uint64(), 42);
  return w;
}

// ---- The C model: the five processes in dataflow order over unbounded streams ----
Result RunModel(const Call& k, uint64_t* model_cycles) {
  RasterParams prm;
  prm.zbuffer = k.zbuffer;
  prm.hard = k.hard;
  prm.thr1 = UFixedFromRaw<24, 4>(ap_uint<24>(k.thr1));
  prm.inv_thr1 = UFixedFromRaw<20, 12>(ap_uint<20>(k.inv_thr1));
  prm.hard_thr = UFixedFromRaw<24, 4>(ap_uint<24>(k.hard_thr));
  prm.align_band = UFixedFromRaw<24, 4>(ap_uint<24>(k.align_band));
  prm.edge_band = UFixedFromRaw<24, 4>(ap_uint<24>(k.edge_band));
  prm.near_plane = UFixedFromRaw<24, 4>(ap_uint<24>(k.near_plane));
  WeightParams wp;
  wp.alpha = UFixedFromRaw<16, 1>(ap_uint<16>(k.alpha));
  wp.beta = UFixedFromRaw<16, 1>(ap_uint<16>(k.beta));
  wp.gamma = UFixedFromRaw<16, 1>(ap_uint<16>(k.gamma));
  wp.delta = UFixedFromRaw<16, 1>(ap_uint<16>(k.delta));
  wp.occlusion_aware = k.occl;

  auto depth = std::make_unique<depth_t[]>(size_t(kImageHeight) * kImageWidth);
  auto depth_mem = std::make_unique<depth_t[]>(size_t(kImageHeight) * kImageWidth);
  for (size_t i = 0; i < k.depth.size(); ++i) depth[i] = UFixedFromRaw<12, 2>(ap_uint<12>(k.depth[i]));
  std::vector<Window> windows(kMaxParticles);
  for (int p = 0; p < k.n; ++p) {
    windows[size_t(p)].u0 = k.win[size_t(p)][0];
    windows[size_t(p)].v0 = k.win[size_t(p)][1];
    windows[size_t(p)].width = k.win[size_t(p)][2];
    windows[size_t(p)].height = k.win[size_t(p)][3];
  }
  auto vmem = std::make_unique<xyz_t[][kMaxVertices]>(3);
  for (int i = 0; i < kMaxVertices; ++i)
    for (int a = 0; a < 3; ++a)
      vmem[a][i] = FixedFromRaw<13, 3>(ap_int<13>(int((k.vwords[size_t(i)] >> (13 * (2 - a))) & 0x1fff)));
  std::vector<face_t> tri(kMaxFaces);
  for (int f = 0; f < k.num_faces; ++f) tri[size_t(f)] = k.fwords[size_t(f)];
  std::vector<prob_t> class_prob(kNumCells);
  for (int c = 0; c < kNumCells; ++c) class_prob[size_t(c)] = UFixedFromRaw<8, 0>(ap_uint<8>(k.prob[size_t(c)]));
  std::vector<cell_index_t> cells(kMaxParticles);
  for (int p = 0; p < k.n; ++p) cells[size_t(p)] = k.cell[size_t(p)];

  hls::stream<ft_t> ft_in, ft_core[kMaxRasterCores];
  hls::stream<Vertex> vert_core[kMaxRasterCores];
  hls::stream<Window> info_core[kMaxRasterCores];
  hls::stream<depth_t> depth_core[kMaxRasterCores];
  hls::stream<RasterCoreOutput> out_core[kMaxRasterCores];
  hls::stream<WeightOut> weights;
  hls::stream<RasterCoreOutput> stats;
  for (int p = 0; p < k.n; ++p)
    for (int e = 0; e < 12; ++e) ft_in.write(FixedFromRaw<36, 14>(ap_int<36>(k.ft[size_t(p)][size_t(e)])));
  DistributeFT(k.n, M, ft_in, ft_core, nullptr);
  VertexMultiplier(k.n, M, k.num_faces, vmem.get(), tri.data(), vert_core, nullptr);
  DepthDistributionCounts counts;
  DistributeDepth(k.n, M, windows.data(), depth.get(), k.img_w, k.img_h, depth_mem.get(), info_core, depth_core,
                  &counts, nullptr);
  // The cores, one particle per call so that each particle's loop records give its ParticleWork.
  auto mem = std::make_unique<RasterCoreMemory>();
  CycleTrace trace;
  std::vector<ParticleWork> work(size_t(k.n));
  for (int p = 0; p < k.n; ++p) {
    const int c = p % M;
    trace.Clear();
    RasterCore(1, k.num_faces, prm, info_core[c], depth_core[c], ft_core[c], vert_core[c], out_core[c], *mem, &trace);
    work[size_t(p)] = ParticleWorkFromTrace(trace);
  }
  MergeWeights(k.n, M, wp, out_core, cells.data(), class_prob.data(), weights, stats, nullptr);
  Result r;
  for (int p = 0; p < k.n; ++p) {
    const WeightOut w = weights.read();
    OutWord o;
    o.weight = uint32_t(RawUnsigned(w.weight).to_uint64());
    o.index = uint32_t(w.index.to_uint64());
    o.stats = PackStats(stats.read());
    r.out.push_back(o);
  }
  r.reads_shared = counts.reads_shared.to_uint64();
  r.reads_unshared = counts.reads_unshared.to_uint64();
  // Cycle model: the image copy, then the rounds (each round's distributor cycles from a
  // DistributeDepth call on that round's windows alone).
  std::vector<uint64_t> round_fill;
  for (int first = 0; first < k.n; first += M) {
    const int active = std::min(M, k.n - first);
    hls::stream<Window> ri[kMaxRasterCores];
    hls::stream<depth_t> rd[kMaxRasterCores];
    DepthDistributionCounts rc;
    trace.Clear();
    DistributeDepth(active, M, windows.data() + first, depth.get(), k.img_w, k.img_h, depth_mem.get(), ri, rd, &rc,
                    &trace);
    for (int c = 0; c < active; ++c) {  // drain what this cycle-model call wrote
      ri[c].read();
      while (!rd[c].empty()) rd[c].read();
    }
    round_fill.push_back(LoopTotal(trace, "depth_distributor", "DD_SETUP") +
                         LoopTotal(trace, "depth_distributor", "DD_SEGMENTS") +
                         LoopTotal(trace, "depth_distributor", "DD_PIXELS"));
  }
  // The copies run side by side on their own streams: the rounds start when the image
  // (depth distributor) and the model (vertex multiplier: kMaxVertices + num_faces words) are
  // on chip; the merger's ρ copy (kNumCells words) bounds the call too, with its II of 3.
  const uint64_t copies = std::max<uint64_t>(uint64_t(k.img_w) * uint64_t(k.img_h), uint64_t(kMaxVertices) + k.num_faces);
  *model_cycles = std::max<uint64_t>(copies + ComposeRounds(work, round_fill, M),
                                     uint64_t(kNumCells) + uint64_t(kWmParticlesII) * uint64_t(k.n));
  return r;
}

// ---- The RTL ----
struct Rtl {
  std::unique_ptr<VerilatedContext> ctx;
  std::unique_ptr<Vweigh_pipeline> m;
  uint64_t cycle = 0;
  Rtl() : ctx(new VerilatedContext), m(new Vweigh_pipeline(ctx.get())) {
    m->clk = 0;
    m->rst = 1;
    m->img_valid = m->win_valid = m->ft_valid = m->model_valid = m->prob_valid = m->cell_valid = 0;
    m->out_ready = 1;
    for (int i = 0; i < 4; ++i) Edge();
    m->rst = 0;
  }
  void Edge() {
    m->clk = 1;
    m->eval();
    m->clk = 0;
    m->eval();
    ++cycle;
  }
  // One call; *cycles = first clock → last output word. rng == nullptr: no bubbles.
  Result Run(const Call& k, uint64_t* cycles, std::mt19937_64* rng = nullptr, double rate = 0,
             bool violate = false) {
    std::bernoulli_distribution bubble(rate);
    auto offer = [&](bool held) { return (held && !violate) || rng == nullptr || !bubble(*rng); };
    m->num_particles = k.n;
    m->num_faces = k.num_faces;
    m->img_width = k.img_w;
    m->img_height = k.img_h;
    m->prm_zbuffer = k.zbuffer;
    m->prm_hard = k.hard;
    m->prm_thr1 = k.thr1;
    m->prm_inv_thr1 = k.inv_thr1;
    m->prm_hard_thr = k.hard_thr;
    m->prm_align_band = k.align_band;
    m->prm_edge_band = k.edge_band;
    m->prm_near_plane = k.near_plane;
    m->prm_alpha = k.alpha;
    m->prm_beta = k.beta;
    m->prm_gamma = k.gamma;
    m->prm_delta = k.delta;
    m->prm_occlusion_aware = k.occl;
    // The parameters are registers a driver writes before it starts the call: two clocks
    // with no input word (the depth distributor registers the image size and its compare).
    m->img_valid = m->win_valid = m->ft_valid = m->model_valid = m->prob_valid = m->cell_valid = 0;
    Edge();
    Edge();
    const size_t n_img = k.depth.size(), n_win = size_t(k.n), n_ft = size_t(k.n) * 12;
    const size_t n_model = k.vwords.size() + k.fwords.size(), n_prob = k.prob.size(), n_cell = size_t(k.n);
    size_t ii = 0, wi = 0, fi = 0, mi = 0, pi = 0, ci = 0;
    bool oi = false, ow = false, of = false, om = false, op = false, oc = false;
    Result r;
    const uint64_t t0 = cycle;
    for (uint64_t guard = 0; r.out.size() < size_t(k.n); ++guard) {
      if (guard > 400'000'000) {
        std::printf("RTL hangs (%zu of %d outputs)\n", r.out.size(), k.n);
        std::exit(2);
      }
      oi = ii < n_img && offer(oi);
      ow = wi < n_win && offer(ow);
      of = fi < n_ft && offer(of);
      om = mi < n_model && offer(om);
      op = pi < n_prob && offer(op);
      oc = ci < n_cell && offer(oc);
      m->img_valid = oi;
      m->img_data = ii < n_img ? k.depth[ii] : 0;
      m->win_valid = ow;
      if (wi < n_win) {
        m->win_u0 = k.win[wi][0];
        m->win_v0 = k.win[wi][1];
        m->win_width = k.win[wi][2];
        m->win_height = k.win[wi][3];
      }
      m->ft_valid = of;
      m->ft_data = fi < n_ft ? uint64_t(k.ft[fi / 12][fi % 12]) & ((uint64_t(1) << 36) - 1) : 0;
      m->model_valid = om;
      m->model_data = mi < k.vwords.size() ? k.vwords[mi] : mi < n_model ? k.fwords[mi - k.vwords.size()] : 0;
      m->prob_valid = op;
      m->prob_data = pi < n_prob ? k.prob[pi] : 0;
      m->cell_valid = oc;
      m->cell_data = ci < n_cell ? uint32_t(k.cell[ci]) : 0;
      m->out_ready = rng == nullptr || !bubble(*rng);
      m->eval();
      const bool hi = m->img_valid && m->img_ready, hw = m->win_valid && m->win_ready;
      const bool hf = m->ft_valid && m->ft_ready, hm = m->model_valid && m->model_ready;
      const bool hp = m->prob_valid && m->prob_ready, hc = m->cell_valid && m->cell_ready;
      if (m->out_valid && m->out_ready) {
        OutWord o;
        o.weight = m->out_weight;
        o.index = m->out_index;
        for (int i = 0; i < 10; ++i) o.stats[size_t(i)] = m->out_stats[i];
        o.stats[9] &= (1u << (314 - 288)) - 1;
        r.out.push_back(o);
      }
      Edge();
      if (hi) ++ii, oi = false;
      if (hw) ++wi, ow = false;
      if (hf) ++fi, of = false;
      if (hm) ++mi, om = false;
      if (hp) ++pi, op = false;
      if (hc) ++ci, oc = false;
    }
    *cycles = cycle - t0;
    if (ii != n_img || wi != n_win || fi != n_ft || mi != n_model || pi != n_prob || ci != n_cell) {
      std::printf("RTL: last output before all inputs were taken (img %zu/%zu, win %zu/%zu, ft %zu/%zu, model "
                  "%zu/%zu, prob %zu/%zu, cell %zu/%zu)\n",
                  ii, n_img, wi, n_win, fi, n_ft, mi, n_model, pi, n_prob, ci, n_cell);
      std::exit(2);
    }
    // The distributor's counters are final once the last window's pixels are read; let the
    // pipeline drain a few clocks (no more inputs) before reading them.
    m->img_valid = m->win_valid = m->ft_valid = m->model_valid = m->prob_valid = m->cell_valid = 0;
    for (int i = 0; i < 4; ++i) Edge();
    r.reads_shared = m->dd_reads_shared;
    r.reads_unshared = m->dd_reads_unshared;
    return r;
  }
};

// ---- Random calls ----
struct Gen {
  std::mt19937_64 rng;
  int calls_made = 0;
  explicit Gen(uint64_t seed) : rng(seed) {}
  double U(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  int I(int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); }
  bool B(double p) { return U(0, 1) < p; }
  static int Xyz(double v) { return int(std::clamp<long>(std::lround(v * 1024), -4096, 4095)); }
  static uint32_t Dist(double m) { return uint32_t(std::clamp<long>(std::lround(m * 1048576), 0, (1 << 24) - 1)); }

  Call Make(const MeshData& mesh, int n, int img_w, int img_h, int max_win, int zbuffer) {
    Call k;
    k.n = n;
    k.img_w = img_w;
    k.img_h = img_h;
    k.num_faces = int(mesh.f.size());
    k.vwords.assign(kMaxVertices, 0);
    for (size_t i = 0; i < mesh.v.size(); ++i) {
      uint64_t w = 0;
      for (int a = 0; a < 3; ++a) w = (w << 13) | (uint64_t(Xyz(mesh.v[i][size_t(a)])) & 0x1fff);
      k.vwords[i] = w;
    }
    for (const auto& f : mesh.f)
      k.fwords.push_back(uint32_t(f[0]) | (uint32_t(f[1]) << 10) | (uint32_t(f[2]) << 20));
    // Parameters (as raster_core_cosim); the inlier kind, the occlusion-aware N_raster and the
    // kind of coefficients follow the call's number, so that a few calls cover each.
    const int idx = calls_made++;
    k.zbuffer = zbuffer;
    k.hard = (idx / 2) % 2;  // calls 0, 1 soft, 2, 3 hard, …
    const double thr1 = B(0.5) ? 1.0 / 256 : std::exp(U(std::log(1.0 / 2048), std::log(0.05)));
    k.thr1 = Dist(thr1);
    k.inv_thr1 = uint32_t(std::clamp<long>(std::lround(256.0 / (k.thr1 / 1048576.0)), 1, (1 << 20) - 1));
    k.hard_thr = Dist(U(0.0005, 0.02));
    k.align_band = Dist(B(0.5) ? 0.05 : U(0, 0.1));
    k.edge_band = Dist(B(0.5) ? 0.01 : U(0.0005, 0.05));
    k.near_plane = Dist(B(0.7) ? 0.05 : U(1.0 / 64, 0.3));
    // α + β + γ = 1 (the driver's rule) in two of three calls; in every third α, β, γ in [1.5, 2)
    // (weights beyond 2, the clamp to 2 − 2^-17) and δ in [0, 2).
    if (idx % 3 != 2) {
      const double a = U(0, 1), b = U(0, 1 - a);
      k.alpha = uint32_t(std::lround(a * 32768));
      k.beta = uint32_t(std::lround(b * 32768));
      k.gamma = 32768 - k.alpha - k.beta;
      k.delta = uint32_t(std::lround(U(0, 1) * 32768));
    } else {
      k.alpha = uint32_t(I(49152, 65535));  // [1.5, 2)
      k.beta = uint32_t(I(49152, 65535));
      k.gamma = uint32_t(I(49152, 65535));
      k.delta = uint32_t(I(0, 65535));
    }
    k.occl = idx % 3 != 1;
    // Camera and object position.
    const double fx = U(0.6, 1.0) * img_w, fy = fx * U(0.98, 1.02);
    const double cx = img_w / 2.0 + U(-5, 5), cy = img_h / 2.0 + U(-5, 5);
    const double tz = U(0.35, 0.8), tx0 = U(-0.05, 0.05), ty0 = U(-0.05, 0.05);
    // Depth image: the object's depth with noise, holes and random values.
    k.depth.resize(size_t(img_w) * img_h);
    const double sigma = std::vector<double>{0.003, 0.01, 0.03}[size_t(I(0, 2))];
    for (auto& d : k.depth) {
      double z = B(0.1) ? 0 : B(0.1) ? U(0, 4) : tz + U(-sigma, sigma);
      d = uint16_t(std::clamp<long>(std::lround(z * 1024), 0, 4095));
    }
    for (int p = 0; p < n; ++p) {
      // Pose: random rotation; translation near (tx0, ty0, tz), or scattered (20 %).
      double q[4], nq = 0;
      for (double& c : q) {
        c = std::normal_distribution<double>(0, 1)(rng);
        nq += c * c;
      }
      for (double& c : q) c /= std::sqrt(nq);
      const double a = q[0], b = q[1], c = q[2], d = q[3];
      const double R[9] = {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c),
                           2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b),
                           2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d};
      const bool scatter = B(0.2);
      const double t[3] = {tx0 + (scatter ? U(-0.15, 0.15) : U(-0.01, 0.01)),
                           ty0 + (scatter ? U(-0.1, 0.1) : U(-0.01, 0.01)), tz + U(-0.02, 0.02)};
      double F[12];
      for (int j = 0; j < 3; ++j) {
        F[j] = fx * R[j] + cx * R[6 + j];
        F[4 + j] = fy * R[3 + j] + cy * R[6 + j];
        F[8 + j] = R[6 + j];
      }
      F[3] = fx * t[0] + cx * t[2];
      F[7] = fy * t[1] + cy * t[2];
      F[11] = t[2];
      std::array<int64_t, 12> ft;
      const int64_t lim = (int64_t(1) << 35) - 1;
      for (int e = 0; e < 12; ++e) ft[size_t(e)] = std::clamp<int64_t>(std::llround(F[e] * 4194304.0), -lim - 1, lim);
      k.ft.push_back(ft);
      // Window around the projected centre, inside the image.
      const int w = std::min({I(std::max(1, max_win / 3), max_win), img_w, kMaxWindow});
      const int h = std::min({I(std::max(1, max_win / 3), max_win), img_h, kMaxWindow});
      const int cu = int(fx * t[0] / t[2] + cx) + I(-3, 3), cv = int(fy * t[1] / t[2] + cy) + I(-3, 3);
      k.win.push_back({std::clamp(cu - w / 2, 0, img_w - w), std::clamp(cv - h / 2, 0, img_h - h), w, h});
      k.cell.push_back(I(0, kNumCells - 1));
    }
    for (int c = 0; c < kNumCells; ++c) k.prob.push_back(uint8_t(I(0, 255)));
    return k;
  }
};

}  // namespace

int main(int argc, char** argv) {
  int calls = 4, n = 23, positional = 0, bubbles = 0, img_w = 160, img_h = 120, max_win = 48;
  uint64_t seed = 4242;
  double rate = 0.3, max_ratio = 1.1;
  bool violate = false;
  // Line-buffered, so a long run's log shows each call as it finishes.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::string set = "torus-small";
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--bubbles" && a + 1 < argc) bubbles = std::atoi(argv[++a]);
    else if (arg == "--rate" && a + 1 < argc) rate = std::atof(argv[++a]);
    else if (arg == "--max-ratio" && a + 1 < argc) max_ratio = std::atof(argv[++a]);
    else if (arg == "--violate-handshake") violate = true;
    else if (arg == "--set" && a + 1 < argc) set = argv[++a];
    else if (arg == "--image" && a + 1 < argc) {
      if (std::sscanf(argv[++a], "%dx%d", &img_w, &img_h) != 2) img_w = 0;
    } else if (arg == "--max-window" && a + 1 < argc) max_win = std::atoi(argv[++a]);
    else if (!arg.empty() && arg[0] != '-' && positional < 3) {
      if (positional == 0) calls = std::atoi(arg.c_str());
      else if (positional == 1) n = std::atoi(arg.c_str());
      else seed = std::strtoull(arg.c_str(), nullptr, 10);
      ++positional;
    } else {
      std::fprintf(stderr,
                   "usage: weigh_pipeline_cosim [calls] [particles] [seed] [--bubbles K] [--rate R] "
                   "[--set torus|torus-small|mesh=FILE[:SCALE]] [--image WxH] [--max-window S] "
                   "[--max-ratio R] [--violate-handshake]\n");
      return 2;
    }
  }
  if (calls < 1 || n < 1 || n > kMaxParticles || bubbles < 0 || !(rate >= 0 && rate < 1) || !(max_ratio >= 1) ||
      img_w < 1 || img_w > kImageWidth || img_h < 1 || img_h > kImageHeight || max_win < 1 || max_win > kMaxWindow) {
    std::fprintf(stderr, "weigh_pipeline_cosim: arguments out of range\n");
    return 2;
  }
  MeshData mesh;
  if (set == "torus-small") mesh = TorusMesh(0.08, 0.03, 8, 8);
  else if (set == "torus") mesh = TorusMesh(0.08, 0.03, 32, 32);
  else if (set.rfind("mesh=", 0) == 0) {
    std::string file = set.substr(5);
    double scale = 1.0;
    const size_t colon = file.rfind(':');
    if (colon != std::string::npos && colon + 1 < file.size() && file.find('/', colon) == std::string::npos) {
      scale = std::atof(file.substr(colon + 1).c_str());
      file = file.substr(0, colon);
    }
    mesh = FileMesh(file, scale);
  } else {
    std::fprintf(stderr, "weigh_pipeline_cosim: unknown --set '%s'\n", set.c_str());
    return 2;
  }
  std::printf("M = %d cores; mesh %s: %zu vertices, %zu faces; %d calls of %d particles; image %dx%d, windows "
              "≤ %d px\n",
              M, set.c_str(), mesh.v.size(), mesh.f.size(), calls, n, img_w, img_h, max_win);
  Verilated::commandArgs(1, argv);
  Rtl rtl;
  if (violate) {
    rtl.ctx->fatalOnError(false);
    rtl.ctx->errorLimit(1 << 30);
  }
  Gen gen(seed);
  int failures = 0;
  uint64_t sum_rtl = 0, sum_model = 0;
  for (int call = 0; call < calls; ++call) {
    // Alternate the z-buffer mode; every other call has n − 1 particles (a partial last round
    // when n is a multiple of M, or a different one otherwise).
    const int nc = (call % 4 == 3 && n > 1) ? n - 1 : n;
    const Call k = gen.Make(mesh, nc, img_w, img_h, max_win, call % 2);
    uint64_t model_cycles = 0;
    const Result ref = RunModel(k, &model_cycles);
    uint64_t cyc = 0;
    auto check = [&](const Result& r, const char* pass) {
      int ok = 0;
      for (int p = 0; p < k.n; ++p) {
        if (r.out[size_t(p)] == ref.out[size_t(p)]) {
          ++ok;
        } else if (++failures <= 5) {
          const OutWord& a = ref.out[size_t(p)];
          const OutWord& b = r.out[size_t(p)];
          std::printf("MISMATCH (%s) call %d particle %d: model weight %u index %u, rtl weight %u index %u%s\n", pass,
                      call, p, a.weight, a.index, b.weight, b.index, a.stats == b.stats ? "" : "; core words differ");
        }
      }
      const bool counts = r.reads_shared == ref.reads_shared && r.reads_unshared == ref.reads_unshared;
      if (!counts && ++failures <= 5)
        std::printf("MISMATCH (%s) call %d: reads shared/unshared model %" PRIu64 "/%" PRIu64 ", rtl %" PRIu64
                    "/%" PRIu64 "\n",
                    pass, call, ref.reads_shared, ref.reads_unshared, r.reads_shared, r.reads_unshared);
      return ok;
    };
    const Result r = rtl.Run(k, &cyc);
    const int ok = check(r, "no bubbles");
    sum_rtl += cyc;
    sum_model += model_cycles;
    // What the words exercise: weights above 0, at the cap 2 − 2^-17, and particles whose
    // core saw inliers.
    int wpos = 0, wcap = 0, inl = 0;
    for (const OutWord& o : ref.out) {
      wpos += o.weight != 0;
      wcap += o.weight == (1u << 18) - 1;
      inl += (o.stats[8] >> 16) != 0 || o.stats[9] != 0;  // inlier_sum (bits 272–313) ≠ 0
    }
    std::printf("call %d: zbuffer=%d hard=%d occl=%u n=%d: %d/%d words bit-exact (weights > 0: %d, capped: %d, "
                "with inliers: %d), reads %" PRIu64 " shared / %" PRIu64 " unshared; cycles RTL %" PRIu64
                " vs model %" PRIu64 " (%.4f)\n",
                call, k.zbuffer, k.hard, k.occl, k.n, ok, k.n, wpos, wcap, inl, ref.reads_shared, ref.reads_unshared,
                cyc, model_cycles, double(cyc) / double(model_cycles));
    for (int b = 1; b <= bubbles; ++b) {
      std::mt19937_64 brng(seed + 1000 * uint64_t(call) + uint64_t(b));
      uint64_t bc = 0;
      const Result rb = rtl.Run(k, &bc, &brng, rate, violate);
      const int bok = check(rb, "bubbles");
      std::printf("call %d bubbles (rate %.2f, pass %d): %d/%d words bit-exact, cycles %" PRIu64 " (%.3f x)\n", call,
                  rate, b, bok, k.n, bc, double(bc) / double(cyc));
    }
  }
  const double ratio = double(sum_rtl) / double(sum_model);
  std::printf("all calls: cycles RTL %" PRIu64 " vs model %" PRIu64 " (ratio %.4f)\n", sum_rtl, sum_model, ratio);
  if (violate) {
    const int fired = rtl.ctx->errorCount();
    std::printf("illegal source: %d assertion failures (%s)\n", fired,
                fired > 0 ? "fired, as they must" : "NONE: the handshake assertions do not work");
    return fired > 0 ? 0 : 1;
  }
  if (ratio < 0.9 || ratio > max_ratio) {
    std::printf("cycles outside [0.9, %.2f] x the cycle model\n", max_ratio);
    ++failures;
  }
  std::printf(failures ? "FAILED\n" : "PASSED\n");
  return failures ? 1 : 0;
}
