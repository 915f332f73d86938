#version 450
// score.comp — pass 3 of the gpu score kernel (z-buffer mode): one invocation per window
// pixel of a particle compares the nearest fragment with the scene and runs the silhouette
// edge test (ScoreReference's z-buffer branch). Each invocation takes kPixelsPerInvocation
// pixels 64 apart (fewer workgroups, so fewer reductions). Grid: x = window pixel / that,
// y = particle.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "reduce.glsl"

void ScorePixel(uint i, uint p, inout int64_t s[kNumSums]) {
  const ivec4 w = ParticleWindow(p);
  if (i >= uint(w.z) * uint(w.w)) return;
  const uint zoff = ZOffset(p);
  const uint bits = zbuf[zoff + i];
  if (bits == 0u) return;
  const float z = DivRN(1.0, uintBitsToFloat(bits));
  const int x = int(i % uint(w.z)), y = int(i / uint(w.z));
  CompareFragment(w.x + x, w.y + y, z, s);
  // Silhouette edge test: uncovered 4-neighbours inside the window.
  const ivec2 dn[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));
  for (int n = 0; n < 4; ++n) {
    const int xn = x + dn[n].x, yn = y + dn[n].y;
    if (xn < 0 || yn < 0 || xn >= w.z || yn >= w.w) continue;
    if (zbuf[zoff + uint(yn) * uint(w.z) + uint(xn)] != 0u) continue;
    const float zs = depth[uint(w.y + yn) * uint(pc.depth_width) + uint(w.x + xn)];
    s[kEdge] += 1;  // a missing reading next to the outline is a discontinuity
    precise float dz = zs - z;
    if (zs > 0.0 && abs(dz) <= pc.edge_band_m) s[kEdgeContinued] += 1;
  }
}

const uint kPixelsPerInvocation = 16u;  // gpu_kernel.cc: kScorePixels

void main() {
  int64_t s[kNumSums];
  for (uint k = 0u; k < kNumSums; ++k) s[k] = 0;
  const uint p = gl_WorkGroupID.y;
  const uint first = gl_WorkGroupID.x * 64u * kPixelsPerInvocation + gl_LocalInvocationIndex;
  if (p < uint(pc.num_particles))
    for (uint j = 0u; j < kPixelsPerInvocation; ++j) ScorePixel(first + 64u * j, p, s);
  ReduceAndAdd(p, s);
}
