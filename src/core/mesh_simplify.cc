// core/mesh_simplify.cc — level of detail with meshoptimizer (Debian libmeshoptimizer):
// weld → edge-collapse simplification (sloppy clustering as the fallback) → compaction, and the
// measured one-sided Hausdorff distance of the result.
#include "posefilter/mesh_simplify.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/option_check.h"
#include "posefilter/error.h"

namespace posefilter {

namespace {

// Input vertices measured for SimplifyReport::max_distance_m at most (above: an even stride).
constexpr std::size_t kDistanceSampleVertices = 4096;

// Closest distance from p to triangle (a, b, c), metres: the point is projected onto the
// triangle's plane and, when that falls outside, onto the nearest edge segment (Voronoi regions
// of the vertices, edges and face, tested in barycentric form).
double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.norm();  // vertex a
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.norm();  // vertex b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + ab * (d1 / (d1 - d3)))).norm();  // edge ab
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.norm();  // vertex c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + ac * (d2 / (d2 - d6)))).norm();  // edge ac
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)  // edge bc
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  const double denom = va + vb + vc;
  if (!(denom > 0)) {  // degenerate (zero-area) triangle: nearest of its three edges' ends
    return std::min({ap.norm(), bp.norm(), cp.norm()});
  }
  const double v = vb / denom, w = vc / denom;
  return (p - (a + ab * v + ac * w)).norm();  // inside the face
}

// Largest distance from (a subsample of) `points` to the surface of `mesh`, metres.
double MaxDistanceToSurface(const std::vector<Eigen::Vector3f>& points, const Mesh& mesh) {
  const std::size_t n = points.size();
  const std::size_t keep = std::min(n, kDistanceSampleVertices);
  double worst = 0;
  for (std::size_t k = 0; k < keep; ++k) {
    const Eigen::Vector3d p = points[(std::uint64_t(k) * n) / keep].cast<double>();
    double best = std::numeric_limits<double>::infinity();
    for (const auto& f : mesh.faces) {
      best = std::min(best, PointTriangleDistance(p, mesh.vertices[f[0]].cast<double>(),
                                                  mesh.vertices[f[1]].cast<double>(),
                                                  mesh.vertices[f[2]].cast<double>()));
      if (best == 0) break;
    }
    worst = std::max(worst, best);
  }
  return worst;
}

}  // namespace

bool SimplifyOptions::IsValid(std::string* why) const {
  if (!(max_relative_error > 0 && max_relative_error <= 1)) return Fail(why, "max_relative_error must be in (0, 1]");
  return true;
}

