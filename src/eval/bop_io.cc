// eval/bop_io.cc — BOP datasets, the YCB-Video folder, BOP detections and the results CSV
// (bop.h). Readers are strict: every value they use must be present, of the right type and
// finite; every error is one line "<file>: <entry>: <what>".
#include "posefilter/bop.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>
#include <tuple>

#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/metrics.h"
#include "posefilter/projection.h"

namespace posefilter {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// "R is a rotation" tolerance (max |RᵀR − I|), as scene_io.cc uses for gt.json.
constexpr double kRotationTolerance = 1e-3;
// Two rows of one image may differ in time by at most this (seconds), as the BOP toolkit allows.
constexpr double kTimeTolerance = 1e-3;
// Smallest width/height of a jittered ground-truth box, pixels (as gt-detections).
constexpr double kMinBoxPx = 4;

// Where a value comes from: the file and the entry inside it, for error messages.
struct Where {
  std::string file;
  std::string entry;  // "image 3, entry 1" or ""
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error(file + ": " + (entry.empty() ? std::string() : entry + ": ") + what);
  }
  Where Sub(const std::string& more) const { return {file, entry.empty() ? more : entry + ", " + more}; }
};

// A dataset's JSON file: a regular file of at most kMaxSmallFileBytes (ReadSmallFile).
json ReadJson(const std::string& path) {
  const std::string text = ReadSmallFile(path, kMaxSmallFileBytes, "JSON");
  try {
    return NameOutOfMemory(path, "JSON", [&] { return json::parse(text); });
  } catch (const json::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw Error(path + ": malformed JSON: " + what);
  }
}

void WriteJson(const json& j, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << j.dump(1) << "\n"; });
}

const json& Key(const json& obj, const char* key, const Where& w) {
  if (!obj.is_object()) w.Fail("must be a JSON object");
  const auto it = obj.find(key);
  if (it == obj.end()) w.Fail(std::string("missing key \"") + key + "\"");
  return *it;
}

double Number(const json& j, const std::string& what, const Where& w) {
  if (!j.is_number()) w.Fail(what + " must be a finite number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) w.Fail(what + " must be a finite number");
  return v;
}

int Integer(const json& j, const std::string& what, const Where& w) {
  const double v = Number(j, what, w);
  if (v != std::floor(v) || std::abs(v) > 2e9) w.Fail(what + " must be an integer");
  return static_cast<int>(v);
}

std::vector<double> Numbers(const json& j, std::size_t n, const std::string& what, const Where& w) {
  if (!j.is_array() || j.size() != n) w.Fail(what + " must be an array of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(Number(j[i], what + "[" + std::to_string(i) + "]", w));
  return v;
}

// A JSON object key that must be a non-negative integer ("12" → 12).
int IdKey(const std::string& key, const std::string& what, const Where& w) {
  int v = -1;
  const auto [ptr, ec] = std::from_chars(key.data(), key.data() + key.size(), v);
  if (key.empty() || ec != std::errc() || ptr != key.data() + key.size() || v < 0)
    w.Fail("key \"" + key + "\" is not " + what);
  return v;
}

std::string Digits6(int id) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06d", id);
  return buf;
}

// Row-major 3×3 (+ t) → isometry; R must be a rotation.
Eigen::Isometry3d MakePose(const std::vector<double>& r9, const Eigen::Vector3d& t_m, const std::string& what,
                           const Where& w) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = r9[i];
  const double ortho = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (ortho > kRotationTolerance || R.determinant() < 0)
    w.Fail(what + " is not a rotation matrix (|RᵀR − I| = " + std::to_string(ortho) + ")");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t_m;
  return T;
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

// ---- Writing -----------------------------------------------------------------------------------

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

// ---- Detections --------------------------------------------------------------------------------

std::vector<BopDetection> ReadBopDetections(const std::string& path) {
  const json root = ReadJson(path);
  const Where file{path, ""};
  const json* list = &root;
  if (root.is_object() && root.contains("detections")) list = &root["detections"];
  if (!list->is_array()) file.Fail("must be a JSON array of {scene_id, image_id, category_id, bbox, score}");
  std::vector<BopDetection> out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& e = (*list)[i];
    const Where w = file.Sub("entry " + std::to_string(i));
    BopDetection d;
    d.scene_id = Integer(Key(e, "scene_id", w), "scene_id", w);
    d.im_id = Integer(Key(e, "image_id", w), "image_id", w);
    d.obj_id = Integer(Key(e, "category_id", w), "category_id", w);
    d.score = Number(Key(e, "score", w), "score", w);
    if (d.score < 0 || d.score > 1) w.Fail("score must be in [0, 1]");
    const std::vector<double> b = Numbers(Key(e, "bbox", w), 4, "bbox", w);
    d.x = b[0];
    d.y = b[1];
    d.w = b[2];
    d.h = b[3];
    if (!(d.w > 0 && d.h > 0)) w.Fail("bbox width and height must be > 0");
    if (const auto it = e.find("time"); it != e.end()) d.time_s = Number(*it, "time", w);
    out.push_back(d);
  }
  return out;
}

