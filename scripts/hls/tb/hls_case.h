// scripts/hls/tb/hls_case.h — the synthetic cases of the HLS test benches and of the
// golden-vector generator (tests/hls/), the vector files' format, and the AXI byte images the
// benches pass every input and output through.
//
// Two cases, built from integers and exact host conversions only (no libm), so that they are
// the same on every compiler and with the vendor's or our ap types. Both share a 640×480 depth
// image (background 1.0 m, a 67 × 67 px patch at 0.75 m in the middle), a pinhole camera
// (fx = fy = 500 px, cx = 320, cy = 240, base = camera frame), a prior with mass on every 97th
// cell, every cell's heuristic volume around (0, 0, 0.8 m), 96 × 96 px cell windows at the image
// centre, the per-particle window growth, region and rotation caps on, all 15 diffusion moves
// equally likely. They differ in the model and the particle count:
//   cube  — a 0.1 m cube (8 vertices, 12 faces), 24 particles;
//   torus — a torus of 1024 vertices and 2048 faces (the engine's bounds; major radius 61,
//           minor 26 units of 2^-10 m, 32 × 32 vertices from an integer sine table), 96 particles.
//
// Vector files (one folder per case, <vector dir>/<case>/<name>.hex): text, one value per line
// as the hexadecimal raw bits of the field (the fixed-point value × 2^F, W bits), fields of a
// struct in declaration order (src/hw/host/axi_pack.h's VisitFields).
//
// The AXI byte images (docs/HW_PACKING.md): a bench writes every memory and register a top
// reads as the bytes a driver would write to DDR and the AXI4-Lite registers
// (posefilter::hw::axi::Pack), unpacks them into the top's arguments, and packs and unpacks
// every output before comparing it, so a layout error shows as a mismatch.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "hw/host/axi_pack.h"
#include "hw/top.h"

namespace hls_case {

using namespace posefilter::hw;
namespace axi = posefilter::hw::axi;

// ---- The cases ----
struct CaseSpec {
  const char* name;
  int particles;  // n
  bool torus;     // the model: the torus, else the cube
};
constexpr CaseSpec kCases[] = {{"cube", 24, false}, {"torus", 96, true}};
constexpr int kNumCases = 2;

// The case called name, or null (with a message).
inline const CaseSpec* FindCase(const std::string& name) {
  for (const CaseSpec& c : kCases)
    if (name == c.name) return &c;
  std::fprintf(stderr, "unknown case '%s' (cube, torus)\n", name.c_str());
  return nullptr;
}

// ---- Vector files ----

// The fields of a value in declaration order, as raw bits, and back.
template <typename T>
std::vector<uint64_t> Words(const T& x) {
  std::vector<uint64_t> w;
  axi::ForEachScalar(x, [&](const auto& f) { w.push_back(axi::RawBits(f)); });
  return w;
}
template <typename T>
void FromWords(T& x, const uint64_t* w) {
  axi::ForEachScalar(x, [&](auto& f) { axi::SetRawBits(f, *w++); });
}

// One vector file: all words of values[0 … n).
template <typename T>
bool WriteVector(const std::string& path, const T* values, int n) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return std::fprintf(stderr, "cannot write %s\n", path.c_str()), false;
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
  const std::size_t per = axi::LayoutOf<T>().fields.size();
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

// The vector folder of a case, and a file in it.
inline std::string CaseDir(const std::string& dir, const CaseSpec& spec) { return dir + "/" + spec.name; }
inline std::string VecPath(const std::string& case_dir, const char* name) { return case_dir + "/" + name + ".hex"; }

// ---- Through the AXI byte images ----

// count values as a driver writes them (an m_axi buffer, or with count 1 an s_axilite struct's
// register image) and as the top reads them: packed to bytes, unpacked into `device`.
template <typename T>
void ViaAxi(const T* host, int count, T* device) {
  const std::vector<uint8_t> bytes = axi::Pack(host, count);
  axi::Unpack(bytes.data(), count, device);
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

// What the tops read of a case, written and read back through the byte images: the m_axi
// buffers (prob, volumes, cell windows, ρ, depth, model, hypotheses) and the s_axilite structs
// (class_sum, gen, init_opt, cfg, rprm, dprm). The seeds are the host's.
inline void CaseViaAxi(const Case& host, Case* device) {
  ViaAxi(&host.prob[0][0], kNumCells, &device->prob[0][0]);
  ViaAxi(&host.class_sum, 1, &device->class_sum);
  ViaAxi(host.volumes, kNumCells, device->volumes);
  ViaAxi(&host.gen, 1, &device->gen);
  ViaAxi(&host.init_opt, 1, &device->init_opt);
  ViaAxi(&host.cfg, 1, &device->cfg);
  ViaAxi(host.cell_windows, kNumCells, device->cell_windows);
  ViaAxi(host.class_prob, kNumCells, device->class_prob);
  ViaAxi(host.depth, kImageHeight * kImageWidth, device->depth);
  ViaAxi(&host.vmem[0][0], 3 * kMaxVertices, &device->vmem[0][0]);
  ViaAxi(host.tri_mem, kMaxFaces, device->tri_mem);
  ViaAxi(host.hypothesis, kNumCells, device->hypothesis);
  ViaAxi(&host.rprm, 1, &device->rprm);
  ViaAxi(&host.dprm, 1, &device->dprm);
  device->resample_seed = host.resample_seed;
  device->diffusion_seed = host.diffusion_seed;
}

inline xyz_t Xyz(double v) { return xyz_t(ap_fixed<13, 3, AP_RND, AP_SAT>(v)); }
inline xyz_t XyzRaw(int raw) {  // raw units of 2^-10 m
  xyz_t x;
  axi::SetRawBits(x, uint64_t(int64_t(raw)));
  return x;
}

// sin(2πk/32) · 1024, rounded (an integer table: no libm in the case).
inline int Sin32(int k) {
  static const int kQuarter[9] = {0, 200, 392, 569, 724, 851, 946, 1004, 1024};
  k &= 31;
  const int q = k / 8, r = k % 8;
  const int v = (q & 1) ? kQuarter[8 - r] : kQuarter[r];
  return q >= 2 ? -v : v;
}
inline int Cos32(int k) { return Sin32(k + 8); }
// a / b rounded half away from zero (b > 0).
inline int64_t RoundDiv(int64_t a, int64_t b) { return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b); }

// The torus: vertex (i, j) = ((R + r cos φ_j) cos θ_i, (R + r cos φ_j) sin θ_i, r sin φ_j),
// θ_i = 2πi/32, φ_j = 2πj/32, R = 61 and r = 26 units of 2^-10 m; quad (i, j) → faces
// (i,j)(i+1,j)(i+1,j+1) and (i,j)(i+1,j+1)(i,j+1), counter-clockwise seen from outside
// (src/synth/shapes.cc's MakeTorus). Returns the face count.
constexpr int kTorusN = 32, kTorusMajor = 61, kTorusMinor = 26;
inline int MakeTorus(xyz_t vmem[3][kMaxVertices], face_t tri_mem[kMaxFaces]) {
  for (int i = 0; i < kTorusN; ++i)
    for (int j = 0; j < kTorusN; ++j) {
      const int v = i * kTorusN + j;
      const int64_t rho = int64_t(kTorusMajor) * 1024 + int64_t(kTorusMinor) * Cos32(j);  // × 2^10
      vmem[0][v] = XyzRaw(int(RoundDiv(rho * Cos32(i), 1 << 20)));
      vmem[1][v] = XyzRaw(int(RoundDiv(rho * Sin32(i), 1 << 20)));
      vmem[2][v] = XyzRaw(int(RoundDiv(int64_t(kTorusMinor) * Sin32(j), 1 << 10)));
    }
  auto idx = [](int i, int j) { return (i % kTorusN) * kTorusN + (j % kTorusN); };
  int f = 0;
  for (int i = 0; i < kTorusN; ++i)
    for (int j = 0; j < kTorusN; ++j) {
      tri_mem[f++] = PackFace(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1));
      tri_mem[f++] = PackFace(idx(i, j), idx(i + 1, j + 1), idx(i, j + 1));
    }
  return f;
}

