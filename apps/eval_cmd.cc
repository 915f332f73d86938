// apps/eval_cmd.cc — `posefilter eval`: compare a results JSON with a gt.json (the metrics:
// docs/DATASETS.md, "Metrics").
//
// For every ground-truth object: ADD, ADD-S (mm), rotation error (deg), translation error (mm),
// the model diameter (mm) and whether ADD / ADD-S are below threshold·diameter; then the recalls
// (fraction of gt objects accepted). A gt object with no result of its name counts as a failure
// ("missing"). With several instances of one name, the i-th gt instance is compared with the
// i-th result of that name (file order); results left over are listed as unmatched.
//
// Dataset mode (--dataset DIR [--split test] --results results.csv): a BOP results CSV against
// a dataset's ground truth (bop.h: BOP split or YCB-Video folder) on its targets: per object and
// overall the ADD / ADD-S recall at threshold·diameter, the YCB-Video AUC of ADD and ADD-S, the
// BOP 2019 VSD / MSSD / MSPD recalls and AR (bop_metrics.h).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "posefilter/bop.h"
#include "posefilter/bop_metrics.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mesh.h"
#include "posefilter/metrics.h"
#include "posefilter/scene_io.h"

namespace posefilter::cli {
namespace {

// Largest number of mesh vertices used as model points when no --points file is given.
constexpr int kMaxMeshPoints = 2000;

// NAME=PATH arguments of `option` by name (ParseNamedPaths, names required).
std::map<std::string, std::string> ParseNamePaths(const std::vector<std::string>& values, const std::string& option) {
  std::map<std::string, std::string> out;
  for (const auto& [name, path] : ParseNamedPaths(values, option, /*require_name=*/true)) out[name] = path;
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

// JSON number, or null when not finite (∞ = no estimate).
nlohmann::json Finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json ScoresJson(const BopScores& s) {
  return {{"obj_id", s.obj_id},           {"name", s.name},
          {"diameter_mm", s.diameter_m * 1e3}, {"n_instances", s.n_instances},
          {"n_estimated", s.n_estimated}, {"add_recall", s.add_recall},
          {"adds_recall", s.adds_recall}, {"auc_add", s.auc_add},
          {"auc_adds", s.auc_adds},       {"vsd_recall", Finite(s.vsd_recall)},
          {"mssd_recall", s.mssd_recall}, {"mspd_recall", s.mspd_recall},
          {"ar", Finite(s.ar)}};
}

void PrintBopTable(std::ostream& os, const BopEvalReport& rep) {
  std::size_t name_w = 3;
  for (const auto& o : rep.objects) name_w = std::max(name_w, o.name.size());
  const std::vector<std::string> heads = {"n",       "est",     "ADD",  "ADD-S", "AUC ADD", "AUC ADD-S",
                                          "VSD",     "MSSD",    "MSPD", "AR"};
  os << Pad("obj", name_w, true);
  for (const auto& h : heads) os << "  " << Pad(h, std::max<std::size_t>(h.size(), 5), false);
  os << "\n";
  auto row = [&](const BopScores& s) {
    auto f = [](double v) { return std::isfinite(v) ? Fixed(v, 3) : std::string("-"); };
    const std::vector<std::string> cells = {std::to_string(s.n_instances), std::to_string(s.n_estimated),
                                            f(s.add_recall), f(s.adds_recall), f(s.auc_add), f(s.auc_adds),
                                            f(s.vsd_recall), f(s.mssd_recall), f(s.mspd_recall), f(s.ar)};
    os << Pad(s.name, name_w, true);
    for (std::size_t c = 0; c < heads.size(); ++c)
      os << "  " << Pad(cells[c], std::max<std::size_t>(heads[c].size(), 5), false);
    os << "\n";
  };
  for (const auto& o : rep.objects) row(o);
  row(rep.overall);
}

// `posefilter eval --dataset`: the BOP / YCB-Video evaluation of a results CSV.
void RunDatasetEval(const std::string& dataset_dir, const std::string& split, const std::string& targets_path,
                    const std::string& results_path, const std::string& json_path, double threshold,
                    double vsd_delta_mm, bool no_vsd, bool quiet, int limit) {
  if (!std::isfinite(vsd_delta_mm) || vsd_delta_mm < 0)
    throw Error("--vsd-delta must be a finite number ≥ 0 (millimetres), got " + std::to_string(vsd_delta_mm));
  Dataset ds = OpenDataset(dataset_dir, split, targets_path);
  if (ds.targets.empty()) throw Error(dataset_dir + ": no targets to evaluate");
  if (limit > 0) {  // the first `limit` images with targets (targets are in image order)
    std::vector<DatasetTarget> kept;
    int images = 0;
    for (std::size_t i = 0; i < ds.targets.size(); ++i) {
      const bool new_image = i == 0 || ds.targets[i].scene_id != ds.targets[i - 1].scene_id ||
                             ds.targets[i].im_id != ds.targets[i - 1].im_id;
      if (new_image && ++images > limit) break;
      kept.push_back(ds.targets[i]);
    }
    ds.targets = kept;
  }
  const std::vector<BopResult> results = ReadBopResultsCsv(results_path);
  BopEvalOptions eo;
  eo.add_threshold = threshold;
  eo.vsd_delta_m = vsd_delta_mm * 1e-3;
  eo.compute_vsd = !no_vsd;
  EvalProgressFn progress;
  if (!quiet && isatty(fileno(stderr)))
    progress = [](int done, int total) {
      std::fprintf(stderr, "\reval: %d/%d images", done, total);
      if (done == total) std::fprintf(stderr, "\n");
      std::fflush(stderr);
    };
  BopEvalReport rep;
  try {
    rep = EvaluateBop(ds, results, eo, progress);
  } catch (const Error& e) {
    // Errors about result rows start with "results:"; name the CSV there.
    const std::string what = e.what();
    if (what.rfind("results: ", 0) == 0) throw Error(results_path + ": " + what.substr(9));
    throw;
  }

  PrintBopTable(std::cout, rep);
  std::cout << "ADD, ADD-S: recall at " << Fixed(threshold, 3) << "·diameter; AUC: YCB-Video area under the "
            << "accuracy curve up to " << Fixed(eo.auc_max_m * 1e3, 0) << " mm; VSD, MSSD, MSPD: BOP 2019 recalls"
            << (no_vsd ? " (VSD off)" : "") << "; AR = mean of the three\n";
  std::cout << rep.n_results_used << " of " << rep.n_results << " result row(s) used (top inst_count per target); "
            << rep.overall.n_instances - rep.overall.n_estimated << " of " << rep.overall.n_instances
            << " gt instance(s) without an estimate (failures)\n";
  if (rep.mean_time_s >= 0) std::cout << "mean time per image: " << Fixed(rep.mean_time_s, 3) << " s\n";

  if (json_path.empty()) return;
  nlohmann::json j;
  j["dataset"] = dataset_dir;
  j["format"] = ds.format;
  j["split"] = ds.split;
  j["targets"] = ds.targets_source;
  j["results"] = results_path;
  j["add_threshold"] = threshold;
  j["vsd_delta_mm"] = vsd_delta_mm;
  j["vsd_taus"] = eo.vsd_taus;
  j["vsd_thresholds"] = eo.vsd_thresholds;
  j["mssd_thresholds"] = eo.mssd_thresholds;
  j["mspd_thresholds_px_at_640"] = eo.mspd_thresholds_px;
  j["auc_max_mm"] = eo.auc_max_m * 1e3;
  j["n_results"] = rep.n_results;
  j["n_results_used"] = rep.n_results_used;
  j["mean_time_per_image_s"] = rep.mean_time_s;
  j["overall"] = ScoresJson(rep.overall);
  j["objects"] = nlohmann::json::array();
  for (const auto& o : rep.objects) j["objects"].push_back(ScoresJson(o));
  j["instances"] = nlohmann::json::array();
  for (const auto& t : rep.instances) {
    nlohmann::json v = nlohmann::json::array();
    for (double e : t.vsd) v.push_back(e);
    j["instances"].push_back({{"scene_id", t.scene_id},
                              {"im_id", t.im_id},
                              {"obj_id", t.obj_id},
                              {"gt_index", t.gt_index},
                              {"estimated", t.estimated},
                              {"add_mm", Finite(t.add_m * 1e3)},
                              {"adds_mm", Finite(t.adds_m * 1e3)},
                              {"mssd_mm", Finite(t.mssd_m * 1e3)},
                              {"mspd_px", Finite(t.mspd_px)},
                              {"vsd", v}});
  }
  WriteFileAtomically(json_path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

// The parsed command line of `eval`.
struct EvalArgs {
  std::string results_path, gt_path, json_path, dataset_dir, split = "test", targets_path;
  double vsd_delta_mm = 15;
  bool no_vsd = false, quiet = false;
  int limit = -1;
  std::vector<std::string> mesh_specs, point_specs;
  double threshold = 0.1;
  double unit_scale = 1.0;
  CLI::Option *gt_opt = nullptr, *dataset_opt = nullptr;
};

// Every option of `eval` on `app`, into *a.
void AddEvalOptions(CLI::App& app, EvalArgs* a) {
  std::string &results_path = a->results_path, &gt_path = a->gt_path, &json_path = a->json_path,
              &dataset_dir = a->dataset_dir, &split = a->split, &targets_path = a->targets_path;
  double &vsd_delta_mm = a->vsd_delta_mm, &threshold = a->threshold, &unit_scale = a->unit_scale;
  bool &no_vsd = a->no_vsd, &quiet = a->quiet;
  int& limit = a->limit;
  std::vector<std::string> &mesh_specs = a->mesh_specs, &point_specs = a->point_specs;
  app.add_option("--results", results_path,
                 "results.json written by posefilter estimate (with --dataset: a BOP results CSV)")
      ->required();
  CLI::Option* gt_opt = a->gt_opt = app.add_option("--gt", gt_path, "gt.json: {objects: [{obj, R, t}]}, object → camera, metres");
  CLI::Option* dataset_opt = a->dataset_opt = app.add_option("--dataset", dataset_dir,
                                     "dataset folder (BOP or YCB-Video): evaluate a results CSV on its targets");
  app.add_option("--split", split, "BOP split of --dataset")->capture_default_str();
  app.add_option("--targets", targets_path,
                 "targets JSON of --dataset (default: test_targets_bop19.json if present, else every gt object)");
  app.add_option("--vsd-delta", vsd_delta_mm, "VSD visibility tolerance delta, millimetres (--dataset)")
      ->capture_default_str();
  app.add_flag("--no-vsd", no_vsd, "skip VSD (no renderings; VSD recall and AR not reported) (--dataset)");
  app.add_flag("--quiet", quiet, "no progress on stderr (--dataset)");
  app.add_option("--limit", limit, "only the first N images with targets (--dataset; as run-dataset --limit)");
  gt_opt->excludes(dataset_opt);
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
  app.callback([&app, gt_opt, dataset_opt] {
    if (gt_opt->count() == 0 && dataset_opt->count() == 0) throw CLI::RequiredError("--gt (or --dataset)");
    if (dataset_opt->count() > 0)
      for (const char* o : {"--mesh", "--points", "--unit-scale"})
        if (app.count(o) > 0)
          throw CLI::ValidationError(o, "not used with --dataset (the dataset has the models)");
  });
}

// Each gt object's model: the diameter of its --mesh, and its ADD points (--points, else the
// mesh's).
std::map<std::string, Model> LoadEvalModels(const std::vector<GtObject>& gt, const std::map<std::string, std::string>& mesh_paths,
                                            const std::map<std::string, std::string>& point_paths, double unit_scale) {
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
  return models;
}

// The rows: the i-th gt instance of a name ↔ the i-th result of that name; *unmatched receives
// the results without a gt object.
std::vector<Row> MatchEvalRows(const std::vector<GtObject>& gt, const std::vector<ObjectResult>& results,
                               const std::map<std::string, Model>& models, double threshold,
                               const std::string& results_path, std::vector<std::string>* unmatched) {
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
  for (std::size_t i = 0; i < results.size(); ++i)
    if (!used[i]) unmatched->push_back(results[i].obj);
  return rows;
}

// --json of a results JSON's evaluation: the recalls and each object's errors.
void WriteEvalJson(const EvalArgs& a, const std::vector<Row>& rows, const std::map<std::string, Model>& models,
                   int n_missing, double recall_add, double recall_adds, const std::vector<std::string>& unmatched) {
  nlohmann::json j;
  j["results"] = a.results_path;
  j["gt"] = a.gt_path;
  j["threshold"] = a.threshold;
  j["n_objects"] = static_cast<int>(rows.size());
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
  WriteFileAtomically(a.json_path, [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

// A results JSON against a gt.json (--gt): the table, the recalls, and --json.
void EvalResultsJson(const EvalArgs& a) {
  if (!std::isfinite(a.threshold) || a.threshold <= 0)
    throw Error("--threshold must be a finite number > 0 (fraction of the diameter), got " +
                std::to_string(a.threshold));
  if (!std::isfinite(a.unit_scale) || a.unit_scale <= 0)
    throw Error("--unit-scale must be a finite number > 0, got " + std::to_string(a.unit_scale));
  const auto mesh_paths = ParseNamePaths(a.mesh_specs, "--mesh");
  const auto point_paths = ParseNamePaths(a.point_specs, "--points");

  const std::vector<GtObject> gt = ReadGtJson(a.gt_path);
  if (gt.empty()) throw Error(a.gt_path + ": no objects to evaluate");
  const std::vector<ObjectResult> results = ReadResultsJson(a.results_path);

  // Check every gt object has a mesh before loading anything.
  for (const auto& g : gt)
    if (!mesh_paths.count(g.obj))
      throw Error("no --mesh NAME=PATH for gt object '" + g.obj + "' (" + a.gt_path + ")");
  const std::map<std::string, Model> models = LoadEvalModels(gt, mesh_paths, point_paths, a.unit_scale);
  std::vector<std::string> unmatched;
  const std::vector<Row> rows = MatchEvalRows(gt, results, models, a.threshold, a.results_path, &unmatched);

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
  const std::string at = " @ " + Fixed(a.threshold, 3) + "·diameter: ";
  std::cout << "ADD recall" << at << Fixed(recall_add, 3) << " (" << n_add << "/" << n << ")\n"
            << "ADD-S recall" << at << Fixed(recall_adds, 3) << " (" << n_adds << "/" << n << ")\n";
  if (n_missing > 0) std::cout << n_missing << " gt object(s) without a result (counted as failures)\n";
  if (!unmatched.empty()) {
    std::cout << "results without a gt object (ignored):";
    for (const auto& u : unmatched) std::cout << " " << u;
    std::cout << "\n";
  }
  if (!a.json_path.empty()) WriteEvalJson(a, rows, models, n_missing, recall_add, recall_adds, unmatched);
}

}  // namespace

int RunEval(int argc, char** argv) {
  CLI::App app{"Compare a results JSON (posefilter estimate) with a gt.json: ADD, ADD-S, "
               "rotation/translation errors and recall at threshold·diameter; or (--dataset) a BOP results "
               "CSV with a dataset: ADD/ADD-S recall and AUC, VSD/MSSD/MSPD recall, AR.",
               "eval"};
  EvalArgs a;
  AddEvalOptions(app, &a);
  return RunApp(app, argc, argv, [&] {
    {
      std::vector<NamedPath> inputs = {{a.results_path, "--results"}, {a.gt_path, "--gt"}, {a.targets_path, "--targets"},
                                       {a.dataset_dir, "--dataset"}};
      for (const auto& spec : a.mesh_specs) inputs.push_back({spec.substr(spec.find('=') + 1), "--mesh"});
      for (const auto& spec : a.point_specs) inputs.push_back({spec.substr(spec.find('=') + 1), "--points"});
      CheckOutputPaths({{a.json_path, "--json"}}, inputs);
    }
    if (a.dataset_opt->count() > 0) {
      if (!std::isfinite(a.threshold) || a.threshold <= 0)
        throw Error("--threshold must be a finite number > 0 (fraction of the diameter), got " +
                    std::to_string(a.threshold));
      if (app.count("--limit") && a.limit < 1) throw Error("--limit must be ≥ 1, got " + std::to_string(a.limit));
      RunDatasetEval(a.dataset_dir, a.split, a.targets_path, a.results_path, a.json_path, a.threshold, a.vsd_delta_mm,
                     a.no_vsd, a.quiet, a.limit);
      return;
    }
    EvalResultsJson(a);
  });
}

}  // namespace posefilter::cli
