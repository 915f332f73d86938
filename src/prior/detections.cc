// 2D detections: JSON I/O and conversion to a raw pyramid (docs/ALGORITHM.md §2, "Detections →
// prior").
// See include/posefilter/prior.h for the format and the conversion formula.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <nlohmann/json.hpp>

#include "core/option_check.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/prior.h"

namespace posefilter {
namespace {

using nlohmann::json;

// Checks one detection; returns "" when fine, else what is wrong (naming the key).
std::string DetectionProblem(const Detection& d) {
  if (d.cls.empty()) return "key \"class\" is empty";
  if (!std::isfinite(d.score) || d.score < 0 || d.score > 1) {
    return "key \"score\" must be in [0, 1] (got " + std::to_string(d.score) + ")";
  }
  if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.w) || !std::isfinite(d.h)) {
    return "key \"bbox\" must hold finite numbers";
  }
  if (d.w <= 0 || d.h <= 0) {
    return "key \"bbox\" must have width and height > 0 (got " + std::to_string(d.w) + "×" +
           std::to_string(d.h) + ")";
  }
  return "";
}

double NumberAt(const json& v, const std::string& where) {
  if (!v.is_number()) throw Error(where + " is not a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw Error(where + " is not finite");
  return x;
}

}  // namespace

Box DetectionBox(const Detection& d) { return Box{d.x + d.w / 2, d.y + d.h / 2, d.w, d.h}; }

std::vector<Detection> ReadDetectionsJson(const std::string& path, bool allow_empty) {
  const std::string text = ReadSmallFile(path, kMaxSmallFileBytes, "detections JSON");
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw Error(path + ": malformed JSON: " + e.what());
  }
  const json* list = &doc;
  if (doc.is_object()) {
    if (!doc.contains("detections")) {
      throw Error(path + ": expected a list of detections or an object with key \"detections\"");
    }
    list = &doc["detections"];
  }
  if (!list->is_array()) {
    throw Error(path + ": key \"detections\" must be a list of detections");
  }
  if (list->empty() && !allow_empty) throw Error(path + " holds no detections");
  std::vector<Detection> out;
  out.reserve(list->size());
  for (size_t i = 0; i < list->size(); ++i) {
    const json& e = (*list)[i];
    const std::string at = path + ": detection " + std::to_string(i);
    if (!e.is_object()) throw Error(at + " is not an object");
    for (const char* key : {"class", "score", "bbox"}) {
      if (!e.contains(key)) throw Error(at + ": missing key \"" + key + "\"");
    }
    Detection d;
    if (!e["class"].is_string()) throw Error(at + ": key \"class\" must be a string");
    d.cls = e["class"].get<std::string>();
    d.score = NumberAt(e["score"], at + ": key \"score\"");
    const json& bb = e["bbox"];
    if (!bb.is_array() || bb.size() != 4) {
      throw Error(at + ": key \"bbox\" must be [x, y, w, h]");
    }
    d.x = NumberAt(bb[0], at + ": key \"bbox\"[0]");
    d.y = NumberAt(bb[1], at + ": key \"bbox\"[1]");
    d.w = NumberAt(bb[2], at + ": key \"bbox\"[2]");
    d.h = NumberAt(bb[3], at + ": key \"bbox\"[3]");
    const std::string problem = DetectionProblem(d);
    if (!problem.empty()) throw Error(at + ": " + problem);
    out.push_back(std::move(d));
  }
  return out;
}

void WriteDetectionsJson(const std::vector<Detection>& detections, const std::string& path) {
  json list = json::array();
  for (size_t i = 0; i < detections.size(); ++i) {
    const Detection& d = detections[i];
    const std::string problem = DetectionProblem(d);
    if (!problem.empty()) {
      throw Error(path + ": detection " + std::to_string(i) + " to write: " + problem);
    }
    list.push_back({{"class", d.cls}, {"score", d.score}, {"bbox", {d.x, d.y, d.w, d.h}}});
  }
  WriteFileAtomically(path, [&](std::ostream& o) { o << json{{"detections", list}}.dump(1) << "\n"; });
}

bool DetectionPriorOptions::IsValid(std::string* why) const {
  if (!std::isfinite(floor_prob) || floor_prob < 1e-6 || floor_prob >= 1) {
    return Fail(why, "floor_prob must be in [1e-6, 1)");
  }
  if (!std::isfinite(max_box_px) || max_box_px < 1) {
    return Fail(why, "max_box_px must be finite and ≥ 1 pixel");
  }
  return true;
}

