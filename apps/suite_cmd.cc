// posefilter suite — the accuracy suites, estimated with the given filter options and scored
// with ADD-S against the ground truth:
//   --world shapes (default): N synthetic scenes of one procedural shape each (targets and
//     occlusion levels in turn, noisy detection prior with false positives);
//   --world ycbv: N table-top scenes of several YCB-Video objects in their stable poses, seen
//     by a structured-light sensor model (table_world.h), every visible object a target,
//     with jittered boxes and false boxes (--prior boxes) or noisy instance masks
//     (--prior masks); per-class recall, AUC of ADD-S and time per object;
//   --world room: the same objects, priors and table in rooms (room_world.h): on small raised
//     surfaces and shelf boards, with floor, walls, furniture and distractors in view.
// Prints a table and the recall at 10% of the diameter; optionally writes it as JSON.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/bop_metrics.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/auto_prior.h"
#include "posefilter/mask_prior.h"
#include "posefilter/metrics.h"
#include "posefilter/room_world.h"
#include "posefilter/estimate_scene.h"
#include "posefilter/stage1.h"
#include "posefilter/synth.h"
#include "posefilter/table_world.h"

namespace posefilter::cli {
namespace {

// The weight of the ground-truth pose T_cam_obj, as the filter weighs it (final thresholds),
// in the best of the cells it could be weighed in: the answer's cell, and every cell whose
// box holds the projection of the object's centre. Above the answer's weight: a search
// failure; below: the score prefers a wrong pose.
double GroundTruthWeight(const SceneInput& input, const Mesh& mesh, const Prior& prior, int cls,
                         const FilterOptions& o, const Eigen::Isometry3d& T_cam_obj, int answer_cell) {
  const Pose6 pose = TransformToPose(input.camera.base_to_camera.inverse() * T_cam_obj);
  const Eigen::Vector3d centre = T_cam_obj * (0.5 * (mesh.Min() + mesh.Max())).cast<double>();
  std::vector<std::pair<Pose6, int>> hyps = {{pose, answer_cell}};
  if (centre.z() > 0) {
    const Eigen::Vector2d uv = input.camera.Project(centre);
    for (int c = 0; c < prior.layout.CellCount(); ++c) {
      const Box& b = prior.boxes[std::size_t(c)];
      if (c != answer_cell && std::fabs(uv.x() - b.cx) <= b.w / 2 && std::fabs(uv.y() - b.cy) <= b.h / 2 && prior.Prob(c, cls) > 1e-4)
        hyps.push_back({pose, c});
    }
  }
  const std::vector<double> w = WeighPoses(input, mesh, prior, cls, o, hyps);
  return *std::max_element(w.begin(), w.end());
}

void WriteJson(const std::string& path, const nlohmann::json& j) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << j.dump(1) << "\n"; });
}

struct TableSuiteArgs {
  std::string models_dir;
  std::string prior_kind;           // "boxes", "masks", "auto" (no detector) or "none" (uniform)
  std::vector<std::string> classes; // classes estimated (empty: all)
  bool scene_pass = true;           // run the joint scene pass over each scene's estimates
  std::string write_dir;
  std::string json_path;
  int count = 0;
  std::uint64_t first_seed = 1;
};

// The table suites' world: its models, classes, ADD-S points and (--prior auto) PPF models.
struct TableSuiteWorld {
  TableWorld world;
  std::vector<std::string> classes;
  // Model points for ADD-S, per model: the dataset's official point sets where present, else the mesh's.
  std::vector<std::vector<Eigen::Vector3f>> points;
  std::map<int, PpfModel> ppf_models;  // --prior auto: per model index, built (or loaded) once
};

// A scene's shared stage 1: its prior, "ok" or why no target is estimated, and the pose seeds
// per class (--prior auto).
struct TableStage1 {
  Prior prior;
  std::string status = "ok";
  std::map<std::string, std::vector<PoseSeed>> seeds_of;
};

