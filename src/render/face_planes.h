// src/render/face_planes.h — per-mesh data for the cpu engine's back-face pre-cull (internal).
//
// A face whose plane faces away from the camera is culled by every engine (2·Area ≤ 0 after
// snapping, raster.h), but finding that out costs the cpu kernel's face pass a gather of its
// three projected corners. With the face's plane known in the object frame, a cheaper test
// decides most of them without touching the vertices: for camera-frame points P = R·v + t and
// the face normal N = (v1 − v0) × (v2 − v0) (object frame, not normalised),
//   2·Area(projected, pixels²) = −fx·fy·det(R)·s / (z0·z1·z2),   s = N·v0 − N·c,
// with c = −R⁻¹·t the camera centre in the object frame. The kernel skips a face only when s
// exceeds a per-call margin that also covers the float transform, the projection and the
// 1/256 px snapping (proof in docs/PERFORMANCE.md, "Why the counts are exact"), so every
// skipped face is one the reference culls: results are unchanged, bit for bit.
//
// Built once per mesh (the filter does it per estimate); the kernel checks that the table was
// built from the mesh it is given (same arrays and counts). A table must be rebuilt when the
// mesh's arrays change.
#pragma once

#include <cstdint>
#include <vector>

#include "posefilter/render.h"

namespace posefilter::render {

struct FacePlanes {
  // The mesh the table describes (identity check only; never dereferenced by the kernel).
  const float* vertices = nullptr;
  const std::uint32_t* faces = nullptr;
  int num_vertices = 0, num_faces = 0;
  // Per face, structure of arrays padded to a multiple of 16 entries (zeros; d: +inf, so that
  // the kernel drops the padding without a lane test):
  std::vector<float> nx, ny, nz;  // N = (v1 − v0) × (v2 − v0), metres², rounded to float
  std::vector<float> d;           // N·v0, metres³, rounded to float
  std::vector<float> len;         // longest edge, metres, rounded up to float
  std::vector<std::uint32_t> i0, i1, i2;  // the face's vertex indices (a copy of `faces`)
  double radius = 0;    // max |v| over the vertices, metres (object frame, rounded up)
  double max_len = 0;   // max of len
};

// Builds the table of the mesh the kernel parameters point at (vertices, num_vertices×3 floats
// in metres; faces, num_faces×3 indices; the pose and the rest are not read), so that the
// kernel's check that table and parameters describe the same arrays holds. Throws
// posefilter::Error naming the face when an index is out of range. A vertex coordinate that is
// not finite makes `radius` infinite, which turns the pre-cull off.
FacePlanes BuildFacePlanes(const ScoreKernelParams& mesh);

// The smallest float ≥ x (x finite or ±inf; NaN stays NaN): the table's lengths and the
// kernel's margin are rounded this way so that they only grow.
float RoundUpToFloat(double x);

}  // namespace posefilter::render
