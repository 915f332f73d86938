// fuzz/make_corpus.cc — writes the seed corpus fuzz/corpus/<target>/ with posefilter's own
// writers (SaveDepthPng, SaveLabelPng, SaveMeshPly, WriteCameraJson, WriteDetectionsJson,
// WriteRawPyramid, WriteBopResultsCsv) plus a few hand-written and slightly broken variants
// (truncated, a flipped byte, a missing key). Deterministic; the committed corpus is its output:
//   build/asan/fuzz/make_corpus fuzz/corpus
// Built with the fuzz targets (fuzz/CMakeLists.txt); scripts/fuzz.sh does not run it.
#include <Eigen/Geometry>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "posefilter/bop.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"

namespace fs = std::filesystem;
using namespace posefilter;

namespace {

fs::path g_out, g_tmp;

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void Seed(const std::string& target, const std::string& name, const std::string& bytes) {
  fs::create_directories(g_out / target);
  std::ofstream out(g_out / target / name, std::ios::binary | std::ios::trunc);
  out << bytes;
}

// The bytes a writer produced for `name` (written into the scratch folder by `write`).
template <class F>
std::string Written(const std::string& name, F&& write) {
  const fs::path p = g_tmp / name;
  write(p.string());
  return ReadAll(p);
}

std::string Truncated(const std::string& s, size_t cut) { return s.substr(0, s.size() > cut ? s.size() - cut : 0); }

std::string Flipped(std::string s, size_t at) {
  if (at < s.size()) s[at] = static_cast<char>(s[at] ^ 0x5a);
  return s;
}

Mesh Tetrahedron() {
  Mesh m;
  m.vertices = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 0.1f}};
  m.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

void PngSeeds() {
  DepthImage depth(4, 3);
  for (int i = 0; i < 12; ++i) depth.data[size_t(i)] = i == 5 ? 0.f : 0.5f + 0.01f * float(i);
  const std::string d16 = Written("d16.png", [&](const std::string& p) { SaveDepthPng(depth, p, 0.001); });
  const std::string g8 =
      Written("g8.png", [&](const std::string& p) { SaveGray8Png({0, 1, 2, 3, 4, 250}, 3, 2, p); });
  RgbImage rgb(2, 2);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = static_cast<std::uint8_t>(40 * i);
  const std::string c8 = Written("rgb.png", [&](const std::string& p) { SaveRgbPng(rgb, p); });
  LabelImage labels;
  labels.width = 3;
  labels.height = 3;
  labels.ids = {0, 0, 1, 0, 2, 2, 300, 0, 1};
  const std::string l16 = Written("l16.png", [&](const std::string& p) { SaveLabelPng(labels, p); });

  Seed("depth_png_fuzz", "depth16.png", d16);
  Seed("depth_png_fuzz", "depth8.png", g8);
  Seed("depth_png_fuzz", "rgb8.png", c8);
  Seed("depth_png_fuzz", "depth16_truncated.png", Truncated(d16, 20));
  Seed("depth_png_fuzz", "depth16_flipped_idat.png", Flipped(d16, d16.size() - 20));
  Seed("label_png_fuzz", "label16.png", l16);
  Seed("label_png_fuzz", "label8.png", g8);
  Seed("label_png_fuzz", "rgb8.png", c8);
  Seed("label_png_fuzz", "label16_truncated.png", Truncated(l16, 16));
}

void MeshSeeds() {
  const std::string bin = Written("tet.ply", [&](const std::string& p) { SaveMeshPly(Tetrahedron(), p); });
  Seed("mesh_ply_fuzz", "tet_binary_le.ply", bin);
  Seed("mesh_ply_fuzz", "tet_binary_le_truncated.ply", Truncated(bin, 7));
  Seed("mesh_ply_fuzz", "quad_ascii.ply",
       "ply\nformat ascii 1.0\ncomment a unit square as one quad\nelement vertex 4\n"
       "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 9\n4 0 1 2 3\n");
  // Big-endian: double coordinates, ushort count, uint indices, one extra element to skip.
  std::string be =
      "ply\r\nformat binary_big_endian 1.0\r\nelement vertex 3\r\nproperty double x\r\n"
      "property double y\r\nproperty double z\r\nelement face 1\r\n"
      "property list ushort uint vertex_index\r\nelement edge 1\r\nproperty int a\r\nend_header\r\n";
  const double xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (double v : xyz) {
    std::uint64_t u;
    std::memcpy(&u, &v, 8);
    for (int b = 7; b >= 0; --b) be.push_back(static_cast<char>((u >> (8 * b)) & 0xff));
  }
  be += std::string("\x00\x03", 2) + std::string("\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x02", 12) +
        std::string("\x00\x00\x00\x07", 4);
  Seed("mesh_ply_fuzz", "tri_binary_be.ply", be);

  Seed("mesh_obj_fuzz", "tet.obj",
       "# tetrahedron\no tet\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\n"
       "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  Seed("mesh_obj_fuzz", "quad_uv_normals.obj",
       "mtllib none.mtl\ng quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
       "vn 0 0 1\nusemtl red\ns off\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf -4//1 -2//1 -1//1\n");
  Seed("mesh_obj_fuzz", "bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\nl 1 2\n");
}

