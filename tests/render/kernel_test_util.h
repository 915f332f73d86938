// tests/render/kernel_test_util.h — helpers of the score kernels' tests (cpu_kernel_test.cc,
// kernel_inputs_test.cc): a kernel's result against the reference kernel's, and the kernel
// parameters of a mesh at a pose in a window of a depth image.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"
#include "posefilter/render.h"

namespace posefilter::kernel_test {

// |a − b| within 1e-4 of |reference| (1e-6 absolute floor).
inline ::testing::AssertionResult Close(double ref, double got, const char* what) {
  const double tol = std::max(1e-6, 1e-4 * std::fabs(ref));
  if (std::fabs(ref - got) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << what << ": reference " << ref << ", cpu " << got;
}

// Exact equality of the counts and of the inlier and depth-difference sums, tolerance on the
// ICP sums; `ctx` names the case. Every χ is a multiple of 2^-23 in [0, 1] and every d a float
// difference of depths ≥ near_m (multiples of 2^-29 for the default 0.05 m) below align_band_m:
// their sums are exact in double whatever the order, so equal depths give equal sums and any
// depth that differs from the reference's shows. The ICP terms are products (rounded).
inline void ExpectSame(const ScoreKernelResult& ref, const ScoreKernelResult& got, const std::string& ctx) {
  EXPECT_EQ(ref.n_raster, got.n_raster) << ctx;
  EXPECT_EQ(ref.n_occluded, got.n_occluded) << ctx;
  EXPECT_EQ(ref.faces_front, got.faces_front) << ctx;
  EXPECT_EQ(ref.faces_total, got.faces_total) << ctx;
  EXPECT_EQ(ref.depth_diff_count, got.depth_diff_count) << ctx;
  EXPECT_EQ(ref.n_edge, got.n_edge) << ctx;
  EXPECT_EQ(ref.n_edge_continued, got.n_edge_continued) << ctx;
  EXPECT_EQ(ref.icp_count, got.icp_count) << ctx;
  EXPECT_EQ(ref.inlier_sum, got.inlier_sum) << ctx;
  EXPECT_EQ(ref.depth_diff_sum, got.depth_diff_sum) << ctx;
  for (int i = 0; i < 21; ++i) EXPECT_TRUE(Close(ref.icp_A[i], got.icp_A[i], "icp_A")) << ctx << " i=" << i;
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(Close(ref.icp_b[i], got.icp_b[i], "icp_b")) << ctx << " i=" << i;
}

// Kernel parameters for `mesh` at pose T (object → camera) in `window`, scored against
// `depth` and, when given, its scene normals.
inline ScoreKernelParams SceneParams(const Mesh& mesh, const Eigen::Isometry3d& T, const Camera& cam, const DepthImage& depth,
                                     const PixelRect& window, const std::vector<float>* normals = nullptr) {
  ScoreKernelParams k = MakeKernelParams(mesh, T, cam);
  k.window = window;
  k.depth = depth.data.data();
  k.depth_width = depth.width;
  k.depth_height = depth.height;
  k.scene_normals = normals ? normals->data() : nullptr;
  return k;
}

}  // namespace posefilter::kernel_test
