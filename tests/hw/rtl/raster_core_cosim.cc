// tests/hw/rtl/raster_core_cosim.cc — co-simulation of the RTL raster core
// (src/hw/rtl/raster_core.sv, verilated) against the C model posefilter::hw::RasterCore
// (src/hw/raster_core.h) on the same random particles: every field of RasterCoreOutput must be
// bit-identical. It also counts the RTL's cycles per particle (from accepting the window word
// to emitting the output word) and compares them with the project's cycle model of the same
// particle: the C model's loop records (trips, II, depths of hw/latency.h) composed by
// ParticleWorkFromTrace(...).Total() (src/hw/cycle_model.h). Fails on any mismatch or when
// Σ RTL cycles is more than 10 % away from Σ model cycles in a mode.
//
// Flow control: the first pass per mode drives every input as soon as it is due and holds
// out_ready at 1 (its cycles are the ones compared with the model). Each further pass
// (--bubbles K: K passes, seeds seed + 1 … seed + K) replays the same particles with random
// bubbles on every interface: an input stream whose next word is due raises valid only with
// probability 1 − rate per clock and then holds valid and data until the handshake, and
// out_ready is 1 with probability 1 − rate per clock. Those passes must be bit-exact too (their
// cycles are only reported). The RTL is verilated with --assert, so a violated SystemVerilog
// assertion (FIFO overflow/underflow, handshake stability, state encoding) stops the run.
//
// Usage: raster_core_cosim [particles_per_mode (default 1000)] [seed (default 12345)]
//            [--bubbles K (default 0)] [--rate R (default 0.3)] [--violate-handshake]
//            [--set torus|mesh=FILE[:SCALE]]
//   --set torus        instead of the random small meshes and 4 tori: particles_per_mode
//                      random poses of the 2048-face torus (random windows up to 200 × 200)
//   --set mesh=FILE    the same with a mesh file (PLY/OBJ), coordinates × SCALE (default 1),
//                      simplified to at most 2048 faces (kMaxFaces)
//   --violate-handshake  in the bubble passes, let the inputs drop valid before ready (an
//                      illegal source): the handshake assertions must fire (they are counted
//                      instead of stopping the run); exit 0 only if they did (the negative
//                      control of ctest raster_core_rtl_assert_fires)
#include <algorithm>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "Vraster_core.h"
#include "hw/cycle_model.h"
#include "hw/fx_math.h"
#include "hw/raster_core.h"
#include "posefilter/mesh.h"
#include "posefilter/mesh_simplify.h"
#include "verilated.h"

