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

ScoreKernelResult ScoreCpu(const ScoreKernelParams& k, CpuWorkspace* ws, const FacePlanes* planes) {
  return ScoreCpuWith(BestCpuTarget(), k, ws, planes);
}

// Proof in brief (docs/PERFORMANCE.md, "Why the counts are exact"). Let P_i = R·v_i + t be
// the exact camera-frame corners (R, t the kernel's floats), N = (v1 − v0) × (v2 − v0) and
// s = N·(v0 − c) with c = −R⁻¹·t. Then 2·Area of the exact projections is
// −fx·fy·det(R)·s/(z0·z1·z2) pixels², so
// s > 0 makes it negative with |2·Area| ≥ fx·fy·det(R)·s/z_max³. The kernel's corners differ
// from the exact projections by at most ε per coordinate (float transform and projection,
// snapping: ≤ 1/512 px), which moves 2·Area by at most 4ε·(W + H) + 8ε² (W, H: the exact
// projections' extents, ≤ f·σ·len·(1 + A)/z_min each, σ ≥ ‖R‖₂, A ≥ |x/z|, |y/z| of every
// vertex). So s > z_max³/(fx·fy·det)·(4ε·(fx + fy)·σ·len·(1 + A)/z_min + 8ε²) proves the snapped
// 2·Area < 0: culled. The float evaluation of s (stored N and N·v0 rounded to float, c rounded,
// three products and sums) is within 2^-20·len·max_len·(radius + |c|) of s (|N| ≤ len²),
// which is added to k1; k1 and k0 are raised by 1 % and rounded up, which covers the float
// evaluation of k1·len + k0.
bool PreCullConstants(const ScoreKernelParams& k, const FacePlanes& p, float c_out[3], float* k1_out, float* k0_out) {
  const double fx = k.fx, fy = k.fy, cx = k.cx, cy = k.cy;
  if (!(fx > 0 && fy > 0 && std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy)))
    return false;
  double R[9], t[3];
  for (int i = 0; i < 9; ++i) R[i] = k.R[i];
  for (int i = 0; i < 3; ++i) t[i] = k.t[i];
  // σ ≥ ‖R‖₂: ‖R‖₂² = λmax(RᵀR) ≤ 1 + ‖RᵀR − I‖_F.
  double g = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double rr = R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j] - (i == j ? 1 : 0);
      g += rr * rr;
    }
  const double sigma = std::sqrt(1 + std::sqrt(g)) * (1 + 1e-9);
  const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                     R[2] * (R[3] * R[7] - R[4] * R[6]);
  if (!(sigma < 1.01) || !(det > 0.9)) return false;
  // c = −R⁻¹·t (adjugate / det).
  const double inv[9] = {(R[4] * R[8] - R[5] * R[7]) / det, (R[2] * R[7] - R[1] * R[8]) / det, (R[1] * R[5] - R[2] * R[4]) / det,
                         (R[5] * R[6] - R[3] * R[8]) / det, (R[0] * R[8] - R[2] * R[6]) / det, (R[2] * R[3] - R[0] * R[5]) / det,
                         (R[3] * R[7] - R[4] * R[6]) / det, (R[1] * R[6] - R[0] * R[7]) / det, (R[0] * R[4] - R[1] * R[3]) / det};
  double c[3];
  for (int i = 0; i < 3; ++i) c[i] = -(inv[3 * i] * t[0] + inv[3 * i + 1] * t[1] + inv[3 * i + 2] * t[2]);
  const double rho = sigma * p.radius;  // |R·v| ≤ rho for every vertex
  const double z_min = t[2] - rho, z_max = t[2] + rho;
  // Float transform error per coordinate of a computed corner (four roundings, ≤ 2^-21·(…)).
  const double dp = std::ldexp(rho + std::fabs(t[0]) + std::fabs(t[1]) + std::fabs(t[2]), -20);
  const double z_min_c = z_min - dp;
  if (!(z_min_c > 0) || !std::isfinite(z_max)) return false;
  const double hxy = std::hypot(t[0], t[1]) + rho;
  const double A = hxy / z_min, A_c = (hxy + 2 * dp) / z_min_c;  // exact / computed corners
  // ε: snapping (1/512 px) + float projection (three roundings) + the transform error's effect.
  auto eps_axis = [&](double f, double cc) {
    return 1.0 / 512 + std::ldexp(f * A_c + std::fabs(cc), -20) + f * dp * (1 + A_c) / z_min_c;
  };
  const double eps = std::fmax(eps_axis(fx, cx), eps_axis(fy, cy));
  if (!(eps < 0.01)) return false;
  const double scale = z_max * z_max * z_max / (fx * fy * det);
  const double cn = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  const double k1 = (scale * 4 * eps * (fx + fy) * sigma * (1 + A) / z_min +
                     std::ldexp(p.max_len * (p.radius + cn), -20)) * 1.01;
  const double k0 = scale * 8 * eps * eps * 1.01;
  // Anything not finite in double (NaN included) is not finite as a float either.
  *k1_out = RoundUpToFloat(k1);
  *k0_out = RoundUpToFloat(k0);
  for (int i = 0; i < 3; ++i) c_out[i] = float(c[i]);
  return std::isfinite(*k1_out) && std::isfinite(*k0_out) && std::isfinite(c_out[0]) && std::isfinite(c_out[1]) &&
         std::isfinite(c_out[2]);
}

