// eval/bop_writers.cc — a dataset written in the BOP layout (bop.h): models/models_info.json
// with the meshes in millimetres, and one scene folder (scene_camera.json, scene_gt.json,
// scene_gt_info.json, depth PNGs). Every file is written atomically.
#include "posefilter/bop.h"

#include <filesystem>
#include <system_error>

#include "eval/bop_io_internal.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter {

namespace {

namespace fs = std::filesystem;
using bop_io_internal::Digits6;
using bop_io_internal::json;

void WriteJson(const json& j, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << j.dump(1) << "\n"; });
}

}  // namespace

void WriteBopModels(const std::string& root, const std::vector<DatasetModel>& models,
                    const std::vector<const Mesh*>& meshes) {
  if (meshes.size() != models.size()) throw Error("WriteBopModels: one mesh pointer per model expected");
  const fs::path dir = fs::path(root) / "models";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create folder: " + ec.message());
  json info = json::object();
  for (std::size_t i = 0; i < models.size(); ++i) {
    const DatasetModel& m = models[i];
    json e;
    e["diameter"] = m.diameter_m * 1e3;
    if (!m.symmetries_discrete.empty()) {
      e["symmetries_discrete"] = json::array();
      for (const auto& S : m.symmetries_discrete) {
        json v = json::array();
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c) v.push_back(c == 3 && r < 3 ? S.matrix()(r, c) * 1e3 : S.matrix()(r, c));
        e["symmetries_discrete"].push_back(v);
      }
    }
    if (!m.symmetries_continuous.empty()) {
      e["symmetries_continuous"] = json::array();
      for (const auto& c : m.symmetries_continuous)
        e["symmetries_continuous"].push_back(
            {{"axis", {c.axis.x(), c.axis.y(), c.axis.z()}},
             {"offset", {c.offset.x() * 1e3, c.offset.y() * 1e3, c.offset.z() * 1e3}}});
    }
    info[std::to_string(m.obj_id)] = e;
    if (meshes[i]) {
      Mesh mm = *meshes[i];
      for (auto& v : mm.vertices) v *= 1000.f;
      SaveMeshPly(mm, (dir / ("obj_" + Digits6(m.obj_id) + ".ply")).string());
    }
  }
  WriteJson(info, (dir / "models_info.json").string());
}

void WriteBopScene(const std::string& root, const std::string& split, const std::vector<DatasetImage>& images,
                   const std::vector<DepthImage>& depths) {
  if (images.empty() || depths.size() != images.size())
    throw Error("WriteBopScene: one depth image per image expected");
  const fs::path dir = fs::path(root) / split / Digits6(images[0].scene_id);
  std::error_code ec;
  fs::create_directories(dir / "depth", ec);
  if (ec) throw Error(dir.string() + ": cannot create folder: " + ec.message());
  json cams = json::object(), gts = json::object(), infos = json::object();
  bool all_info = true;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const DatasetImage& im = images[i];
    if (im.scene_id != images[0].scene_id) throw Error("WriteBopScene: images of different scenes");
    const std::string key = std::to_string(im.im_id);
    const Camera& c = im.camera;
    cams[key] = {{"cam_K", {c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0}}, {"depth_scale", im.depth_scale_m * 1e3}};
    json list = json::array(), info_list = json::array();
    for (const auto& g : im.gt) {
      json R = json::array();
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) R.push_back(g.T_cam_obj.linear()(r, k));
      const Eigen::Vector3d t = g.T_cam_obj.translation() * 1e3;
      list.push_back({{"cam_R_m2c", R}, {"cam_t_m2c", {t.x(), t.y(), t.z()}}, {"obj_id", g.obj_id}});
      all_info = all_info && g.has_info;
      info_list.push_back({{"bbox_obj", {g.bbox_obj[0], g.bbox_obj[1], g.bbox_obj[2], g.bbox_obj[3]}},
                           {"bbox_visib", {g.bbox_visib[0], g.bbox_visib[1], g.bbox_visib[2], g.bbox_visib[3]}},
                           {"visib_fract", g.visib_fract}});
    }
    gts[key] = list;
    infos[key] = info_list;
    SaveDepthPng(depths[i], (dir / "depth" / (Digits6(im.im_id) + ".png")).string(), im.depth_scale_m);
  }
  WriteJson(cams, (dir / "scene_camera.json").string());
  WriteJson(gts, (dir / "scene_gt.json").string());
  if (all_info) WriteJson(infos, (dir / "scene_gt_info.json").string());
}

}  // namespace posefilter