namespace {

using namespace posefilter::hw;

struct Particle {
  int u0, v0, w, h;
  std::vector<uint16_t> depth;  // raw F10
  int64_t ft[12];               // raw F22
  std::vector<int16_t> vert;    // raw F10, 3 per vertex, 3 vertices per face
  int num_faces;
  // params
  int zbuffer, hard;
  uint32_t thr1, inv_thr1, hard_thr, align_band, edge_band, near_plane;
};

struct Out {
  uint64_t inlier, n_raster, n_occluded, n_depth, diff_count, n_edge, n_cont, front, total;
  int64_t diff;
  bool operator==(const Out& o) const {
    return inlier == o.inlier && n_raster == o.n_raster && n_occluded == o.n_occluded &&
           n_depth == o.n_depth && diff_count == o.diff_count && n_edge == o.n_edge &&
           n_cont == o.n_cont && front == o.front && total == o.total && diff == o.diff;
  }
};

void Print(const char* who, const Out& o) {
  std::printf("  %s: inlier=%" PRIu64 " n_raster=%" PRIu64 " n_occ=%" PRIu64 " n_depth=%" PRIu64
              " diff=%" PRId64 " diff_count=%" PRIu64 " n_edge=%" PRIu64 " n_cont=%" PRIu64
              " front=%" PRIu64 " total=%" PRIu64 "\n",
              who, o.inlier, o.n_raster, o.n_occluded, o.n_depth, o.diff, o.diff_count, o.n_edge,
              o.n_cont, o.front, o.total);
}

int64_t SignExtend(uint64_t v, int bits) {
  const uint64_t m = uint64_t(1) << (bits - 1);
  v &= (bits == 64) ? ~uint64_t(0) : ((uint64_t(1) << bits) - 1);
  return int64_t((v ^ m) - m);
}

// ---- The C model ----
// The C model's outputs and *model_cycles, the cycle model of the particle.
Out RunModel(const Particle& p, RasterCoreMemory& mem, CycleTrace& trace, int64_t* model_cycles) {
  RasterParams prm;
  prm.zbuffer = p.zbuffer;
  prm.hard = p.hard;
  prm.thr1 = UFixedFromRaw<24, 4>(ap_uint<24>(p.thr1));
  prm.inv_thr1 = UFixedFromRaw<20, 12>(ap_uint<20>(p.inv_thr1));
  prm.hard_thr = UFixedFromRaw<24, 4>(ap_uint<24>(p.hard_thr));
  prm.align_band = UFixedFromRaw<24, 4>(ap_uint<24>(p.align_band));
  prm.edge_band = UFixedFromRaw<24, 4>(ap_uint<24>(p.edge_band));
  prm.near_plane = UFixedFromRaw<24, 4>(ap_uint<24>(p.near_plane));
  hls::stream<Window> info;
  hls::stream<depth_t> depth;
  hls::stream<ft_t> ft;
  hls::stream<Vertex> vert;
  hls::stream<RasterCoreOutput> out;
  Window w;
  w.u0 = p.u0;
  w.v0 = p.v0;
  w.width = p.w;
  w.height = p.h;
  info.write(w);
  for (uint16_t d : p.depth) depth.write(UFixedFromRaw<12, 2>(ap_uint<12>(d)));
  for (int e = 0; e < 12; ++e) {
    ft_t f = FixedFromRaw<36, 14>(ap_int<36>(p.ft[e]));
    ft.write(f);
  }
  for (size_t i = 0; i < p.vert.size(); i += 3) {
    Vertex v;
    v.x = FixedFromRaw<13, 3>(ap_int<13>(p.vert[i]));
    v.y = FixedFromRaw<13, 3>(ap_int<13>(p.vert[i + 1]));
    v.z = FixedFromRaw<13, 3>(ap_int<13>(p.vert[i + 2]));
    vert.write(v);
  }
  trace.Clear();
  RasterCore(1, p.num_faces, prm, info, depth, ft, vert, out, mem, &trace);
  *model_cycles = int64_t(ParticleWorkFromTrace(trace).Total());
  const RasterCoreOutput o = out.read();
  Out r;
  r.inlier = RawUnsigned(o.inlier_sum).to_uint64();
  r.n_raster = o.n_raster.to_uint64();
  r.n_occluded = o.n_occluded.to_uint64();
  r.n_depth = o.n_depth.to_uint64();
  r.diff = SignExtend(uint64_t(RawSigned(o.depth_diff_sum).to_int64()), 56);
  r.diff_count = o.depth_diff_count.to_uint64();
  r.n_edge = o.n_edge.to_uint64();
  r.n_cont = o.n_edge_continued.to_uint64();
  r.front = o.faces_front.to_uint64();
  r.total = o.faces_total.to_uint64();
  return r;
}

// ---- The RTL ----
struct Rtl {
  std::unique_ptr<VerilatedContext> ctx;
  std::unique_ptr<Vraster_core> m;
  uint64_t cycle = 0;
  Rtl() : ctx(new VerilatedContext), m(new Vraster_core(ctx.get())) {
    m->clk = 0;
    m->rst = 1;
    m->win_valid = m->depth_valid = m->ft_valid = m->vert_valid = 0;
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
  // Drives one particle and returns its output and cycle count. rng == nullptr: every input
  // word is offered as soon as it is due and out_ready is 1 (the core's inputs never starve);
  // otherwise random bubbles with probability `rate` per stream and clock (see the top).
  // violate: the inputs do not hold valid until ready (an illegal source; the negative
  // control of the handshake assertions, which must stop the run).
  Out Run(const Particle& p, uint64_t* cycles, std::mt19937_64* rng = nullptr, double rate = 0,
          bool violate = false) {
    std::bernoulli_distribution bubble(rate);
    auto offer = [&](bool held) { return (held && !violate) || rng == nullptr || !bubble(*rng); };
    bool ow = false, od = false, of = false, ov = false;  // valid raised and not yet taken
    m->prm_zbuffer = p.zbuffer;
    m->prm_hard = p.hard;
    m->prm_thr1 = p.thr1;
    m->prm_inv_thr1 = p.inv_thr1;
    m->prm_hard_thr = p.hard_thr;
    m->prm_align_band = p.align_band;
    m->prm_edge_band = p.edge_band;
    m->prm_near_plane = p.near_plane;
    m->num_faces = p.num_faces;
    size_t wi = 0, di = 0, fi = 0, vi = 0;
    const size_t nv = p.vert.size() / 3;
    uint64_t t0 = 0;
    Out r{};
    for (uint64_t guard = 0;; ++guard) {
      if (guard > 50'000'000) {
        std::printf("RTL hangs\n");
        std::exit(2);
      }
      ow = wi < 1 && offer(ow);
      od = di < p.depth.size() && offer(od);
      of = fi < 12 && offer(of);
      ov = vi < nv && offer(ov);
      m->win_valid = ow;
      m->win_u0 = p.u0;
      m->win_v0 = p.v0;
      m->win_width = p.w;
      m->win_height = p.h;
      m->depth_valid = od;
      m->depth_data = di < p.depth.size() ? p.depth[di] : 0;
      m->ft_valid = of;
      m->ft_data = uint64_t(p.ft[fi < 12 ? fi : 0]) & ((uint64_t(1) << 36) - 1);
      m->vert_valid = ov;
      if (vi < nv) {
        m->vert_x = uint16_t(p.vert[3 * vi]) & 0x1fff;
        m->vert_y = uint16_t(p.vert[3 * vi + 1]) & 0x1fff;
        m->vert_z = uint16_t(p.vert[3 * vi + 2]) & 0x1fff;
      }
      m->out_ready = rng == nullptr || !bubble(*rng);
      m->eval();
      const bool hw = m->win_valid && m->win_ready, hd = m->depth_valid && m->depth_ready;
      const bool hf = m->ft_valid && m->ft_ready, hv = m->vert_valid && m->vert_ready;
      const bool ho = m->out_valid && m->out_ready;
      if (ho) {
        r.inlier = m->out_inlier_sum;
        r.n_raster = m->out_n_raster;
        r.n_occluded = m->out_n_occluded;
        r.n_depth = m->out_n_depth;
        r.diff = SignExtend(m->out_depth_diff_sum, 56);
        r.diff_count = m->out_depth_diff_count;
        r.n_edge = m->out_n_edge;
        r.n_cont = m->out_n_edge_continued;
        r.front = m->out_faces_front;
        r.total = m->out_faces_total;
      }
      const uint64_t now = cycle;
      Edge();
      if (hw) {
        ++wi;
        t0 = now;
        ow = false;
      }
      if (hd) {
        ++di;
        od = false;
      }
      if (hf) {
        ++fi;
        of = false;
      }
      if (hv) {
        ++vi;
        ov = false;
      }
      if (ho) {
        *cycles = now - t0 + 1;
        if (di != p.depth.size() || fi != 12 || vi != nv) {
          std::printf("RTL output before consuming its inputs\n");
          std::exit(2);
        }
        return r;
      }
    }
  }
};

// ---- Meshes for the particle sets (--set) ----
struct MeshData {
  std::vector<std::array<double, 3>> v;  // metres
  std::vector<std::array<int, 3>> f;     // vertex indices, CCW from outside
};

// A torus of nu × nv quads (2·nu·nv faces), radii R and r in metres.
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

// A mesh file (posefilter::LoadMesh), coordinates × scale, simplified to the core's kMaxFaces.
MeshData FileMesh(const std::string& path, double scale) {
  posefilter::Mesh loaded = posefilter::LoadMesh(path, scale);
  if (int(loaded.faces.size()) > kMaxFaces) loaded = posefilter::SimplifyMesh(loaded, kMaxFaces);
  MeshData m;
  for (const auto& v : loaded.vertices) m.v.push_back({double(v.x()), double(v.y()), double(v.z())});
  for (const auto& f : loaded.faces) m.f.push_back({int(f[0]), int(f[1]), int(f[2])});
  return m;
}

// ---- Random particles ----
struct Gen {
  std::mt19937_64 rng;
  explicit Gen(uint64_t seed) : rng(seed) {}
  double U(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  int I(int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); }
  bool B(double p) { return U(0, 1) < p; }

