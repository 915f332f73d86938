// src/core/plane_fit.h — the least-squares plane through a set of 3D points: their centroid
// and the eigenvector of the smallest eigenvalue of their scatter matrix Σ (p − c)(p − c)ᵀ.
// Used by the support plane's refit (src/prior/support_plane.cc) and the flatness check of the
// convex hull (src/core/stable_poses.cc).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace posefilter {

struct LeastSquaresPlane {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // same units as the points
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // unit; its sign is arbitrary
};

// `pts` must not be empty.
inline LeastSquaresPlane FitLeastSquaresPlane(const std::vector<Eigen::Vector3d>& pts) {
  LeastSquaresPlane plane;
  for (const auto& p : pts) plane.centroid += p;
  plane.centroid /= double(pts.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) scatter += (p - plane.centroid) * (p - plane.centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(scatter);
  plane.normal = es.eigenvectors().col(0).normalized();  // eigenvalues ascending: the least spread
  return plane;
}

}  // namespace posefilter
