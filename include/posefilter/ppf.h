// posefilter/ppf.h — pose proposals by point-pair-feature voting (Drost et al. 2010), the
// pose half of the detector-free stage 1 (`--prior auto`, posefilter/auto_prior.h).
//
// Method (docs/ALGORITHM.md, "No detector"):
//   Model (once per mesh, cached on disk): points sampled on the mesh's faces by area, one
//   point per voxel of side step = distance_step · diameter and per normal direction in it
//   (normals more than 30° apart stay separate points: both sides of a thin wall). For every
//   ordered pair (m_r, m_i) the feature
//     F = (‖d‖, ∠(n_r, d), ∠(n_i, d), ∠(n_r, n_i)),  d = m_i − m_r,
//   quantised to (⌊‖d‖ / step⌋, angle bins of π / angle_bins), keys a table entry
//   (r, α_m) (at most max_bucket entries per key, an even stride through the pairs): α_m is the angle about the x axis that brings m_i into the half-plane
//   {y > 0, z = 0} once m_r is moved to the origin and n_r turned onto the x axis (T_m).
//   Scene: the pixels of one candidate region back-projected, averaged per voxel of the same
//   step (position and normal; voxels whose normals disagree are dropped). Every
//   reference_stride-th point s_r pairs with every scene point within the model's diameter;
//   each model entry with the pair's key votes for (r, α = α_m − α_s) in s_r's accumulator
//   (alpha_bins bins over 2π; α_s is rounded to the entries' 2π / 65536 and the difference
//   wraps on that 16-bit circle, so a vote is a subtract, a multiply and a shift). Each
//   accumulator's peak is a pose
//     T_cam_obj = T_s⁻¹ · R_x(−α) · T_m,
//   and poses within cluster_translation · diameter and cluster_rotation_rad of a higher-voted
//   one join its cluster; clusters are ranked by summed votes.
// Units: metres, radians; the model is in the object frame, scene points in the camera frame.
// Deterministic: the model's surface samples come from a fixed seed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"

namespace posefilter {

struct PpfOptions {
  double distance_step = 0.05;     // voxel side and distance bin, fraction of the diameter, (0, 0.5]
  int angle_bins = 15;             // bins of each feature angle over [0, π] (12°), [4, 64]
  // Entries kept per key (an even stride through a fuller one), ≥ 1: the pairs of one flat
  // face all share a few keys, whose thousands of entries say little and cost most votes.
  int max_bucket = 512;
  int alpha_bins = 30;             // bins of α over 2π (12°), [4, 256]
  int reference_stride = 5;        // every n-th scene point is a reference point, ≥ 1
  double cluster_translation = 0.1;   // clustering: fraction of the diameter, > 0
  double cluster_rotation_rad = 0.5236;  // clustering: 30°, > 0
  int max_proposals = 4;           // clusters returned per MatchPpf call, ≥ 1
  // Clusters with fewer than this fraction of the best cluster's votes are not returned, (0, 1].
  double min_relative_votes = 0.3;
  int threads = 0;                 // voting workers (0 = all cores); the result does not depend on it
  bool IsValid(std::string* why) const;
};

// A point on a surface with its outward unit normal.
struct OrientedPoint {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();
  Eigen::Vector3f n = Eigen::Vector3f::UnitZ();
};

// One model pair of the hash table: reference point index and its α_m, quantised:
// α_m = −π + alpha · 2π / 65536 (radians).
struct PpfEntry {
  std::uint16_t reference = 0;
  std::uint16_t alpha = 0;
};

// The hashed model of one mesh.
struct PpfModel {
  std::uint64_t mesh_hash = 0;     // MeshContentHash of the mesh it was built from
  double diameter = 0;             // metres
  double step = 0;                 // distance_step · diameter, metres
  int angle_bins = 0, distance_bins = 0;
  std::vector<OrientedPoint> points;   // object frame, at most kMaxPoints
  static constexpr std::size_t kMaxPoints = 2048;
  // Key k's entries are entries[offsets[k] .. offsets[k + 1]); KeyCount() + 1 offsets.
  std::vector<std::uint32_t> offsets;
  std::vector<PpfEntry> entries;

  int KeyCount() const { return distance_bins * angle_bins * angle_bins * angle_bins; }
  // The quantised feature of the pair (a, b): its key, or −1 when ‖d‖ is outside the table
  // (beyond the diameter, or the two points coincide).
  int Key(const OrientedPoint& a, const OrientedPoint& b) const;
};

// A 64-bit FNV-1a hash of the mesh's vertices and faces (bytes as stored): a changed mesh
// gets another hash, so its cached model is not reused.
std::uint64_t MeshContentHash(const Mesh& mesh);

// Builds the model (the mesh must be valid; throws Error naming the mesh otherwise).
PpfModel BuildPpfModel(const Mesh& mesh, const PpfOptions& opt = {});

// The cache folder: $POSEFILTER_CACHE_DIR, else $XDG_CACHE_HOME/posefilter, else
// $HOME/.cache/posefilter; "" when none is set (no cache).
std::string DefaultPpfCacheDir();

// The model of `mesh`, from `cache_dir` when a cached model for this mesh (content hash) and
// these options is there and whole; otherwise built and written there (the folder is made;
// the write is atomic). A cache file that cannot be read, is cut short, fails its checksum or
// was made from another mesh or other options is rebuilt and overwritten, never trusted.
// `cache_dir` "" = no cache. `status` (optional) receives "loaded", "built" or
// "rebuilt (<why>)"; a cache folder that cannot be written is not an error: the model is
// returned, and `status` says "built (cache not written: <why>)".
PpfModel LoadOrBuildPpfModel(const Mesh& mesh, const PpfOptions& opt, const std::string& cache_dir,
                             std::string* status = nullptr);
// The cache file's path for this mesh and these options.
std::string PpfCachePath(const Mesh& mesh, const PpfOptions& opt, const std::string& cache_dir);

// Scene points of the pixels where `pixel_mask` (width × height, non-zero = use) is set:
// back-projected (camera frame), averaged per voxel of side `step` metres, with the voxel's
// mean normal (from the depth image's per-pixel normals, facing the camera); voxels whose
// normals disagree (mean normal shorter than 0.6) or with fewer than 3 normals are dropped.
std::vector<OrientedPoint> PpfScenePoints(const DepthImage& depth, const Camera& camera,
                                          const std::vector<std::uint8_t>& pixel_mask, double step);
// The same with the image's normals already computed (ComputeSceneNormals, posefilter/render.h:
// 3 floats per pixel), for several masks of one image.
std::vector<OrientedPoint> PpfScenePoints(const DepthImage& depth, const Camera& camera,
                                          const std::vector<float>& normals,
                                          const std::vector<std::uint8_t>& pixel_mask, double step);

// A pose proposal: object → camera, and its cluster's summed votes.
struct PoseProposal {
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();
  double votes = 0;
};

// Votes with the scene points and returns the best clusters, most votes first (at most
// opt.max_proposals, each with ≥ opt.min_relative_votes of the best's votes). Empty when
// the scene has fewer than 3 points. Votes are no verification: a pose that differs from the
// true one only in parts the camera cannot see (a part turned to the hidden side) can win;
// the filter's weight, which renders each pose against the depth, tells them apart.
std::vector<PoseProposal> MatchPpf(const PpfModel& model, const std::vector<OrientedPoint>& scene,
                                   const PpfOptions& opt = {});

}  // namespace posefilter
