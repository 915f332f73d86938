// eval/bop_dataset_reader.cc — the datasets of bop.h: a BOP dataset (models_info.json, the
// split's scene folders, the targets file), the YCB-Video folder (scenes/ + models/),
// OpenDataset, which tells them apart, and the loaders of an image's depth and a model's mesh
// and points. Readers are strict: every value they use must be present, of the right type and
// finite; every error is one line "<file>: <entry>: <what>".
#include "posefilter/bop.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <system_error>
#include <tuple>

#include "eval/bop_io_internal.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/metrics.h"

namespace posefilter {

namespace {

namespace fs = std::filesystem;
using bop_io_internal::Digits6;
using bop_io_internal::Integer;
using bop_io_internal::json;
using bop_io_internal::Key;
using bop_io_internal::MakePose;
using bop_io_internal::Number;
using bop_io_internal::Numbers;
using bop_io_internal::ReadJson;
using bop_io_internal::Where;

// A JSON object key that must be a non-negative integer ("12" → 12).
int IdKey(const std::string& key, const std::string& what, const Where& w) {
  int v = -1;
  const auto [ptr, ec] = std::from_chars(key.data(), key.data() + key.size(), v);
  if (key.empty() || ec != std::errc() || ptr != key.data() + key.size() || v < 0)
    w.Fail("key \"" + key + "\" is not " + what);
  return v;
}

bool IsAllDigits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::vector<fs::path> SortedSubdirs(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory()) out.push_back(e.path());
  if (ec) throw Error(dir.string() + ": cannot list folder: " + ec.message());
  std::sort(out.begin(), out.end());
  return out;
}

// models_info.json → models (no mesh path yet).
std::vector<DatasetModel> ReadModelsInfo(const std::string& path) {
  const json j = ReadJson(path);
  const Where file{path, ""};
  if (!j.is_object() || j.empty()) file.Fail("must be a JSON object {\"<obj_id>\": {...}} with at least one model");
  std::vector<DatasetModel> models;
  for (const auto& [key, info] : j.items()) {
    const int id = IdKey(key, "an obj_id", file);
    const Where w = file.Sub("obj_id " + std::to_string(id));
    if (id < 1) w.Fail("obj_id must be ≥ 1");
    DatasetModel m;
    m.obj_id = id;
    m.name = "obj_" + Digits6(id);
    m.diameter_m = Number(Key(info, "diameter", w), "diameter", w) * 1e-3;
    if (!(m.diameter_m > 0)) w.Fail("diameter must be > 0 (millimetres)");
    if (const auto it = info.find("symmetries_discrete"); it != info.end()) {
      if (!it->is_array()) w.Fail("symmetries_discrete must be an array of 16-number arrays");
      for (std::size_t s = 0; s < it->size(); ++s) {
        const std::string what = "symmetries_discrete[" + std::to_string(s) + "]";
        const std::vector<double> v = Numbers((*it)[s], 16, what, w);
        if (std::abs(v[12]) + std::abs(v[13]) + std::abs(v[14]) + std::abs(v[15] - 1) > 1e-6)
          w.Fail(what + ": last row must be 0 0 0 1");
        const std::vector<double> r9 = {v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]};
        m.symmetries_discrete.push_back(MakePose(r9, Eigen::Vector3d(v[3], v[7], v[11]) * 1e-3, what, w));
      }
    }
    if (const auto it = info.find("symmetries_continuous"); it != info.end()) {
      if (!it->is_array()) w.Fail("symmetries_continuous must be an array of {axis, offset}");
      for (std::size_t s = 0; s < it->size(); ++s) {
        const std::string what = "symmetries_continuous[" + std::to_string(s) + "]";
        const Where ws = w.Sub(what);
        const std::vector<double> a = Numbers(Key((*it)[s], "axis", ws), 3, "axis", ws);
        const std::vector<double> o = Numbers(Key((*it)[s], "offset", ws), 3, "offset", ws);
        ContinuousSymmetry c;
        c.axis = Eigen::Vector3d(a[0], a[1], a[2]);
        if (!(c.axis.norm() > 1e-9)) ws.Fail("axis must not be zero");
        c.axis.normalize();
        c.offset = Eigen::Vector3d(o[0], o[1], o[2]) * 1e-3;
        m.symmetries_continuous.push_back(c);
      }
    }
    models.push_back(std::move(m));
  }
  std::sort(models.begin(), models.end(), [](const auto& a, const auto& b) { return a.obj_id < b.obj_id; });
  return models;
}

