// Tests of Mesh (validation, bounds, diameter), LoadMesh (assimp) and SaveMeshPly.
#include "posefilter/mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>
#include <numbers>
#include <string>

#include "posefilter/error.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

using testing_util::ExpectError;
using testing_util::ExpectInvalid;
using testing_util::ReadFile;

// A fresh directory per test.
class MeshFileTest : public testing_util::ScratchDirTest {
 protected:
  MeshFileTest() : ScratchDirTest("mesh") {}
};

// Axis-aligned box [0,a]×[0,b]×[0,c] with 12 outward (CCW) triangles.
Mesh Box(float a, float b, float c) {
  Mesh m;
  m.name = "box";
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back((i & 1) ? a : 0.f, (i & 2) ? b : 0.f, (i & 4) ? c : 0.f);
  }
  m.faces = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
             {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

Eigen::Vector3f FaceNormal(const Mesh& m, size_t f) {
  const auto& t = m.faces[f];
  return (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
}

TEST(MeshTest, BoxIsValidWithOutwardNormals) {
  const Mesh m = Box(0.1f, 0.2f, 0.3f);
  std::string why;
  ASSERT_TRUE(m.IsValid(&why)) << why;
  const Eigen::Vector3f centre(0.05f, 0.1f, 0.15f);
  for (size_t f = 0; f < m.faces.size(); ++f) {
    EXPECT_GT(FaceNormal(m, f).dot(m.vertices[m.faces[f][0]] - centre), 0.f) << "face " << f;
  }
}

TEST(MeshTest, IsValidNamesTheViolation) {
  ExpectInvalid(Mesh(), "no vertices");

  Mesh no_faces = Box(1, 1, 1);
  no_faces.faces.clear();
  ExpectInvalid(no_faces, "no faces");

  Mesh bad_index = Box(1, 1, 1);
  bad_index.faces[3][1] = 8;  // one past the last vertex
  ExpectInvalid(bad_index, "face 3");

  Mesh nan_vertex = Box(1, 1, 1);
  nan_vertex.vertices[5].y() = std::numeric_limits<float>::quiet_NaN();
  ExpectInvalid(nan_vertex, "vertex 5");

  Mesh inf_vertex = Box(1, 1, 1);
  inf_vertex.vertices[0].x() = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(inf_vertex.IsValid(nullptr));
}

TEST(MeshTest, BoundsAndDiameterOfBox) {
  Mesh m = Box(0.1f, 0.2f, 0.3f);
  for (auto& v : m.vertices) v += Eigen::Vector3f(-1.f, 2.f, 0.5f);  // off-origin
  EXPECT_TRUE(m.Min().isApprox(Eigen::Vector3f(-1.f, 2.f, 0.5f)));
  EXPECT_TRUE(m.Max().isApprox(Eigen::Vector3f(-0.9f, 2.2f, 0.8f)));
  // Space diagonal: sqrt(0.1² + 0.2² + 0.3²).
  EXPECT_NEAR(m.Diameter(), std::sqrt(0.01 + 0.04 + 0.09), 1e-6);
}

TEST(MeshTest, DiameterOfDegenerateMeshes) {
  Mesh m;
  EXPECT_EQ(m.Diameter(), 0.0);
  m.vertices.emplace_back(1.f, 2.f, 3.f);
  EXPECT_EQ(m.Diameter(), 0.0);
  EXPECT_TRUE(m.Min().isApprox(Eigen::Vector3f(1.f, 2.f, 3.f)));
}

// Above 4096 vertices the diameter is computed on a subsample: it must be a lower bound of the
// exact value, close to it, and deterministic.
TEST(MeshTest, DiameterOfLargeMeshIsCloseLowerBound) {
  Mesh m;
  const int n = 5000;  // more than the exact-diameter limit of 4096 vertices
  // Points on an ellipsoid with semi-axes 0.03, 0.05, 0.11 m (Fibonacci spiral, deterministic);
  // the farthest pair is not on a coordinate axis in general.
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / n;
    const double r = std::sqrt(1.0 - y * y);
    const double a = golden * i;
    m.vertices.emplace_back(float(0.03 * r * std::cos(a)), float(0.05 * y),
                            float(0.11 * r * std::sin(a)));
  }
  // Brute force in plain loops over doubles (the sanitizer build compiles tests without
  // optimisation).
  std::vector<double> x(n), y(n), z(n);
  for (int i = 0; i < n; ++i) x[i] = m.vertices[i].x(), y[i] = m.vertices[i].y(), z[i] = m.vertices[i].z();
  double exact = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (d2 > exact) exact = d2;
    }
  }
  exact = std::sqrt(exact);
  const double d = m.Diameter();
  EXPECT_LE(d, exact + 1e-9);
  EXPECT_GE(d, 0.995 * exact);
  EXPECT_EQ(d, m.Diameter());
}