std::vector<Detection> ToPriorDetections(const std::vector<BopDetection>& detections, const Dataset& dataset,
                                         const std::string& source) {
  std::vector<Detection> out;
  for (const auto& d : detections) {
    const DatasetModel* m = dataset.Model(d.obj_id);
    if (!m)
      throw Error(source + ": scene " + std::to_string(d.scene_id) + ", image " + std::to_string(d.im_id) +
                  ": category_id " + std::to_string(d.obj_id) + " has no model in the dataset");
    out.push_back({m->name, d.score, d.x, d.y, d.w, d.h});
  }
  return out;
}

GtBoxDetection JitteredGtBox(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera,
                             const std::string& cls, double jitter_px, double score, Rng& rng) {
  if (!std::isfinite(jitter_px) || jitter_px < 0) throw Error("gt boxes: jitter must be finite and ≥ 0 pixels");
  if (!std::isfinite(score) || score < 0 || score > 1) throw Error("gt boxes: score must be in [0, 1]");
  const double jx = rng.Normal(), jy = rng.Normal(), jw = rng.Normal(), jh = rng.Normal();
  GtBoxDetection out;
  out.silhouette = ProjectedBox(mesh, T_cam_obj, camera);
  const Box& box = out.silhouette;
  out.in_view = box.w > 0 && box.h > 0;
  if (!out.in_view) return out;
  Box b = box;
  b.cx += std::clamp(jitter_px * jx, -0.25 * box.w, 0.25 * box.w);
  b.cy += std::clamp(jitter_px * jy, -0.25 * box.h, 0.25 * box.h);
  b.w = std::max(kMinBoxPx, box.w + jitter_px * jw);
  b.h = std::max(kMinBoxPx, box.h + jitter_px * jh);
  out.detection = {cls, score, b.cx - b.w / 2, b.cy - b.h / 2, b.w, b.h};
  return out;
}

// ---- Results CSV -------------------------------------------------------------------------------

std::string FormatBopCsvRow(const BopResult& r) {
  std::string s = std::to_string(r.scene_id) + "," + std::to_string(r.im_id) + "," + std::to_string(r.obj_id) + ",";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f,", r.score);
  s += buf;
  const Eigen::Matrix3d R = r.T_cam_obj.linear();
  for (int i = 0; i < 9; ++i) {
    std::snprintf(buf, sizeof buf, i < 8 ? "%.9g " : "%.9g,", R(i / 3, i % 3));
    s += buf;
  }
  const Eigen::Vector3d t = r.T_cam_obj.translation() * 1e3;
  std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f,", t.x(), t.y(), t.z());
  s += buf;
  std::snprintf(buf, sizeof buf, "%.6f", r.time_s);
  return s + buf;
}