// The shared stage 1 of a scene (posefilter/stage1.h) on the world's classes: --prior boxes
// (the scene's detections), none, or auto / auto-regions (regions of the depth, for every
// target class, as `estimate --prior auto` does for its meshes). The auto priors' time goes
// into *stage1_ms.
TableStage1 TableSceneStage1(const TableSuiteArgs& a, TableSuiteWorld& w, const TableScene& scene,
                             std::vector<double>* stage1_ms) {
  Stage1Options so;
  so.classes = w.classes;
  so.what = "--prior " + a.prior_kind;
  std::vector<Stage1Object> wanted;  // each target class once, in the scene's order
  const bool automatic = a.prior_kind == "auto" || a.prior_kind == "auto-regions";
  for (const TableObject& o : scene.objects)
    if (o.target && std::none_of(wanted.begin(), wanted.end(), [&](const Stage1Object& x) { return x.name == o.cls; })) {
      const TableModel& model = w.world.models()[std::size_t(o.model)];
      const PpfModel* ppf = nullptr;
      if (a.prior_kind == "auto") {
        auto it = w.ppf_models.find(o.model);
        if (it == w.ppf_models.end())
          it = w.ppf_models.emplace(o.model, LoadOrBuildPpfModel(model.mesh, {}, DefaultPpfCacheDir())).first;
        ppf = &it->second;
      }
      wanted.push_back({o.cls, &model.mesh, ppf, model.diameter});
    }
  if (automatic) {
    so.kind = Stage1Kind::kAuto;
    so.auto_ppf = a.prior_kind == "auto";
    so.require_candidates = false;
  } else if (a.prior_kind == "none") {
    so.kind = Stage1Kind::kNone;
  } else {
    so.kind = Stage1Kind::kDetections;
    so.detections = scene.detections;
  }
  const auto t_stage1 = std::chrono::steady_clock::now();
  Stage1 s = BuildStage1(SceneInput{scene.depth, scene.camera}, wanted, so);
  TableStage1 out;
  if (automatic) {
    stage1_ms->push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_stage1).count());
    if (s.no_candidates) out.status = "no candidates";
    for (std::size_t k = 0; k < wanted.size(); ++k) out.seeds_of[wanted[k].name] = std::move(s.seeds[k]);
  }
  out.prior = std::move(s.prior);
  return out;
}

// One target of a table scene: its estimate's input and prior, and what became of it.
struct TableJob {
  std::size_t j = 0;  // index in scene.objects
  SceneInput input;
  Prior prior;
  std::string status;
  FilterOptions o;
  EstimateResult r;
  EstimateResult alone;  // before the scene pass
  bool estimated = false;
  double pass_ms = 0;
  std::string pass_note;  // "re-estimated" / "replaced" by the scene pass
};

