// posefilter/camera.h — pinhole camera: intrinsics plus the base→camera extrinsic.
//
// Frames (docs/ALGORITHM.md §1): camera frame is OpenCV (x right, y down, z forward), metres.
// Pixel (u, v) = (column, row); the centre of pixel (i, j) is at u = i, v = j (OpenCV).
#pragma once

#include <Eigen/Geometry>
#include <string>

namespace posefilter {

struct Camera {
  int width = 640;     // image width, pixels
  int height = 480;    // image height, pixels
  double fx = 542.556;  // focal length, pixels (thesis camera, §6.1.5)
  double fy = 537.666;
  double cx = 325.065;  // principal point, pixels
  double cy = 224.214;
  // C of eq. 6.9 [ALGORITHM.md]: maps points in the robot base frame to the camera frame.
  Eigen::Isometry3d base_to_camera = Eigen::Isometry3d::Identity();

  // True when sizes are positive, the focal lengths give a field of view in [0.5, 175] degrees
  // along each axis, the principal point lies within one image side of the image
  // (cx in [-width, 2·width], cy likewise), and base_to_camera is a finite rigid transform.
  // Names the violated constraint.
  bool IsValid(std::string* why) const;

  // Camera-frame point (metres) → pixel coordinates. z must be > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_cam) const {
    return {fx * p_cam.x() / p_cam.z() + cx, fy * p_cam.y() / p_cam.z() + cy};
  }
  // Pixel (u, v) with depth z (metres, camera z) → camera-frame point.
  Eigen::Vector3d Backproject(double u, double v, double z) const {
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
  }
};

}  // namespace posefilter
