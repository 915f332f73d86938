// posefilter/pose.h — 6-DoF poses as the particle filter stores them.
//
// A particle's pose (x, y, z, roll, pitch, yaw) maps object → base frame (docs/ALGORITHM.md §1):
//   T = Tr(x, y, z) · Rz(yaw) · Ry(pitch) · Rx(roll)            (eq. 6.2, 6.6–6.7, 7.6–7.7 [ALGORITHM.md])
// Units: metres and radians.
#pragma once

#include <Eigen/Geometry>

namespace posefilter {

struct Pose6 {
  double x = 0, y = 0, z = 0;            // translation, metres
  double roll = 0, pitch = 0, yaw = 0;   // rotations about x, y, z, radians
};

// T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll).
Eigen::Isometry3d PoseToTransform(const Pose6& p);
// Inverse of PoseToTransform; angles returned with pitch in [-π/2, π/2], roll/yaw in (-π, π].
Pose6 TransformToPose(const Eigen::Isometry3d& T);
// Wraps an angle to (-π, π].
double WrapAngle(double a);

}  // namespace posefilter
