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
#include "posefilter/scene_pass.h"
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

// The YCB-Video table-top suite (--world ycbv), or with `room` the room suite (--world room).
void RunTableSuite(const TableSuiteArgs& a, const TableSceneOptions& topt, const RoomSceneOptions* room, const FilterOptions& opt) {
  namespace fs = std::filesystem;
  const std::vector<std::string> ycbv = YcbVideoClassNames();
  for (const std::string& c : a.classes)
    if (std::find(ycbv.begin(), ycbv.end(), c) == ycbv.end()) throw Error("--targets: '" + c + "' is not a YCB-Video class");
  if (a.models_dir.empty())
    throw Error(std::string(room ? "--world room" : "--world ycbv") + " needs the YCB-Video meshes: give --models DIR, or set POSEFILTER_DATA "
                "(scripts/get_data.sh ycbv DIR fetches them; README \"Data\")");
  const TableWorld world = TableWorld::LoadYcbVideo(a.models_dir);
  const std::vector<std::string> classes = world.ClassNames();
  // Model points for ADD-S: the dataset's official point sets where present, else the mesh's.
  std::vector<std::vector<Eigen::Vector3f>> points;
  for (const TableModel& m : world.models()) {
    const fs::path xyz = fs::path(a.models_dir) / "points" / (m.mesh.name + ".xyz");
    points.push_back(fs::exists(xyz) ? ReadXyzPoints(xyz.string()) : SamplePoints(m.mesh));
  }
  struct ClassStats {
    int n = 0, found = 0;
    int found_alone = 0;  // before the scene pass
    std::vector<double> adds, times;
  };
  std::map<std::string, ClassStats> per_class;
  nlohmann::json rows = nlohmann::json::array();
  std::vector<double> all_adds, all_times;
  std::map<int, PpfModel> ppf_models;  // --prior auto: per model index, built (or loaded) once
  std::vector<double> stage1_ms;       // --prior auto: the stage 1's time per scene
  int found = 0, total = 0, found_alone = 0;
  // Recall by visible fraction: [0.5, 1], [0.3, 0.5), [0, 0.3).
  const double kVisibBounds[3] = {0.5, 0.3, 0.0};
  int visib_n[3] = {0, 0, 0}, visib_found[3] = {0, 0, 0};
  std::printf("%6s %-22s %5s %9s %6s %6s %7s %7s %5s %8s\n", "seed", "object", "visib", "ADD-S[mm]", "%diam", "found",
              "weight", "gt_w", "iter", "time[ms]");
  for (int i = 0; i < a.count; ++i) {
    const std::uint64_t seed = a.first_seed + std::uint64_t(i);
    const TableScene scene = room ? MakeRoomScene(world, *room, seed) : world.MakeScene(topt, seed);
    if (!a.write_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof(name), "scene_%06llu", (unsigned long long)seed);
      WriteTableScene(scene, (fs::path(a.write_dir) / name).string());
    }
    const int W = scene.camera.width, H = scene.camera.height;
    const PyramidLayout layout = PyramidLayout::Thesis(W, H, int(classes.size()));
    Prior box_prior;
    std::string scene_status = "ok";
    std::map<std::string, std::vector<PoseSeed>> seeds_of;  // --prior auto: per class
    if (a.prior_kind == "auto" || a.prior_kind == "auto-regions") {
      // No detector: candidate regions in the depth, for every object class the scene is
      // searched for (its targets), as `estimate --prior auto` does for its meshes.
      std::vector<AutoObject> wanted;
      for (const TableObject& o : scene.objects)
        if (o.target && std::none_of(wanted.begin(), wanted.end(), [&](const AutoObject& w) { return w.name == o.cls; })) {
          const PpfModel* ppf = nullptr;
          if (a.prior_kind == "auto") {
            auto model = ppf_models.find(o.model);
            if (model == ppf_models.end())
              model = ppf_models.emplace(o.model, LoadOrBuildPpfModel(world.models()[std::size_t(o.model)].mesh, {},
                                                                      DefaultPpfCacheDir())).first;
            ppf = &model->second;
          }
          wanted.push_back({o.cls, world.models()[std::size_t(o.model)].diameter, ppf});
        }
      const auto t_stage1 = std::chrono::steady_clock::now();
      AutoProposals proposals = ProposeAuto(scene.depth, scene.camera, wanted);
      stage1_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_stage1).count());
      if (proposals.detections.empty()) scene_status = "no candidates";
      box_prior = PriorFromDetections(proposals.detections, layout, classes);
      for (std::size_t k = 0; k < wanted.size(); ++k) seeds_of[wanted[k].name] = std::move(proposals.seeds[k]);
    } else if (a.prior_kind == "none") {
      box_prior = UniformPrior(layout, classes);
    } else {
      box_prior = PriorFromDetections(scene.detections, layout, classes);
    }
    // --prior auto: the stage 1's time shared by the scene's targets (in each row's stage1_ms).
    const auto targets = std::count_if(scene.objects.begin(), scene.objects.end(), [](const TableObject& o) { return o.target; });
    const double stage1_share = stage1_ms.size() == std::size_t(i) + 1 && targets > 0 ? stage1_ms.back() / double(targets) : 0.0;
    // Each target estimated on its own, then (--scene-pass) the scene pass over all of them,
    // then the rows.
    struct Job {
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
    std::vector<Job> jobs;
    for (std::size_t j = 0; j < scene.objects.size(); ++j) {
      const TableObject& obj = scene.objects[j];
      if (!obj.target) continue;
      if (!a.classes.empty() && std::find(a.classes.begin(), a.classes.end(), obj.cls) == a.classes.end()) continue;
      const TableModel& model = world.models()[std::size_t(obj.model)];
      Job job;
      job.j = j;
      job.input = SceneInput{scene.depth, scene.camera, {}};
      if (auto it = seeds_of.find(obj.cls); it != seeds_of.end()) job.input.seeds = it->second;
      job.prior = box_prior;
      job.status = scene_status;
      if (a.prior_kind == "masks") {
        LabelImage l{W, H, {}};
        l.ids.resize(scene.masks.size());
        for (std::size_t q = 0; q < l.ids.size(); ++q) l.ids[q] = scene.masks[q] == j + 1 ? 1 : 0;
        if (std::count(l.ids.begin(), l.ids.end(), 1) == 0) {
          job.status = "no mask";
        } else {
          const InstanceMask m = MasksFromLabels(l, {{1, obj.cls}}, "mask").front();
          job.input.mask = m.pixels;
          job.prior = PriorFromDetections({MaskDetection(m)}, layout, classes);
        }
      }
      job.o = opt;
      job.o.seed = opt.seed + std::uint64_t(i);
      if (job.status == "ok") {
        try {
          job.r = EstimatePose(job.input, model.mesh, job.prior, job.prior.ClassIndex(obj.cls), job.o);
          job.alone = job.r;
          job.estimated = true;
        } catch (const Error& e) {
          job.status = e.what();  // counted as not found
        }
      }
      jobs.push_back(std::move(job));
    }
    if (a.scene_pass) {
      std::vector<SceneObject> objs;
      std::vector<Job*> of;
      for (Job& job : jobs)
        if (job.estimated) {
          const TableObject& obj = scene.objects[job.j];
          objs.push_back({&world.models()[std::size_t(obj.model)].mesh, box_prior.ClassIndex(obj.cls), job.r});
          of.push_back(&job);
        }
      FilterOptions o = opt;
      o.seed = opt.seed + std::uint64_t(i);
      const std::vector<ScenePassResult> passed = RunScenePass(SceneInput{scene.depth, scene.camera, {}}, box_prior, objs, o);
      for (std::size_t k = 0; k < passed.size(); ++k) {
        of[k]->r = passed[k].estimate;
        of[k]->pass_ms = passed[k].time_ms;
        of[k]->pass_note = passed[k].replaced ? "pass: replaced" : passed[k].reestimated ? "pass: re-estimated, kept" : "";
      }
    }
    for (const Job& job : jobs) {
      const TableObject& obj = scene.objects[job.j];
      const std::size_t j = job.j;
      const TableModel& model = world.models()[std::size_t(obj.model)];
      double adds = std::numeric_limits<double>::infinity(), weight = 0, gt_weight = 0, time_ms = 0;
      int iterations = 0;
      bool ok = false;
      std::string status = job.status;
      bool ok_alone = false;
      if (job.estimated) {
        const EstimateResult& r = job.r;
        const PoseErrors e = ComputePoseErrors(points[std::size_t(obj.model)], model.diameter, r.T_cam_obj, obj.T_cam_obj);
        ok_alone = ComputePoseErrors(points[std::size_t(obj.model)], model.diameter, job.alone.T_cam_obj, obj.T_cam_obj).adds_ok;
        adds = e.adds;
        ok = e.adds_ok;
        weight = r.weight;
        iterations = r.iterations;
        time_ms = r.time_ms + job.pass_ms;
        gt_weight =
            GroundTruthWeight(job.input, model.mesh, job.prior, job.prior.ClassIndex(obj.cls), job.o, obj.T_cam_obj, r.cell);
      }
      ++total;
      found += ok;
      for (int b = 0; b < 3; ++b)
        if (obj.visible_fraction >= kVisibBounds[b]) {
          ++visib_n[b];
          visib_found[b] += ok;
          break;
        }
      ClassStats& cs = per_class[obj.cls];
      ++cs.n;
      cs.found += ok;
      cs.found_alone += ok_alone;
      found_alone += ok_alone;
      cs.adds.push_back(adds);
      all_adds.push_back(adds);
      if (time_ms > 0) cs.times.push_back(time_ms), all_times.push_back(time_ms);
      const std::string note = status == "ok" ? job.pass_note : status;
      std::printf("%6llu %-22s %5.2f %9.1f %6.1f %6s %7.3f %7.3f %5d %8.0f%s%s\n", (unsigned long long)seed, obj.cls.c_str(),
                  obj.visible_fraction, 1000 * adds, 100 * adds / model.diameter, ok ? "yes" : "NO", weight, gt_weight, iterations,
                  time_ms, note.empty() ? "" : "  ", note.c_str());
      std::fflush(stdout);
      rows.push_back({{"seed", seed}, {"obj", obj.cls}, {"instance", j + 1}, {"visible_fraction", obj.visible_fraction},
                      {"adds_m", std::isfinite(adds) ? nlohmann::json(adds) : nlohmann::json(nullptr)},
                      {"diameter_m", model.diameter}, {"found", ok}, {"weight", weight}, {"gt_weight", gt_weight}, {"iterations", iterations},
                      {"time_ms", time_ms}, {"stage1_ms", stage1_share}, {"scene_pass_ms", job.pass_ms},
                      {"scene_pass", job.pass_note}, {"found_before_pass", ok_alone}, {"status", status}});
    }
  }
  if (total == 0) throw Error("the suite held no target (check --targets)");
  std::printf("\n%-22s %5s %6s %7s %10s %12s\n", "class", "n", "found", "recall", "AUC ADD-S", "median[ms]");
  nlohmann::json class_rows = nlohmann::json::object();
  for (const auto& [cls, cs] : per_class) {
    const double auc = YcbvAuc(cs.adds, 0.1);
    std::printf("%-22s %5d %6d %6.0f%% %10.1f %12.0f\n", cls.c_str(), cs.n, cs.found, 100.0 * cs.found / cs.n, 100 * auc,
                Median(cs.times));
    class_rows[cls] = {{"n", cs.n}, {"found", cs.found}, {"recall", double(cs.found) / cs.n}, {"auc_adds", auc},
                       {"median_time_ms", Median(cs.times)}, {"found_before_pass", cs.found_alone}};
  }
  const double recall = double(found) / total, auc = YcbvAuc(all_adds, 0.1);
  double mean_ms = 0;
  for (double t : all_times) mean_ms += t;
  mean_ms = all_times.empty() ? 0 : mean_ms / double(all_times.size());
  std::printf("recall (ADD-S < 10%% of diameter): %d/%d = %.1f%%, AUC of ADD-S %.1f, median %.0f ms (mean %.0f ms) per object\n",
              found, total, 100 * recall, 100 * auc, Median(all_times), mean_ms);
  nlohmann::json by_visib = nlohmann::json::array();
  std::printf("by visible fraction:");
  for (int b = 0; b < 3; ++b) {
    const char* name[3] = {">= 0.5", "0.3-0.5", "< 0.3"};
    std::printf("  %s: %d/%d", name[b], visib_found[b], visib_n[b]);
    by_visib.push_back({{"min_visible_fraction", kVisibBounds[b]}, {"n", visib_n[b]}, {"found", visib_found[b]}});
  }
  std::printf("\n");
  if (a.scene_pass) {
    std::printf("scene pass: %d/%d found after it, %d/%d before; by class (before -> after):", found, total, found_alone, total);
    for (const auto& [cls, cs] : per_class)
      if (cs.found != cs.found_alone) std::printf("  %s %d -> %d", cls.c_str(), cs.found_alone, cs.found);
    std::printf("\n");
  }
  if (!stage1_ms.empty())
    std::printf("stage 1 (--prior %s): median %.0f ms per scene, %.0f ms per object on average\n", a.prior_kind.c_str(),
                Median(stage1_ms), std::accumulate(stage1_ms.begin(), stage1_ms.end(), 0.0) / total);
  if (!a.json_path.empty())
    WriteJson(a.json_path, {{"world", room ? "room" : "ycbv"}, {"by_visible_fraction", by_visib}, {"prior", a.prior_kind}, {"scene_pass", a.scene_pass}, {"objects", rows}, {"classes", class_rows},
                            {"recall_adds", recall}, {"recall_adds_before_pass", double(found_alone) / total}, {"auc_adds", auc}, {"median_time_ms", Median(all_times)},
                            {"mean_time_ms", mean_ms}, {"stage1_median_ms_per_scene", Median(stage1_ms)}});
}

}  // namespace

