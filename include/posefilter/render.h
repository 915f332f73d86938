// posefilter/render.h — rendering a mesh in a pose and scoring it against the depth image.
//
// The score kernel (thesis §6.2, §7.5 and §7.5.1; docs/ALGORITHM.md §5) renders the mesh inside
// a window of the image and compares each rendered pixel's depth z_r with the scene depth z_s:
//   soft inlier χ(d), d = |z_r − z_s|: 1 for d ≤ thr1, 2 − d·(1/thr1) on the ramp (continuous form
//   of the thesis's slope, an erratum: docs/HARDWARE.md §8), 0 for d ≥ thr2 = 2·thr1; or hard:
//   1 iff d ≤ hard_thr.
//   Missing scene depth (z_s = 0) is never an inlier.
// ScoreKernelParams is the one plain parameter struct of the float engines (reference and cpu);
// ScoreKernelResult the numbers they must agree on. The hw engine's raster core
// (src/hw/raster_core.h) computes the same counters in fixed point.
//
// Rasterization rules (all backends): pixel (i, j) is sampled at its centre (u = i, v = j);
// vertices snap to a 1/256-pixel grid; Pineda edge functions (eq. 6.12–6.20 [ALGORITHM.md]) in exact integer
// arithmetic; a pixel on an edge belongs to exactly one of the two triangles sharing it;
// back faces culled when 2·Area ≤ 0 (§6.2); depth is interpolated perspective-correctly
// (1/z linear in screen space: the "depth recovery" of §7.5.3); triangles with a vertex
// closer than near_m are skipped (no clipping).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"

namespace posefilter {

// A pixel rectangle [u0, u0+width) × [v0, v0+height) of the image.
struct PixelRect {
  int u0 = 0, v0 = 0, width = 0, height = 0;
  long Area() const { return long(width) * height; }
};

struct InlierParams {
  float thr1_m = 1.0f / 256;     // χ = 1 up to here (2^-8 m ≈ 3.9 mm, §7.5.1)
  bool hard = false;             // GRIP's original hard switch instead of the soft ramp
  float hard_thr_m = 0.005f;     // hard mode: χ = 1 iff d ≤ this (5 mm, eq. 7.4 [ALGORITHM.md])
};

// χ(d) for a depth difference d ≥ 0 in metres (thr2 = 2·thr1; the ramp is 2 − d·(1/thr1),
// with 1/thr1 rounded to float once: a multiply, as the thesis's 2 − 256·d for thr1 = 2^-8).
inline float SoftInlier(float d, const InlierParams& p) {
  if (p.hard) return d <= p.hard_thr_m ? 1.0f : 0.0f;
  if (d <= p.thr1_m) return 1.0f;
  if (d >= 2 * p.thr1_m) return 0.0f;
  return 2.0f - d * (1.0f / p.thr1_m);
}

struct ScoreKernelParams {
  // Model, object frame: vertices num_vertices×3 floats (metres), faces num_faces×3 indices.
  const float* vertices = nullptr;
  int num_vertices = 0;
  const std::uint32_t* faces = nullptr;
  int num_faces = 0;
  // Object → camera rigid transform, row-major R (3×3) and t (metres).
  float R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  float t[3] = {0, 0, 0};
  // Pinhole intrinsics, pixels.
  float fx = 0, fy = 0, cx = 0, cy = 0;
  float near_m = 0.05f;  // triangles with a vertex at z < near_m are skipped
  // Window of the image to render in (already clipped to the image).
  PixelRect window;
  // Scene depth image (row-major, metres, 0 = missing), depth_width × depth_height.
  const float* depth = nullptr;
  int depth_width = 0, depth_height = 0;
  InlierParams inlier;
  // true: exact per-window z-buffer (only the nearest fragment of a pixel counts);
  // false: the thesis's z-buffer-free mode (every front-face fragment counts, §7.5.1).
  bool zbuffer = true;
  float align_band_m = 0.05f;  // band of depth differences that enter depth_diff_sum, metres
  // Optional unit scene normals (camera frame, 3 floats per depth pixel, zeros = none):
  // when set, the kernel also accumulates the ICP normal equations.
  const float* scene_normals = nullptr;
  float edge_band_m = 0.01f;   // silhouette edge test: "no depth step" band, metres
};

struct ScoreKernelResult {
  double inlier_sum = 0;       // I = Σ χ over counted fragments
  std::int64_t n_raster = 0;   // counted fragments (z-buffer: covered pixels)
  // Counted fragments whose scene depth lies in front of them by more than the inlier ramp
  // (χ = 0 and z_s < z_r): the object is hidden there by something else (occlusion).
  std::int64_t n_occluded = 0;
  // Σ (z_s − z_r) and count over counted fragments with valid scene depth within
  // ±align_band_m of the rendering: the mean depth misalignment, for the align-depth move.
  double depth_diff_sum = 0;
  std::int64_t depth_diff_count = 0;
  // With scene_normals: the point-to-plane ICP normal equations over the same fragments
  // (upper triangle of the 6×6 A row by row, and b; unknowns ω (rad), τ (m), camera frame).
  double icp_A[21] = {};
  double icp_b[6] = {};
  std::int64_t icp_count = 0;
  // z-buffer mode only: silhouette edge samples (a covered pixel and an uncovered
  // 4-neighbour inside the window, whatever that neighbour's scene depth), and those where
  // the scene surface continues across the outline (the neighbour has valid scene depth and
  // |z_s(neighbour) − z_r| ≤ edge_band_m). A missing reading next to the outline counts as a
  // discontinuity (sensors drop pixels at depth steps), never as continued.
  std::int64_t n_edge = 0;
  std::int64_t n_edge_continued = 0;
  std::int64_t faces_front = 0;  // faces that passed near-plane test and culling
  std::int64_t faces_total = 0;  // faces of the model
};

// Per-worker scratch memory of the reference kernel (no global render state).
struct RenderWorkspace {
  std::vector<float> zbuffer;          // window-sized, metres, +inf = empty
  std::vector<float> cam_vertices;     // num_vertices × 3, camera frame
};

// Kernel parameters for `mesh` at T_cam_obj (object → camera) seen by `camera`: model,
// pose and intrinsics filled in, window = the whole image; the scene depth and the other
// fields keep their defaults. The mesh must outlive the parameters.
ScoreKernelParams MakeKernelParams(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera);

// Unit normals of the scene surface (camera frame, facing the camera), 3 floats per depth
// pixel, from central differences of the back-projected depth; zero on the image border,
// where a 4-neighbour is missing, or across a depth step of more than 2 cm. `threads`: worker
// threads over the rows (0 or less = all cores, capped at 4 per hardware thread); the result
// does not depend on it.
std::vector<float> ComputeSceneNormals(const DepthImage& depth, const Camera& camera, int threads = 0);

// The reference score kernel: readable float/int64 C++, the executable spec.
ScoreKernelResult ScoreReference(const ScoreKernelParams& params, RenderWorkspace* ws);

// Renders `mesh` at T_cam_obj into a full depth image with a z-test against what `depth`
// already holds (0 = empty): used to build synthetic scenes and overlays. Pixels the mesh wins
// get its depth and, when `labels` is non-null (width×height), the value `label`.
// Uses exactly the rasterization rules above (with back-face culling, z-buffer on).
void RenderDepth(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera,
                 DepthImage* depth, std::vector<int>* labels = nullptr, int label = 1);

}  // namespace posefilter
