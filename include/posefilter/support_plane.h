// posefilter/support_plane.h — the dominant plane of a depth image (the table the objects
// stand on) and which pixels lie on it.
//
// Objects on a table are seen against the table: a pose laid into the table plane, or sunk
// below it, explains the table's depth as well as a thin object explains its own few
// centimetres of relief. The filter therefore takes the table's pixels out of the scene it
// scores against (FilterOptions::support.plane; docs/ALGORITHM.md, "Support plane"): they
// are never inliers, never hide an object, and do not count in N_depth.
//
// Method: RANSAC over a regular grid of the valid depth pixels (back-projected to the camera
// frame), a least-squares refit on the inliers, then each pixel is "on the plane" when its
// point lies within a depth-dependent band of it. The band follows the sensor: residuals of
// structured-light depth grow with z², so it is k·σ₁·z² with σ₁ (metres at 1 m) measured
// from the plane's own residuals (median absolute deviation), clamped to
// [min_band_m, max_band_m]. Deterministic: the RANSAC draws come from a fixed seed.
//
// Frames and units: camera frame (OpenCV), metres; the plane is n·x + d = 0 with n a unit
// normal pointing towards the camera side (d > 0 for a plane in front of the camera).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"

namespace posefilter {

struct SupportPlaneOptions {
  int samples = 4000;                // valid pixels the fit uses (regular grid), ≥ 50
  int iterations = 200;              // RANSAC hypotheses, ≥ 1
  double ransac_band_m = 0.01;       // RANSAC inlier distance at 1 m (× z²), metres, > 0
  // A plane is accepted only when at least this fraction of the sampled pixels lie on it: a
  // box face or a wall patch is not the support. (0, 1].
  double min_fraction = 0.15;
  double band_sigmas = 3.0;          // k: the pixel band is k·σ₁·z², > 0
  double min_band_m = 0.003;         // band clamp, metres, 0 < min ≤ max
  double max_band_m = 0.012;
  bool IsValid(std::string* why) const;
};

struct SupportPlane {
  bool found = false;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, towards the camera (camera frame)
  double offset = 0;            // n·x + offset = 0, metres
  double fraction = 0;          // fraction of the sampled pixels on the plane
  double sigma_1m = 0;          // residual σ₁ at 1 m (robust), metres
  // Signed height of a camera-frame point above the plane (towards the camera), metres.
  double Height(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  // The band half-width at depth z (metres): clamp(k·σ₁·z², min, max).
  double Band(double z, const SupportPlaneOptions& opt) const;
};

// The dominant plane of `depth`; found = false when no plane holds min_fraction of the valid
// pixels (or there are fewer than 50 of them). Throws Error on invalid options or a depth
// image whose size differs from the camera's.
SupportPlane FindSupportPlane(const DepthImage& depth, const Camera& camera, const SupportPlaneOptions& opt = {});

// Per pixel (row-major, width × height): 1 where the depth is valid and lies within the
// plane's band, 0 elsewhere (all 0 when !plane.found).
std::vector<std::uint8_t> SupportPlanePixels(const DepthImage& depth, const Camera& camera, const SupportPlane& plane,
                                             const SupportPlaneOptions& opt = {});

}  // namespace posefilter