TEST_F(MeshFileTest, PlyRoundTripIsExact) {
  Mesh m = Box(0.1f, 0.25f, 0.05f);
  for (auto& v : m.vertices) v += Eigen::Vector3f(0.0123f, -0.5f, 1e-3f);
  const std::string path = Path("box.ply");
  SaveMeshPly(m, path);

  // The header promises binary little-endian floats and uchar/int face lists.
  const std::string head = ReadFile(path);
  ASSERT_NE(head.find("end_header\n"), std::string::npos);
  EXPECT_EQ(head.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(head.find("element vertex 8\n"), std::string::npos);
  EXPECT_NE(head.find("element face 12\n"), std::string::npos);
  EXPECT_EQ(fs::file_size(path), head.find("end_header\n") + 11 + 8 * 12 + 12 * 13);

  const Mesh back = LoadMesh(path);
  EXPECT_EQ(back.name, "box");
  ASSERT_EQ(back.vertices.size(), m.vertices.size());
  ASSERT_EQ(back.faces.size(), m.faces.size());
  // Compare triangle by triangle through the coordinates (robust to vertex re-ordering).
  for (size_t f = 0; f < m.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(back.vertices[back.faces[f][k]], m.vertices[m.faces[f][k]]) << "face " << f;
    }
  }
  EXPECT_NEAR(back.Diameter(), m.Diameter(), 1e-7);
}

TEST_F(MeshFileTest, AsciiPlyWithExtraDataAndPolygons) {
  // Extra vertex properties (normals, colour), an extra element, a quad (fan-triangulated),
  // a degenerate 2-corner face (dropped), an unused vertex (dropped), CRLF line ends.
  const std::string path = Write("extra.ply",
                                 "ply\r\nformat ascii 1.0\r\ncomment hello\r\n"
                                 "element vertex 5\r\n"
                                 "property float nx\r\nproperty double x\r\nproperty float y\r\n"
                                 "property float z\r\nproperty uchar red\r\n"
                                 "element face 3\r\n"
                                 "property uchar flags\r\n"
                                 "property list uchar int vertex_indices\r\n"
                                 "element material 1\r\nproperty float shininess\r\n"
                                 "end_header\r\n"
                                 "0 0 0 0 255\r\n0 10 0 0 1\r\n0 10 20 0 2\r\n0 0 20 0 3\r\n"
                                 "0 99 99 99 4\r\n"
                                 "7 4 0 1 2 3\r\n7 2 0 1\r\n7 3 2 1 0\r\n"
                                 "0.5\r\n");
  const Mesh m = LoadMesh(path, 0.01);
  ASSERT_EQ(m.faces.size(), 3u);     // quad → 2, + 1 triangle
  ASSERT_EQ(m.vertices.size(), 4u);  // vertex 4 unused
  EXPECT_TRUE(m.Max().isApprox(Eigen::Vector3f(0.1f, 0.2f, 0.f)));
  // Winding is kept: the quad faces +z, the last triangle (2,1,0) faces −z.
  EXPECT_GT(FaceNormal(m, 0).z(), 0.f);
  EXPECT_GT(FaceNormal(m, 1).z(), 0.f);
  EXPECT_LT(FaceNormal(m, 2).z(), 0.f);
}

