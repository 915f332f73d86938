// posefilter hw-report — the hw engine's cycle model, side by side with the thesis's figures
// (thesis Ch. 7: Tables 7.2, 7.3 [HARDWARE.md], Fig. 7.11, 7.21), on one of two scenes:
//   - a synthetic scene comparable to the thesis's (640×480, thesis camera, N = 510, windows
//     capped at 200×200, a model of 1024 vertices / 2048 faces — the synthetic torus);
//   - --frame DIR: a real frame (a YCB-Video scene folder: depth.png, camera.json, gt.json,
//     label.png) with one object's mesh reduced to the engine's level of detail and the windows
//     its label mask's box gives (the box a segmentation front end would report), as the
//     thesis's real scenes.
// Two configurations: "thesis" (ThesisFilterOptions, from the option table's thesis column:
// the given options with every extension of ours off: no z-buffer, the thesis's 13 moves, no
// annealing, niches, support plane or polish) and "ours" (the options as given).
// docs/HARDWARE.md explains the model and the comparison.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/hw_engine.h"
#include "posefilter/mask_prior.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
#include "posefilter/metrics.h"
#include "posefilter/option_table.h"
#include "posefilter/synth.h"

namespace posefilter::cli {
namespace {

// The thesis's figures (Tables 7.2, 7.3 [HARDWARE.md]) for M = 1, 5, 10 cores; < 0 = not reported.
struct ThesisRow {
  int cores;
  double depth_distribution_ms, first_iteration_ms, average_iteration_ms;
};
constexpr ThesisRow kThesis[] = {{1, 204, -1, -1}, {5, 85, 177, 120}, {10, 55, 115, 80}};
constexpr double kThesisInitRatio = 41, kThesisResampleRatio = 45, kThesisFacesRatio = 2.06;

const ThesisRow* ThesisFor(int cores) {
  for (const auto& r : kThesis)
    if (r.cores == cores) return &r;
  return nullptr;
}

std::string Ms(double v) {
  if (v < 0) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// What the report models: the scene, the object and its prior, and the ground truth.
struct ReportScene {
  std::string description;  // for the header line
  SceneInput input;
  Mesh target;
  Prior prior;
  int cls = -1;
  Eigen::Isometry3d gt = Eigen::Isometry3d::Identity();
  std::vector<float> raw_pyramid;  // the synthetic scene's raw stage-1 output (empty for a frame)
};

// A YCB-Video scene folder: depth.png, camera.json, gt.json, label.png; the mesh models/<obj>.ply
// (metres). The prior: the object's label-mask box as its one detection.
ReportScene FrameScene(const std::string& dir, const std::string& models_arg, const std::string& object) {
  namespace fs = std::filesystem;
  const fs::path frame(dir);
  if (!fs::is_directory(frame)) throw Error(dir + ": not a folder (--frame)");
  for (const char* f : {"depth.png", "camera.json", "gt.json", "label.png"})
    if (!fs::exists(frame / f)) throw Error((frame / f).string() + ": missing (--frame needs depth.png, camera.json, gt.json, label.png)");
  const fs::path models = models_arg.empty() ? frame.parent_path().parent_path() / "models" : fs::path(models_arg);
  ReportScene r;
  const CameraFile cam = ReadCameraJson((frame / "camera.json").string());
  r.input.camera = cam.camera;
  r.input.depth = LoadDepthPng((frame / "depth.png").string(), cam.depth_scale, cam.camera.width, cam.camera.height);
  ValidateScene(r.input, (frame / "depth.png").string());
  const std::vector<GtObject> gt = ReadGtJson((frame / "gt.json").string());
  if (gt.empty()) throw Error((frame / "gt.json").string() + ": no object");
  const GtObject* obj = &gt[0];
  if (!object.empty()) {
    obj = nullptr;
    for (const GtObject& g : gt)
      if (g.obj == object) obj = &g;
    if (!obj) throw Error("--object: '" + object + "' is not in " + (frame / "gt.json").string());
  }
  const fs::path mesh_path = models / (obj->obj + ".ply");
  if (!fs::exists(mesh_path)) throw Error(mesh_path.string() + ": missing (--models)");
  r.target = LoadMesh(mesh_path.string());
  r.target.name = obj->obj;
  r.gt = obj->T_cam_obj;
  const LabelImage labels = LoadLabelPng((frame / "label.png").string());
  if (labels.width != r.input.camera.width || labels.height != r.input.camera.height)
    throw Error((frame / "label.png").string() + ": label image is " + std::to_string(labels.width) + "x" +
                std::to_string(labels.height) + " but the camera is " + std::to_string(r.input.camera.width) + "x" +
                std::to_string(r.input.camera.height));
  const std::vector<InstanceMask> masks = MasksFromLabels(labels, YcbVideoMaskClasses(), (frame / "label.png").string());
  const InstanceMask* mask = nullptr;
  for (const InstanceMask& m : masks)
    if (m.cls == obj->obj) mask = &m;
  if (!mask) throw Error((frame / "label.png").string() + ": no pixel labelled '" + obj->obj + "'");
  const std::vector<std::string> classes = YcbVideoClassNames();
  r.prior = PriorFromDetections({MaskDetection(*mask)}, PyramidLayout::Thesis(), classes);
  r.cls = r.prior.ClassIndex(obj->obj);
  r.description = "frame " + frame.filename().string() + ", " + obj->obj;
  return r;
}

ReportScene SyntheticScene(std::uint64_t seed, const std::string& target, double occlusion) {
  SynthOptions so;
  so.target = target;
  so.occlusion = occlusion;
  std::string why;
  if (!so.IsValid(&why)) throw Error("invalid scene option: " + why);
  const SynthScene scene = MakeSynthScene(so, seed);
  ReportScene r;
  r.input = SceneInput{scene.depth, scene.camera};
  r.target = scene.target;
  r.prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
  r.cls = r.prior.ClassIndex(scene.target.name);
  r.gt = scene.gt[0].T_cam_obj;
  r.raw_pyramid = scene.raw_pyramid;
  r.description = "scene seed " + std::to_string(seed) + ", " + target;
  return r;
}

struct Configuration {
  std::string name;
  FilterOptions options;
  HwProfile profile;
  PoseErrors errors;
};

nlohmann::json ProfileJson(const HwProfile& p, const PoseErrors& e) {
  nlohmann::json models = nlohmann::json::array();
  for (const HwCoreModel& m : p.models) {
    nlohmann::json mods = nlohmann::json::array();
    for (const auto& mod : m.modules)
      mods.push_back({{"module", mod.module},
                      {"cycles", mod.cycles},
                      {"ms", p.CyclesToMs(mod.cycles)},
                      {"memory_latency_cycles", mod.memory_cycles},
                      {"memory_latency_ms", p.CyclesToMs(mod.memory_cycles)}});
    models.push_back({{"cores", m.cores},
                      {"depth_distribution_ms", p.CyclesToMs(m.depth_distribution_cycles)},
                      {"first_iteration_ms", p.CyclesToMs(m.first_iteration_cycles)},
                      {"average_iteration_ms", p.CyclesToMs(m.average_iteration_cycles)},
                      {"weigh_ms", p.CyclesToMs(m.weigh_cycles)},
                      {"update_ms", p.CyclesToMs(m.update_cycles)},
                      {"iteration_ms", p.CyclesToMs(m.iteration_cycles)},
                      {"depth_reads_shared", m.depth_reads_shared},
                      {"depth_reads_unshared", m.depth_reads_unshared},
                      {"memory_latency_ms", p.CyclesToMs(m.memory_cycles)},
                      {"modules", mods}});
  }
  nlohmann::json init_mods = nlohmann::json::array();
  for (const auto& mod : p.init_modules)
    init_mods.push_back({{"module", mod.module}, {"cycles", mod.cycles}, {"memory_latency_cycles", mod.memory_cycles}});
  const double faces_ratio = p.faces_front > 0 ? p.faces_total / p.faces_front : 0;
  return {{"vertices", p.num_vertices}, {"faces", p.num_faces}, {"particles", p.num_particles},
          {"iterations", p.iterations}, {"modelled_iterations", p.modelled_iterations}, {"clock_mhz", p.clock_mhz},
          {"weight", p.result.weight}, {"adds_m", e.adds}, {"found", e.adds_ok},
          {"mean_window_area", p.mean_window_area}, {"postprocess_ms", p.CyclesToMs(p.postprocess_cycles)},
          {"init_ms", p.CyclesToMs(p.init_cycles)}, {"init_modules", init_mods},
          {"init_reads_per_draw", p.init_reads}, {"init_reads_linear_per_draw", p.init_reads_linear},
          {"resample_reads_per_draw", p.resample_reads}, {"resample_reads_linear_per_draw", p.resample_reads_linear},
          {"faces_total", p.faces_total}, {"faces_front", p.faces_front}, {"faces_ratio", faces_ratio},
          {"models", models}};
}

void PrintProfile(const Configuration& c) {
  const HwProfile& p = c.profile;
  std::printf("configuration \"%s\": weight %.3f, ADD-S %.1f mm (%s), mean window %.0f px^2, %d iterations (%d modelled)\n",
              c.name.c_str(), p.result.weight, 1000 * c.errors.adds, c.errors.adds_ok ? "found" : "not found",
              p.mean_window_area, p.iterations, p.modelled_iterations);
  std::printf("%-34s %10s %10s %10s\n", "per iteration [ms]", "", "ours", "thesis");
  for (const HwCoreModel& m : p.models) {
    const ThesisRow* t = ThesisFor(m.cores);
    std::printf("M = %d cores\n", m.cores);
    std::printf("  %-32s %10s %10s %10s\n", "depth distribution", "", Ms(p.CyclesToMs(m.depth_distribution_cycles)).c_str(),
                Ms(t ? t->depth_distribution_ms : -1).c_str());
    std::printf("  %-32s %10s %10s %10s\n", "first iteration", "", Ms(p.CyclesToMs(m.first_iteration_cycles)).c_str(),
                Ms(t ? t->first_iteration_ms : -1).c_str());
    std::printf("  %-32s %10s %10s %10s\n", "average iteration", "", Ms(p.CyclesToMs(m.average_iteration_cycles)).c_str(),
                Ms(t ? t->average_iteration_ms : -1).c_str());
    std::printf("  %-32s %10s %10s\n", "  weigh region (modelled its)", "", Ms(p.CyclesToMs(m.weigh_cycles)).c_str());
    std::printf("  %-32s %10s %10s\n", "  resample + diffusion", "", Ms(p.CyclesToMs(m.update_cycles)).c_str());
    std::printf("  %-32s %10.0f %10s\n", "  depth px read, shared", m.depth_reads_shared, "");
    std::printf("  %-32s %10.0f %10s\n", "  depth px read, unshared", m.depth_reads_unshared, "");
    std::printf("  per module [cycles, ms; of which DDR latency, cycles]:\n");
    for (const auto& mod : m.modules)
      std::printf("    %-30s %10.0f %10s %10.0f\n", mod.module.c_str(), mod.cycles, Ms(p.CyclesToMs(mod.cycles)).c_str(),
                  mod.memory_cycles);
  }
  std::printf("%-34s %10s %10s\n", "once per run", "ours", "thesis");
  std::printf("  %-32s %10s %10s\n", "post-process [ms]", Ms(p.CyclesToMs(p.postprocess_cycles)).c_str(), "-");
  std::printf("  %-32s %10s %10s\n", "initialisation [ms]", Ms(p.CyclesToMs(p.init_cycles)).c_str(), "-");
  const double init_ratio = p.init_reads > 0 ? p.init_reads_linear / p.init_reads : 0;
  const double res_ratio = p.resample_reads > 0 ? p.resample_reads_linear / p.resample_reads : 0;
  const double faces_ratio = p.faces_front > 0 ? p.faces_total / p.faces_front : 0;
  std::printf("  %-32s %4.1f -> %-5.2f %10s\n", "init reads per draw", p.init_reads_linear, p.init_reads, "2520->61.5");
  std::printf("  %-32s %10.1fx %9.0fx\n", "  threshold tracker saving", init_ratio, kThesisInitRatio);
  std::printf("  %-32s %4.1f -> %-5.2f %10s\n", "resample reads per draw", p.resample_reads_linear, p.resample_reads,
              "375->8.34");
  std::printf("  %-32s %10.1fx %9.0fx\n", "  threshold tracker saving", res_ratio, kThesisResampleRatio);
  std::printf("  %-32s %10.2f %10.2f\n\n", "faces / rendered faces", faces_ratio, kThesisFacesRatio);
}

}  // namespace

int RunHwReport(int argc, char** argv) {
  CLI::App app{"Cycle model of the hw engine on a synthetic scene, compared with the thesis", "hw-report"};
  std::uint64_t scene_seed = 1;
  std::string target = "torus";
  double occlusion = 0.0;
  std::string json_path;
  HwProfileOptions popt;
  FilterOptions opt;
  opt.engine = "hw";
  opt.stop.max_iterations = 50;  // the thesis's 50-iteration figures
  opt.stop.confidence = 1.0;     // run all of them
  opt.restarts = 1;
  // The thesis's depth fragments are 200×200 for every particle (eq. 7.8, Table 7.2 [HARDWARE.md]): windows of
  // at least 4 object diameters are clipped to the 200-pixel cap.
  opt.render.min_window_diameters = 4;
  std::string frame_dir, models_dir, object;
  app.add_option("--frame", frame_dir,
                 "a real frame instead of the synthetic scene: a YCB-Video scene folder (depth.png, camera.json, "
                 "gt.json, label.png); the prior is the object's label-mask box");
  app.add_option("--models", models_dir, "meshes of --frame, <obj>.ply in metres (default: FRAME/../../models)");
  app.add_option("--object", object, "object of --frame (default: the first of its gt.json)");
  app.add_option("--scene-seed", scene_seed, "synthetic scene seed")->capture_default_str()->transform(SeedValidator());
  app.add_option("--target", target, "synthetic object kind (torus: 1024 vertices, 2048 faces)")->capture_default_str();
  app.add_option("--occlusion", occlusion, "occluded fraction of the target")->capture_default_str();
  app.add_option("--cores", popt.cores, "raster-core counts to model")->delimiter(',')->capture_default_str();
  app.add_option("--clock-mhz", popt.clock_mhz, "clock frequency, MHz")->capture_default_str();
  app.add_option("--profile-every", popt.profile_every,
                 "model every k-th iteration (the first always; others reuse the last model)")
      ->capture_default_str();
  auto* window_option =
      app.add_option("--window-diameters", opt.render.min_window_diameters,
                     "minimum window side in object diameters (default 4 on the synthetic scene: every window 200x200, "
                     "as the thesis's Table 7.2; with --frame the filter's default: the windows the frame's box gives)");
  std::vector<std::string> configs = {"thesis", "ours"};
  app.add_option("--configs", configs,
                 "configurations to model: thesis (the options with every extension of ours off: no z-buffer, 13 moves, "
                 "no annealing, niches, support plane or polish), ours (the options as given)")
      ->delimiter(',')
      ->check(CLI::IsMember({"thesis", "ours"}))
      ->capture_default_str();
  app.add_option("--json", json_path, "also write the report as JSON");
  AddFilterOptions(app, &opt);

  return RunApp(app, argc, argv, [&] {
    if (opt.engine != "hw") throw Error("--engine: hw-report models the hw engine only");
    if (frame_dir.empty() && (!models_dir.empty() || !object.empty()))
      throw Error(std::string(models_dir.empty() ? "--object" : "--models") + " applies to --frame only");
    if (!frame_dir.empty() && window_option->count() == 0) opt.render.min_window_diameters = FilterOptions{}.render.min_window_diameters;
    CheckFilterOptions(opt);
    CheckOutputPaths({{json_path, "--json"}}, {});
    std::string pwhy;
    if (!popt.IsValid(&pwhy)) throw Error("invalid hw-report option: " + pwhy);
    const ReportScene scene = frame_dir.empty() ? SyntheticScene(scene_seed, target, occlusion)
                                                : FrameScene(frame_dir, models_dir, object);
    popt.raw_pyramid = scene.raw_pyramid;
    if (configs.empty()) throw Error("--configs: name at least one of thesis, ours");
    std::vector<Configuration> runs;
    for (const std::string& name : configs) {
      if (std::any_of(runs.begin(), runs.end(), [&](const Configuration& c) { return c.name == name; })) continue;
      Configuration c;
      c.name = name;
      c.options = name == "thesis" ? ThesisFilterOptions(opt) : opt;
      c.profile = ProfileHw(scene.input, scene.target, scene.prior, scene.cls, c.options, popt);
      c.errors = ComputePoseErrors(SamplePoints(scene.target), scene.target.Diameter(), c.profile.result.T_cam_obj,
                                   scene.gt);
      runs.push_back(std::move(c));
    }
    const HwProfile& p0 = runs[0].profile;
    std::printf("hw-report: %s (%d vertices, %d faces in the engine), %dx%d, N = %d, %.0f MHz\n\n",
                scene.description.c_str(), p0.num_vertices, p0.num_faces, scene.input.camera.width,
                scene.input.camera.height, p0.num_particles, p0.clock_mhz);
    for (const Configuration& c : runs) PrintProfile(c);

    // Side by side: Table 7.2 [HARDWARE.md] (depth distribution) and 7.3 (iterations) against each configuration.
    std::printf("side by side [ms]            %10s", "thesis");
    for (const Configuration& c : runs) std::printf(" %10s", c.name.c_str());
    std::printf("\n");
    for (std::size_t k = 0; k < p0.models.size(); ++k) {
      const int cores = p0.models[k].cores;
      const ThesisRow* t = ThesisFor(cores);
      const auto row = [&](const char* what, double thesis, double HwCoreModel::*field) {
        std::printf("M = %-2d %-22s %10s", cores, what, Ms(thesis).c_str());
        for (const Configuration& c : runs) std::printf(" %10s", Ms(c.profile.CyclesToMs(c.profile.models[k].*field)).c_str());
        std::printf("\n");
      };
      row("depth distribution", t ? t->depth_distribution_ms : -1, &HwCoreModel::depth_distribution_cycles);
      row("first iteration", t ? t->first_iteration_ms : -1, &HwCoreModel::first_iteration_cycles);
      row("average iteration", t ? t->average_iteration_ms : -1, &HwCoreModel::average_iteration_cycles);
    }

    if (!json_path.empty()) {
      nlohmann::json confs = nlohmann::json::object();
      for (const Configuration& c : runs) confs[c.name] = ProfileJson(c.profile, c.errors);
      nlohmann::json tables = nlohmann::json::array();
      for (const auto& r : kThesis)
        tables.push_back({{"cores", r.cores},
                          {"depth_distribution_ms", r.depth_distribution_ms},
                          {"first_iteration_ms", r.first_iteration_ms},
                          {"average_iteration_ms", r.average_iteration_ms}});
      nlohmann::json j = {
          {"scene", scene.description}, {"configurations", confs},
          {"thesis", {{"tables", tables}, {"init_tracker_saving", kThesisInitRatio},
                      {"resample_tracker_saving", kThesisResampleRatio}, {"faces_ratio", kThesisFacesRatio}}}};
      if (frame_dir.empty()) {
        j["scene_seed"] = scene_seed;
        j["target"] = target;
      } else {
        j["frame"] = frame_dir;
        j["object"] = scene.target.name;
      }
      WriteFileAtomically(json_path, [&](std::ostream& out) { out << j.dump(1) << "\n"; });
    }
  });
}

}  // namespace posefilter::cli