inline void MakeCase(Case* c, const CaseSpec& spec) {
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
  // The model memory beyond the model is zero (the driver writes whole buffers).
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < kMaxVertices; ++k) c->vmem[j][k] = 0;
  for (int f = 0; f < kMaxFaces; ++f) c->tri_mem[f] = 0;
  WeighConfig& cfg = c->cfg;
  if (spec.torus) {
    cfg.num_faces = MakeTorus(c->vmem, c->tri_mem);
    // The bounding box: corner k = (±(R + r), ±(R + r), ±r), bit j of k the sign of axis j.
    const int half[3] = {kTorusMajor + kTorusMinor, kTorusMajor + kTorusMinor, kTorusMinor};
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 3; ++j) cfg.bbox[k][j] = XyzRaw((k >> j) & 1 ? half[j] : -half[j]);
  } else {
    // The cube: vertex k = (±0.05, ±0.05, ±0.05) with bit j of k giving the sign of axis j.
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 3; ++j) c->vmem[j][k] = Xyz((k >> j) & 1 ? 0.05 : -0.05);
    const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int f = 0; f < 12; ++f) c->tri_mem[f] = PackFace(faces[f][0], faces[f][1], faces[f][2]);
    cfg.num_faces = 12;
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 3; ++j) cfg.bbox[k][j] = c->vmem[j][k];
  }
  cfg.num_cores = 1;
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
  c->rprm.num_particles = spec.particles;
  if (spec.torus) {
    c->rprm.num_elite = 4;
    c->rprm.pool_size = 80;
    c->rprm.region_cap = 32;
    c->rprm.rotation_cap = 10;
  } else {
    c->rprm.num_elite = 2;
    c->rprm.pool_size = 20;
    c->rprm.region_cap = 8;
    c->rprm.rotation_cap = 3;
  }
  c->dprm = ThesisDiffusionParams();
  double p[kNumHwMoves];
  for (double& x : p) x = 1.0;
  std::string why;
  SetMoveProbabilities(&c->dprm, p, &why);
  const double rot[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, trans[3] = {0, 0, 0};
  SetAlignDepthCamera(&c->dprm, rot, trans, &why);
  c->dprm.sigma_floor_lsb = 1;
}

}  // namespace hls_case