TEST_F(MeshFileTest, BigEndianPlyAndPlyMagicWithOtherExtension) {
  std::string ply =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar ushort vertex_indices\nend_header\n";
  auto be32 = [&](float f) {
    const std::uint32_t u = std::bit_cast<std::uint32_t>(f);
    for (int k = 3; k >= 0; --k) ply.push_back(char((u >> (8 * k)) & 0xff));
  };
  for (float f : {0.f, 0.f, 0.f, 0.25f, 0.f, 0.f, 0.f, 0.5f, -1.f}) be32(f);
  ply += std::string("\x03\x00\x00\x00\x01\x00\x02", 7);
  const Mesh m = LoadMesh(Write("be.dat", ply));
  ASSERT_EQ(m.faces.size(), 1u);
  EXPECT_EQ(m.name, "be");
  EXPECT_EQ(m.vertices[1], Eigen::Vector3f(0.25f, 0.f, 0.f));
  EXPECT_EQ(m.vertices[2], Eigen::Vector3f(0.f, 0.5f, -1.f));
}

TEST_F(MeshFileTest, EveryTruncationOfABinaryPlyIsAnError) {
  SaveMeshPly(Box(0.1f, 0.2f, 0.3f), Path("full.ply"));
  const std::string bytes = ReadFile(Path("full.ply"));
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::string path = Write("cut.ply", bytes.substr(0, n));
    EXPECT_THROW(LoadMesh(path), Error) << "truncated to " << n << " of " << bytes.size();
  }
  EXPECT_NO_THROW(LoadMesh(Write("cut.ply", bytes)));
}

TEST_F(MeshFileTest, MalformedPlyVariants) {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n";
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + verts + "3 0 1 3\n", "indexes vertex 3"},
      {head + verts + "3 0 1 -1\n", "invalid vertex index"},
      {head + verts + "3 0 1 1.5\n", "integer"},
      {head + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "bad number"},
      {head + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "non-finite"},
      {head + verts, "truncated"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
       "end_header\n3 0 1 2\n", "no element \"vertex\""},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "end_header\n" + verts, "x, y or z"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n" + verts, "no triangles"},
      {"ply\nformat ascii 2.0 blah\nelement vertex 99999999999\nproperty float x\nend_header\n",
       "more entries than the file holds"},
      {"ply\nformat xml 1.0\nend_header\n", "unknown format"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty quad x\nend_header\n", "property"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nbogus line\nend_header\n", "unknown header"},
      {"ply\nelement vertex 0\nend_header\n", "format"},
      {"PLY\nformat ascii 1.0\nend_header\n", "magic"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string path = Write("bad.ply", text);
    ExpectError([&] { LoadMesh(path); }, {path, expected});
  }
}

TEST_F(MeshFileTest, ObjWithQuadsIsTriangulatedScaledAndKeepsWinding) {
  // A 20 mm × 40 mm quad in the z = 10 mm plane, CCW seen from +z, plus a triangle.
  const std::string path = Write("plate_mm.obj",
                                 "# test plate, millimetres\n"
                                 "v 0 0 10\nv 20 0 10\nv 20 40 10\nv 0 40 10\nv 0 0 30\n"
                                 "f 1 2 3 4\n"
                                 "f 1 5 2\n");
  const Mesh m = LoadMesh(path, 0.001);
  EXPECT_EQ(m.name, "plate_mm");
  EXPECT_EQ(m.vertices.size(), 5u);
  ASSERT_EQ(m.faces.size(), 3u);  // quad → 2 triangles, + 1
  EXPECT_TRUE(m.Min().isApprox(Eigen::Vector3f(0.f, 0.f, 0.01f)));
  EXPECT_TRUE(m.Max().isApprox(Eigen::Vector3f(0.02f, 0.04f, 0.03f)));
  int plus_z = 0;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Eigen::Vector3f n = FaceNormal(m, f);
    if (n.z() > 0) ++plus_z;
  }
  EXPECT_EQ(plus_z, 2);  // the quad's two triangles still face +z
}