// Each target of scene `i` (seed `seed`) estimated on its own, then (--scene-pass) the scene
// pass over all of them (posefilter/estimate_scene.h); --prior masks: each target on its own
// mask (posefilter/stage1.h).
std::vector<TableJob> EstimateTableScene(const TableSuiteArgs& a, const TableSuiteWorld& w, const TableScene& scene,
                                         const TableStage1& stage1, const FilterOptions& opt, int i) {
  std::vector<TableJob> jobs;
  for (std::size_t j = 0; j < scene.objects.size(); ++j) {
    const TableObject& obj = scene.objects[j];
    if (!obj.target) continue;
    if (!a.classes.empty() && std::find(a.classes.begin(), a.classes.end(), obj.cls) == a.classes.end()) continue;
    TableJob job;
    job.j = j;
    job.input = SceneInput{scene.depth, scene.camera, {}};
    if (auto it = stage1.seeds_of.find(obj.cls); it != stage1.seeds_of.end()) job.input.seeds = it->second;
    job.prior = stage1.prior;
    job.status = stage1.status;
    if (a.prior_kind == "masks") {
      LabelImage l{scene.camera.width, scene.camera.height, {}};
      l.ids.resize(scene.masks.size());
      for (std::size_t q = 0; q < l.ids.size(); ++q) l.ids[q] = scene.masks[q] == j + 1 ? 1 : 0;
      if (std::count(l.ids.begin(), l.ids.end(), 1) == 0) {
        job.status = "no mask";
      } else {
        Stage1Options so;
        so.kind = Stage1Kind::kMasks;
        so.classes = w.classes;
        so.masks = MasksFromLabels(l, {{1, obj.cls}}, "mask");
        Stage1 s = BuildStage1(job.input, {{obj.cls}}, so);
        job.input.mask = std::move(s.instances.at(0).mask);
        job.prior = std::move(s.instances.at(0).prior);
      }
    }
    job.o = opt;
    job.o.seed = opt.seed + std::uint64_t(i);  // as the scene's estimates below
    jobs.push_back(std::move(job));
  }
  std::vector<SceneEstimateObject> objects;
  std::vector<TableJob*> of;
  for (TableJob& job : jobs) {
    if (job.status != "ok") continue;
    const TableObject& obj = scene.objects[job.j];
    SceneEstimateObject x;
    x.mesh = &w.world.models()[std::size_t(obj.model)].mesh;
    x.cls = job.prior.ClassIndex(obj.cls);
    if (a.prior_kind == "masks") x.own_prior = &job.prior, x.mask = job.input.mask;
    x.seeds = job.input.seeds;
    objects.push_back(std::move(x));
    of.push_back(&job);
  }
  EstimateSceneOptions so;
  so.scene_pass = a.scene_pass;
  so.pass_min_objects = 1;
  so.keep_going = true;
  FilterOptions o = opt;
  o.seed = opt.seed + std::uint64_t(i);
  const std::vector<SceneEstimate> est = EstimateScene(SceneInput{scene.depth, scene.camera, {}}, stage1.prior, objects, o, so);
  for (std::size_t k = 0; k < est.size(); ++k) {
    TableJob& job = *of[k];
    if (!est[k].estimated) {
      job.status = est[k].error;  // counted as not found
      continue;
    }
    job.estimated = true;
    job.alone = est[k].alone;
    job.r = est[k].passed ? est[k].pass.estimate : est[k].alone;
    if (!est[k].passed) continue;
    job.pass_ms = est[k].pass.time_ms;
    job.pass_note = est[k].pass.replaced      ? "pass: replaced"
                    : est[k].pass.reestimated ? "pass: re-estimated, kept"
                                              : "";
  }
  return jobs;
}

// The running totals of a table suite.
struct TableSuiteTotals {
  struct ClassStats {
    int n = 0, found = 0;
    int found_alone = 0;  // before the scene pass
    std::vector<double> adds, times;
  };
  std::map<std::string, ClassStats> per_class;
  nlohmann::json rows = nlohmann::json::array();
  std::vector<double> all_adds, all_times;
  std::vector<double> stage1_ms;  // --prior auto: the stage 1's time per scene
  int found = 0, total = 0, found_alone = 0;
  // Recall by visible fraction: [0.5, 1], [0.3, 0.5), [0, 0.3).
  static constexpr double kVisibBounds[3] = {0.5, 0.3, 0.0};
  int visib_n[3] = {0, 0, 0}, visib_found[3] = {0, 0, 0};
};