// Targets file (test_targets_bop19.json) restricted to nothing: every entry must name an image
// of the dataset and a model.
std::vector<DatasetTarget> ReadTargets(const std::string& path, const Dataset& ds) {
  const json j = ReadJson(path);
  const Where file{path, ""};
  if (!j.is_array()) file.Fail("must be a JSON array of {scene_id, im_id, obj_id, inst_count}");
  std::vector<DatasetTarget> out;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const Where w = file.Sub("entry " + std::to_string(i));
    DatasetTarget t;
    t.scene_id = Integer(Key(j[i], "scene_id", w), "scene_id", w);
    t.im_id = Integer(Key(j[i], "im_id", w), "im_id", w);
    t.obj_id = Integer(Key(j[i], "obj_id", w), "obj_id", w);
    t.inst_count = Integer(Key(j[i], "inst_count", w), "inst_count", w);
    if (t.inst_count < 1) w.Fail("inst_count must be ≥ 1");
    if (!ds.Image(t.scene_id, t.im_id))
      w.Fail("scene " + std::to_string(t.scene_id) + " image " + std::to_string(t.im_id) + " is not in " +
             (ds.split.empty() ? std::string("the dataset") : "split '" + ds.split + "'"));
    if (!ds.Model(t.obj_id)) w.Fail("obj_id " + std::to_string(t.obj_id) + " has no model");
    out.push_back(t);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return std::tie(a.scene_id, a.im_id, a.obj_id) < std::tie(b.scene_id, b.im_id, b.obj_id);
  });
  return out;
}

// Targets from the ground truth: per image, each object with its instance count.
std::vector<DatasetTarget> TargetsFromGt(const Dataset& ds) {
  std::vector<DatasetTarget> out;
  for (const auto& im : ds.images) {
    std::map<int, int> count;
    for (const auto& g : im.gt) ++count[g.obj_id];
    for (const auto& [obj, n] : count) out.push_back({im.scene_id, im.im_id, obj, n});
  }
  return out;
}

void FinishTargets(Dataset* ds, const std::string& targets_path, const std::string& default_path) {
  std::error_code ec;
  std::string path = targets_path;
  if (path.empty() && !default_path.empty() && fs::exists(default_path, ec)) path = default_path;
  if (!path.empty()) {
    ds->targets = ReadTargets(path, *ds);
    ds->targets_source = path;
  } else {
    ds->targets = TargetsFromGt(*ds);
    ds->targets_source = "scene_gt";
  }
}

}  // namespace

// ---- Dataset lookups ---------------------------------------------------------------------------

const DatasetModel* Dataset::Model(int obj_id) const {
  for (const auto& m : models)
    if (m.obj_id == obj_id) return &m;
  return nullptr;
}

const DatasetModel* Dataset::ModelByName(const std::string& name) const {
  for (const auto& m : models)
    if (m.name == name) return &m;
  return nullptr;
}

const DatasetImage* Dataset::Image(int scene_id, int im_id) const {
  const auto it = std::lower_bound(images.begin(), images.end(), std::make_pair(scene_id, im_id),
                                   [](const DatasetImage& a, const std::pair<int, int>& k) {
                                     return std::make_pair(a.scene_id, a.im_id) < k;
                                   });
  return it != images.end() && it->scene_id == scene_id && it->im_id == im_id ? &*it : nullptr;
}