  static int16_t Xyz(double v) {
    long r = std::lround(v * 1024);
    return int16_t(std::clamp<long>(r, -4096, 4095));
  }
  static uint32_t Dist(double m) { return uint32_t(std::clamp<long>(std::lround(m * 1048576), 0, (1 << 24) - 1)); }

  void Params(Particle& p, int zbuffer) {
    p.zbuffer = zbuffer;
    p.hard = B(0.3);
    double thr1 = B(0.5) ? 1.0 / 256 : std::exp(U(std::log(1.0 / 2048), std::log(0.05)));
    p.thr1 = Dist(thr1);
    p.inv_thr1 = uint32_t(std::clamp<long>(std::lround(256.0 / (p.thr1 / 1048576.0)), 1, (1 << 20) - 1));
    p.hard_thr = Dist(U(0.0005, 0.02));
    p.align_band = Dist(B(0.5) ? 0.05 : U(0, 0.1));
    p.edge_band = Dist(B(0.5) ? 0.01 : U(0.0005, 0.05));
    p.near_plane = Dist(B(0.7) ? 0.05 : U(1.0 / 64, 0.3));
  }

  // FT = K·[R | t] quantized to F22 (saturated like ft_t).
  void Pose(Particle& p, double tx, double ty, double tz, double* fx, double* fy, double* cx, double* cy) {
    double q[4];
    double n = 0;
    for (double& c : q) {
      c = std::normal_distribution<double>(0, 1)(rng);
      n += c * c;
    }
    n = std::sqrt(n);
    for (double& c : q) c /= n;
    const double a = q[0], b = q[1], c = q[2], d = q[3];
    const double R[9] = {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c),
                         2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b),
                         2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d};
    *fx = U(500, 700);
    *fy = *fx * U(0.98, 1.02);
    *cx = U(300, 340);
    *cy = U(220, 260);
    const double t[3] = {tx, ty, tz};
    double F[12];
    for (int j = 0; j < 3; ++j) {
      F[j] = *fx * R[j] + *cx * R[6 + j];
      F[4 + j] = *fy * R[3 + j] + *cy * R[6 + j];
      F[8 + j] = R[6 + j];
    }
    F[3] = *fx * t[0] + *cx * t[2];
    F[7] = *fy * t[1] + *cy * t[2];
    F[11] = t[2];
    const int64_t lim = (int64_t(1) << 35) - 1;
    for (int e = 0; e < 12; ++e)
      p.ft[e] = std::clamp<int64_t>(std::llround(F[e] * 4194304.0), -lim - 1, lim);
  }

