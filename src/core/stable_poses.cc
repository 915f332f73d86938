// core/stable_poses.cc — convex hull (Debian's libqhull_r), centre of mass, and the stable
// resting poses of a rigid object with their probabilities (stable_poses.h).
#include "posefilter/stable_poses.h"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>

#include "core/option_check.h"
#include "core/plane_fit.h"
#include "posefilter/error.h"

namespace posefilter {
namespace {

// Vertices of a convex polygon (indices into `pts`) in the plane with unit normal n, sorted
// counter-clockwise seen from the side n points to.
std::vector<int> SortPolygon(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& ids,
                             const Eigen::Vector3d& n) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int i : ids) centre += pts[std::size_t(i)];
  centre /= double(ids.size());
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  std::vector<std::pair<double, int>> by_angle;
  for (int i : ids) {
    const Eigen::Vector3d d = pts[std::size_t(i)] - centre;
    by_angle.push_back({std::atan2(d.dot(e2), d.dot(e1)), i});
  }
  std::sort(by_angle.begin(), by_angle.end());
  std::vector<int> out;
  for (const auto& [a, i] : by_angle) out.push_back(i);
  return out;
}

// Signed distance of p beyond the edge a→b of a CCW polygon with normal n (> 0: outside).
double BeyondEdge(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& n) {
  const Eigen::Vector3d edge = b - a;
  const Eigen::Vector3d out = edge.cross(n);  // outward in-plane normal of a CCW edge
  const double len = out.norm();
  return len > 0 ? (p - a).dot(out) / len : 0.0;
}

}  // namespace

