// src/render/raster.h — the triangle rasterizer every float engine shares (internal).
//
// Screen coordinates are fixed point with kSubpixelBits fractional bits (1/256 pixel); the
// centre of pixel (i, j) is at (i·256, j·256). Edge functions (Pineda, eq. 6.12–6.13 [ALGORITHM.md]) are
// evaluated in exact int64 arithmetic and stepped incrementally (eq. 6.19–6.20 [ALGORITHM.md]), so any
// backend that snaps vertices the same way covers exactly the same pixels.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "posefilter/render.h"

namespace posefilter::render {

inline constexpr int kSubpixelBits = 8;
inline constexpr std::int64_t kSubpixelOne = std::int64_t(1) << kSubpixelBits;
// Vertices projecting farther than this from the origin (pixels) make the triangle skipped;
// keeps every edge-function product below 2^60.
inline constexpr double kMaxScreenCoord = double(1 << 20);

// A projected triangle: fixed-point screen coordinates and 1/z (1/metres, float) per vertex.
struct ScreenTriangle {
  std::int64_t x[3], y[3];
  float inv_z[3];
};

// Projects a camera-frame point (metres) with the pinhole model and snaps it to the subpixel
// grid. Returns false when z < near_m or the point lands absurdly far off screen.
inline bool ProjectAndSnap(float px, float py, float pz, const ScoreKernelParams& k,
                           std::int64_t* sx, std::int64_t* sy, float* inv_z) {
  if (!(pz >= k.near_m)) return false;
  const float u = k.fx * px / pz + k.cx;
  const float v = k.fy * py / pz + k.cy;
  if (!(std::fabs(u) < kMaxScreenCoord && std::fabs(v) < kMaxScreenCoord)) return false;
  *sx = std::llround(double(u) * kSubpixelOne);
  *sy = std::llround(double(v) * kSubpixelOne);
  *inv_z = 1.0f / pz;
  return true;
}

// Transforms the model's vertices to the camera frame: p_cam = R·v + t (float, row-major R).
inline void TransformVertices(const ScoreKernelParams& k, float* out) {
  for (int i = 0; i < k.num_vertices; ++i) {
    const float* v = k.vertices + 3 * i;
    out[3 * i + 0] = k.R[0] * v[0] + k.R[1] * v[1] + k.R[2] * v[2] + k.t[0];
    out[3 * i + 1] = k.R[3] * v[0] + k.R[4] * v[1] + k.R[5] * v[2] + k.t[1];
    out[3 * i + 2] = k.R[6] * v[0] + k.R[7] * v[1] + k.R[8] * v[2] + k.t[2];
  }
}

inline std::int64_t FloorDiv(std::int64_t a, std::int64_t b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}
inline std::int64_t CeilDiv(std::int64_t a, std::int64_t b) { return -FloorDiv(-a, b); }

// Twice the signed area of the triangle (§6.2): (V2x−V0x)(V1y−V0y) − (V2y−V0y)(V1x−V0x).
// Positive for a front face (counter-clockwise from outside, seen through a y-down image).
inline std::int64_t TwiceArea(const ScreenTriangle& t) {
  return (t.x[2] - t.x[0]) * (t.y[1] - t.y[0]) - (t.y[2] - t.y[0]) * (t.x[1] - t.x[0]);
}

// Rasterizes a front-facing triangle (TwiceArea > 0) inside `clip` and calls
// fn(u, v, z) for every covered pixel centre, z the perspective-correct depth in metres
// (barycentric λ_k = E_k / 2Area, eq. 6.21–6.22 [ALGORITHM.md], applied to 1/z).
//
// Depth arithmetic is float, in exactly this order (binding for every float engine):
//   1/z = ((float(E0)·iz0 + float(E1)·iz1) + float(E2)·iz2) · (1 / float(2Area)),  z = 1 / (1/z),
// with iz_k = 1/z_k of the vertices (float) and float(E) the int64 edge value rounded to
// nearest. float(E) is exact while |E| < 2^24 and rounds the same way from int32 or double,
// which lets the SIMD kernel (cpu_kernel_impl.inc) reproduce every depth bit for bit with 16
// float lanes. 1/z > 0 inside a triangle (the E_k are ≥ 0 and sum to 2Area > 0).
template <class Fn>
void RasterizeTriangle(const ScreenTriangle& t, std::int64_t area2, const PixelRect& clip, Fn&& fn) {
  const std::int64_t min_x = std::min({t.x[0], t.x[1], t.x[2]});
  const std::int64_t max_x = std::max({t.x[0], t.x[1], t.x[2]});
  const std::int64_t min_y = std::min({t.y[0], t.y[1], t.y[2]});
  const std::int64_t max_y = std::max({t.y[0], t.y[1], t.y[2]});
  const std::int64_t u_lo = std::max<std::int64_t>(clip.u0, CeilDiv(min_x, kSubpixelOne));
  const std::int64_t u_hi = std::min<std::int64_t>(clip.u0 + clip.width - 1, FloorDiv(max_x, kSubpixelOne));
  const std::int64_t v_lo = std::max<std::int64_t>(clip.v0, CeilDiv(min_y, kSubpixelOne));
  const std::int64_t v_hi = std::min<std::int64_t>(clip.v0 + clip.height - 1, FloorDiv(max_y, kSubpixelOne));
  if (u_lo > u_hi || v_lo > v_hi) return;

  // Edge k lies opposite vertex k, from Va = V[k+1] to Vb = V[k+2] (eq. 6.13 [ALGORITHM.md]):
  //   E_k(P) = (Px − Va.x)(Vb.y − Va.y) − (Py − Va.y)(Vb.x − Va.x) = A·(Px − Va.x) + B·(Py − Va.y).
  // Inside: E_k > 0 for all k. A pixel exactly on an edge (E_k = 0) belongs to the triangle
  // only when the edge "owns" it (A > 0, or A = 0 and B > 0): of two triangles sharing the
  // edge (which see it with opposite A, B) exactly one covers the pixel (top-left rule).
  std::int64_t A[3], B[3], row_e[3], min_e[3];
  for (int k = 0; k < 3; ++k) {
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    A[k] = t.y[b] - t.y[a];
    B[k] = -(t.x[b] - t.x[a]);
    row_e[k] = A[k] * (u_lo * kSubpixelOne - t.x[a]) + B[k] * (v_lo * kSubpixelOne - t.y[a]);
    min_e[k] = (A[k] > 0 || (A[k] == 0 && B[k] > 0)) ? 0 : 1;
  }
  const float inv_area2 = 1.0f / float(area2);
  for (std::int64_t v = v_lo; v <= v_hi; ++v) {
    std::int64_t e[3] = {row_e[0], row_e[1], row_e[2]};
    for (std::int64_t u = u_lo; u <= u_hi; ++u) {
      if (e[0] >= min_e[0] && e[1] >= min_e[1] && e[2] >= min_e[2]) {
        // Depth recovery: 1/z is affine in screen space, z itself is not.
        const float inv_z =
            ((float(e[0]) * t.inv_z[0] + float(e[1]) * t.inv_z[1]) + float(e[2]) * t.inv_z[2]) * inv_area2;
        fn(int(u), int(v), 1.0f / inv_z);
      }
      for (int k = 0; k < 3; ++k) e[k] += A[k] * kSubpixelOne;  // step in x (eq. 6.20 [ALGORITHM.md])
    }
    for (int k = 0; k < 3; ++k) row_e[k] += B[k] * kSubpixelOne;  // step in y (eq. 6.19 [ALGORITHM.md])
  }
}

// Runs `fn(u, v, z)` over every fragment of every front face of the model (camera-frame
// vertices in `cam`, num_vertices×3) inside `clip`. Returns the number of front faces.
template <class Fn>
std::int64_t RasterizeMesh(const ScoreKernelParams& k, const float* cam, const PixelRect& clip, Fn&& fn) {
  std::int64_t front = 0;
  for (int f = 0; f < k.num_faces; ++f) {
    ScreenTriangle t;
    bool ok = true;
    for (int c = 0; c < 3 && ok; ++c) {
      const float* p = cam + 3 * std::size_t(k.faces[3 * f + c]);
      ok = ProjectAndSnap(p[0], p[1], p[2], k, &t.x[c], &t.y[c], &t.inv_z[c]);
    }
    if (!ok) continue;
    const std::int64_t area2 = TwiceArea(t);
    if (area2 <= 0) continue;  // back-face culling: culled when 2·Area ≤ 0 (§6.2)
    ++front;
    RasterizeTriangle(t, area2, clip, fn);
  }
  return front;
}

}  // namespace posefilter::render