  void Depth(Particle& p, double zc) {
    const double sigma = std::vector<double>{0.003, 0.01, 0.03, 0.2}[I(0, 3)];
    const double pzero = U(0, 0.3), prand = U(0, 0.3);
    p.depth.resize(size_t(p.w) * p.h);
    for (auto& d : p.depth) {
      double z;
      if (B(pzero)) z = 0;
      else if (B(prand)) z = U(0, 4);
      else z = zc + U(-sigma, sigma);
      d = uint16_t(std::clamp<long>(std::lround(z * 1024), 0, 4095));
    }
  }

  void Window(Particle& p, double u, double v, int w, int h) {
    p.w = w;
    p.h = h;
    const int cu = std::isfinite(u) ? int(std::clamp(u, -1e6, 1e6)) : 320;
    const int cv = std::isfinite(v) ? int(std::clamp(v, -1e6, 1e6)) : 240;
    p.u0 = std::clamp(cu - w / 2 + I(-w / 3, w / 3), 0, 640 - w);
    p.v0 = std::clamp(cv - h / 2 + I(-h / 3, h / 3), 0, 480 - h);
  }

  Particle Small(int zbuffer) {
    Particle p;
    Params(p, zbuffer);
    p.num_faces = I(1, 64);
    const int kind = I(0, 99);
    double s = std::exp(U(std::log(0.005), std::log(0.15)));  // object radius
    double tz = U(0.15, 2.0), tx = U(-0.3, 0.3) * tz, ty = U(-0.25, 0.25) * tz;
    if (kind < 10) {  // near plane, W < 1/64, behind the camera
      tz = U(-0.05, 0.12);
      s = U(0.02, 0.1);
    } else if (kind < 15) {  // guard band: far off axis, close
      tz = U(0.05, 0.3);
      tx = tz * U(8, 20) * (B(0.5) ? 1 : -1);
      s = U(0.01, 0.2);
    } else if (kind < 20) {  // big coordinates
      s = U(0.5, 3.5);
      tz = U(0.5, 3.9);
    }
    double fx, fy, cx, cy;
    Pose(p, tx, ty, tz, &fx, &fy, &cx, &cy);
    const bool soup = B(0.5);
    for (int f = 0; f < p.num_faces; ++f) {
      double c[3] = {0, 0, 0};
      double r = s;
      if (!soup) {
        for (double& x : c) x = U(-s, s);
        r = s * U(0.05, 0.5);
      }
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j) p.vert.push_back(Xyz(c[j] + U(-r, r)));
    }
    const double zc = tz > 0.01 ? tz : 0.5;
    Window(p, fx * tx / zc + cx, fy * ty / zc + cy, I(1, 64), I(1, 64));
    Depth(p, zc);
    return p;
  }

  // Random pose of a fixed mesh (--set): object 0.3–0.7 m away, random window of 16–200 px per
  // side around its projected centre.
  Particle FromMesh(int zbuffer, const MeshData& mesh) {
    Particle p;
    Params(p, zbuffer);
    const double tz = U(0.3, 0.7);
    const double tx = U(-0.03, 0.03), ty = U(-0.03, 0.03);
    double fx, fy, cx, cy;
    Pose(p, tx, ty, tz, &fx, &fy, &cx, &cy);
    p.num_faces = int(mesh.f.size());
    for (const auto& f : mesh.f)
      for (int c : f)
        for (int k = 0; k < 3; ++k) p.vert.push_back(Xyz(mesh.v[size_t(c)][size_t(k)]));
    Window(p, fx * tx / tz + cx, fy * ty / tz + cy, I(16, 200), I(16, 200));
    Depth(p, tz);
    return p;
  }

  // A torus of nu × nv quads (2·nu·nv faces, consistent winding) in a 200 × 200 window; 32 × 32
  // is the size of hw-report's torus (2048 faces).
  Particle Torus(int zbuffer, int nu, int nv) {
    Particle p;
    Params(p, zbuffer);
    const double R = U(0.06, 0.1), r = U(0.02, 0.04);
    const double tz = U(0.3, 0.7);
    double fx, fy, cx, cy;
    Pose(p, U(-0.03, 0.03), U(-0.03, 0.03), tz, &fx, &fy, &cx, &cy);
    auto P = [&](int i, int j, int k) {
      const double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv;
      const double v[3] = {(R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a), r * std::sin(b)};
      return Xyz(v[k]);
    };
    p.num_faces = 0;
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const int q[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
        const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
        for (auto& t : tri) {
          for (int c : t)
            for (int k = 0; k < 3; ++k) p.vert.push_back(P(q[c][0], q[c][1], k));
          ++p.num_faces;
        }
      }
    Window(p, cx, cy, 200, 200);
    Depth(p, tz);
    return p;
  }
};

}  // namespace

