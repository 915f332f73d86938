// core/mesh.cc — mesh validation, bounds and diameter (its files: src/io/mesh_io.cc).
#include "posefilter/mesh.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/option_check.h"

namespace posefilter {

namespace {

// Vertex count up to which Diameter() is exact (O(V²) pairs: 4096² / 2 ≈ 8.4 M distances).
constexpr size_t kDiameterExactVertices = 4096;

// Deterministic subsample of `n_keep` vertex indices out of `v.size()`: first the extreme
// vertices along 13 directions (axes, face diagonals, space diagonals; both ends), which hold
// the diameter's end points for most real objects, then an even stride through the rest.
std::vector<size_t> DiameterSubsample(const std::vector<Eigen::Vector3f>& v, size_t n_keep) {
  static constexpr float kDirs[13][3] = {
      {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1},
      {0, 1, 1}, {0, 1, -1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};
  std::vector<char> taken(v.size(), 0);
  std::vector<size_t> keep;
  keep.reserve(n_keep);
  for (const auto& d : kDirs) {
    const Eigen::Vector3f dir(d[0], d[1], d[2]);
    size_t lo = 0, hi = 0;
    for (size_t i = 1; i < v.size(); ++i) {
      const float p = v[i].dot(dir);
      if (p < v[lo].dot(dir)) lo = i;
      if (p > v[hi].dot(dir)) hi = i;
    }
    for (size_t i : {lo, hi}) {
      if (!taken[i]) {
        taken[i] = 1;
        keep.push_back(i);
      }
    }
  }
  const size_t remaining = n_keep - keep.size();
  for (size_t k = 0; k < remaining; ++k) {
    // k < 4096, so k·n fits in 64 bits for any mesh that fits in memory.
    size_t i = static_cast<size_t>((std::uint64_t(k) * v.size()) / remaining);
    // Step past indices already taken (at most 26 of them), wrapping around.
    while (taken[i]) i = (i + 1) % v.size();
    taken[i] = 1;
    keep.push_back(i);
  }
  return keep;
}

}  // namespace

bool Mesh::IsValid(std::string* why) const {
  if (vertices.empty()) return Fail(why, "mesh has no vertices");
  if (faces.empty()) return Fail(why, "mesh has no faces");
  for (size_t i = 0; i < vertices.size(); ++i) {
    if (!vertices[i].allFinite()) {
      return Fail(why, "vertex " + std::to_string(i) + " has a non-finite coordinate");
    }
    if (vertices[i].cwiseAbs().maxCoeff() > kMaxCoordinate) {
      return Fail(why, "vertex " + std::to_string(i) + " lies " + std::to_string(vertices[i].cwiseAbs().maxCoeff()) +
                           " from the origin, beyond the +-" + std::to_string(int(kMaxCoordinate)) +
                           " of any object (wrong unit scale?)");
    }
  }
  bool any_area = false;
  for (size_t f = 0; f < faces.size(); ++f) {
    for (std::uint32_t idx : faces[f]) {
      if (idx >= vertices.size()) {
        return Fail(why, "face " + std::to_string(f) + " indexes vertex " + std::to_string(idx) + " but the mesh has " +
                             std::to_string(vertices.size()) + " vertices");
      }
    }
    if (!any_area) {
      const Eigen::Vector3d a = vertices[faces[f][0]].cast<double>(), b = vertices[faces[f][1]].cast<double>(),
                            c = vertices[faces[f][2]].cast<double>();
      any_area = (b - a).cross(c - a).norm() > 0;
    }
  }
  if (!any_area) return Fail(why, "every face is degenerate (zero area): nothing to render");
  return true;
}

double Mesh::Diameter() const {
  const size_t n = vertices.size();
  if (n < 2) return 0.0;
  // Coordinates in double so that the squared distances of metre-scale meshes are exact enough.
  std::vector<Eigen::Vector3d> p;
  if (n <= kDiameterExactVertices) {
    p.reserve(n);
    for (const auto& v : vertices) p.push_back(v.cast<double>());
  } else {
    for (size_t i : DiameterSubsample(vertices, kDiameterExactVertices)) {
      p.push_back(vertices[i].cast<double>());
    }
  }
  // Plain arrays and scalar arithmetic (the same sums as Eigen's squaredNorm, in the same order):
  // this O(n²) loop runs at full speed in builds that do not inline Eigen (the sanitizers').
  const size_t m = p.size();
  std::vector<double> x(m), y(m), z(m);
  for (size_t i = 0; i < m; ++i) x[i] = p[i].x(), y[i] = p[i].y(), z[i] = p[i].z();
  double best = 0.0;
  for (size_t i = 0; i < m; ++i) {
    const double xi = x[i], yi = y[i], zi = z[i];
    for (size_t j = i + 1; j < m; ++j) {
      const double dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (d2 > best) best = d2;
    }
  }
  return std::sqrt(best);
}

Eigen::Vector3f Mesh::Min() const {
  if (vertices.empty()) return Eigen::Vector3f::Zero();
  Eigen::Vector3f m = vertices.front();
  for (const auto& v : vertices) m = m.cwiseMin(v);
  return m;
}

Eigen::Vector3f Mesh::Max() const {
  if (vertices.empty()) return Eigen::Vector3f::Zero();
  Eigen::Vector3f m = vertices.front();
  for (const auto& v : vertices) m = m.cwiseMax(v);
  return m;
}

}  // namespace posefilter