namespace cpu_detail {

CoreScratch PrepareScratch(const ScoreKernelParams& k, CpuWorkspace* ws, const FacePlanes* planes) {
  const PixelRect& w = k.window;
  const std::size_t nv = std::size_t(k.num_vertices) + 16, cap = (std::size_t(k.num_faces) + 31) / 16 * 16;
  CoreScratch s;
  s.vrec = AlignTo64(Grow(&ws->vrec, 4 * nv + 16));
  s.vok = Grow(&ws->vok, nv);
  s.tri_cap = std::int64_t(cap);
  s.tri = AlignTo64(Grow(&ws->tri, kTriFields * cap + 16));
  s.fast = Grow(&ws->fast, kFastBins * cap);
  s.slow = Grow(&ws->slow, cap);
  s.wide = Grow(&ws->wide, cap);
  // The raster's window buffer (both modes). Rows of width + 48 floats (16 of slack before
  // each row, 32 after: a row piece of 16 starting at the last column), 16 floats before row 0,
  // 4 spare rows (the kernel's 4-row vectors may read and write back up to 3 rows below the
  // window) and 64 floats after.
  s.zb_stride = std::int64_t(w.width) + 48;
  s.zb = Grow(&ws->zbuffer, std::size_t(s.zb_stride) * (std::size_t(w.height) + 4) + 80) + 16;
  constexpr int kFragCap = 1024;  // scored in batches that stay in L1
  s.frag_cap = kFragCap;
  s.frag_idx = Grow(&ws->frag_idx, kFragCap + 16);
  s.frag_iz = Grow(&ws->frag_iz, kFragCap + 16);
  s.covmask = Grow(&ws->covmask, 3 * (std::size_t(w.width) / 4 + 8));
  s.pc_nx = nullptr;
  s.cand = nullptr;
  s.preculled = &ws->faces_preculled;
  if (planes) {
    if (planes->vertices != k.vertices || planes->faces != k.faces || planes->num_vertices != k.num_vertices ||
        planes->num_faces != k.num_faces)
      throw Error("cpu kernel: the face planes were built from another mesh (vertices/faces)");
    if (PreCullConstants(k, *planes, s.pc_c, &s.pc_k1, &s.pc_k0)) {
      s.pc_nx = planes->nx.data();
      s.pc_ny = planes->ny.data();
      s.pc_nz = planes->nz.data();
      s.pc_d = planes->d.data();
      s.pc_len = planes->len.data();
      s.pc_i0 = planes->i0.data();
      s.pc_i1 = planes->i1.data();
      s.pc_i2 = planes->i2.data();
      s.cand = Grow(&ws->cand, 4 * (cap + 16));
    }
  }
  return s;
}

}  // namespace cpu_detail

ScoreKernelResult ScoreCpuWith(CpuTarget target, const ScoreKernelParams& k, CpuWorkspace* ws, const FacePlanes* planes) {
  if (!CpuTargetSupported(target))
    throw Error(std::string("cpu kernel: this build/CPU cannot run the '") + CpuTargetName(target) + "' variant");
  ScoreKernelResult r;
  r.faces_total = k.num_faces;
  ws->faces_preculled = 0;
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

  const cpu_detail::CoreScratch s = cpu_detail::PrepareScratch(k, ws, planes);
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
