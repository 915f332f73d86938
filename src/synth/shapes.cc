// Procedural meshes of the synthetic world (synth.h). Every mesh is closed, its faces wind
// counter-clockwise seen from outside (mesh.h), and its object frame sits at the centre of
// its axis-aligned bounding box. Units: metres.
#include <cmath>
#include <sstream>

#include "posefilter/error.h"
#include "posefilter/synth.h"

namespace posefilter {
namespace {

void CheckSize(const char* what, const char* name, double v) {
  if (!std::isfinite(v) || v <= 0) {
    std::ostringstream os;
    os << what << ": " << name << " must be finite and > 0 (got " << v << ")";
    throw Error(os.str());
  }
}

void CheckCount(const char* what, const char* name, int n) {
  if (n < 3 || n > 4096) {
    std::ostringstream os;
    os << what << ": " << name << " must be in [3, 4096] (got " << n << ")";
    throw Error(os.str());
  }
}

std::uint32_t AddVertex(Mesh* m, double x, double y, double z) {
  m->vertices.emplace_back(float(x), float(y), float(z));
  return std::uint32_t(m->vertices.size() - 1);
}

// Quad a-b-c-d (CCW from outside) as two triangles.
void AddQuad(Mesh* m, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  m->faces.push_back({a, b, c});
  m->faces.push_back({a, c, d});
}

// Recentres the vertices on their bounding-box centre.
void CentreOnBox(Mesh* m) {
  const Eigen::Vector3f c = 0.5f * (m->Min() + m->Max());
  for (auto& v : m->vertices) v -= c;
}

}  // namespace

Mesh MakeBox(double sx, double sy, double sz, const std::string& name) {
  CheckSize("MakeBox", "sx", sx);
  CheckSize("MakeBox", "sy", sy);
  CheckSize("MakeBox", "sz", sz);
  Mesh m;
  m.name = name;
  const double hx = sx / 2, hy = sy / 2, hz = sz / 2;
  // Vertex i has x = ±hx by bit 0, y by bit 1, z by bit 2.
  for (int i = 0; i < 8; ++i)
    AddVertex(&m, (i & 1) ? hx : -hx, (i & 2) ? hy : -hy, (i & 4) ? hz : -hz);
  AddQuad(&m, 0, 2, 3, 1);  // z = −hz, normal −z
  AddQuad(&m, 4, 5, 7, 6);  // z = +hz, normal +z
  AddQuad(&m, 0, 1, 5, 4);  // y = −hy, normal −y
  AddQuad(&m, 2, 6, 7, 3);  // y = +hy, normal +y
  AddQuad(&m, 0, 4, 6, 2);  // x = −hx, normal −x
  AddQuad(&m, 1, 3, 7, 5);  // x = +hx, normal +x
  return m;
}

Mesh MakeCylinder(double radius, double height, int segments, const std::string& name) {
  CheckSize("MakeCylinder", "radius", radius);
  CheckSize("MakeCylinder", "height", height);
  CheckCount("MakeCylinder", "segments", segments);
  Mesh m;
  m.name = name;
  const double hz = height / 2;
  const auto n = std::uint32_t(segments);
  for (std::uint32_t i = 0; i < n; ++i) {  // bottom ring 0..n−1, top ring n..2n−1
    const double a = 2 * M_PI * i / n;
    AddVertex(&m, radius * std::cos(a), radius * std::sin(a), -hz);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    AddVertex(&m, radius * std::cos(a), radius * std::sin(a), hz);
  }
  const std::uint32_t cb = AddVertex(&m, 0, 0, -hz), ct = AddVertex(&m, 0, 0, hz);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    AddQuad(&m, i, j, n + j, n + i);  // side, CCW around +z → outward
    m.faces.push_back({cb, j, i});     // bottom cap, normal −z
    m.faces.push_back({ct, n + i, n + j});  // top cap, normal +z
  }
  CentreOnBox(&m);  // odd segment counts: the ring is not symmetric in x
  return m;
}

Mesh MakeLShape(double size, double thickness, double depth, const std::string& name) {
  CheckSize("MakeLShape", "size", size);
  CheckSize("MakeLShape", "thickness", thickness);
  CheckSize("MakeLShape", "depth", depth);
  if (thickness >= size) throw Error("MakeLShape: thickness must be < size");
  Mesh m;
  m.name = name;
  const double s = size, t = thickness, hz = depth / 2;
  // The L outline, CCW seen from +z; P3 is the reflex corner.
  const double px[6] = {0, s, s, t, t, 0};
  const double py[6] = {0, 0, t, t, s, s};
  for (int i = 0; i < 6; ++i) AddVertex(&m, px[i], py[i], -hz);  // 0..5 bottom
  for (int i = 0; i < 6; ++i) AddVertex(&m, px[i], py[i], hz);   // 6..11 top
  // Caps: a fan from P0 (the corner opposite the reflex one) stays inside the L.
  for (std::uint32_t i = 1; i + 1 < 6; ++i) {
    m.faces.push_back({6, 6 + i, 6 + i + 1});  // top, CCW from +z
    m.faces.push_back({0, i + 1, i});          // bottom, reversed
  }
  for (std::uint32_t i = 0; i < 6; ++i) {  // walls: outward is to the right of each edge
    const std::uint32_t j = (i + 1) % 6;
    AddQuad(&m, i, j, 6 + j, 6 + i);
  }
  CentreOnBox(&m);
  return m;
}

Mesh MakeTorus(double major_r, double minor_r, int nu, int nv, const std::string& name) {
  CheckSize("MakeTorus", "major_r", major_r);
  CheckSize("MakeTorus", "minor_r", minor_r);
  CheckCount("MakeTorus", "nu", nu);
  CheckCount("MakeTorus", "nv", nv);
  if (minor_r >= major_r) throw Error("MakeTorus: minor_r must be < major_r");
  Mesh m;
  m.name = name;
  // Vertex (i, j): θ = 2πi/nu around z, φ = 2πj/nv around the tube.
  for (int i = 0; i < nu; ++i) {
    const double th = 2 * M_PI * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double ph = 2 * M_PI * j / nv;
      const double r = major_r + minor_r * std::cos(ph);
      AddVertex(&m, r * std::cos(th), r * std::sin(th), minor_r * std::sin(ph));
    }
  }
  auto idx = [&](int i, int j) { return std::uint32_t((i % nu) * nv + (j % nv)); };
  // ∂/∂θ × ∂/∂φ points out of the tube, so (i,j) → (i+1,j) → (i+1,j+1) is CCW from outside.
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) AddQuad(&m, idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
  CentreOnBox(&m);  // odd nu: the ring is not symmetric in x
  return m;
}

std::vector<std::string> SynthClassNames() { return {"box", "cylinder", "lshape", "torus"}; }

Mesh MakeShape(const std::string& kind) {
  if (kind == "box") return MakeBox(0.12, 0.08, 0.16, "box");
  if (kind == "cylinder") return MakeCylinder(0.04, 0.14, 32, "cylinder");
  if (kind == "lshape") return MakeLShape(0.14, 0.05, 0.06, "lshape");
  if (kind == "torus") return MakeTorus(0.06, 0.025, 32, 32, "torus");
  std::string kinds;
  for (const auto& k : SynthClassNames()) kinds += (kinds.empty() ? "" : ", ") + k;
  throw Error("unknown synthetic shape '" + kind + "' (kinds: " + kinds + ")");
}

}  // namespace posefilter