void JsonSeeds() {
  CameraFile cam;
  cam.camera.width = 64;
  cam.camera.height = 48;
  cam.camera.fx = cam.camera.fy = 50;
  cam.camera.cx = 31.5;
  cam.camera.cy = 23.5;
  cam.depth_scale = 0.001;
  const std::string cj = Written("camera.json", [&](const std::string& p) { WriteCameraJson(cam, p); });
  Seed("camera_json_fuzz", "camera.json", cj);
  Seed("camera_json_fuzz", "camera_no_base.json",
       "{\"fx\": 500, \"fy\": 500.5, \"cx\": 319.5, \"cy\": 239.5, \"width\": 640, \"height\": 480, "
       "\"depth_scale\": 1e-4}");
  Seed("camera_json_fuzz", "camera_bad.json",
       "{\"fx\": null, \"fy\": \"nan\", \"cx\": 1, \"cy\": 2, \"width\": 64.5, \"height\": -1, "
       "\"depth_scale\": 0, \"base_to_camera\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}");

  std::vector<Detection> dets = {{"mug", 0.9, 10, 12, 30.5, 20}, {"bowl", 0.25, 0, 0, 64, 48}};
  const std::string dj = Written("dets.json", [&](const std::string& p) { WriteDetectionsJson(dets, p); });
  Seed("detections_json_fuzz", "detections_object.json", std::string(1, '\0') + dj);
  Seed("detections_json_fuzz", "detections_list.json",
       std::string(1, '\0') + "[{\"class\": \"mug\", \"score\": 1, \"bbox\": [1, 2, 3, 4]}]");
  Seed("detections_json_fuzz", "detections_empty_allowed.json", std::string(1, '\1') + "{\"detections\": []}");
  Seed("detections_json_fuzz", "detections_bad.json",
       std::string(1, '\0') + "[{\"class\": \"\", \"score\": 1.5, \"bbox\": [1, 2, -3, 1e999]}]");
}

void PyramidSeeds() {
  // Layout as pyramid_raw_fuzz.cc derives it from its first two bytes.
  auto layout_of = [](int b0, int b1) {
    PyramidLayout l;
    l.image_width = 64;
    l.image_height = 48;
    l.num_classes = 1 + b0 % 3;
    const int grids[3][2] = {{1, 2}, {2, 4}, {4, 8}};
    for (int k = 0; k < 1 + b1 % 3; ++k) {
      l.levels.push_back({grids[k][0], grids[k][1], 4 * 64.0 / grids[k][1], 4 * 48.0 / grids[k][0]});
    }
    return l;
  };
  for (const auto& [b0, b1] : {std::pair{0, 0}, std::pair{1, 1}}) {
    const PyramidLayout l = layout_of(b0, b1);
    std::vector<float> raw(size_t(l.CellCount()) * l.RawValuesPerCell());
    for (size_t i = 0; i < raw.size(); ++i) raw[i] = 0.25f * float(int(i % 7) - 3);
    const std::string name = "pyr_" + std::to_string(b0) + std::to_string(b1);
    const std::string bytes = std::string{char(b0), char(b1)} +
                              Written(name, [&](const std::string& p) { WriteRawPyramid(raw, l, p); });
    Seed("pyramid_raw_fuzz", name + ".bin", bytes);
    if (b0 == 1) {
      std::string nan = bytes;
      const float q = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(&nan[2 + 4 * 9], &q, 4);
      Seed("pyramid_raw_fuzz", name + "_nan.bin", nan);
      Seed("pyramid_raw_fuzz", name + "_truncated.bin", Truncated(bytes, 4));
    }
  }
}

void CsvSeeds() {
  BopResult a;
  a.scene_id = 48;
  a.im_id = 1;
  a.obj_id = 2;
  a.score = 0.75;
  a.T_cam_obj.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  a.T_cam_obj.translation() = Eigen::Vector3d(0.01, -0.02, 0.8);
  a.time_s = 1.5;
  BopResult b = a;
  b.obj_id = 5;
  b.T_cam_obj.linear().setIdentity();
  const std::string csv = Written("results.csv", [&](const std::string& p) { WriteBopResultsCsv({a, b}, p); });
  Seed("bop_csv_fuzz", "results.csv", csv);
  std::string crlf;
  for (char c : csv) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  Seed("bop_csv_fuzz", "results_crlf.csv", crlf);
  Seed("bop_csv_fuzz", "results_bad.csv",
       std::string(kBopCsvHeader) + "\n1,2,3,+0.5,1 0 0 0 1 0 0 0 -1,1 2,nan\n\n1,2,3\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_corpus <corpus folder>\n");
    return 2;
  }
  g_out = argv[1];
  g_tmp = fs::temp_directory_path() / "posefilter_make_corpus";
  fs::remove_all(g_tmp);
  fs::create_directories(g_tmp);
  PngSeeds();
  MeshSeeds();
  JsonSeeds();
  PyramidSeeds();
  CsvSeeds();
  fs::remove_all(g_tmp);
  return 0;
}