int main(int argc, char** argv) {
  int n = 1000;
  uint64_t seed = 12345;
  int bubbles = 0;
  double rate = 0.3;
  std::string set;
  bool violate = false;
  int positional = 0;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--bubbles" && a + 1 < argc) {
      bubbles = std::atoi(argv[++a]);
    } else if (arg == "--rate" && a + 1 < argc) {
      rate = std::atof(argv[++a]);
    } else if (arg == "--violate-handshake") {
      violate = true;
    } else if (arg == "--set" && a + 1 < argc) {
      set = argv[++a];
    } else if (!arg.empty() && arg[0] != '-' && positional < 2) {
      if (positional++ == 0) n = std::atoi(arg.c_str());
      else seed = std::strtoull(arg.c_str(), nullptr, 10);
    } else {
      std::fprintf(stderr,
                   "usage: raster_core_cosim [particles_per_mode] [seed] [--bubbles K] [--rate R] "
                   "[--set torus|mesh=FILE[:SCALE]]\n");
      return 2;
    }
  }
  if (n < 1 || bubbles < 0 || !(rate >= 0 && rate < 1)) {
    std::fprintf(stderr, "raster_core_cosim: particles ≥ 1, bubbles ≥ 0, 0 ≤ rate < 1\n");
    return 2;
  }
  Verilated::commandArgs(1, argv);
  auto mem = std::make_unique<RasterCoreMemory>();
  auto trace = std::make_unique<CycleTrace>();
  Rtl rtl;
  if (violate) {  // count the failed assertions instead of stopping at the first
    rtl.ctx->fatalOnError(false);
    rtl.ctx->errorLimit(1 << 30);
  }
  Gen gen(seed);
  MeshData mesh;
  if (set == "torus") {
    mesh = TorusMesh(0.08, 0.03, 32, 32);
  } else if (set.rfind("mesh=", 0) == 0) {
    std::string file = set.substr(5);
    double scale = 1.0;
    const size_t colon = file.rfind(':');
    if (colon != std::string::npos && colon + 1 < file.size() && file.find('/', colon) == std::string::npos) {
      scale = std::atof(file.substr(colon + 1).c_str());
      file = file.substr(0, colon);
    }
    mesh = FileMesh(file, scale);
  } else if (!set.empty()) {
    std::fprintf(stderr, "raster_core_cosim: unknown --set '%s'\n", set.c_str());
    return 2;
  }
  if (!set.empty())
    std::printf("set %s: %zu faces, %d particles per mode\n", set.c_str(), mesh.f.size(), n);
  int failures = 0;
  for (int zbuffer = 0; zbuffer <= 1; ++zbuffer) {
    std::vector<Particle> parts;
    // The 4 tori follow the random particles, except in the (short) negative control.
    const int count = set.empty() && !violate ? n + 4 : n;
    for (int i = 0; i < count; ++i)
      parts.push_back(!set.empty() ? gen.FromMesh(zbuffer, mesh)
                      : i < n    ? gen.Small(zbuffer)
                      : (i % 2 ? gen.Torus(zbuffer, 32, 32) : gen.Torus(zbuffer, 16, 12)));
    std::vector<Out> model_out;
    int ok = 0, total = 0, soft = 0, hard = 0;
    int64_t sum_rtl = 0, sum_model = 0;
    double worst = 0, best = 1e9;
    uint64_t ramp = 0, occl = 0, band = 0, edges = 0;
    for (int i = 0; i < count; ++i) {
      const Particle& p = parts[size_t(i)];
      int64_t model = 0;
      const Out m = RunModel(p, *mem, *trace, &model);
      model_out.push_back(m);
      uint64_t cyc = 0;
      const Out r = rtl.Run(p, &cyc);
      sum_rtl += int64_t(cyc);
      sum_model += model;
      const double ratio = double(cyc) / double(model);
      worst = std::max(worst, ratio);
      best = std::min(best, ratio);
      ++total;
      (p.hard ? hard : soft)++;
      if (m.inlier % 1024) ++ramp;
      occl += m.n_occluded != 0;
      band += m.diff_count != 0;
      edges += m.n_cont != 0;
      if (std::getenv("RC_COSIM_VERBOSE"))
        std::printf("p%d F=%d w=%d h=%d rtl=%" PRIu64 " model=%" PRId64 " (%+" PRId64 ")\n", i, p.num_faces, p.w, p.h,
                    cyc, model, int64_t(cyc) - model);
      if (m == r) {
        ++ok;
      } else if (++failures <= 5) {
        std::printf("MISMATCH zbuffer=%d particle %d (F=%d, window %dx%d at %d,%d, hard=%d)\n", zbuffer,
                    i, p.num_faces, p.w, p.h, p.u0, p.v0, p.hard);
        Print("model", m);
        Print("rtl  ", r);
      }
    }
    const double sratio = double(sum_rtl) / double(sum_model);
    std::printf("zbuffer=%d: %d/%d particles bit-exact (%d soft, %d hard; %" PRIu64
                " with a ramp chi, %" PRIu64 " with occlusions, %" PRIu64 " with align-band hits, %" PRIu64
                " with continued edges)\n",
                zbuffer, ok, total, soft, hard, ramp, occl, band, edges);
    std::printf("zbuffer=%d: cycles RTL %" PRId64 " vs model %" PRId64 " (ratio %.4f), per particle %.4f .. %.4f\n",
                zbuffer, sum_rtl, sum_model, sratio, best, worst);
    if (ok != total || sratio < 0.9 || sratio > 1.1) failures += 1;
    // The same particles with random bubbles on every interface: bit-exact again.
    for (int b = 1; b <= bubbles; ++b) {
      std::mt19937_64 brng(seed + uint64_t(b));
      int bok = 0;
      int64_t bcycles = 0;
      for (int i = 0; i < count; ++i) {
        uint64_t cyc = 0;
        const Out r = rtl.Run(parts[size_t(i)], &cyc, &brng, rate, violate);
        bcycles += int64_t(cyc);
        if (r == model_out[size_t(i)]) {
          ++bok;
        } else if (++failures <= 5) {
          std::printf("MISMATCH with bubbles (seed %" PRIu64 ") zbuffer=%d particle %d\n", seed + uint64_t(b),
                      zbuffer, i);
          Print("model", model_out[size_t(i)]);
          Print("rtl  ", r);
        }
      }
      std::printf("zbuffer=%d bubbles (rate %.2f, seed %" PRIu64 "): %d/%d particles bit-exact, cycles RTL %" PRId64
                  " (%.3f x the run without bubbles)\n",
                  zbuffer, rate, seed + uint64_t(b), bok, count, bcycles, double(bcycles) / double(sum_rtl));
    }
  }
  if (violate) {  // the negative control passes only if the assertions fired
    const int fired = rtl.ctx->errorCount();
    std::printf("illegal source: %d assertion failures (%s)\n", fired,
                fired > 0 ? "fired, as they must" : "NONE: the handshake assertions do not work");
    return fired > 0 ? 0 : 1;
  }
  std::printf(failures ? "FAILED\n" : "PASSED\n");
  return failures ? 1 : 0;
}
