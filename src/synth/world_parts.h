// src/synth/world_parts.h — pieces the YCB worlds share (internal): 2-D footprints, stable-pose
// draws, the structured-light sensor model, noisy masks and jittered boxes. Implemented in
// table_world.cc; the room world (room_world.cc) uses them as the table world does.
//
// Frames and units: metres, radians, pixels; footprints in the frame of the surface the
// objects rest on (z up); depth images hold camera z (0 = missing).
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/rng.h"
#include "posefilter/stable_poses.h"
#include "posefilter/table_world.h"

namespace posefilter::synth {

// The canvas margin, px, around the image on which each object's full silhouette is rendered
// (the part the image border cuts off counts as hidden).
inline constexpr int kPad = 400;

// Convex hull of 2-D points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d> pts);
// True when the convex polygons a and b are at least `gap` (metres) apart along one of their
// edge normals (separating axis test; a conservative stand-in for the Euclidean gap).
bool Separated(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double gap);
std::vector<Eigen::Vector2d> Shifted(const std::vector<Eigen::Vector2d>& p, const Eigen::Vector2d& d);
// A stable pose index drawn by the poses' probabilities.
int DrawPose(const std::vector<StablePose>& poses, Rng& rng);
// SensorModel on the clean depth: `labels` (0 background, i + 1 object i) of the num_objects
// objects (material patches), `meshes`/`poses` (object → camera) every rendered surface (the
// projector's view). Draws from `rng` in a fixed order.
DepthImage ApplySensor(const DepthImage& clean, const std::vector<int>& labels, int num_objects,
                       const std::vector<const Mesh*>& meshes, const std::vector<Eigen::Isometry3d>& poses,
                       const Camera& cam, const SensorModel& s, Rng& rng);
// The visible pixels of `label` with the outline moved by `shift` pixels (> 0 out) and ragged.
std::vector<std::uint8_t> NoisyMask(const std::vector<int>& labels, int label, int W, int H, int shift, Rng& rng);
// b0 with centre and size noise N(0, sigma²) px (centre noise clamped to a quarter of the box),
// size scaled by `scale`.
Box JitterBox(const Box& b0, double sigma, double scale, Rng& rng);
Detection ToDetection(const std::string& cls, double score, const Box& b);

}  // namespace posefilter::synth