// Scores one target against its ground truth, prints its row and adds it to the totals.
void ReportTableJob(const TableSuiteWorld& w, const TableScene& scene, const TableJob& job, std::uint64_t seed,
                    double stage1_share, TableSuiteTotals* t) {
  const TableObject& obj = scene.objects[job.j];
  const std::size_t j = job.j;
  const TableModel& model = w.world.models()[std::size_t(obj.model)];
  double adds = std::numeric_limits<double>::infinity(), weight = 0, gt_weight = 0, time_ms = 0;
  int iterations = 0;
  bool ok = false;
  std::string status = job.status;
  bool ok_alone = false;
  if (job.estimated) {
    const EstimateResult& r = job.r;
    const PoseErrors e = ComputePoseErrors(w.points[std::size_t(obj.model)], model.diameter, r.T_cam_obj, obj.T_cam_obj);
    ok_alone = ComputePoseErrors(w.points[std::size_t(obj.model)], model.diameter, job.alone.T_cam_obj, obj.T_cam_obj).adds_ok;
    adds = e.adds;
    ok = e.adds_ok;
    weight = r.weight;
    iterations = r.iterations;
    time_ms = r.time_ms + job.pass_ms;
    gt_weight = GroundTruthWeight(job.input, model.mesh, job.prior, job.prior.ClassIndex(obj.cls), job.o, obj.T_cam_obj, r.cell);
  }
  ++t->total;
  t->found += ok;
  for (int b = 0; b < 3; ++b)
    if (obj.visible_fraction >= TableSuiteTotals::kVisibBounds[b]) {
      ++t->visib_n[b];
      t->visib_found[b] += ok;
      break;
    }
  TableSuiteTotals::ClassStats& cs = t->per_class[obj.cls];
  ++cs.n;
  cs.found += ok;
  cs.found_alone += ok_alone;
  t->found_alone += ok_alone;
  cs.adds.push_back(adds);
  t->all_adds.push_back(adds);
  if (time_ms > 0) cs.times.push_back(time_ms), t->all_times.push_back(time_ms);
  const std::string note = status == "ok" ? job.pass_note : status;
  std::printf("%6llu %-22s %5.2f %9.1f %6.1f %6s %7.3f %7.3f %5d %8.0f%s%s\n", (unsigned long long)seed, obj.cls.c_str(),
              obj.visible_fraction, 1000 * adds, 100 * adds / model.diameter, ok ? "yes" : "NO", weight, gt_weight, iterations,
              time_ms, note.empty() ? "" : "  ", note.c_str());
  std::fflush(stdout);
  t->rows.push_back({{"seed", seed}, {"obj", obj.cls}, {"instance", j + 1}, {"visible_fraction", obj.visible_fraction},
                     {"adds_m", std::isfinite(adds) ? nlohmann::json(adds) : nlohmann::json(nullptr)},
                     {"diameter_m", model.diameter}, {"found", ok}, {"weight", weight}, {"gt_weight", gt_weight}, {"iterations", iterations},
                     {"time_ms", time_ms}, {"stage1_ms", stage1_share}, {"scene_pass_ms", job.pass_ms},
                     {"scene_pass", job.pass_note}, {"found_before_pass", ok_alone}, {"status", status}});
}

// The table suite's summary: per class, recall, by visible fraction, the scene pass, the
// stage 1's time; and the JSON (--json).
void PrintTableSummary(const TableSuiteArgs& a, const TableSuiteTotals& t, bool room) {
  const int found = t.found, total = t.total;
  std::printf("\n%-22s %5s %6s %7s %10s %12s\n", "class", "n", "found", "recall", "AUC ADD-S", "median[ms]");
  nlohmann::json class_rows = nlohmann::json::object();
  for (const auto& [cls, cs] : t.per_class) {
    const double auc = YcbvAuc(cs.adds, 0.1);
    std::printf("%-22s %5d %6d %6.0f%% %10.1f %12.0f\n", cls.c_str(), cs.n, cs.found, 100.0 * cs.found / cs.n, 100 * auc,
                Median(cs.times));
    class_rows[cls] = {{"n", cs.n}, {"found", cs.found}, {"recall", double(cs.found) / cs.n}, {"auc_adds", auc},
                       {"median_time_ms", Median(cs.times)}, {"found_before_pass", cs.found_alone}};
  }
  const double recall = double(found) / total, auc = YcbvAuc(t.all_adds, 0.1);
  double mean_ms = 0;
  for (double v : t.all_times) mean_ms += v;
  mean_ms = t.all_times.empty() ? 0 : mean_ms / double(t.all_times.size());
  std::printf("recall (ADD-S < 10%% of diameter): %d/%d = %.1f%%, AUC of ADD-S %.1f, median %.0f ms (mean %.0f ms) per object\n",
              found, total, 100 * recall, 100 * auc, Median(t.all_times), mean_ms);
  nlohmann::json by_visib = nlohmann::json::array();
  std::printf("by visible fraction:");
  for (int b = 0; b < 3; ++b) {
    const char* name[3] = {">= 0.5", "0.3-0.5", "< 0.3"};
    std::printf("  %s: %d/%d", name[b], t.visib_found[b], t.visib_n[b]);
    by_visib.push_back({{"min_visible_fraction", TableSuiteTotals::kVisibBounds[b]}, {"n", t.visib_n[b]}, {"found", t.visib_found[b]}});
  }
  std::printf("\n");
  if (a.scene_pass) {
    std::printf("scene pass: %d/%d found after it, %d/%d before; by class (before -> after):", found, total, t.found_alone, total);
    for (const auto& [cls, cs] : t.per_class)
      if (cs.found != cs.found_alone) std::printf("  %s %d -> %d", cls.c_str(), cs.found_alone, cs.found);
    std::printf("\n");
  }
  if (!t.stage1_ms.empty())
    std::printf("stage 1 (--prior %s): median %.0f ms per scene, %.0f ms per object on average\n", a.prior_kind.c_str(),
                Median(t.stage1_ms), std::accumulate(t.stage1_ms.begin(), t.stage1_ms.end(), 0.0) / total);
  if (!a.json_path.empty())
    WriteJson(a.json_path, {{"world", room ? "room" : "ycbv"}, {"by_visible_fraction", by_visib}, {"prior", a.prior_kind}, {"scene_pass", a.scene_pass}, {"objects", t.rows}, {"classes", class_rows},
                            {"recall_adds", recall}, {"recall_adds_before_pass", double(t.found_alone) / total}, {"auc_adds", auc}, {"median_time_ms", Median(t.all_times)},
                            {"mean_time_ms", mean_ms}, {"stage1_median_ms_per_scene", Median(t.stage1_ms)}});
}

