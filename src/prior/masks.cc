// prior/masks.cc — instance masks as a stage-1 prior (mask_prior.h).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <set>

#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mask_prior.h"

namespace posefilter {

std::map<int, std::string> ReadMaskClasses(const std::string& path) {
  const std::string text = ReadSmallFile(path, kMaxSmallFileBytes, "mask class map");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path + ": malformed mask class map JSON: " + e.what());
  }
  std::map<int, std::string> out;
  auto add = [&](long id, const nlohmann::json& name, const std::string& where) {
    if (id < 1 || id > 65535) throw Error(path + ": mask id " + where + " must be an integer in [1, 65535]");
    if (!name.is_string() || name.get<std::string>().empty())
      throw Error(path + ": the class of mask id " + where + " must be a non-empty string");
    out[int(id)] = name.get<std::string>();
  };
  if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) add(long(i) + 1, j[i], std::to_string(i + 1));
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      std::size_t used = 0;
      long id = -1;
      try {
        id = std::stol(key, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != key.size()) throw Error(path + ": mask id '" + key + "' is not an integer");
      add(id, value, "'" + key + "'");
    }
  } else {
    throw Error(path + ": the mask class map must be a JSON object {\"id\": \"class\"} or a list of classes");
  }
  if (out.empty()) throw Error(path + ": the mask class map is empty");
  return out;
}

std::map<int, std::string> YcbVideoMaskClasses() {
  std::map<int, std::string> out;
  const std::vector<std::string> names = YcbVideoClassNames();
  for (std::size_t i = 0; i < names.size(); ++i) out[int(i) + 1] = names[i];
  return out;
}

std::vector<InstanceMask> MasksFromLabels(const LabelImage& labels, const std::map<int, std::string>& classes,
                                          const std::string& what) {
  const int W = labels.width, H = labels.height;
  std::map<int, InstanceMask> by_id;
  std::set<int> unknown;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const int id = labels.ids[std::size_t(v) * W + u];
      if (id == 0) continue;
      const auto c = classes.find(id);
      if (c == classes.end()) {
        unknown.insert(id);
        continue;
      }
      InstanceMask& m = by_id[id];
      if (m.pixels.empty()) {
        m.id = id;
        m.cls = c->second;
        m.pixels.assign(std::size_t(W) * H, 0);
        m.box = Box{double(u), double(v), double(u), double(v)};  // (u0, v0, u1, v1) while scanning
      }
      m.pixels[std::size_t(v) * W + u] = 1;
      ++m.area;
      m.box.cx = std::min(m.box.cx, double(u));
      m.box.cy = std::min(m.box.cy, double(v));
      m.box.w = std::max(m.box.w, double(u));
      m.box.h = std::max(m.box.h, double(v));
    }
  if (!unknown.empty()) {
    // The first ten ids, then a count: a 16-bit mask can hold thousands.
    constexpr std::size_t kShown = 10;
    std::string ids;
    std::size_t shown = 0;
    for (int id : unknown) {
      if (shown++ == kShown) break;
      ids += (ids.empty() ? "" : ", ") + std::to_string(id);
    }
    if (unknown.size() > kShown) ids += " and " + std::to_string(unknown.size() - kShown) + " more";
    throw Error(what + ": mask id" + (unknown.size() > 1 ? "s " : " ") + ids + " not in the class map");
  }
  if (by_id.empty()) throw Error(what + ": the mask is empty (no pixel holds an instance id)");
  std::vector<InstanceMask> out;
  for (auto& [id, m] : by_id) {
    const double u0 = m.box.cx, v0 = m.box.cy, u1 = m.box.w, v1 = m.box.h;
    m.box = Box{0.5 * (u0 + u1), 0.5 * (v0 + v1), u1 - u0 + 1, v1 - v0 + 1};
    out.push_back(std::move(m));
  }
  return out;
}

Detection MaskDetection(const InstanceMask& mask, double score) {
  return {mask.cls, score, mask.box.cx - mask.box.w / 2, mask.box.cy - mask.box.h / 2, mask.box.w, mask.box.h};
}

}  // namespace posefilter