namespace {

std::vector<std::string> SplitOn(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (true) {
    const auto e = s.find(sep, b);
    out.push_back(s.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return out;
}

std::vector<std::string> SplitSpaces(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string tok; in >> tok;) out.push_back(tok);
  return out;
}

double ParseDouble(const std::string& tok, const std::string& what, const Where& w) {
  double v = 0;
  const char* first = tok.data();
  const char* last = first + tok.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (tok.empty() || ec != std::errc() || ptr != last) w.Fail(what + ": not a number: '" + tok + "'");
  if (!std::isfinite(v)) w.Fail(what + ": non-finite value '" + tok + "'");
  return v;
}

int ParseInt(const std::string& tok, const std::string& what, const Where& w) {
  int v = 0;
  const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (tok.empty() || ec != std::errc() || ptr != tok.data() + tok.size() || v < 0)
    w.Fail(what + ": not a non-negative integer: '" + tok + "'");
  return v;
}

}  // namespace

std::vector<BopResult> ReadBopResultsCsv(const std::string& path) {
  CheckInputFile(path, kMaxResultsCsvBytes, "results CSV");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open results CSV");
  std::vector<BopResult> out;
  std::map<std::pair<int, int>, std::pair<double, int>> times;  // image → (time, first line)
  std::string line;
  int line_no = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const Where w{path, "line " + std::to_string(line_no)};
    if (!header) {
      if (line != kBopCsvHeader) w.Fail(std::string("header must be exactly \"") + kBopCsvHeader + "\"");
      header = true;
      continue;
    }
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const std::vector<std::string> f = SplitOn(line, ',');
    if (f.size() != 7)
      w.Fail("expected 7 fields scene_id,im_id,obj_id,score,R,t,time, got " + std::to_string(f.size()) +
             " (truncated row?)");
    BopResult r;
    r.scene_id = ParseInt(f[0], "scene_id", w);
    r.im_id = ParseInt(f[1], "im_id", w);
    r.obj_id = ParseInt(f[2], "obj_id", w);
    r.score = ParseDouble(f[3], "score", w);
    const std::vector<std::string> rt = SplitSpaces(f[4]), tt = SplitSpaces(f[5]);
    if (rt.size() != 9) w.Fail("R must hold 9 space-separated numbers, got " + std::to_string(rt.size()));
    if (tt.size() != 3) w.Fail("t must hold 3 space-separated numbers (mm), got " + std::to_string(tt.size()));
    std::vector<double> R9;
    for (const auto& tok : rt) R9.push_back(ParseDouble(tok, "R", w));
    Eigen::Vector3d t;
    for (int k = 0; k < 3; ++k) t[k] = ParseDouble(tt[k], "t", w) * 1e-3;
    r.T_cam_obj = MakePose(R9, t, "R", w);
    r.time_s = ParseDouble(f[6], "time", w);
    const auto key = std::make_pair(r.scene_id, r.im_id);
    if (const auto it = times.find(key); it != times.end()) {
      if (std::abs(it->second.first - r.time_s) > kTimeTolerance)
        w.Fail("time " + f[6] + " differs from line " + std::to_string(it->second.second) + " of the same image (" +
               std::to_string(it->second.first) + "); BOP needs one time per image");
    } else {
      times.emplace(key, std::make_pair(r.time_s, line_no));
    }
    out.push_back(r);
  }
  if (in.bad()) throw Error(path + ": read error");
  if (!header) throw Error(path + ": empty file (no header \"" + std::string(kBopCsvHeader) + "\")");
  return out;
}

void WriteBopResultsCsv(const std::vector<BopResult>& results, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << kBopCsvHeader << "\n";
    for (const auto& r : results) out << FormatBopCsvRow(r) << "\n";
  });
}

void AppendBopResultsCsv(const std::vector<BopResult>& results, const std::string& path) {
  std::error_code ec;
  const bool fresh = !fs::exists(path, ec) || fs::file_size(path, ec) == 0;
  if (!fresh) {
    std::ifstream in(path, std::ios::binary);
    in.seekg(-1, std::ios::end);
    char last = 0;
    if (!in.get(last) || last != '\n')
      throw Error(path + ": does not end with a newline (a partly written row?); remove the last line and rerun");
  }
  std::string text;
  if (fresh) text += std::string(kBopCsvHeader) + "\n";
  for (const auto& r : results) text += FormatBopCsvRow(r) + "\n";
  AppendFileDurably(path, text);
}

}  // namespace posefilter
