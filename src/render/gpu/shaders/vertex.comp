#version 450
// vertex.comp — pass 1 of the gpu score kernel: every vertex of every particle transformed to
// the camera frame, projected and snapped to the 1/256-pixel grid (render::ProjectAndSnap,
// TransformVertices: the same float operations in the same order). Grid: x = vertex, y = particle.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

void main() {
  const uint i = gl_GlobalInvocationID.x, p = gl_GlobalInvocationID.y;
  if (i >= uint(pc.num_vertices) || p >= uint(pc.num_particles)) return;
  const uint b = p * kParticleWords;
  float R[9];
  for (int k = 0; k < 9; ++k) R[k] = uintBitsToFloat(particles[b + uint(k)]);
  const float t0 = uintBitsToFloat(particles[b + 9u]), t1 = uintBitsToFloat(particles[b + 10u]),
              t2 = uintBitsToFloat(particles[b + 11u]);
  const float v0 = vertices[3u * i], v1 = vertices[3u * i + 1u], v2 = vertices[3u * i + 2u];
  // p_cam = R·v + t, row by row, left to right (((R0·v0 + R1·v1) + R2·v2) + t0).
  precise float px = R[0] * v0 + R[1] * v1 + R[2] * v2 + t0;
  precise float py = R[3] * v0 + R[4] * v1 + R[5] * v2 + t1;
  precise float pz = R[6] * v0 + R[7] * v1 + R[8] * v2 + t2;
  ivec4 rec = ivec4(0);
  if (pz >= pc.near_m) {  // false for NaN too, as !(pz >= near_m) in the reference
    precise float fxpx = pc.fx * px;
    precise float fypy = pc.fy * py;
    precise float u = DivRN(fxpx, pz) + pc.cx;
    precise float v = DivRN(fypy, pz) + pc.cy;
    if (abs(u) < 1048576.0 && abs(v) < 1048576.0) {  // kMaxScreenCoord = 2^20 px
      precise float us = u * 256.0;  // exact: a power of two
      precise float vs = v * 256.0;
      rec = ivec4(RoundHalfAway(us), RoundHalfAway(vs), floatBitsToInt(DivRN(1.0, pz)), 1);
    }
  }
  vrec[p * uint(pc.num_vertices) + i] = rec;
}
