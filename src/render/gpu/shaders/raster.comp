#version 450
// raster.comp — pass 2 of the gpu score kernel: one invocation per (face, particle) runs
// render::RasterizeMesh / RasterizeTriangle for that face inside the particle's window:
// near-plane test, back-face culling (2·Area ≤ 0), Pineda edge functions in exact integers with
// the top-left ownership rule (eq. 6.12–6.20 [ALGORITHM.md]), perspective-correct 1/z in the reference's float
// order. A face whose clipped box holds at most kInlineBox pixels is rastered here, stepping
// the edge functions (eq. 6.19–6.20 [ALGORITHM.md]); a larger one is listed for raster_big.comp, which spreads
// its pixels over a workgroup (one invocation per face would serialise a large triangle, and
// Mesa's lavapipe caps the loop iterations of an invocation). Grid: x = face, y = particle.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "triangle.glsl"
#include "reduce.glsl"

const int kInlineBox = 256;

void RasterFace(uint f, uint p, inout int64_t s[kNumSums]) {
  Face t;
  if (!LoadFace(f, p, t)) return;
  if (t.area2 <= 0) return;  // back face (§6.2)
  s[kFront] += 1;
  const ivec4 w = ParticleWindow(p);
  Raster r;
  if (!SetupRaster(t, w, r)) return;
  if ((r.u_hi - r.u_lo + 1) * (r.v_hi - r.v_lo + 1) > kInlineBox) {
    const uint j = atomicAdd(jobs[0], 1u);
    jobs[1u + 2u * j] = f;
    jobs[2u + 2u * j] = p;
    return;
  }
  int64_t row_e[3], step_x[3], step_y[3];
  for (int k = 0; k < 3; ++k) {
    row_e[k] = EdgeAt(r, k, r.u_lo, r.v_lo);
    step_x[k] = Mul64(r.A[k], 256);  // eq. 6.20 [ALGORITHM.md]
    step_y[k] = Mul64(r.B[k], 256);  // eq. 6.19 [ALGORITHM.md]
  }
  for (int v = r.v_lo; v <= r.v_hi; ++v) {
    int64_t e0 = row_e[0], e1 = row_e[1], e2 = row_e[2];
    for (int u = r.u_lo; u <= r.u_hi; ++u) {
      Fragment(t, r, p, w, u, v, e0, e1, e2, s);
      e0 += step_x[0];
      e1 += step_x[1];
      e2 += step_x[2];
    }
    for (int k = 0; k < 3; ++k) row_e[k] += step_y[k];
  }
}

void main() {
  int64_t s[kNumSums];
  for (uint k = 0u; k < kNumSums; ++k) s[k] = 0;
  const uint f = gl_GlobalInvocationID.x, p = gl_WorkGroupID.y;
  if (f < uint(pc.num_faces) && p < uint(pc.num_particles)) RasterFace(f, p, s);
  ReduceAndAdd(p, s);
}