// The YCB-Video table-top suite (--world ycbv), or with `room` the room suite (--world room).
void RunTableSuite(const TableSuiteArgs& a, const TableSceneOptions& topt, const RoomSceneOptions* room, const FilterOptions& opt) {
  namespace fs = std::filesystem;
  const std::vector<std::string> ycbv = YcbVideoClassNames();
  for (const std::string& c : a.classes)
    if (std::find(ycbv.begin(), ycbv.end(), c) == ycbv.end()) throw Error("--targets: '" + c + "' is not a YCB-Video class");
  if (a.models_dir.empty())
    throw Error(std::string(room ? "--world room" : "--world ycbv") + " needs the YCB-Video meshes: give --models DIR, or set POSEFILTER_DATA "
                "(scripts/get_data.sh ycbv DIR fetches them; README \"Data\")");
  TableSuiteWorld w{TableWorld::LoadYcbVideo(a.models_dir), {}, {}, {}};
  w.classes = w.world.ClassNames();
  for (const TableModel& m : w.world.models()) {
    const fs::path xyz = fs::path(a.models_dir) / "points" / (m.mesh.name + ".xyz");
    w.points.push_back(fs::exists(xyz) ? ReadXyzPoints(xyz.string()) : SamplePoints(m.mesh));
  }
  TableSuiteTotals t;
  std::printf("%6s %-22s %5s %9s %6s %6s %7s %7s %5s %8s\n", "seed", "object", "visib", "ADD-S[mm]", "%diam", "found",
              "weight", "gt_w", "iter", "time[ms]");
  for (int i = 0; i < a.count; ++i) {
    const std::uint64_t seed = a.first_seed + std::uint64_t(i);
    const TableScene scene = room ? MakeRoomScene(w.world, *room, seed) : w.world.MakeScene(topt, seed);
    if (!a.write_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof(name), "scene_%06llu", (unsigned long long)seed);
      WriteTableScene(scene, (fs::path(a.write_dir) / name).string());
    }
    const TableStage1 stage1 = TableSceneStage1(a, w, scene, &t.stage1_ms);
    // --prior auto: the stage 1's time shared by the scene's targets (in each row's stage1_ms).
    const auto targets = std::count_if(scene.objects.begin(), scene.objects.end(), [](const TableObject& o) { return o.target; });
    const double stage1_share = t.stage1_ms.size() == std::size_t(i) + 1 && targets > 0 ? t.stage1_ms.back() / double(targets) : 0.0;
    for (const TableJob& job : EstimateTableScene(a, w, scene, stage1, opt, i))
      ReportTableJob(w, scene, job, seed, stage1_share, &t);
  }
  if (t.total == 0) throw Error("the suite held no target (check --targets)");
  PrintTableSummary(a, t, room != nullptr);
}