ConvexHull ComputeConvexHull(const std::vector<Eigen::Vector3d>& points, const std::string& what) {
  if (points.size() < 4) throw Error(what + ": a convex hull needs at least 4 points (got " + std::to_string(points.size()) + ")");
  std::vector<coordT> coords;
  coords.reserve(points.size() * 3);
  for (const auto& p : points) {
    if (!p.allFinite()) throw Error(what + ": a point is not finite");
    coords.insert(coords.end(), {p.x(), p.y(), p.z()});
  }
  // A flat or degenerate point set (a plane, a line, one point) has no volume: said plainly,
  // before qhull would (its precision errors name facets, not the cause). Flat means every point
  // lies within 1e-6 of the largest extent from the least-squares plane (or line) through them.
  {
    const LeastSquaresPlane fit = FitLeastSquaresPlane(points);
    double thickness = 0, extent = 0;
    for (const auto& p : points) {
      thickness = std::max(thickness, std::abs((p - fit.centroid).dot(fit.normal)));
      extent = std::max(extent, (p - fit.centroid).norm());
    }
    if (!(thickness > 1e-6 * extent)) {
      char size[96];
      std::snprintf(size, sizeof size, "%.3g m across, %.3g m thick", 2 * extent, 2 * thickness);
      throw Error(what + ": flat: every vertex lies in one plane (" + size +
                  "), so it has no volume; stable poses and the support-plane features need a solid mesh");
    }
  }
  // qhull reports errors on a stream: an in-memory one, so its message can name `what`.
  char* err_text = nullptr;
  std::size_t err_size = 0;
  FILE* err = open_memstream(&err_text, &err_size);
  qhT qh_storage;
  qhT* qh = &qh_storage;
  qh_zero(qh, err);
  // Default options: coplanar facets are merged (C-0), so a box has 6 faces, not 12.
  char options[] = "qhull";
  const int code = qh_new_qhull(qh, 3, int(points.size()), coords.data(), False, options, nullptr, err);
  ConvexHull hull;
  if (code == 0) {
    std::map<int, int> index;  // qhull point id → hull vertex index
    vertexT* vertex;
    FORALLvertices {
      const int id = qh_pointid(qh, vertex->point);
      index[id] = int(hull.vertices.size());
      hull.vertices.push_back(points[std::size_t(id)]);
    }
    facetT* facet;
    FORALLfacets {
      ConvexHull::Face f;
      f.normal = Eigen::Vector3d(facet->normal[0], facet->normal[1], facet->normal[2]);
      f.offset = facet->offset;
      vertexT **vertexp;
      std::vector<int> ids;
      FOREACHvertex_(facet->vertices) ids.push_back(index[qh_pointid(qh, vertex->point)]);
      f.polygon = SortPolygon(hull.vertices, ids, f.normal);
      hull.faces.push_back(std::move(f));
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  std::fclose(err);
  std::string message(err_text ? err_text : "");
  std::free(err_text);
  if (code != 0) {
    const auto eol = message.find('\n', message.find_first_not_of('\n'));
    throw Error(what + ": no convex hull (the points span no volume?)" +
                (message.empty() ? "" : ": qhull: " + message.substr(0, std::min<std::size_t>(eol, 160))));
  }
  // Areas, volume and centroid: fans of triangles from each face's first vertex, tetrahedra
  // from an interior point (the mean of the hull vertices).
  Eigen::Vector3d inner = Eigen::Vector3d::Zero();
  for (const auto& v : hull.vertices) inner += v;
  inner /= double(hull.vertices.size());
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (auto& f : hull.faces) {
    const Eigen::Vector3d& a = hull.vertices[std::size_t(f.polygon[0])];
    for (std::size_t k = 1; k + 1 < f.polygon.size(); ++k) {
      const Eigen::Vector3d& b = hull.vertices[std::size_t(f.polygon[k])];
      const Eigen::Vector3d& c = hull.vertices[std::size_t(f.polygon[k + 1])];
      f.area += 0.5 * (b - a).cross(c - a).norm();
      const double vol = std::fabs((a - inner).dot((b - inner).cross(c - inner))) / 6.0;
      hull.volume += vol;
      moment += vol * (inner + a + b + c) / 4.0;
    }
  }
  if (!(hull.volume > 0)) throw Error(what + ": the convex hull has no volume");
  hull.centroid = moment / hull.volume;
  return hull;
}

namespace {

std::vector<Eigen::Vector3d> Points(const Mesh& mesh) {
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) pts.push_back(v.cast<double>());
  return pts;
}

// CentreOfMass with the mesh's hull already computed. Signed tetrahedra from the hull's
// centroid r (inside the object): the sum is the enclosed volume for a closed surface
// wherever r is, and stays small for an open one.
Eigen::Vector3d CentreOfMass(const Mesh& mesh, const ConvexHull& hull) {
  const std::vector<Eigen::Vector3d> pts = Points(mesh);
  const Eigen::Vector3d r = hull.centroid;
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = pts[f[0]] - r, b = pts[f[1]] - r, c = pts[f[2]] - r;
    const double v = a.dot(b.cross(c)) / 6.0;
    volume += v;
    moment += v * (a + b + c) / 4.0;
  }
  // Inverted winding flips both sums, so |volume| is what tells a closed surface.
  if (std::fabs(volume) >= 0.25 * hull.volume) return r + moment / volume;
  return hull.centroid;
}

// Solid angle of triangle (a, b, c) seen from the origin, steradians (Van Oosterom and
// Strackee 1983).
double SolidAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double num = std::fabs(a.dot(b.cross(c)));
  const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2 * std::atan2(num, den);
}

}  // namespace

Eigen::Vector3d CentreOfMass(const Mesh& mesh) {
  return CentreOfMass(mesh, ComputeConvexHull(Points(mesh), "mesh '" + mesh.name + "'"));
}

bool StablePoseOptions::IsValid(std::string* why) const {
  if (!(min_probability >= 0 && min_probability < 1)) return Fail(why, "min_probability must be in [0, 1)");
  return true;
}

