// Procedural meshes: closed, outward-facing, the right sizes and volumes; bad sizes rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "posefilter/error.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using Vec = Eigen::Vector3d;

Vec V(const Mesh& m, std::uint32_t i) { return m.vertices[i].cast<double>(); }

// Every directed edge appears exactly once and its reverse exactly once: a closed,
// consistently oriented 2-manifold.
void ExpectClosed(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k) ++edges[{f[k], f[(k + 1) % 3]}];
  for (const auto& [e, n] : edges) {
    ASSERT_EQ(n, 1) << m.name << ": directed edge " << e.first << "→" << e.second << " used " << n << " times";
    auto it = edges.find({e.second, e.first});
    ASSERT_TRUE(it != edges.end()) << m.name << ": edge " << e.first << "→" << e.second << " has no twin (hole)";
  }
}

double SignedVolume(const Mesh& m) {
  double v = 0;
  for (const auto& f : m.faces) v += V(m, f[0]).dot(V(m, f[1]).cross(V(m, f[2])));
  return v / 6;
}

// Parity of the crossings of a ray from p along a fixed, generic direction: true = inside.
bool Inside(const Mesh& m, const Vec& p) {
  const Vec dir = Vec(0.5773, 0.5832, 0.5714).normalized();
  int crossings = 0;
  for (const auto& f : m.faces) {  // Möller–Trumbore
    const Vec a = V(m, f[0]), e1 = V(m, f[1]) - a, e2 = V(m, f[2]) - a;
    const Vec h = dir.cross(e2);
    const double det = e1.dot(h);
    if (std::fabs(det) < 1e-15) continue;
    const Vec s = p - a;
    const double u = s.dot(h) / det;
    if (u < 0 || u > 1) continue;
    const Vec q = s.cross(e1);
    const double v = dir.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    if (e2.dot(q) / det > 0) ++crossings;
  }
  return crossings % 2 == 1;
}

// For every face: a point just in front of it (along its normal) is outside, a point just
// behind it is inside. Holds for non-convex meshes too.
void ExpectOutwardFaces(const Mesh& m, double eps) {
  int bad = 0;
  for (const auto& f : m.faces) {
    const Vec a = V(m, f[0]), b = V(m, f[1]), c = V(m, f[2]);
    const Vec n = (b - a).cross(c - a).normalized();
    const Vec centre = (a + b + c) / 3;
    if (Inside(m, centre + eps * n) || !Inside(m, centre - eps * n)) ++bad;
  }
  EXPECT_EQ(bad, 0) << m.name << ": faces facing inwards";
}

// Convex meshes: every face normal points away from the vertex centroid.
void ExpectConvexOutward(const Mesh& m) {
  Vec centroid = Vec::Zero();
  for (const auto& v : m.vertices) centroid += v.cast<double>();
  centroid /= double(m.vertices.size());
  for (const auto& f : m.faces) {
    const Vec a = V(m, f[0]), b = V(m, f[1]), c = V(m, f[2]);
    EXPECT_GT((b - a).cross(c - a).dot((a + b + c) / 3 - centroid), 0) << m.name;
  }
}

void ExpectBounds(const Mesh& m, double sx, double sy, double sz) {
  const Eigen::Vector3f lo = m.Min(), hi = m.Max();
  EXPECT_NEAR(hi.x() - lo.x(), sx, 1e-6) << m.name;
  EXPECT_NEAR(hi.y() - lo.y(), sy, 1e-6) << m.name;
  EXPECT_NEAR(hi.z() - lo.z(), sz, 1e-6) << m.name;
  EXPECT_LT((lo + hi).norm(), 1e-6) << m.name << ": not centred on its bounding box";
}

TEST(SynthShapes, BoxIsClosedOutwardAndSized) {
  const Mesh m = MakeBox(0.1, 0.2, 0.3);
  std::string why;
  EXPECT_TRUE(m.IsValid(&why)) << why;
  EXPECT_EQ(m.name, "box");
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.faces.size(), 12u);
  ExpectClosed(m);
  ExpectConvexOutward(m);
  ExpectBounds(m, 0.1, 0.2, 0.3);
  EXPECT_NEAR(SignedVolume(m), 0.1 * 0.2 * 0.3, 1e-9);
}

