// scripts/hls/tb/hls_case.h — the small synthetic case of the HLS test benches and of the
// golden-vector generator (tests/hls/), and the vector files' format.
//
// The case (built from integers and host conversions only, the same on every compiler and
// with the vendor's or our ap types): a 640×480 depth image (background 1.0 m, a 67 × 67 px
// patch at 0.75 m in the middle), a 0.1 m cube (8 vertices, 12 faces) seen by a pinhole camera
// (fx = fy = 500 px, cx = 320, cy = 240, base = camera frame), a prior with mass on every 97th
// cell, every cell's heuristic volume around (0, 0, 0.8 m), 96 × 96 px cell windows at the
// image centre, kCaseParticles particles, the per-particle window growth on, region and
// rotation caps on, all 15 diffusion moves equally likely.
//
// Vector files: text, one value per line as the hexadecimal raw bits of the field (the
// fixed-point value × 2^F, two's complement, W bits), fields of a struct in declaration order.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "hw/top.h"

namespace hls_case {

using namespace posefilter::hw;

constexpr int kCaseParticles = 24;  // particles of the case (n)
constexpr int kCaseFaces = 12;

// ---- Raw bits of the ap types (the common API of the vendor's and our headers) ----
template <int W>
uint64_t Bits(const ap_uint<W>& x) { return x.to_uint64(); }
template <int W>
uint64_t Bits(const ap_int<W>& x) { return ap_uint<W>(x.range(W - 1, 0)).to_uint64(); }
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
uint64_t Bits(const ap_fixed<W, I, Q, O, N>& x) { return ap_uint<W>(x.range(W - 1, 0)).to_uint64(); }
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
uint64_t Bits(const ap_ufixed<W, I, Q, O, N>& x) { return ap_uint<W>(x.range(W - 1, 0)).to_uint64(); }
inline uint64_t Bits(uint64_t v) { return v; }

template <int W>
void SetBits(ap_uint<W>& x, uint64_t v) { x = ap_uint<W>(v); }
template <int W>
void SetBits(ap_int<W>& x, uint64_t v) { x.range(W - 1, 0) = ap_uint<W>(v); }
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
void SetBits(ap_fixed<W, I, Q, O, N>& x, uint64_t v) { x.range(W - 1, 0) = ap_uint<W>(v); }
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
void SetBits(ap_ufixed<W, I, Q, O, N>& x, uint64_t v) { x.range(W - 1, 0) = ap_uint<W>(v); }

// The fields of the structs that cross the tops' ports, in declaration order.
inline std::vector<uint64_t> Words(const Sample& s) {
  return {Bits(s.x), Bits(s.y), Bits(s.z), Bits(s.roll), Bits(s.pitch), Bits(s.yaw), Bits(s.cell)};
}
inline void FromWords(Sample& s, const uint64_t* w) {
  SetBits(s.x, w[0]), SetBits(s.y, w[1]), SetBits(s.z, w[2]), SetBits(s.roll, w[3]), SetBits(s.pitch, w[4]),
      SetBits(s.yaw, w[5]), SetBits(s.cell, w[6]);
}
inline std::vector<uint64_t> Words(const RasterCoreOutput& o) {
  return {Bits(o.inlier_sum), Bits(o.n_raster), Bits(o.n_occluded), Bits(o.n_depth), Bits(o.depth_diff_sum),
          Bits(o.depth_diff_count), Bits(o.n_edge), Bits(o.n_edge_continued), Bits(o.faces_front), Bits(o.faces_total)};
}
inline void FromWords(RasterCoreOutput& o, const uint64_t* w) {
  SetBits(o.inlier_sum, w[0]), SetBits(o.n_raster, w[1]), SetBits(o.n_occluded, w[2]), SetBits(o.n_depth, w[3]),
      SetBits(o.depth_diff_sum, w[4]), SetBits(o.depth_diff_count, w[5]), SetBits(o.n_edge, w[6]),
      SetBits(o.n_edge_continued, w[7]), SetBits(o.faces_front, w[8]), SetBits(o.faces_total, w[9]);
}
template <typename T>
std::vector<uint64_t> Words(const T& x) { return {Bits(x)}; }
template <typename T>
void FromWords(T& x, const uint64_t* w) { SetBits(x, w[0]); }

// One vector file: all words of values[0 … n).
template <typename T>
bool WriteVector(const std::string& path, const T* values, int n) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  for (int i = 0; i < n; ++i)
    for (uint64_t w : Words(values[i])) std::fprintf(f, "%llx\n", static_cast<unsigned long long>(w));
  return std::fclose(f) == 0;
}
inline bool ReadWords(const std::string& path, std::vector<uint64_t>* words) {
  FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return false;
  unsigned long long w = 0;
  while (std::fscanf(f, "%llx", &w) == 1) words->push_back(w);
  std::fclose(f);
  return true;
}
// values[0 … n) from a vector file; false (with a message) when it is missing or too short.
template <typename T>
bool ReadVector(const std::string& path, T* values, int n) {
  std::vector<uint64_t> w;
  if (!ReadWords(path, &w)) return std::fprintf(stderr, "cannot read %s\n", path.c_str()), false;
  const std::size_t per = Words(values[0]).size();
  if (w.size() != per * std::size_t(n))
    return std::fprintf(stderr, "%s: %zu words, expected %zu\n", path.c_str(), w.size(), per * n), false;
  for (int i = 0; i < n; ++i) FromWords(values[i], &w[per * i]);
  return true;
}
// A bench's exit status: 0 = every output equals its golden vector, 1 = a mismatch, 2 = an
// input or golden vector could not be read (so a test that expects a mismatch cannot pass on a
// missing file).
constexpr int kTbPass = 0, kTbMismatch = 1, kTbMissingInput = 2;
// What CompareVector adds for an unreadable golden file (more than any count of mismatches).
constexpr int kTbMissingCount = 1 << 24;
inline int TbStatus(int bad) { return bad >= kTbMissingCount ? kTbMissingInput : bad ? kTbMismatch : kTbPass; }