std::vector<float> DetectionsToRawPyramid(const std::vector<Detection>& detections,
                                          const PyramidLayout& layout,
                                          const std::vector<std::string>& classes,
                                          const DetectionPriorOptions& opt) {
  std::string why;
  if (!layout.IsValid(&why)) throw Error("detection prior: invalid pyramid layout: " + why);
  if (!opt.IsValid(&why)) throw Error("detection prior options: " + why);
  const int nc = layout.num_classes;
  if (int(classes.size()) != nc) {
    throw Error("detection prior: " + std::to_string(classes.size()) +
                " class names given but the layout has num_classes = " + std::to_string(nc));
  }
  if (opt.floor_prob * nc >= 1) {
    throw Error("detection prior options: floor_prob × num_classes must be < 1 (got " +
                std::to_string(opt.floor_prob) + " × " + std::to_string(nc) + ")");
  }
  // Validate and resolve class names.
  std::vector<int> cls_of(detections.size());
  std::vector<Box> box_of(detections.size());
  for (size_t i = 0; i < detections.size(); ++i) {
    const Detection& d = detections[i];
    const std::string problem = DetectionProblem(d);
    if (!problem.empty()) {
      throw Error("detection prior: detection " + std::to_string(i) + ": " + problem);
    }
    const auto it = std::find(classes.begin(), classes.end(), d.cls);
    if (it == classes.end()) {
      throw Error("detection prior: detection " + std::to_string(i) + ": unknown class \"" +
                  d.cls + "\"");
    }
    cls_of[i] = int(it - classes.begin());
    box_of[i] = DetectionBox(d);
  }

  const int cells = layout.CellCount();
  const int per = layout.RawValuesPerCell();
  const double floor = opt.floor_prob;
  std::vector<float> raw(size_t(cells) * per, 0.f);
  std::vector<double> q(nc);
  for (int cell = 0; cell < cells; ++cell) {
    const Box anchor = layout.AnchorBox(cell);
    std::fill(q.begin(), q.end(), floor);
    double best = 0;
    int best_det = -1;
    for (size_t i = 0; i < detections.size(); ++i) {
      const double cover = BoxCoverage(anchor, box_of[i]);
      if (cover <= 0) continue;
      const double s = detections[i].score * cover;
      q[cls_of[i]] = std::max(q[cls_of[i]], s);
      if (best_det < 0 || s > best) {
        best = s;
        best_det = int(i);
      }
    }
    double total = 0;
    for (double v : q) total += v;
    if (total > 1) {
      // Scale the part above the floor so Σ q = 1 (every class keeps its floor).
      const double k = (1 - nc * floor) / (total - nc * floor);
      for (double& v : q) v = floor + (v - floor) * k;
      total = 1;
    }
    float* r = &raw[size_t(cell) * per];
    for (int j = 0; j < nc; ++j) r[j] = float(std::log(q[j]));
    // Background logit: sigmoid(−c) = T ⇒ c = ln((1 − T)/T); clamped to the exp ROM range.
    const double c = total >= 1 ? -16.0 : std::log((1 - total) / total);
    r[nc + 4] = float(std::clamp(c, -16.0, 16.0));
    if (best_det >= 0) EncodeBox(anchor, box_of[best_det], r + nc);
  }
  return raw;
}

std::vector<std::string> ClassesForObjects(const std::vector<std::string>& objects,
                                           const std::vector<Detection>& detections) {
  std::vector<std::string> classes;
  std::set<std::string> seen;
  for (const auto& o : objects)
    if (seen.insert(o).second) classes.push_back(o);
  for (const auto& d : detections)
    if (seen.insert(d.cls).second) classes.push_back(d.cls);
  return classes;
}

std::vector<std::string> CheckDetectionsForObjects(const std::vector<Detection>& detections,
                                                   const std::vector<std::string>& objects, int width, int height,
                                                   const std::string& source) {
  auto on_image = [&](const Detection& d) { return d.x < width && d.y < height && d.x + d.w > 0 && d.y + d.h > 0; };
  std::vector<std::string> warnings;
  for (std::size_t i = 0; i < detections.size(); ++i)
    if (!on_image(detections[i]))
      warnings.push_back(source + ": detection " + std::to_string(i) + " ('" + detections[i].cls +
                         "') lies wholly outside the " + std::to_string(width) + "x" + std::to_string(height) +
                         " image (ignored)");
  std::vector<std::string> missing;
  for (const auto& o : objects)
    if (std::none_of(detections.begin(), detections.end(), [&](const Detection& d) { return d.cls == o && on_image(d); }))
      missing.push_back(o);
  if (!objects.empty() && missing.size() == objects.size()) {
    // Boxes of the objects' classes exist but none lies on the image: that is the cause to name.
    const auto off_image = std::count_if(detections.begin(), detections.end(), [&](const Detection& d) {
      return std::find(objects.begin(), objects.end(), d.cls) != objects.end();
    });
    if (off_image > 0)
      throw Error(source + ": every detection of the objects' classes (" + std::to_string(off_image) +
                  ") lies wholly outside the " + std::to_string(width) + "x" + std::to_string(height) +
                  " image; are the boxes from another image or in other units than pixels?");
    std::set<std::string> classes;
    for (const auto& d : detections) classes.insert(d.cls);
    std::string have, want;
    for (const auto& c : classes) have += (have.empty() ? "" : ", ") + c;
    for (const auto& o : objects) want += (want.empty() ? "" : ", ") + o;
    throw Error(source + ": no detection on the image is of an object's class (objects: " + want +
                "; detection classes: " + have + "); name each object after its detector class");
  }
  for (const auto& o : missing)
    warnings.push_back(source + ": no detection of '" + o + "' on the image; its prior is uniform");
  return warnings;
}

Prior PriorFromDetections(const std::vector<Detection>& detections, const PyramidLayout& layout,
                          const std::vector<std::string>& classes,
                          const DetectionPriorOptions& opt) {
  PostProcessOptions pp;
  pp.max_box_px = opt.max_box_px;
  return PostProcessPyramid(DetectionsToRawPyramid(detections, layout, classes, opt), layout,
                            classes, pp);
}

}  // namespace posefilter
