#version 450
// raster_big.comp — pass 2b of the gpu score kernel: one workgroup per face that raster.comp
// listed as large (jobs); its 64 invocations share the face's clipped box, pixel i of the box
// going to invocation i mod 64, each edge function evaluated exactly at the pixel (the same
// integers the stepping of raster.comp reaches). Grid: jobs.comp's x × y workgroups.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "triangle.glsl"
#include "reduce.glsl"

const uint kMaxGroupsX = 65535u;

void main() {
  int64_t s[kNumSums];
  for (uint k = 0u; k < kNumSums; ++k) s[k] = 0;
  const uint job = gl_WorkGroupID.y * kMaxGroupsX + gl_WorkGroupID.x;
  uint p = 0xffffffffu;  // no particle: nothing to add
  if (job < jobs[0]) {
    const uint f = jobs[1u + 2u * job];
    p = jobs[2u + 2u * job];
    Face t;
    Raster r;
    const ivec4 w = ParticleWindow(p);
    LoadFace(f, p, t);  // listed faces are usable and front
    SetupRaster(t, w, r);
    const uint bw = uint(r.u_hi - r.u_lo + 1), box = bw * uint(r.v_hi - r.v_lo + 1);
    for (uint i = gl_LocalInvocationIndex; i < box; i += 64u) {
      const int u = r.u_lo + int(i % bw), v = r.v_lo + int(i / bw);
      Fragment(t, r, p, w, u, v, EdgeAt(r, 0, u, v), EdgeAt(r, 1, u, v), EdgeAt(r, 2, u, v), s);
    }
  }
  ReduceAndAdd(p, s);
}
