// apps/eval_cmd.cc — `posefilter eval`: compare a results JSON with a gt.json (SPEC §8).
//
// For every ground-truth object: ADD, ADD-S (mm), rotation error (deg), translation error (mm),
// the model diameter (mm) and whether ADD / ADD-S are below threshold·diameter; then the recalls
// (fraction of gt objects accepted). A gt object with no result of its name counts as a failure
// ("missing"). With several instances of one name, the i-th gt instance is compared with the
// i-th result of that name (file order); results left over are listed as unmatched.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "posefilter/error.h"
#include "posefilter/mesh.h"
#include "posefilter/metrics.h"
#include "posefilter/scene_io.h"

namespace posefilter::cli {
namespace {

// Largest number of mesh vertices used as model points when no --points file is given.
constexpr int kMaxMeshPoints = 2000;

// Parses repeated "NAME=PATH" values of `option` into name → path; throws Error on a value
// without '=', an empty NAME or PATH, or a NAME given twice.
std::map<std::string, std::string> ParseNamePaths(const std::vector<std::string>& values,
                                                  const std::string& option) {
  std::map<std::string, std::string> out;
  for (const auto& v : values) {
    const auto eq = v.find('=');
    if (eq == std::string::npos)
      throw Error(option + ": expected NAME=PATH, got '" + v + "' (no '=')");
    const std::string name = v.substr(0, eq), path = v.substr(eq + 1);
    if (name.empty()) throw Error(option + ": empty NAME in '" + v + "'");
    if (path.empty()) throw Error(option + ": empty PATH in '" + v + "'");
    if (!out.emplace(name, path).second) throw Error(option + ": NAME '" + name + "' given twice");
  }
  return out;
}

struct Model {
  std::vector<Eigen::Vector3f> points;  // object frame, metres
  double diameter = 0;                  // metres (Mesh::Diameter of the mesh)
  std::string points_source;            // the .xyz path, or "mesh"
};

struct Row {
  std::string obj;
  std::optional<PoseErrors> err;  // empty: no result for this gt object
};

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string Pad(const std::string& s, std::size_t width, bool left) {
  if (s.size() >= width) return s;
  const std::string fill(width - s.size(), ' ');
  return left ? s + fill : fill + s;
}

void PrintTable(std::ostream& os, const std::vector<Row>& rows) {
  std::size_t name_w = 3;
  for (const auto& r : rows) name_w = std::max(name_w, r.obj.size());
  const std::vector<std::string> heads = {"ADD (mm)",  "ADD-S (mm)",    "rot err (deg)", "trans err (mm)",
                                          "diam (mm)", "ADD ok",        "ADD-S ok"};
  os << Pad("obj", name_w, true);
  for (const auto& h : heads) os << "  " << Pad(h, std::max<std::size_t>(h.size(), 8), false);
  os << "\n";
  for (const auto& r : rows) {
    std::vector<std::string> cells;
    if (r.err) {
      const PoseErrors& e = *r.err;
      cells = {Fixed(e.add * 1e3, 2),     Fixed(e.adds * 1e3, 2),     Fixed(e.rot_deg, 2),
               Fixed(e.trans_m * 1e3, 2), Fixed(e.diameter * 1e3, 1), e.add_ok ? "yes" : "no",
               e.adds_ok ? "yes" : "no"};
    } else {
      cells = {"missing", "missing", "missing", "missing", "-", "no", "no"};
    }
    os << Pad(r.obj, name_w, true);
    for (std::size_t c = 0; c < heads.size(); ++c)
      os << "  " << Pad(cells[c], std::max<std::size_t>(heads[c].size(), 8), false);
    os << "\n";
  }
}

}  // namespace

int RunEval(int argc, char** argv) {
  CLI::App app{"Compare a results JSON (posefilter estimate) with a gt.json: ADD, ADD-S, "
               "rotation/translation errors and recall at threshold·diameter.",
               "eval"};
  std::string results_path, gt_path, json_path;
  std::vector<std::string> mesh_specs, point_specs;
  double threshold = 0.1;
  double unit_scale = 1.0;
  app.add_option("--results", results_path, "results.json written by posefilter estimate")->required();
  app.add_option("--gt", gt_path, "gt.json: {objects: [{obj, R, t}]}, object → camera, metres")->required();
  app.add_option("--mesh", mesh_specs,
                 "NAME=PATH mesh of an object (repeatable); every gt object needs one. Its "
                 "diameter sets the threshold; its vertices are the model points unless --points")
      ->take_all();
  app.add_option("--points", point_specs,
                 "NAME=PATH.xyz official model points (\"x y z\" metres per line), overriding "
                 "the mesh vertices for ADD/ADD-S (repeatable)")
      ->take_all();
  app.add_option("--threshold", threshold, "acceptance threshold, fraction of the model diameter")
      ->capture_default_str();
  app.add_option("--unit-scale", unit_scale, "factor applied to mesh coordinates (0.001 for mm meshes)")
      ->capture_default_str();
  app.add_option("--json", json_path, "also write the per-object errors and recalls to this JSON file");

  return RunApp(app, argc, argv, [&] {
    if (!std::isfinite(threshold) || threshold <= 0)
      throw Error("--threshold must be a finite number > 0 (fraction of the diameter), got " +
                  std::to_string(threshold));
    if (!std::isfinite(unit_scale) || unit_scale <= 0)
      throw Error("--unit-scale must be a finite number > 0, got " + std::to_string(unit_scale));
    const auto mesh_paths = ParseNamePaths(mesh_specs, "--mesh");
    const auto point_paths = ParseNamePaths(point_specs, "--points");

    const std::vector<GtObject> gt = ReadGtJson(gt_path);
    if (gt.empty()) throw Error(gt_path + ": no objects to evaluate");
    const std::vector<ObjectResult> results = ReadResultsJson(results_path);

    // Check every gt object has a mesh before loading anything.
    for (const auto& g : gt)
      if (!mesh_paths.count(g.obj))
        throw Error("no --mesh NAME=PATH for gt object '" + g.obj + "' (" + gt_path + ")");

    std::map<std::string, Model> models;
    for (const auto& g : gt) {
      if (models.count(g.obj)) continue;
      const Mesh mesh = LoadMesh(mesh_paths.at(g.obj), unit_scale);
      Model m;
      m.diameter = mesh.Diameter();
      if (!std::isfinite(m.diameter) || m.diameter <= 0)
        throw Error(mesh_paths.at(g.obj) + ": mesh of '" + g.obj + "' has zero diameter");
      if (const auto it = point_paths.find(g.obj); it != point_paths.end()) {
        m.points = ReadXyzPoints(it->second);
        m.points_source = it->second;
      } else {
        m.points = SamplePoints(mesh, kMaxMeshPoints);
        m.points_source = "mesh";
      }
      models.emplace(g.obj, std::move(m));
    }

    // i-th gt instance of a name ↔ i-th result of that name.
    std::vector<bool> used(results.size(), false);
    std::vector<Row> rows;
    for (const auto& g : gt) {
      Row row{g.obj, std::nullopt};
      for (std::size_t i = 0; i < results.size(); ++i) {
        if (used[i] || results[i].obj != g.obj) continue;
        used[i] = true;
        const Model& m = models.at(g.obj);
        try {
          row.err = ComputePoseErrors(m.points, m.diameter, results[i].T_cam_obj, g.T_cam_obj, threshold);
        } catch (const Error& e) {
          throw Error(results_path + ": object '" + g.obj + "': " + e.what());
        }
        break;
      }
      rows.push_back(std::move(row));
    }
    std::vector<std::string> unmatched;
    for (std::size_t i = 0; i < results.size(); ++i)
      if (!used[i]) unmatched.push_back(results[i].obj);

    int n_add = 0, n_adds = 0, n_missing = 0;
    for (const auto& r : rows) {
      if (!r.err) ++n_missing;
      if (r.err && r.err->add_ok) ++n_add;
      if (r.err && r.err->adds_ok) ++n_adds;
    }
    const int n = static_cast<int>(rows.size());
    const double recall_add = static_cast<double>(n_add) / n;
    const double recall_adds = static_cast<double>(n_adds) / n;

    PrintTable(std::cout, rows);
    const std::string at = " @ " + Fixed(threshold, 3) + "·diameter: ";
    std::cout << "ADD recall" << at << Fixed(recall_add, 3) << " (" << n_add << "/" << n << ")\n"
              << "ADD-S recall" << at << Fixed(recall_adds, 3) << " (" << n_adds << "/" << n << ")\n";
    if (n_missing > 0) std::cout << n_missing << " gt object(s) without a result (counted as failures)\n";
    if (!unmatched.empty()) {
      std::cout << "results without a gt object (ignored):";
      for (const auto& u : unmatched) std::cout << " " << u;
      std::cout << "\n";
    }

    if (!json_path.empty()) {
      nlohmann::json j;
      j["results"] = results_path;
      j["gt"] = gt_path;
      j["threshold"] = threshold;
      j["n_objects"] = n;
      j["n_missing"] = n_missing;
      j["recall_add"] = recall_add;
      j["recall_adds"] = recall_adds;
      j["objects"] = nlohmann::json::array();
      for (const auto& r : rows) {
        const Model& m = models.at(r.obj);
        nlohmann::json o;
        o["obj"] = r.obj;
        o["status"] = r.err ? "ok" : "missing";
        o["diameter_mm"] = m.diameter * 1e3;
        o["points"] = m.points_source;
        o["n_points"] = m.points.size();
        if (r.err) {
          o["add_mm"] = r.err->add * 1e3;
          o["adds_mm"] = r.err->adds * 1e3;
          o["rot_deg"] = r.err->rot_deg;
          o["trans_mm"] = r.err->trans_m * 1e3;
          o["add_ok"] = r.err->add_ok;
          o["adds_ok"] = r.err->adds_ok;
        } else {
          for (const char* k : {"add_mm", "adds_mm", "rot_deg", "trans_mm"}) o[k] = nullptr;
          o["add_ok"] = false;
          o["adds_ok"] = false;
        }
        j["objects"].push_back(std::move(o));
      }
      j["unmatched_results"] = unmatched;
      std::ofstream out(json_path);
      if (!out) throw Error(json_path + ": cannot open for writing (--json)");
      out << j.dump(2) << "\n";
      out.flush();
      if (!out) throw Error(json_path + ": write failed (--json)");
    }
  });
}

}  // namespace posefilter::cli