std::vector<std::string> Dataset::ClassNames() const {
  std::vector<std::string> names;
  for (const auto& m : models) names.push_back(m.name);
  return names;
}

// ---- BOP ---------------------------------------------------------------------------------------

Dataset ReadBopDataset(const std::string& root, const std::string& split, const std::string& targets_path) {
  Dataset ds;
  ds.root = root;
  ds.split = split;
  ds.format = "bop";
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw Error(root + ": dataset folder not found");
  const fs::path models_dir = fs::path(root) / "models";
  ds.models = ReadModelsInfo((models_dir / "models_info.json").string());
  for (auto& m : ds.models) {
    m.mesh_path = (models_dir / (m.name + ".ply")).string();
    m.mesh_unit_scale = 1e-3;
    if (!fs::exists(m.mesh_path, ec))
      throw Error(m.mesh_path + ": missing model file (obj_id " + std::to_string(m.obj_id) +
                  " of models_info.json)");
  }

  // Image size of every image (camera.json at the root), if given.
  int width = 0, height = 0;
  if (const fs::path cam = fs::path(root) / "camera.json"; fs::exists(cam, ec)) {
    const json j = ReadJson(cam.string());
    const Where w{cam.string(), ""};
    width = Integer(Key(j, "width", w), "width", w);
    height = Integer(Key(j, "height", w), "height", w);
    if (width < 1 || height < 1) w.Fail("width and height must be ≥ 1");
  }

  if (split.empty()) throw Error(root + ": no split given (e.g. test)");
  const fs::path split_dir = fs::path(root) / split;
  if (!fs::is_directory(split_dir, ec)) throw Error(split_dir.string() + ": split folder not found");
  for (const fs::path& scene_dir : SortedSubdirs(split_dir)) {
    const std::string scene_name = scene_dir.filename().string();
    if (!IsAllDigits(scene_name)) continue;  // not a scene folder
    const int scene_id = std::stoi(scene_name);

    const std::string cam_path = (scene_dir / "scene_camera.json").string();
    const json cams = ReadJson(cam_path);
    const Where cam_file{cam_path, ""};
    if (!cams.is_object()) cam_file.Fail("must be a JSON object {\"<im_id>\": {...}}");
    std::map<int, DatasetImage> images;
    for (const auto& [key, c] : cams.items()) {
      const int im_id = IdKey(key, "an image id", cam_file);
      const Where w = cam_file.Sub("image " + std::to_string(im_id));
      const std::vector<double> K = Numbers(Key(c, "cam_K", w), 9, "cam_K", w);
      if (std::abs(K[1]) > 1e-6 || std::abs(K[3]) > 1e-9 || std::abs(K[6]) > 1e-9 || std::abs(K[7]) > 1e-9 ||
          std::abs(K[8] - 1) > 1e-9)
        w.Fail("cam_K must be [fx 0 cx 0 fy cy 0 0 1] (no skew)");
      DatasetImage im;
      im.scene_id = scene_id;
      im.im_id = im_id;
      im.camera.fx = K[0];
      im.camera.fy = K[4];
      im.camera.cx = K[2];
      im.camera.cy = K[5];
      im.camera.width = width;
      im.camera.height = height;
      if (!(im.camera.fx > 0 && im.camera.fy > 0)) w.Fail("cam_K focal lengths must be > 0");
      im.depth_scale_m = Number(Key(c, "depth_scale", w), "depth_scale", w) * 1e-3;
      if (!(im.depth_scale_m > 0)) w.Fail("depth_scale must be > 0 (millimetres per PNG unit)");
      im.depth_path = (scene_dir / "depth" / (Digits6(im_id) + ".png")).string();
      images.emplace(im_id, std::move(im));
    }

    const std::string gt_path = (scene_dir / "scene_gt.json").string();
    if (fs::exists(gt_path, ec)) {
      const json gts = ReadJson(gt_path);
      const Where gt_file{gt_path, ""};
      if (!gts.is_object()) gt_file.Fail("must be a JSON object {\"<im_id>\": [...]}");
      for (const auto& [key, list] : gts.items()) {
        const int im_id = IdKey(key, "an image id", gt_file);
        const Where wi = gt_file.Sub("image " + std::to_string(im_id));
        const auto it = images.find(im_id);
        if (it == images.end()) wi.Fail("not in scene_camera.json");
        if (!list.is_array()) wi.Fail("must be an array of {obj_id, cam_R_m2c, cam_t_m2c}");
        DatasetImage& im = it->second;
        im.has_gt = true;
        im.gt_source = gt_path;
        for (std::size_t e = 0; e < list.size(); ++e) {
          const Where w = wi.Sub("entry " + std::to_string(e));
          GtInstance g;
          g.obj_id = Integer(Key(list[e], "obj_id", w), "obj_id", w);
          if (!ds.Model(g.obj_id)) w.Fail("obj_id " + std::to_string(g.obj_id) + " not in models_info.json");
          const std::vector<double> R = Numbers(Key(list[e], "cam_R_m2c", w), 9, "cam_R_m2c", w);
          const std::vector<double> t = Numbers(Key(list[e], "cam_t_m2c", w), 3, "cam_t_m2c", w);
          g.T_cam_obj = MakePose(R, Eigen::Vector3d(t[0], t[1], t[2]) * 1e-3, "cam_R_m2c", w);
          im.gt.push_back(g);
        }
      }
      for (const auto& [im_id, im] : images)
        if (!im.has_gt) gt_file.Fail("image " + std::to_string(im_id) + " of scene_camera.json has no entry");
    }

    const std::string info_path = (scene_dir / "scene_gt_info.json").string();
    if (fs::exists(info_path, ec) && fs::exists(gt_path, ec)) {
      const json infos = ReadJson(info_path);
      const Where info_file{info_path, ""};
      if (!infos.is_object()) info_file.Fail("must be a JSON object {\"<im_id>\": [...]}");
      for (const auto& [key, list] : infos.items()) {
        const int im_id = IdKey(key, "an image id", info_file);
        const Where wi = info_file.Sub("image " + std::to_string(im_id));
        const auto it = images.find(im_id);
        if (it == images.end()) wi.Fail("not in scene_camera.json");
        DatasetImage& im = it->second;
        if (!list.is_array() || list.size() != im.gt.size())
          wi.Fail("must be an array with one entry per scene_gt.json entry (" + std::to_string(im.gt.size()) + ")");
        for (std::size_t e = 0; e < list.size(); ++e) {
          const Where w = wi.Sub("entry " + std::to_string(e));
          GtInstance& g = im.gt[e];
          const std::vector<double> bo = Numbers(Key(list[e], "bbox_obj", w), 4, "bbox_obj", w);
          const std::vector<double> bv = Numbers(Key(list[e], "bbox_visib", w), 4, "bbox_visib", w);
          std::copy(bo.begin(), bo.end(), g.bbox_obj);
          std::copy(bv.begin(), bv.end(), g.bbox_visib);
          g.visib_fract = Number(Key(list[e], "visib_fract", w), "visib_fract", w);
          if (g.visib_fract < 0 || g.visib_fract > 1) w.Fail("visib_fract must be in [0, 1]");
          g.has_info = true;
        }
      }
    }
    for (auto& [id, im] : images) ds.images.push_back(std::move(im));
  }
  if (ds.images.empty()) throw Error(split_dir.string() + ": no scene folder (6-digit name) with images");
  FinishTargets(&ds, targets_path, (fs::path(root) / "test_targets_bop19.json").string());
  return ds;
}