std::vector<StablePose> ComputeStablePoses(const Mesh& mesh, const StablePoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw Error("stable poses: " + why);
  if (!mesh.IsValid(&why)) throw Error("mesh '" + mesh.name + "': " + why);
  const ConvexHull hull = ComputeConvexHull(Points(mesh), "mesh '" + mesh.name + "'");
  const Eigen::Vector3d com = CentreOfMass(mesh, hull);
  const int F = int(hull.faces.size());

  // Per face: height of the centre of mass above it, the foot of the perpendicular, and the
  // edge it lies furthest beyond (−1: inside, the face is stable).
  std::vector<double> height(F);
  std::vector<int> tip_edge(F, -1);
  for (int f = 0; f < F; ++f) {
    const ConvexHull::Face& face = hull.faces[std::size_t(f)];
    height[f] = -(face.normal.dot(com) + face.offset);
    const Eigen::Vector3d foot = com + height[f] * face.normal;
    double worst = 0;
    const int m = int(face.polygon.size());
    for (int k = 0; k < m; ++k) {
      const double beyond = BeyondEdge(foot, hull.vertices[std::size_t(face.polygon[k])],
                                       hull.vertices[std::size_t(face.polygon[(k + 1) % m])], face.normal);
      if (beyond > worst) worst = beyond, tip_edge[f] = k;
    }
  }
  // The face across each edge: faces indexed by their edges' vertex pairs.
  std::map<std::pair<int, int>, std::vector<int>> by_edge;
  for (int f = 0; f < F; ++f) {
    const auto& poly = hull.faces[std::size_t(f)].polygon;
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const int a = poly[k], b = poly[(k + 1) % poly.size()];
      by_edge[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  }
  auto across = [&](int f, int k) {
    const auto& poly = hull.faces[std::size_t(f)].polygon;
    const int a = poly[std::size_t(k)], b = poly[std::size_t((k + 1) % int(poly.size()))];
    for (int g : by_edge[{std::min(a, b), std::max(a, b)}])
      if (g != f) return g;
    return -1;
  };
  // Where each face drains: tipping lowers the centre of mass strictly, so the walk ends at a
  // stable face (the step limit only guards against rounding).
  std::vector<int> rest(F, -1);
  for (int f = 0; f < F; ++f) {
    int g = f;
    for (int step = 0; step < F && tip_edge[g] >= 0; ++step) {
      const int next = across(g, tip_edge[g]);
      if (next < 0 || height[next] >= height[g]) break;
      g = next;
    }
    rest[f] = g;
  }
  // A drop in a uniformly random orientation first lands on the face its downward ray from
  // the centre of mass leaves the hull through: with the probability of the face's solid
  // angle seen from the centre of mass (its capture region), over 4π. Faces add theirs to
  // the stable face they drain to.
  std::vector<double> mass(F, 0.0);
  for (int f = 0; f < F; ++f) {
    const auto& poly = hull.faces[std::size_t(f)].polygon;
    const Eigen::Vector3d a = hull.vertices[std::size_t(poly[0])] - com;
    double omega = 0;
    for (std::size_t k = 1; k + 1 < poly.size(); ++k)
      omega += SolidAngle(a, hull.vertices[std::size_t(poly[k])] - com, hull.vertices[std::size_t(poly[k + 1])] - com);
    mass[std::size_t(rest[f])] += omega / (4 * M_PI);
  }
  std::vector<StablePose> poses;
  double kept = 0;
  for (int f = 0; f < F; ++f)
    if (mass[f] > 0 && mass[f] >= options.min_probability) kept += mass[f];
  for (int f = 0; f < F; ++f) {
    if (!(mass[f] > 0) || mass[f] < options.min_probability) continue;
    const ConvexHull::Face& face = hull.faces[std::size_t(f)];
    StablePose p;
    p.face = f;
    p.probability = mass[f] / kept;
    p.com_height_m = height[f];
    // Resting face normal → table −z; the foot of the centre of mass → table origin.
    const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(face.normal, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d foot = com + height[f] * face.normal;
    p.T_table_obj.linear() = R;
    p.T_table_obj.translation() = -R * foot;
    poses.push_back(p);
  }
  std::stable_sort(poses.begin(), poses.end(), [](const StablePose& a, const StablePose& b) { return a.probability > b.probability; });
  return poses;
}

}  // namespace posefilter
