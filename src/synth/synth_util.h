// src/synth/synth_util.h — pieces both synthetic worlds use (internal): planes as meshes,
// random rotations, label counts and the simple parts of the sensor models.
//
// Frames and units: metres; depth images hold camera z (0 = missing).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <vector>

#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"
#include "posefilter/rng.h"

namespace posefilter::synth {

// Radians per degree.
inline constexpr double kDeg = M_PI / 180.0;

// v is finite and lo <= v <= hi (the synthetic worlds' option checks).
inline bool InRange(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

// Uniformly distributed rotation: a normalised 4-D Gaussian is a uniform unit quaternion.
Eigen::Matrix3d RandomRotation(Rng& rng);

// The rectangle centre + a·ex + b·ey, a ∈ [a0, a1], b ∈ [b0, b1] (metres; ex, ey unit and
// orthogonal) as a grid of `step`-sized quads, two triangles each, counter-clockwise seen
// from the side ex × ey points to. Quads with a vertex whose camera z (T_cam · p) is below
// min_z are left out: the renderer skips triangles that reach behind the near plane, so a
// large plane must be cut into pieces that stay in front of the camera.
Mesh PlaneGridMesh(const Eigen::Vector3d& centre, const Eigen::Vector3d& ex, const Eigen::Vector3d& ey, double a0,
                   double a1, double b0, double b1, double step, const Eigen::Isometry3d& T_cam, double min_z);

std::size_t CountLabel(const std::vector<int>& labels, int label);

// Per pixel (row-major): 1 where the depth is valid and a valid 4-neighbour lies more than
// jump_m away in depth (an occlusion boundary; sensors lose those pixels), else 0.
std::vector<std::uint8_t> DepthEdgePixels(const DepthImage& depth, double jump_m);

// Drops random disc-shaped blobs (radius 2–8 px) until `fraction` of all pixels are covered.
void DropHoles(DepthImage* depth, double fraction, Rng& rng);

}  // namespace posefilter::synth