int RunSuite(int argc, char** argv) {
  CLI::App app{"Accuracy of the filter on synthetic scenes with ground truth", "suite"};
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
  // $POSEFILTER_DATA/ycbv/models (README "Data"); without POSEFILTER_DATA, --models is needed.
  if (const char* data = std::getenv("POSEFILTER_DATA"); data != nullptr && *data != '\0')
    ta.models_dir = (std::filesystem::path(data) / "ycbv" / "models").string();
  ta.prior_kind = "boxes";
  FilterOptions opt;
  app.add_option("--world", world,
                 "shapes: one procedural shape per scene; ycbv: several YCB-Video objects on a table; room: YCB-Video "
                 "objects on small raised surfaces and shelf boards in a room with furniture")
      ->check(CLI::IsMember({"shapes", "ycbv", "room"}))
      ->capture_default_str();
  app.add_option("--count", count, "number of scenes")->capture_default_str();
  app.add_option("--first-seed", first_seed, "scene i uses seed first_seed + i")->capture_default_str()->transform(SeedValidator());
  app.add_option("--targets", targets, "shapes: object kinds, used in turn; ycbv, room: the classes estimated (default all)")
      ->delimiter(',');
  app.add_option("--occlusions", occlusions, "shapes: occlusion levels, used in turn")->delimiter(',');
  app.add_option("--box-jitter", synth.box_jitter_px, "detection box noise sigma (px)")->capture_default_str();
  app.add_option("--false-positives", synth.false_positives, "false detections per scene")->capture_default_str();
  app.add_option("--min-distance", synth.min_distance_m, "min camera→target distance, m (ycbv: 0.6, room: 0.5)")->capture_default_str();
  app.add_option("--max-distance", synth.max_distance_m, "max camera→target distance, m (ycbv: 1.3, room: 1.5)")->capture_default_str();
  app.add_option("--models", ta.models_dir,
                 "ycbv, room: folder of the 21 YCB-Video meshes, <class>.ply in metres (and points/<class>.xyz) or a BOP "
                 "ycbv models folder (default: $POSEFILTER_DATA/ycbv/models)")
      ->capture_default_str();
  app.add_option("--prior", ta.prior_kind,
                 "ycbv, room: boxes (jittered, with false boxes), masks (noisy instance masks), auto (no detector: regions "
                 "found in the depth and PPF pose proposals), auto-regions (auto without the PPF proposals) or none "
                 "(uniform)")
      ->check(CLI::IsMember({"boxes", "masks", "auto", "auto-regions", "none"}))
      ->capture_default_str();
  app.add_option("--min-objects", table.min_objects, "ycbv, room: objects per scene, at least (room: 2)")->capture_default_str();
  app.add_option("--max-objects", table.max_objects, "ycbv, room: objects per scene, at most (room: 4)")->capture_default_str();
  app.add_option("--box-scale-min", table.box_scale_min, "ycbv, room: detection boxes scaled by a factor from this ...")
      ->capture_default_str();
  app.add_option("--box-scale-max", table.box_scale_max, "ycbv, room: ... to this")->capture_default_str();
  app.add_flag("--scene-pass,!--no-scene-pass", ta.scene_pass,
               "ycbv (not --prior masks): after the per-object estimates, the joint scene pass (posefilter/scene_pass.h) "
               "re-weighs each object against the pixels better estimates leave it and re-estimates one whose pixels "
               "another claims")
      ->default_str(ta.scene_pass ? "true" : "false");
  app.add_option("--write-scenes", ta.write_dir, "ycbv, room: also write every scene to DIR/scene_<seed>/ (for peers)");
  app.add_option("--json", json_path, "also write the table as JSON");
  AddFilterOptions(app, &opt);

  return RunApp(app, argc, argv, [&] {
    CheckFilterOptions(opt);
    if (count < 1) throw Error("--count must be >= 1");
    if (first_seed > UINT64_MAX - std::uint64_t(count - 1))
      throw Error("--first-seed + --count - 1 is above 2^64 - 1: the last scene's seed would wrap to 0");
    CheckOutputPaths({{json_path, "--json"}}, {{ta.models_dir, "--models"}, {ta.write_dir, "--write-scenes"}});
    // The scene pass needs scenes of several objects sharing one prior (--prior masks gives each its own).
    const bool ycb = world == "ycbv" || world == "room";
    if (app.count("--scene-pass") && ta.scene_pass && (!ycb || ta.prior_kind == "masks"))
      throw Error("--scene-pass needs --world ycbv or room and a prior the scene's objects share (not --prior masks)");
    if (ta.prior_kind == "masks") ta.scene_pass = false;
    if (ycb) {
      table.box_jitter_px = synth.box_jitter_px;
      table.false_positives = synth.false_positives;
      if (app.count("--min-distance")) table.min_distance_m = synth.min_distance_m;
      if (app.count("--max-distance")) table.max_distance_m = synth.max_distance_m;
      // The room world takes the same options where given, else its own defaults.
      room.box_jitter_px = table.box_jitter_px;
      room.false_positives = table.false_positives;
      room.box_scale_min = table.box_scale_min;
      room.box_scale_max = table.box_scale_max;
      if (app.count("--min-distance")) room.min_distance_m = synth.min_distance_m;
      if (app.count("--max-distance")) room.max_distance_m = synth.max_distance_m;
      if (app.count("--min-objects")) room.min_objects = table.min_objects;
      if (app.count("--max-objects")) room.max_objects = table.max_objects;
      std::string why;
      const bool valid = world == "room" ? room.IsValid(&why) : table.IsValid(&why);
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
      ta.classes = targets;
      ta.count = count;
      ta.first_seed = first_seed;
      ta.json_path = json_path;
      RunTableSuite(ta, table, world == "room" ? &room : nullptr, opt);
      return;
    }
    if (targets.empty()) targets = SynthClassNames();
    if (occlusions.empty()) throw Error("--occlusions must not be empty");
    nlohmann::json rows = nlohmann::json::array();
    int found = 0;
    double total_ms = 0;
    FilterStats rtl_stats;  // --engine rtl: the Verilated weighings' clocks, summed over scenes
    std::printf("%5s %-9s %6s %9s %8s %6s %7s %7s %5s %8s\n", "seed", "target", "occl", "ADD-S[mm]", "%diam", "found",
                "weight", "gt_w", "iter", "time[ms]");
    for (int i = 0; i < count; ++i) {
      SynthOptions so = synth;
      so.target = targets[i % targets.size()];
      so.occlusion = occlusions[(i / targets.size()) % occlusions.size()];
      std::string why;
      if (!so.IsValid(&why)) throw Error("invalid scene option " + NameSynthOption(why));
      const std::uint64_t seed = first_seed + i;
      const SynthScene scene = MakeSynthScene(so, seed);
      const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
      FilterOptions o = opt;
      o.seed = opt.seed + i;
      const SceneInput input{scene.depth, scene.camera, {}};
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
    const double recall = double(found) / count;
    std::printf("recall (ADD-S < 10%% of diameter): %d/%d = %.0f%%, mean time %.0f ms per object\n", found, count,
                100 * recall, total_ms / count);
    if (rtl_stats.rtl_calls > 0)
      std::printf("rtl: %.0f clocks per weighing simulated (weighing pipeline, AP_START to AP_DONE), cycle model %.0f "
                  "(ratio %.3f), over %lld weighings\n",
                  double(rtl_stats.rtl_cycles) / double(rtl_stats.rtl_calls),
                  double(rtl_stats.rtl_model_cycles) / double(rtl_stats.rtl_calls),
                  double(rtl_stats.rtl_cycles) / double(rtl_stats.rtl_model_cycles), (long long)rtl_stats.rtl_calls);
    if (!json_path.empty()) WriteJson(json_path, {{"scenes", rows}, {"recall_adds", recall}});
  });
}

}  // namespace posefilter::cli