// The parsed command line of `suite`.
struct SuiteArgs {
  std::string world = "shapes";
  int count = 20;
  std::uint64_t first_seed = 1;
  std::vector<std::string> targets;
  std::vector<double> occlusions = {0.0, 0.3, 0.5};
  std::string json_path;
  SynthOptions synth;
  TableSceneOptions table;
  RoomSceneOptions room;
  TableSuiteArgs ta;
  FilterOptions opt;
};

// Every option of `suite` on `app`, into a.
void AddSuiteOptions(CLI::App& app, SuiteArgs& a) {
  // $POSEFILTER_DATA/ycbv/models (README "Data"); without POSEFILTER_DATA, --models is needed.
  if (const char* data = std::getenv("POSEFILTER_DATA"); data != nullptr && *data != '\0')
    a.ta.models_dir = (std::filesystem::path(data) / "ycbv" / "models").string();
  a.ta.prior_kind = "boxes";
  app.add_option("--world", a.world,
                 "shapes: one procedural shape per scene; ycbv: several YCB-Video objects on a table; room: YCB-Video "
                 "objects on small raised surfaces and shelf boards in a room with furniture")
      ->check(CLI::IsMember({"shapes", "ycbv", "room"}))
      ->capture_default_str();
  app.add_option("--count", a.count, "number of scenes")->capture_default_str();
  app.add_option("--first-seed", a.first_seed, "scene i uses seed first_seed + i")
      ->capture_default_str()
      ->transform(SeedValidator());
  app.add_option("--targets", a.targets,
                 "shapes: object kinds, used in turn; ycbv, room: the classes estimated (default all)")
      ->delimiter(',');
  app.add_option("--occlusions", a.occlusions, "shapes: occlusion levels, used in turn")->delimiter(',');
  app.add_option("--box-jitter", a.synth.box_jitter_px, "detection box noise sigma (px)")->capture_default_str();
  app.add_option("--false-positives", a.synth.false_positives, "false detections per scene")->capture_default_str();
  app.add_option("--min-distance", a.synth.min_distance_m, "min camera→target distance, m (ycbv: 0.6, room: 0.5)")
      ->capture_default_str();
  app.add_option("--max-distance", a.synth.max_distance_m, "max camera→target distance, m (ycbv: 1.3, room: 1.5)")
      ->capture_default_str();
  app.add_option("--models", a.ta.models_dir,
                 "ycbv, room: folder of the 21 YCB-Video meshes, <class>.ply in metres (and points/<class>.xyz) or a BOP "
                 "ycbv models folder (default: $POSEFILTER_DATA/ycbv/models)")
      ->capture_default_str();
  app.add_option("--prior", a.ta.prior_kind,
                 "ycbv, room: boxes (jittered, with false boxes), masks (noisy instance masks), auto (no detector: regions "
                 "found in the depth and PPF pose proposals), auto-regions (auto without the PPF proposals) or none "
                 "(uniform)")
      ->check(CLI::IsMember({"boxes", "masks", "auto", "auto-regions", "none"}))
      ->capture_default_str();
  app.add_option("--min-objects", a.table.min_objects, "ycbv, room: objects per scene, at least (room: 2)")
      ->capture_default_str();
  app.add_option("--max-objects", a.table.max_objects, "ycbv, room: objects per scene, at most (room: 4)")
      ->capture_default_str();
  app.add_option("--box-scale-min", a.table.box_scale_min,
                 "ycbv, room: detection boxes scaled by a factor from this ...")
      ->capture_default_str();
  app.add_option("--box-scale-max", a.table.box_scale_max, "ycbv, room: ... to this")->capture_default_str();
  app.add_flag("--scene-pass,!--no-scene-pass", a.ta.scene_pass,
               "ycbv (not --prior masks): after the per-object estimates, the joint scene pass (posefilter/scene_pass.h) "
               "re-weighs each object against the pixels better estimates leave it and re-estimates one whose pixels "
               "another claims")
      ->default_str(a.ta.scene_pass ? "true" : "false");
  app.add_option("--write-scenes", a.ta.write_dir,
                 "ycbv, room: also write every scene to DIR/scene_<seed>/ (for peers)");
  app.add_option("--json", a.json_path, "also write the table as JSON");
  AddFilterOptions(app, &a.opt);
}

