#include "posefilter/pose.h"

#include <cmath>

namespace posefilter {

double WrapAngle(double a) {
  a = std::remainder(a, 2 * M_PI);  // in [-π, π]
  if (a <= -M_PI) a += 2 * M_PI;
  return a;
}

Eigen::Isometry3d PoseToTransform(const Pose6& p) {
  // T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll)   (eq. 7.6–7.7 [ALGORITHM.md])
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(p.pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(p.roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.x, p.y, p.z);
  return T;
}

Pose6 TransformToPose(const Eigen::Isometry3d& T) {
  // R = Rz(yaw)Ry(pitch)Rx(roll): R20 = −sin(pitch), R21 = cos(pitch)sin(roll),
  // R22 = cos(pitch)cos(roll), R10 = sin(yaw)cos(pitch), R00 = cos(yaw)cos(pitch).
  const Eigen::Matrix3d R = T.linear();
  Pose6 p;
  p.x = T.translation().x();
  p.y = T.translation().y();
  p.z = T.translation().z();
  const double cp = std::hypot(R(0, 0), R(1, 0));
  p.pitch = std::atan2(-R(2, 0), cp);
  if (cp > 1e-9) {
    p.roll = std::atan2(R(2, 1), R(2, 2));
    p.yaw = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock: only roll − yaw (or roll + yaw) is defined; put it all in roll
    p.yaw = 0;
    p.roll = std::atan2(-R(1, 2), R(1, 1));
  }
  p.roll = WrapAngle(p.roll);
  p.yaw = WrapAngle(p.yaw);
  return p;
}

}  // namespace posefilter