// Compares values[0 … n) with a golden vector file bit for bit; prints every mismatch. Returns
// the number of mismatches, or kTbMissingCount when the file cannot be read.
template <typename T>
int CompareVector(const std::string& path, const T* values, int n) {
  std::vector<uint64_t> golden;
  if (!ReadWords(path, &golden)) return std::fprintf(stderr, "cannot read %s\n", path.c_str()), kTbMissingCount;
  std::vector<uint64_t> got;
  for (int i = 0; i < n; ++i)
    for (uint64_t w : Words(values[i])) got.push_back(w);
  int bad = got.size() != golden.size();
  if (bad) std::fprintf(stderr, "%s: %zu words, expected %zu\n", path.c_str(), got.size(), golden.size());
  for (std::size_t i = 0; i < got.size() && i < golden.size(); ++i)
    if (got[i] != golden[i]) {
      if (bad < 10)
        std::fprintf(stderr, "%s: word %zu is %llx, golden %llx\n", path.c_str(), i, static_cast<unsigned long long>(got[i]),
                     static_cast<unsigned long long>(golden[i]));
      ++bad;
    }
  if (!bad) std::printf("%s: %zu words match\n", path.c_str(), got.size());
  return bad;
}

// ---- The case ----

// Every memory and register of the three tops (≈ 1 MB: allocate it, not on the stack).
struct Case {
  // HwInitTop
  prob_t prob[kNumCells][1];
  class_sum_t class_sum;
  HeuristicVolume volumes[kNumCells];
  InitGenerators gen;
  InitOptions init_opt;
  // HwWeighTop<M>
  WeighConfig cfg;
  Window cell_windows[kNumCells];
  prob_t class_prob[kNumCells];
  depth_t depth[kImageHeight * kImageWidth];
  xyz_t vmem[3][kMaxVertices];
  face_t tri_mem[kMaxFaces];
  // HwUpdateTop
  hypothesis_t hypothesis[kNumCells];
  ResampleParams rprm;
  DiffusionParams dprm;
  uint32_t resample_seed = 0x2F1D3;
  uint32_t diffusion_seed = 0x51ED;
};