// --world ycbv or room: the scene options from the shared ones (the room world takes them
// where given, else its own defaults), checked with the options' names as typed.
void SetTableSuiteOptions(const CLI::App& app, SuiteArgs& a) {
  a.table.box_jitter_px = a.synth.box_jitter_px;
  a.table.false_positives = a.synth.false_positives;
  if (app.count("--min-distance")) a.table.min_distance_m = a.synth.min_distance_m;
  if (app.count("--max-distance")) a.table.max_distance_m = a.synth.max_distance_m;
  // The room world takes the same options where given, else its own defaults.
  a.room.box_jitter_px = a.table.box_jitter_px;
  a.room.false_positives = a.table.false_positives;
  a.room.box_scale_min = a.table.box_scale_min;
  a.room.box_scale_max = a.table.box_scale_max;
  if (app.count("--min-distance")) a.room.min_distance_m = a.synth.min_distance_m;
  if (app.count("--max-distance")) a.room.max_distance_m = a.synth.max_distance_m;
  if (app.count("--min-objects")) a.room.min_objects = a.table.min_objects;
  if (app.count("--max-objects")) a.room.max_objects = a.table.max_objects;
  std::string why;
  const bool valid = a.world == "room" ? a.room.IsValid(&why) : a.table.IsValid(&why);
  if (!valid) {
    // The options' names in the message, as the user typed them.
    const std::pair<const char*, const char*> names[] = {
        {"min_objects", "--min-objects"},     {"max_objects", "--max-objects"},
        {"min_distance_m", "--min-distance"}, {"max_distance_m", "--max-distance"},
        {"box_jitter_px", "--box-jitter"},    {"false_positives", "--false-positives"},
        {"box_scale_min", "--box-scale-min"}, {"box_scale_max", "--box-scale-max"}};
    for (const auto& [field, option] : names)
      for (std::size_t at; (at = why.find(field)) != std::string::npos;) why.replace(at, std::strlen(field), option);
    throw Error("invalid scene option: " + why);
  }
}

