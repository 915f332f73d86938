// Pose conventions (docs/ALGORITHM.md §1): T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll), round trips,
// wrapping.
#include "posefilter/pose.h"

#include <gtest/gtest.h>

#include <cmath>

#include "posefilter/rng.h"

namespace posefilter {
namespace {

TEST(PoseTest, MatchesTheThesisMatrices) {
  const Pose6 p{0.1, -0.2, 0.7, 0.3, -0.5, 1.1};
  const Eigen::Isometry3d T = PoseToTransform(p);
  const double cr = std::cos(p.roll), sr = std::sin(p.roll);
  const double cp = std::cos(p.pitch), sp = std::sin(p.pitch);
  const double cy = std::cos(p.yaw), sy = std::sin(p.yaw);
  Eigen::Matrix3d Rz, RyRx;
  Rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;  // eq. 6.6 / 7.6 [ALGORITHM.md]
  RyRx << cp, sp * sr, sp * cr, 0, cr, -sr, -sp, cp * sr, cp * cr;  // eq. 7.7 [ALGORITHM.md]
  EXPECT_TRUE(T.linear().isApprox(Rz * RyRx, 1e-12));
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0.1, -0.2, 0.7)));
}

TEST(PoseTest, RoundTripsRandomPoses) {
  Rng rng(3);
  for (int i = 0; i < 1000; ++i) {
    Pose6 p{rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(0.2, 2), rng.Uniform(-M_PI, M_PI),
            rng.Uniform(-M_PI / 2 + 1e-3, M_PI / 2 - 1e-3), rng.Uniform(-M_PI, M_PI)};
    const Pose6 q = TransformToPose(PoseToTransform(p));
    EXPECT_NEAR(q.x, p.x, 1e-12);
    EXPECT_NEAR(q.roll, p.roll, 1e-9);
    EXPECT_NEAR(q.pitch, p.pitch, 1e-9);
    EXPECT_NEAR(q.yaw, p.yaw, 1e-9);
    // Any angles (pitch beyond ±π/2 included) give the same transform back.
    Pose6 r = p;
    r.pitch = rng.Uniform(-M_PI, M_PI);
    EXPECT_TRUE(PoseToTransform(TransformToPose(PoseToTransform(r))).isApprox(PoseToTransform(r), 1e-9));
  }
}

TEST(PoseTest, GimbalLockStillReproducesTheRotation) {
  const Pose6 p{0, 0, 1, 0.4, M_PI / 2, -0.3};
  EXPECT_TRUE(PoseToTransform(TransformToPose(PoseToTransform(p))).isApprox(PoseToTransform(p), 1e-9));
}

TEST(PoseTest, WrapAngle) {
  EXPECT_NEAR(WrapAngle(3 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(WrapAngle(-M_PI), M_PI, 1e-12);
  EXPECT_NEAR(WrapAngle(2 * M_PI + 0.25), 0.25, 1e-12);
  EXPECT_NEAR(WrapAngle(-0.25), -0.25, 1e-12);
}

}  // namespace
}  // namespace posefilter