TEST(SynthShapes, CylinderIsClosedOutwardAndSized) {
  const Mesh m = MakeCylinder(0.05, 0.12, 32, "can");
  EXPECT_EQ(m.name, "can");
  EXPECT_EQ(m.vertices.size(), 66u);
  EXPECT_EQ(m.faces.size(), 128u);
  ExpectClosed(m);
  ExpectConvexOutward(m);
  ExpectBounds(m, 0.1, 0.1, 0.12);  // 32 segments: vertices at 0°, 90°, 180°, 270°
  EXPECT_NEAR(SignedVolume(m), 16 * 0.05 * 0.05 * std::sin(2 * M_PI / 32) * 0.12, 1e-9);
  // Odd segment count: still centred on its bounding box.
  const Mesh odd = MakeCylinder(0.05, 0.1, 7);
  ExpectClosed(odd);
  EXPECT_LT((odd.Min() + odd.Max()).norm(), 1e-6);
}

TEST(SynthShapes, LShapeIsClosedOutwardNonConvexAndSized) {
  const double s = 0.14, t = 0.05, d = 0.06;
  const Mesh m = MakeLShape(s, t, d);
  ExpectClosed(m);
  ExpectOutwardFaces(m, 1e-4);
  ExpectBounds(m, s, s, d);
  EXPECT_NEAR(SignedVolume(m), (s * s - (s - t) * (s - t)) * d, 1e-9);
  // Non-convex: the bounding-box corner opposite the legs is outside the L.
  EXPECT_FALSE(Inside(m, Vec(s / 2 - 0.01, s / 2 - 0.01, 0)));
  EXPECT_TRUE(Inside(m, Vec(-s / 2 + 0.01, -s / 2 + 0.01, 0)));
}

TEST(SynthShapes, TorusIsClosedOutwardAndSized) {
  const double R = 0.06, r = 0.025;
  const Mesh m = MakeTorus(R, r, 32, 32);
  EXPECT_EQ(m.faces.size(), 2048u);
  ExpectClosed(m);
  ExpectOutwardFaces(m, 1e-4);
  ExpectBounds(m, 2 * (R + r), 2 * (R + r), 2 * r * std::sin(2 * M_PI * 8 / 32));
  const double exact = 2 * M_PI * M_PI * R * r * r;
  EXPECT_GT(SignedVolume(m), 0.97 * exact);
  EXPECT_LT(SignedVolume(m), exact);  // inscribed polygons: a little less
  EXPECT_FALSE(Inside(m, Vec(0, 0, 0)));  // the hole
  EXPECT_TRUE(Inside(m, Vec(R, 0.001, 0.001)));
}

TEST(SynthShapes, MakeShapeKindsHaveDefaultSizes) {
  const auto kinds = SynthClassNames();
  ASSERT_EQ(kinds.size(), 4u);
  for (const auto& k : kinds) {
    const Mesh m = MakeShape(k);
    EXPECT_EQ(m.name, k);
    ExpectClosed(m);
    EXPECT_GT(SignedVolume(m), 0) << k;
    const Eigen::Vector3f ext = m.Max() - m.Min();
    EXPECT_GE(ext.maxCoeff(), 0.08f) << k;
    EXPECT_LE(ext.maxCoeff(), 0.20f) << k;
  }
}

TEST(SynthShapes, BadArgumentsThrow) {
  EXPECT_THROW(MakeBox(-0.1, 0.1, 0.1), Error);
  EXPECT_THROW(MakeBox(0.1, NAN, 0.1), Error);
  EXPECT_THROW(MakeCylinder(0.05, 0.1, 2), Error);
  EXPECT_THROW(MakeCylinder(0, 0.1), Error);
  EXPECT_THROW(MakeLShape(0.1, 0.1, 0.05), Error);  // thickness ≥ size
  EXPECT_THROW(MakeTorus(0.02, 0.03), Error);        // minor ≥ major
  EXPECT_THROW(MakeTorus(0.05, 0.01, 32, 1), Error);
  std::vector<std::string> parts = SynthClassNames();  // the message lists the known kinds
  parts.push_back("banana");
  testing_util::ExpectError([] { MakeShape("banana"); }, parts);
}

}  // namespace
}  // namespace posefilter
