// posefilter/metrics.h — pose-error metrics against ground truth (docs/DATASETS.md, "Metrics").
//
// All poses map object → camera (x_cam = T·x_obj); model points are in the object frame,
// metres. Errors are returned in metres / degrees; the CLI prints millimetres.
//   ADD   (Hinterstoisser et al. 2012): mean_p ‖T_est·p − T_gt·p‖.
//   ADD-S (symmetric objects):          mean_p min_q ‖T_gt·p − T_est·q‖.
// A pose is accepted ("ok") when its error is below threshold·diameter (the reported recall
// uses 10 %).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "posefilter/mesh.h"

namespace posefilter {

// ADD, metres: mean over the points of ‖T_est·p − T_gt·p‖. Throws Error on an empty point set.
double AddError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                const Eigen::Isometry3d& T_gt);

// ADD-S, metres: mean over the ground-truth points T_gt·p of the distance to the closest
// estimated point T_est·q. Exact nearest neighbours through a k-d tree (O(N log N) build,
// ~O(log N) per query). Always ≤ AddError for the same inputs. Throws Error on an empty set.
double AddSError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                 const Eigen::Isometry3d& T_gt);

// Angle of the relative rotation R_est^T·R_gt, degrees in [0, 180]
// (θ = atan2(‖vee(R − Rᵀ)‖/2, (tr R − 1)/2), accurate near 0 and 180°).
double RotationErrorDeg(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_gt);

// ‖t_est − t_gt‖, metres.
double TranslationError(const Eigen::Vector3d& t_est, const Eigen::Vector3d& t_gt);

struct PoseErrors {
  double add = 0;       // ADD, metres
  double adds = 0;      // ADD-S, metres
  double rot_deg = 0;   // rotation error, degrees
  double trans_m = 0;   // translation error, metres
  double diameter = 0;  // object diameter used for the thresholds, metres
  bool add_ok = false;   // add  < threshold·diameter
  bool adds_ok = false;  // adds < threshold·diameter
};

// All errors of one estimate. diameter (metres) must be finite and > 0, threshold (fraction of
// the diameter, default 0.1 = 10 %) finite and > 0, the poses finite; otherwise throws Error.
PoseErrors ComputePoseErrors(const std::vector<Eigen::Vector3f>& pts, double diameter,
                             const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_gt,
                             double threshold = 0.1);

// Deterministic point set for the metrics: the mesh's vertices, every k-th one with the stride
// k = ⌈V / max_points⌉ (so ≤ max_points points, all of them when V ≤ max_points).
// Throws Error (naming the mesh) when it has no vertices or max_points < 1.
std::vector<Eigen::Vector3f> SamplePoints(const Mesh& mesh, int max_points = 2000);

// Reads an "x y z" per line point file (metres, as $POSEFILTER_DATA/ycbv/models/points/*.xyz).
// Blank lines are skipped. Throws Error naming the file (and the 1-based line) when the file is
// missing, a line does not hold exactly three numbers, a value is NaN/inf, or there are no points.
std::vector<Eigen::Vector3f> ReadXyzPoints(const std::string& path);

}  // namespace posefilter
