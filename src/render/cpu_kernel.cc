// The cpu engine's score kernel: input checks, workspace sizing and runtime dispatch between
// the portable, AVX2 and AVX-512 variants of cpu_kernel_impl.inc; the valid-depth SAT.
#include "render/cpu_kernel.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "posefilter/error.h"

namespace posefilter::render {
namespace {

bool CpuHasAvx2() {
#if defined(__x86_64__) || defined(__i386__)
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2") &&
         __builtin_cpu_supports("popcnt");
#else
  return false;
#endif
}

bool CpuHasAvx512() {
#if defined(__x86_64__) || defined(__i386__)
  return CpuHasAvx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw");
#else
  return false;
#endif
}

template <class T>
T* Grow(std::vector<T>* v, std::size_t n) {
  if (v->size() < n) v->resize(n);
  return v->data();
}

// The first 64-byte aligned element of a buffer with at least 15 spare elements.
std::int32_t* AlignTo64(std::int32_t* p) {
  const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
  return p + ((64 - a % 64) % 64) / sizeof(std::int32_t);
}

}  // namespace

const char* CpuTargetName(CpuTarget t) {
  switch (t) {
    case CpuTarget::kPortable: return "portable";
    case CpuTarget::kAvx2: return "avx2";
    case CpuTarget::kAvx512: return "avx512";
  }
  return "unknown";
}

bool ParseCpuTarget(const std::string& name, CpuTarget* t) {
  for (CpuTarget c : {CpuTarget::kPortable, CpuTarget::kAvx2, CpuTarget::kAvx512}) {
    if (name == CpuTargetName(c)) {
      *t = c;
      return true;
    }
  }
  return false;
}

bool CpuTargetSupported(CpuTarget t) {
  switch (t) {
    case CpuTarget::kPortable: return true;
    case CpuTarget::kAvx2: return cpu_detail::BuiltAvx2() && CpuHasAvx2();
    case CpuTarget::kAvx512: return cpu_detail::BuiltAvx512() && CpuHasAvx512();
  }
  return false;
}

std::vector<CpuTarget> SupportedCpuTargets() {
  std::vector<CpuTarget> out;
  for (CpuTarget t : {CpuTarget::kPortable, CpuTarget::kAvx2, CpuTarget::kAvx512})
    if (CpuTargetSupported(t)) out.push_back(t);
  return out;
}

CpuTarget BestCpuTarget() {
  // Decided once per process from the CPU's feature bits (immutable facts, not mutable state).
  static const CpuTarget best = CpuTargetSupported(CpuTarget::kAvx512) ? CpuTarget::kAvx512
                                : CpuTargetSupported(CpuTarget::kAvx2) ? CpuTarget::kAvx2
                                                                       : CpuTarget::kPortable;
  return best;
}

ScoreKernelResult ScoreCpu(const ScoreKernelParams& k, CpuWorkspace* ws) {
  return ScoreCpuWith(BestCpuTarget(), k, ws);
}

ScoreKernelResult ScoreCpuWith(CpuTarget target, const ScoreKernelParams& k, CpuWorkspace* ws) {
  if (!CpuTargetSupported(target))
    throw Error(std::string("cpu kernel: this build/CPU cannot run the '") + CpuTargetName(target) + "' variant");
  ScoreKernelResult r;
  r.faces_total = k.num_faces;
  const PixelRect& w = k.window;
  if (w.width <= 0 || w.height <= 0) return r;  // as ScoreReference: nothing rendered or counted
  if (k.num_vertices < 0 || k.num_faces < 0 || (k.num_vertices > 0 && !k.vertices) ||
      (k.num_faces > 0 && !k.faces))
    throw Error("cpu kernel: mesh pointers/counts are invalid (vertices/faces)");
  if (!k.depth || k.depth_width <= 0 || k.depth_height <= 0)
    throw Error("cpu kernel: no scene depth image (depth/depth_width/depth_height)");
  if (w.u0 < 0 || w.v0 < 0 || w.u0 + w.width > k.depth_width || w.v0 + w.height > k.depth_height)
    throw Error("cpu kernel: window " + std::to_string(w.u0) + "," + std::to_string(w.v0) + " " +
                std::to_string(w.width) + "x" + std::to_string(w.height) + " is not inside the " +
                std::to_string(k.depth_width) + "x" + std::to_string(k.depth_height) + " depth image");
  // Outside the fast path's domain (1/z must be positive for the max-1/z z-buffer; images
  // beyond 2^20 px a side would break the double-exactness bounds, beyond 2^28 pixels the
  // int32 gather indices; meshes beyond 2^26 faces the int32 offsets of the setup records):
  // the reference.
  if (!(k.near_m > 0) || k.depth_width > (1 << 20) || k.depth_height > (1 << 20) ||
      std::int64_t(k.depth_width) * k.depth_height > (std::int64_t(1) << 28) || k.num_faces > (1 << 26)) {
    for (int f = 0; f < 3 * k.num_faces; ++f)
      if (k.faces[f] >= std::uint32_t(k.num_vertices))
        throw Error("cpu kernel: face " + std::to_string(f / 3) + " has a vertex index out of range");
    return ScoreReference(k, &ws->reference);
  }

  const std::size_t nv = std::size_t(k.num_vertices) + 16, cap = (std::size_t(k.num_faces) + 31) / 16 * 16;
  cpu_detail::CoreScratch s;
  s.vx = Grow(&ws->vx, nv);
  s.vex_x = Grow(&ws->vexact, 2 * nv);
  s.vex_y = s.vex_x + nv;
  s.vok = Grow(&ws->vok, nv);
  s.viz = Grow(&ws->viz, nv);
  s.tri_cap = std::int64_t(cap);
  s.tri = AlignTo64(Grow(&ws->tri, cpu_detail::kTriFields * cap + 16));
  s.fast = Grow(&ws->fast, cpu_detail::kFastBins * cap);
  s.slow = Grow(&ws->slow, cap);
  s.wide = Grow(&ws->wide, cap);
  s.zb = nullptr;
  s.zb_stride = 0;
  if (k.zbuffer) {
    // Rows of width + 48 floats (16 of slack before each row, 32 after: a row piece of 16
    // starting at the last column), 16 floats before row 0, 4 spare rows (the kernel's 4-row
    // vectors may read and write back up to 3 rows below the window) and 64 floats after.
    s.zb_stride = std::int64_t(w.width) + 48;
    s.zb = Grow(&ws->zbuffer, std::size_t(s.zb_stride) * (std::size_t(w.height) + 4) + 80) + 16;
  }
  constexpr int kFragCap = 1024;  // scored in batches that stay in L1
  s.frag_cap = kFragCap;
  s.frag_idx = Grow(&ws->frag_idx, kFragCap + 16);
  s.frag_iz = Grow(&ws->frag_iz, kFragCap + 16);
  std::int64_t bad = -1;
  switch (target) {
    case CpuTarget::kPortable: bad = cpu_detail::CorePortable(k, s, &r); break;
    case CpuTarget::kAvx2: bad = cpu_detail::CoreAvx2(k, s, &r); break;
    case CpuTarget::kAvx512: bad = cpu_detail::CoreAvx512(k, s, &r); break;
  }
  if (bad >= 0) throw Error("cpu kernel: face " + std::to_string(bad) + " has a vertex index out of range");
  return r;
}

ValidDepthSat::ValidDepthSat(const float* depth, int width, int height) : width_(width), height_(height) {
  if (width < 0 || height < 0) throw Error("ValidDepthSat: negative image size");
  if (!depth && std::int64_t(width) * height > 0) throw Error("ValidDepthSat: no depth data");
  const std::size_t w1 = std::size_t(width) + 1;
  sat_.assign(w1 * (std::size_t(height) + 1), 0);
  for (int v = 0; v < height; ++v) {
    std::int64_t row = 0;
    for (int u = 0; u < width; ++u) {
      row += depth[std::size_t(v) * width + u] > 0 ? 1 : 0;
      sat_[(v + 1) * w1 + (u + 1)] = sat_[v * w1 + (u + 1)] + row;
    }
  }
}

std::int64_t ValidDepthSat::Count(const PixelRect& r) const {
  // Clip to the image: [u0, u1) × [v0, v1).
  const std::int64_t u0 = std::max<std::int64_t>(0, r.u0), v0 = std::max<std::int64_t>(0, r.v0);
  const std::int64_t u1 = std::min<std::int64_t>(width_, std::int64_t(r.u0) + r.width);
  const std::int64_t v1 = std::min<std::int64_t>(height_, std::int64_t(r.v0) + r.height);
  if (u0 >= u1 || v0 >= v1) return 0;
  const std::size_t w1 = std::size_t(width_) + 1;
  auto at = [&](std::int64_t u, std::int64_t v) { return sat_[std::size_t(v) * w1 + std::size_t(u)]; };
  return at(u1, v1) - at(u0, v1) - at(u1, v0) + at(u0, v0);
}

}  // namespace posefilter::render