inline xyz_t Xyz(double v) { return xyz_t(ap_fixed<13, 3, AP_RND, AP_SAT>(v)); }

inline void MakeCase(Case* c) {
  class_sum_t sum = 0;
  for (int i = 0; i < kNumCells; ++i) {
    c->prob[i][0] = i % 97 == 0 ? prob_t(ap_ufixed<8, 0, AP_RND, AP_SAT>((i % 7 + 1) / 8.0)) : prob_t(0);
    sum += c->prob[i][0];
    c->class_prob[i] = c->prob[i][0];
    HeuristicVolume& v = c->volumes[i];
    v.x_min = Xyz(-0.02 + 0.001 * (i % 5));
    v.x_max = Xyz(0.02);
    v.y_min = Xyz(-0.02);
    v.y_max = Xyz(0.02 - 0.001 * (i % 3));
    v.z_min = Xyz(0.76);
    v.z_max = Xyz(0.84);
    c->cell_windows[i] = SaturatedWindow(320 + (i % 5) * 4 - 8, 240 + (i % 3) * 4 - 4, 96, 96, kImageWidth, kImageHeight);
    c->hypothesis[i] = i % 3;
  }
  c->class_sum = sum;
  for (int v = 0; v < kImageHeight; ++v)
    for (int u = 0; u < kImageWidth; ++u) {
      const bool patch = u >= 287 && u < 354 && v >= 207 && v < 274;
      c->depth[v * kImageWidth + u] = depth_t(patch ? 0.75 : 1.0);
    }
  // The cube: vertex k = (±0.05, ±0.05, ±0.05) with bit j of k giving the sign of axis j.
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 3; ++j) c->vmem[j][k] = Xyz((k >> j) & 1 ? 0.05 : -0.05);
  const int faces[kCaseFaces][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (int f = 0; f < kCaseFaces; ++f) c->tri_mem[f] = PackFace(faces[f][0], faces[f][1], faces[f][2]);
  WeighConfig& cfg = c->cfg;
  cfg.num_cores = 1;
  cfg.num_faces = kCaseFaces;
  cfg.img_width = kImageWidth;
  cfg.img_height = kImageHeight;
  cfg.cam.fx = intr_t(500.0);
  cfg.cam.fy = intr_t(500.0);
  cfg.cam.cx = intr_t(320.0);
  cfg.cam.cy = intr_t(240.0);
  for (int k = 0; k < 9; ++k) cfg.cam.rot[k] = trig_t(k % 4 == 0 ? 1.0 : 0.0);
  for (int k = 0; k < 3; ++k) cfg.cam.trans[k] = ctrans_t(0.0);
  cfg.raster = DefaultRasterParams();
  cfg.weight = DefaultWeightParams();
  cfg.grow_window = 1;
  cfg.max_window = 120;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 3; ++j) cfg.bbox[k][j] = c->vmem[j][k];
  c->rprm.num_particles = kCaseParticles;
  c->rprm.num_elite = 2;
  c->rprm.pool_size = 20;
  c->rprm.region_cap = 8;
  c->rprm.rotation_cap = 3;
  c->dprm = ThesisDiffusionParams();
  double p[kNumHwMoves];
  for (double& x : p) x = 1.0;
  std::string why;
  SetMoveProbabilities(&c->dprm, p, &why);
  const double rot[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, trans[3] = {0, 0, 0};
  SetAlignDepthCamera(&c->dprm, rot, trans, &why);
  c->dprm.sigma_floor_lsb = 1;
}

// File names of the vectors (in the vector directory).
inline std::string VecPath(const std::string& dir, const char* name) { return dir + "/" + name + ".hex"; }

}  // namespace hls_case