// ---- YCB-Video folder ----------------------------------------------------------------------------

Dataset ReadYcbvFolder(const std::string& root, const std::string& targets_path) {
  Dataset ds;
  ds.root = root;
  ds.format = "ycbv";
  std::error_code ec;
  const fs::path models_dir = fs::path(root) / "models", scenes_dir = fs::path(root) / "scenes";
  if (!fs::is_directory(models_dir, ec)) throw Error(models_dir.string() + ": models folder not found");
  if (!fs::is_directory(scenes_dir, ec)) throw Error(scenes_dir.string() + ": scenes folder not found");

  std::vector<fs::path> plys;
  for (const auto& e : fs::directory_iterator(models_dir, ec))
    if (e.is_regular_file() && e.path().extension() == ".ply") plys.push_back(e.path());
  std::sort(plys.begin(), plys.end());
  if (plys.empty()) throw Error(models_dir.string() + ": no .ply models");
  const std::vector<std::string> ycbv = YcbVideoClassNames();
  int next_id = static_cast<int>(ycbv.size()) + 1;
  for (const auto& p : plys) {
    DatasetModel m;
    m.name = p.stem().string();
    const auto it = std::find(ycbv.begin(), ycbv.end(), m.name);
    m.obj_id = it != ycbv.end() ? static_cast<int>(it - ycbv.begin()) + 1 : next_id++;
    m.mesh_path = p.string();
    m.mesh_unit_scale = 1;
    const fs::path pts = models_dir / "points" / (m.name + ".xyz");
    if (fs::exists(pts, ec)) m.points_path = pts.string();
    ds.models.push_back(std::move(m));
  }
  std::sort(ds.models.begin(), ds.models.end(), [](const auto& a, const auto& b) { return a.obj_id < b.obj_id; });

  std::set<std::string> used_models;
  const std::vector<fs::path> scene_dirs = SortedSubdirs(scenes_dir);
  for (std::size_t k = 0; k < scene_dirs.size(); ++k) {
    const fs::path& dir = scene_dirs[k];
    const std::string name = dir.filename().string();
    DatasetImage im;
    // "<anything>_<scene digits>_<image digits>" → (scene, image); else (0, position).
    const auto u2 = name.rfind('_');
    const auto u1 = u2 == std::string::npos || u2 == 0 ? std::string::npos : name.rfind('_', u2 - 1);
    const std::string s1 = u1 == std::string::npos ? "" : name.substr(u1 + 1, u2 - u1 - 1);
    const std::string s2 = u2 == std::string::npos ? "" : name.substr(u2 + 1);
    if (IsAllDigits(s1) && IsAllDigits(s2) && s1.size() < 9 && s2.size() < 9) {
      im.scene_id = std::stoi(s1);
      im.im_id = std::stoi(s2);
    } else {
      im.scene_id = 0;
      im.im_id = static_cast<int>(k) + 1;
    }
    const std::string cam_path = (dir / "camera.json").string();
    const CameraFile cam = ReadCameraJson(cam_path);
    im.camera = cam.camera;
    im.depth_scale_m = cam.depth_scale;
    im.depth_path = (dir / "depth.png").string();
    const std::string gt_path = (dir / "gt.json").string();
    if (fs::exists(gt_path, ec)) {
      const std::vector<GtObject> gt = ReadGtJson(gt_path);
      im.has_gt = true;
      im.gt_source = gt_path;
      for (std::size_t e = 0; e < gt.size(); ++e) {
        const DatasetModel* m = ds.ModelByName(gt[e].obj);
        if (!m)
          throw Error(gt_path + ": objects[" + std::to_string(e) + "]: obj '" + gt[e].obj + "' has no model " +
                      (models_dir / (gt[e].obj + ".ply")).string());
        used_models.insert(m->name);
        GtInstance g;
        g.obj_id = m->obj_id;
        g.T_cam_obj = gt[e].T_cam_obj;
        im.gt.push_back(g);
      }
    }
    if (const DatasetImage* other = ds.Image(im.scene_id, im.im_id))
      throw Error(dir.string() + ": scene " + std::to_string(im.scene_id) + " image " + std::to_string(im.im_id) +
                  " already used by " + fs::path(other->depth_path).parent_path().string());
    ds.images.push_back(std::move(im));
    std::sort(ds.images.begin(), ds.images.end(), [](const auto& a, const auto& b) {
      return std::make_pair(a.scene_id, a.im_id) < std::make_pair(b.scene_id, b.im_id);
    });
  }
  if (ds.images.empty()) throw Error(scenes_dir.string() + ": no scene folders");

  // Diameters (metres): over the official points when present, else the mesh's.
  for (auto& m : ds.models) {
    if (!m.points_path.empty()) {
      const std::vector<Eigen::Vector3f> pts = ReadXyzPoints(m.points_path);
      // Squared distances in float (as Eigen's squaredNorm of the difference, same order), in
      // plain arrays so that the O(n²) loop is fast in builds that do not inline Eigen.
      const std::size_t n = pts.size();
      std::vector<float> x(n), y(n), z(n);
      for (std::size_t i = 0; i < n; ++i) x[i] = pts[i].x(), y[i] = pts[i].y(), z[i] = pts[i].z();
      float d2 = 0;
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
          const float dx = x[i] - x[j], dy = y[i] - y[j], dz = z[i] - z[j];
          const float e = dx * dx + dy * dy + dz * dz;
          if (e > d2) d2 = e;
        }
      m.diameter_m = std::sqrt(double(d2));
    } else if (used_models.count(m.name)) {
      m.diameter_m = LoadDatasetMesh(m).Diameter();
    }
    if (used_models.count(m.name) && !(m.diameter_m > 0))
      throw Error(m.mesh_path + ": model '" + m.name + "' has zero diameter");
  }
  FinishTargets(&ds, targets_path, "");
  return ds;
}