// --world shapes: one procedural shape per scene, the targets and occlusion levels in turn.
void RunShapesSuite(SuiteArgs& a) {
  if (a.targets.empty()) a.targets = SynthClassNames();
  if (a.occlusions.empty()) throw Error("--occlusions must not be empty");
  nlohmann::json rows = nlohmann::json::array();
  int found = 0;
  double total_ms = 0;
  FilterStats rtl_stats;  // --engine rtl: the Verilated weighings' clocks, summed over scenes
  std::printf("%5s %-9s %6s %9s %8s %6s %7s %7s %5s %8s\n", "seed", "target", "occl", "ADD-S[mm]", "%diam", "found",
              "weight", "gt_w", "iter", "time[ms]");
  for (int i = 0; i < a.count; ++i) {
    SynthOptions so = a.synth;
    so.target = a.targets[i % a.targets.size()];
    so.occlusion = a.occlusions[(i / a.targets.size()) % a.occlusions.size()];
    std::string why;
    if (!so.IsValid(&why)) throw Error("invalid scene option " + NameSynthOption(why));
    const std::uint64_t seed = a.first_seed + i;
    const SynthScene scene = MakeSynthScene(so, seed);
    const SceneInput input{scene.depth, scene.camera, {}};
    Stage1Options stage1;  // the scene's noisy detections, as a raw pyramid
    stage1.kind = Stage1Kind::kPyramid;
    stage1.classes = scene.classes;
    stage1.raw_pyramid = scene.raw_pyramid;
    const Prior prior = BuildStage1(input, {{scene.target.name}}, stage1).prior;
    FilterOptions o = a.opt;
    o.seed = a.opt.seed + i;
    const int cls = prior.ClassIndex(scene.target.name);
    const EstimateResult r = EstimatePose(input, scene.target, prior, cls, o);
    const double gt_weight = GroundTruthWeight(input, scene.target, prior, cls, o, scene.gt[0].T_cam_obj, r.cell);
    const double diameter = scene.target.Diameter();
    const PoseErrors e = ComputePoseErrors(SamplePoints(scene.target), diameter, r.T_cam_obj, scene.gt[0].T_cam_obj);
    found += e.adds_ok;
    total_ms += r.time_ms;
    rtl_stats += r.stats;
    std::printf("%5llu %-9s %6.2f %9.1f %8.1f %6s %7.3f %7.3f %5d %8.0f\n", (unsigned long long)seed, so.target.c_str(),
                scene.occlusion_achieved, 1000 * e.adds, 100 * e.adds / diameter, e.adds_ok ? "yes" : "NO", r.weight,
                gt_weight, r.iterations, r.time_ms);
    std::fflush(stdout);
    rows.push_back({{"seed", seed}, {"target", so.target}, {"occlusion", scene.occlusion_achieved},
                    {"adds_m", e.adds}, {"add_m", e.add}, {"diameter_m", diameter}, {"found", e.adds_ok},
                    {"rot_deg", e.rot_deg}, {"trans_m", e.trans_m}, {"weight", r.weight}, {"gt_weight", gt_weight},
                    {"iterations", r.iterations}, {"time_ms", r.time_ms}});
  }
  const double recall = double(found) / a.count;
  std::printf("recall (ADD-S < 10%% of diameter): %d/%d = %.0f%%, mean time %.0f ms per object\n", found, a.count,
              100 * recall, total_ms / a.count);
  if (rtl_stats.rtl_calls > 0)
    std::printf("rtl: %.0f clocks per weighing simulated (weighing pipeline, AP_START to AP_DONE), cycle model %.0f "
                "(ratio %.3f), over %lld weighings\n",
                double(rtl_stats.rtl_cycles) / double(rtl_stats.rtl_calls),
                double(rtl_stats.rtl_model_cycles) / double(rtl_stats.rtl_calls),
                double(rtl_stats.rtl_cycles) / double(rtl_stats.rtl_model_cycles), (long long)rtl_stats.rtl_calls);
  if (!a.json_path.empty()) WriteJson(a.json_path, {{"scenes", rows}, {"recall_adds", recall}});
}

}  // namespace

int RunSuite(int argc, char** argv) {
  CLI::App app{"Accuracy of the filter on synthetic scenes with ground truth", "suite"};
  SuiteArgs a;
  AddSuiteOptions(app, a);
  return RunApp(app, argc, argv, [&] {
    CheckFilterOptions(a.opt);
    if (a.count < 1) throw Error("--count must be >= 1");
    if (a.first_seed > UINT64_MAX - std::uint64_t(a.count - 1))
      throw Error("--first-seed + --count - 1 is above 2^64 - 1: the last scene's seed would wrap to 0");
    CheckOutputPaths({{a.json_path, "--json"}}, {{a.ta.models_dir, "--models"}, {a.ta.write_dir, "--write-scenes"}});
    // The scene pass needs scenes of several objects sharing one prior (--prior masks gives each its own).
    const bool ycb = a.world == "ycbv" || a.world == "room";
    if (app.count("--scene-pass") && a.ta.scene_pass && (!ycb || a.ta.prior_kind == "masks"))
      throw Error("--scene-pass needs --world ycbv or room and a prior the scene's objects share (not --prior masks)");
    if (a.ta.prior_kind == "masks") a.ta.scene_pass = false;
    if (!ycb) return RunShapesSuite(a);
    SetTableSuiteOptions(app, a);
    a.ta.classes = a.targets;
    a.ta.count = a.count;
    a.ta.first_seed = a.first_seed;
    a.ta.json_path = a.json_path;
    RunTableSuite(a.ta, a.table, a.world == "room" ? &a.room : nullptr, a.opt);
  });
}

}  // namespace posefilter::cli
