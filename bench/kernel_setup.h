// bench/kernel_setup.h — the score kernel's benchmark workload, shared by the Google Benchmark
// cases (kernel_bench.cc, render_bench.cc) and the A/B tool (kernel_ab.cc).
//
// The torus (R 6 cm, r 2.5 cm, n×n quads = 2·n² triangles) at 0.8 m in front of a wall at 1.2 m,
// rendered into a 640×480 depth image with the thesis camera; the poses to score lie near the
// true one: 3 mm deeper and turned by up to ±0.3 rad about varying axes (a mix of inliers, ramp
// values and misses, as in a converging particle set); `spread` instead turns them by up to ±π
// and moves them by up to ±3 cm sideways and −5…+20 cm in depth (a first iteration's spread).
// Every pose is scored inside the same 200×200 window.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/synth.h"

namespace posefilter {

// Poses of the Google Benchmark cases.
inline constexpr int kPoses = 16;

// The torus's true pose (object → camera): 0.8 m away, turned by 0.7 rad about (1, 1, 0).
inline Eigen::Isometry3d BenchTruthPose() {
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  truth.translation() = Eigen::Vector3d(0.01, -0.02, 0.8);
  return truth;
}

// The depth image of `mesh` at pose T in front of a wall at 1.2 m.
inline DepthImage DepthBeforeWall(const Mesh& mesh, const Eigen::Isometry3d& T, const Camera& camera) {
  DepthImage depth(camera.width, camera.height, 0.f);
  RenderDepth(mesh, T, camera, &depth);
  for (float& z : depth.data)
    if (z == 0) z = 1.2f;
  return depth;
}

// The kernel parameters of `mesh` at pose T, scored against `depth` inside the 200×200 window
// of every benchmark. They point into `mesh` and `depth`.
inline ScoreKernelParams BenchParams(const Mesh& mesh, const Eigen::Isometry3d& T, const Camera& camera,
                                     const DepthImage& depth, bool zbuffer) {
  ScoreKernelParams k = MakeKernelParams(mesh, T, camera);
  k.window = PixelRect{225, 124, 200, 200};
  k.depth = depth.data.data();
  k.depth_width = depth.width;
  k.depth_height = depth.height;
  k.zbuffer = zbuffer;
  return k;
}

// The scene and the kernel parameters of each pose (seeded: the same poses every run).
struct KernelSetup {
  Mesh mesh;
  Camera camera;
  DepthImage depth;
  std::vector<ScoreKernelParams> params;  // one per pose

  KernelSetup(int n, bool zbuffer, int poses = kPoses, bool spread = false) : mesh(MakeTorus(0.06, 0.025, n, n)) {
    const Eigen::Isometry3d truth = BenchTruthPose();
    depth = DepthBeforeWall(mesh, truth, camera);
    Rng rng(17);
    for (int i = 0; i < poses; ++i) {
      Eigen::Isometry3d T = truth;
      const double az = rng.Normal(), ay = rng.Normal(), ax = rng.Normal();  // one per statement, as GCC ordered them
      const Eigen::Vector3d axis(ax, ay, az);
      const double turn = spread ? 3.1 : 0.3;  // radians
      T.linear() = truth.linear() * Eigen::AngleAxisd(rng.Uniform(-turn, turn), axis.normalized()).toRotationMatrix();
      if (spread) {
        const double dz = rng.Uniform(-0.05, 0.2), dy = rng.Uniform(-0.03, 0.03), dx = rng.Uniform(-0.03, 0.03);
        T.translation() += Eigen::Vector3d(dx, dy, dz);
      } else {
        T.translation().z() += 0.003;
      }
      params.push_back(BenchParams(mesh, T, camera, depth, zbuffer));
    }
    // MakeKernelParams keeps pointers into `mesh`: the setup must not be copied or moved.
  }
  KernelSetup(const KernelSetup&) = delete;
  KernelSetup& operator=(const KernelSetup&) = delete;
};

}  // namespace posefilter