TEST_F(MeshFileTest, ObjWithSeveralObjectsIsMerged) {
  const std::string path = Write("two.obj",
                                 "o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
                                 "o second\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf 4 5 6\n");
  const Mesh m = LoadMesh(path);
  EXPECT_EQ(m.faces.size(), 2u);
  EXPECT_EQ(m.vertices.size(), 6u);
  EXPECT_TRUE(m.Max().isApprox(Eigen::Vector3f(6.f, 6.f, 5.f)));
  std::string why;
  EXPECT_TRUE(m.IsValid(&why)) << why;
}

TEST_F(MeshFileTest, NodeTransformsAreApplied) {
  // Collada scene: one triangle instanced by two nodes, translated by (1,2,3) and rotated 90°
  // about z then translated by (0,0,-1). Y_UP so assimp leaves the axes alone.
  const std::string dae = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="tri" name="tri"><mesh>
      <source id="tri-pos"><float_array id="tri-pos-array" count="9">0 0 0 1 0 0 0 1 0</float_array>
        <technique_common><accessor source="#tri-pos-array" count="3" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="tri-vtx"><input semantic="POSITION" source="#tri-pos"/></vertices>
      <triangles count="1"><input semantic="VERTEX" source="#tri-vtx" offset="0"/><p>0 1 2</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene">
      <node id="a" name="a"><matrix>1 0 0 1 0 1 0 2 0 0 1 3 0 0 0 1</matrix>
        <instance_geometry url="#tri"/></node>
      <node id="b" name="b"><matrix>0 -1 0 0 1 0 0 0 0 0 1 -1 0 0 0 1</matrix>
        <instance_geometry url="#tri"/></node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
  const Mesh m = LoadMesh(Write("two_instances.dae", dae), 2.0);
  ASSERT_EQ(m.faces.size(), 2u);
  ASSERT_EQ(m.vertices.size(), 6u);
  // Expected vertex sets (× unit_scale 2): a: (1,2,3),(2,2,3),(1,3,3); b: (0,0,-1),(0,1,-1),(-1,0,-1).
  const std::vector<Eigen::Vector3f> expected = {{2, 4, 6}, {4, 4, 6}, {2, 6, 6},
                                                 {0, 0, -2}, {0, 2, -2}, {-2, 0, -2}};
  for (const auto& e : expected) {
    bool found = false;
    for (const auto& v : m.vertices) found = found || (v - e).norm() < 1e-5f;
    EXPECT_TRUE(found) << "missing vertex " << e.transpose();
  }
}

TEST_F(MeshFileTest, MissingFileNamesTheFile) {
  const std::string path = Path("nope.ply");
  ExpectError([&] { LoadMesh(path); }, {path, "not found"});
}

TEST_F(MeshFileTest, FileOverTheByteLimitIsRefusedUnread) {
  // A sparse file one byte over kMaxMeshBytes: refused from its size, before any byte is read
  // (read, it would need several times the limit in memory).
  const std::string path = Path("huge.obj");
  { std::ofstream(path) << "v 0 0 0\n"; }
  fs::resize_file(path, kMaxMeshBytes + 1);
  ExpectError([&] { LoadMesh(path); }, {path, std::to_string(kMaxMeshBytes + 1) + " bytes, over the limit of " +
                                                  std::to_string(kMaxMeshBytes) + " bytes"});
}

TEST_F(MeshFileTest, DirectoryIsRejected) {
  ExpectError([&] { LoadMesh(dir().string()); }, {dir().string()});
}

TEST_F(MeshFileTest, GarbagePlyIsRejected) {
  const std::string path = Write("garbage.ply", "this is not a mesh \x01\x02\x03 at all\n");
  ExpectError([&] { LoadMesh(path); }, {path});
}