Mesh SimplifyMesh(const Mesh& mesh, int max_faces, const SimplifyOptions& options, SimplifyReport* report) {
  const std::string what = "SimplifyMesh: mesh '" + mesh.name + "'";
  std::string why;
  if (max_faces < kMinSimplifyFaces)
    throw Error(what + ": max_faces must be >= " + std::to_string(kMinSimplifyFaces) + " (got " +
                std::to_string(max_faces) + ")");
  if (!options.IsValid(&why)) throw Error(what + ": invalid option: " + why);
  if (!mesh.IsValid(&why)) throw Error(what + ": " + why);

  SimplifyReport rep;
  rep.faces_in = int(mesh.faces.size());
  rep.vertices_in = int(mesh.vertices.size());
  if (mesh.faces.size() <= std::size_t(max_faces)) {
    rep.faces_out = rep.faces_in;
    rep.vertices_out = rep.vertices_in;
    rep.unchanged = true;
    if (report != nullptr) *report = rep;
    return mesh;
  }

  // Flat buffers for meshoptimizer: positions (x, y, z floats, stride 12 bytes) and indices.
  const std::size_t nv = mesh.vertices.size(), ni = 3 * mesh.faces.size();
  std::vector<float> positions(3 * nv);
  for (std::size_t i = 0; i < nv; ++i)
    for (int a = 0; a < 3; ++a) positions[3 * i + a] = mesh.vertices[i][a];
  std::vector<unsigned int> indices(ni);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int a = 0; a < 3; ++a) indices[3 * f + a] = mesh.faces[f][a];

  // Weld vertices with identical positions: the simplifier only collapses edges it sees as
  // shared, so a mesh with per-face vertices would otherwise fall apart at every edge.
  std::vector<unsigned int> remap(nv);
  const std::size_t nw =
      meshopt_generateVertexRemap(remap.data(), indices.data(), ni, positions.data(), nv, 3 * sizeof(float));
  std::vector<float> welded(3 * nw);
  meshopt_remapVertexBuffer(welded.data(), positions.data(), nv, 3 * sizeof(float), remap.data());
  meshopt_remapIndexBuffer(indices.data(), indices.data(), ni, remap.data());

  // Edge collapse within the error bound, then (if allowed) sloppy clustering to the budget.
  const std::size_t target = 3 * std::size_t(max_faces);
  std::vector<unsigned int> out(ni);  // worst case: all indices (meshoptimizer's contract)
  float rel_error = 0;
  std::size_t no = meshopt_simplify(out.data(), indices.data(), ni, welded.data(), nw, 3 * sizeof(float), target,
                                    float(options.max_relative_error), 0, &rel_error);
  if (no > target) {
    if (!options.allow_sloppy)
      throw Error(what + ": cannot reach " + std::to_string(max_faces) + " faces within max_relative_error " +
                  std::to_string(options.max_relative_error) + " without the sloppy pass (reached " +
                  std::to_string(no / 3) + ")");
    no = meshopt_simplifySloppy(out.data(), indices.data(), ni, welded.data(), nw, 3 * sizeof(float), target, FLT_MAX,
                                &rel_error);
    rep.sloppy = true;
  }
  out.resize(no);

  // Keep the non-degenerate triangles and only the vertices they use (in input order).
  Mesh result;
  result.name = mesh.name;
  std::vector<std::uint32_t> new_index(nw, std::numeric_limits<std::uint32_t>::max());
  std::vector<char> used(nw, 0);
  for (std::size_t i = 0; i + 2 < out.size(); i += 3) {
    const unsigned int a = out[i], b = out[i + 1], c = out[i + 2];
    if (a == b || b == c || a == c) continue;
    used[a] = used[b] = used[c] = 1;
  }
  for (std::size_t v = 0; v < nw; ++v) {
    if (!used[v]) continue;
    new_index[v] = std::uint32_t(result.vertices.size());
    result.vertices.emplace_back(welded[3 * v], welded[3 * v + 1], welded[3 * v + 2]);
  }
  for (std::size_t i = 0; i + 2 < out.size(); i += 3) {
    const unsigned int a = out[i], b = out[i + 1], c = out[i + 2];
    if (a == b || b == c || a == c) continue;
    result.faces.push_back({new_index[a], new_index[b], new_index[c]});
  }
  if (result.faces.empty() || result.faces.size() > std::size_t(max_faces))
    throw Error(what + ": simplification to " + std::to_string(max_faces) + " faces failed (got " +
                std::to_string(result.faces.size()) + ")");

  rep.faces_out = int(result.faces.size());
  rep.vertices_out = int(result.vertices.size());
  rep.error_m = double(rel_error) * meshopt_simplifyScale(welded.data(), nw, 3 * sizeof(float));
  if (report != nullptr) {
    rep.max_distance_m = MaxDistanceToSurface(mesh.vertices, result);
    *report = rep;
  }
  return result;
}

const Mesh& MeshAtLod(const Mesh& mesh, int max_faces, Mesh* storage) {
  if (max_faces < kMinSimplifyFaces || mesh.faces.size() <= std::size_t(max_faces) || !mesh.IsValid(nullptr))
    return mesh;
  *storage = SimplifyMesh(mesh, max_faces);
  return *storage;
}

}  // namespace posefilter