Dataset OpenDataset(const std::string& root, const std::string& split, const std::string& targets_path) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw Error(root + ": dataset folder not found");
  if (fs::exists(fs::path(root) / "models" / "models_info.json", ec) && !split.empty() &&
      fs::is_directory(fs::path(root) / split, ec))
    return ReadBopDataset(root, split, targets_path);
  if (fs::is_directory(fs::path(root) / "scenes", ec) && fs::is_directory(fs::path(root) / "models", ec))
    return ReadYcbvFolder(root, targets_path);
  if (fs::exists(fs::path(root) / "models" / "models_info.json", ec))
    return ReadBopDataset(root, split, targets_path);  // names the missing split folder
  throw Error(root + ": neither a BOP dataset (models/models_info.json + <split>/) nor a YCB-Video folder "
                     "(scenes/ + models/)");
}

SceneInput LoadDatasetScene(const DatasetImage& image) {
  const std::string where = "scene " + std::to_string(image.scene_id) + ", image " + std::to_string(image.im_id);
  SceneInput s;
  try {
    // A camera without a size (no camera.json) takes the PNG's; otherwise the header must match.
    s.depth = LoadDepthPng(image.depth_path, image.depth_scale_m, image.camera.width, image.camera.height);
  } catch (const Error& e) {
    throw Error(where + ": " + e.what());
  }
  s.camera = image.camera;
  if (s.camera.width == 0 && s.camera.height == 0) {
    s.camera.width = s.depth.width;
    s.camera.height = s.depth.height;
  } else if (s.camera.width != s.depth.width || s.camera.height != s.depth.height) {
    throw Error(image.depth_path + ": " + where + ": depth is " + std::to_string(s.depth.width) + "x" +
                std::to_string(s.depth.height) + ", the camera " + std::to_string(s.camera.width) + "x" +
                std::to_string(s.camera.height));
  }
  return s;
}

Mesh LoadDatasetMesh(const DatasetModel& model) {
  Mesh m = LoadMesh(model.mesh_path, model.mesh_unit_scale);
  m.name = model.name;
  return m;
}

std::vector<Eigen::Vector3f> LoadDatasetPoints(const DatasetModel& model, int max_points) {
  if (!model.points_path.empty()) return ReadXyzPoints(model.points_path);
  return SamplePoints(LoadDatasetMesh(model), max_points);
}

}  // namespace posefilter