TEST_F(MeshFileTest, TruncatedBinaryPlyIsRejected) {
  SaveMeshPly(Box(1, 1, 1), Path("full.ply"));
  const std::string bytes = ReadFile(Path("full.ply"));
  const std::string path = Write("cut.ply", bytes.substr(0, bytes.size() - 40));
  ExpectError([&] { LoadMesh(path); }, {path});
}

TEST_F(MeshFileTest, ObjWithoutFacesIsRejected) {
  const std::string path = Write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  ExpectError([&] { LoadMesh(path); }, {path});
}

TEST_F(MeshFileTest, ObjWithOnlyLinesIsRejected) {
  const std::string path = Write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
  ExpectError([&] { LoadMesh(path); }, {path, "no triangles"});
}

TEST_F(MeshFileTest, EmptyFileIsRejected) {
  const std::string path = Write("empty.obj", "");
  ExpectError([&] { LoadMesh(path); }, {path});
}

TEST_F(MeshFileTest, BadUnitScaleIsRejected) {
  const std::string path = Write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NO_THROW(LoadMesh(path, 1.0));
  for (double s : {0.0, -0.001, std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity()}) {
    ExpectError([&] { LoadMesh(path, s); }, {path, "unit scale"});
  }
}

TEST_F(MeshFileTest, SaveRejectsInvalidMeshAndBadPath) {
  Mesh bad = Box(1, 1, 1);
  bad.faces[0][0] = 100;
  const std::string path = Path("bad.ply");
  ExpectError([&] { SaveMeshPly(bad, path); }, {path, "face 0"});
  EXPECT_FALSE(fs::exists(path));
  const std::string no_dir = Path("no/such/dir/box.ply");
  ExpectError([&] { SaveMeshPly(Box(1, 1, 1), no_dir); }, {no_dir});
}

// ---- YCB-Video meshes from /work/shared (optional) -------------------------------------------

fs::path YcbvModels() { return testing_util::YcbvDataDir() / "models"; }

TEST(MeshYcbvTest, MugMatchesModelsInfo) {
  const fs::path dir = YcbvModels();
  if (!fs::exists(dir / "025_mug.ply") || !fs::exists(dir / "models_info.json")) {
    GTEST_SKIP() << "YCB-Video models not found under " << dir;
  }
  const Mesh m = LoadMesh((dir / "025_mug.ply").string());
  EXPECT_EQ(m.name, "025_mug");
  EXPECT_GT(m.vertices.size(), 1000u);
  std::string why;
  EXPECT_TRUE(m.IsValid(&why)) << why;

  std::ifstream is(dir / "models_info.json");
  const auto info = nlohmann::json::parse(is)["models"]["025_mug"];
  const double diameter_m = info["diameter_mm_from_points"].get<double>() / 1000.0;
  EXPECT_NEAR(m.Diameter(), diameter_m, 0.05 * diameter_m)
      << "mesh diameter " << m.Diameter() << " m vs points " << diameter_m << " m";
  const Eigen::Vector3f extent = m.Max() - m.Min();
  for (int k = 0; k < 3; ++k) {
    const double e = info["bbox_extent_mm"][k].get<double>() / 1000.0;
    EXPECT_NEAR(extent[k], e, 0.02 * e + 1e-3) << "axis " << k;
  }
}

TEST(MeshYcbvTest, UnitScaleMultipliesCoordinates) {
  const fs::path file = YcbvModels() / "061_foam_brick.ply";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not found";
  const Mesh m = LoadMesh(file.string());
  const Mesh mm = LoadMesh(file.string(), 1000.0);
  ASSERT_EQ(m.vertices.size(), mm.vertices.size());
  EXPECT_NEAR(mm.Diameter(), 1000.0 * m.Diameter(), 1e-3 * 1000.0 * m.Diameter());
}

}  // namespace
}  // namespace posefilter
