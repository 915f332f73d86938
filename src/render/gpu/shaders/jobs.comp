#version 450
// jobs.comp — between raster.comp and raster_big.comp: the indirect dispatch size for the
// listed large faces, x · y ≥ count workgroups with x ≤ 65535.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 1) in;

void main() {
  const uint n = jobs[0];
  job_groups[0] = min(n, 65535u);
  job_groups[1] = (n + 65534u) / 65535u;
  job_groups[2] = 1u;
}
