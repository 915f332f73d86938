// posefilter estimate — poses of one or more objects from a depth PNG, a camera, meshes and a
// stage-1 prior (raw pyramid file, detections JSON, or none). `posefilter view` is the same
// command writing the viewer page (posefilter/view.h) as its --out, or the page of a results
// JSON (--results) without estimating.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <sstream>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mask_prior.h"
#include "posefilter/estimate_scene.h"
#include "posefilter/overlay.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
#include "posefilter/stage1.h"
#include "view_cli.h"

namespace posefilter::cli {
namespace {

std::vector<std::string> ReadClassList(const std::string& path) {
  std::istringstream in(ReadSmallFile(path, kMaxSmallFileBytes, "class list"));
  std::vector<std::string> classes;
  std::string line;
  while (std::getline(in, line)) {
    line.erase(line.find_last_not_of(" \t\r") + 1);
    if (!line.empty()) classes.push_back(line);
  }
  if (classes.empty()) throw Error(path + ": class list is empty");
  return classes;
}

struct PriorArgs {
  std::string prior_arg, mask_path, mask_classes_path, classes_path;
};

// The stage-1 options of `estimate`'s --prior or --mask (posefilter/stage1.h).
Stage1Options EstimateStage1Options(const PriorArgs& in, const SceneInput& scene) {
  Stage1Options so;
  const int W = scene.camera.width, H = scene.camera.height;
  if (!in.mask_path.empty()) {
    const LabelImage labels = LoadLabelPng(in.mask_path);
    if (labels.width != W || labels.height != H)
      throw Error(in.mask_path + ": mask image is " + std::to_string(labels.width) + "x" + std::to_string(labels.height) +
                  " but the camera is " + std::to_string(W) + "x" + std::to_string(H));
    const auto classes_of = in.mask_classes_path.empty() ? YcbVideoMaskClasses() : ReadMaskClasses(in.mask_classes_path);
    so.kind = Stage1Kind::kMasks;
    so.masks = MasksFromLabels(labels, classes_of, in.mask_path);
    so.what = in.mask_path;
  } else if (in.prior_arg == "auto") {
    so.kind = Stage1Kind::kAuto;
    so.what = "--prior auto";
    so.cache_dir = DefaultPpfCacheDir();
  } else if (in.prior_arg == "none") {
    so.kind = Stage1Kind::kNone;
  } else if (std::filesystem::path(in.prior_arg).extension() == ".json") {
    so.kind = Stage1Kind::kDetections;
    so.detections = ReadDetectionsJson(in.prior_arg);
    so.check_detections = true;
    so.what = in.prior_arg;
  } else {
    so.kind = Stage1Kind::kPyramid;
    so.classes = in.classes_path.empty() ? YcbVideoClassNames() : ReadClassList(in.classes_path);
    so.pyramid_path = in.prior_arg;
    so.what = in.prior_arg;
  }
  return so;
}

// The stage 1 of `estimate` into *stage1, and its estimates: one per mesh (with --prior auto,
// with its pose seeds) on stage1->prior, or with --mask one per instance of a class with a
// mesh, on the instance's prior (in *stage1).
std::vector<SceneEstimateObject> MakeJobs(const PriorArgs& in, const SceneInput& scene, const std::vector<Mesh>& meshes,
                                          bool quiet, Stage1* stage1) {
  const Stage1Options so = EstimateStage1Options(in, scene);
  std::vector<Stage1Object> objects;
  for (const Mesh& m : meshes) objects.push_back({m.name, &m});
  const auto t_stage1 = std::chrono::steady_clock::now();
  *stage1 = BuildStage1(scene, objects, so);
  for (const std::string& w : stage1->warnings) std::fprintf(stderr, "posefilter estimate: warning: %s\n", w.c_str());
  if (so.kind == Stage1Kind::kAuto && !quiet) {
    for (std::size_t k = 0; k < meshes.size(); ++k)
      std::fprintf(stderr, "posefilter estimate: PPF model of '%s': %s%s\n", meshes[k].name.c_str(),
                   stage1->cache_status[k].c_str(),
                   so.cache_dir.empty() ? " (no cache folder: set POSEFILTER_CACHE_DIR)" : (" (cache " + so.cache_dir + ")").c_str());
    std::fprintf(stderr, "posefilter estimate: --prior auto: stage 1 in %.0f ms\n",
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_stage1).count());
  }
  std::vector<SceneEstimateObject> jobs;
  if (so.kind != Stage1Kind::kMasks) {
    for (std::size_t k = 0; k < meshes.size(); ++k) {
      jobs.emplace_back();
      jobs.back().mesh = &meshes[k];
      jobs.back().seeds = std::move(stage1->seeds[k]);
    }
    return jobs;
  }
  for (std::size_t k = 0; k < meshes.size(); ++k)
    if (std::none_of(stage1->instances.begin(), stage1->instances.end(), [&](const Stage1Instance& i) { return i.object == k; }))
      throw Error(in.mask_path + ": no instance of '" + meshes[k].name + "' (a --mesh class) in the mask");
  for (Stage1Instance& instance : stage1->instances) {
    jobs.emplace_back();
    jobs.back().mesh = &meshes[instance.object];
    jobs.back().own_prior = &instance.prior;
    jobs.back().mask = std::move(instance.mask);
  }
  return jobs;
}

// What the estimates found: per object the result row, its mesh and (when recorded) the
// particle sets of its filter run.
struct Estimated {
  std::vector<ObjectResult> results;
  std::vector<const Mesh*> meshes;
  std::vector<std::vector<ParticleSet>> particles;
};

ObjectResult ToObjectResult(const EstimateResult& r) {
  ObjectResult o;
  o.obj = r.obj;
  o.pose_base = r.pose_base;
  o.T_cam_obj = r.T_cam_obj;
  o.weight = r.weight;
  o.iterations = r.iterations;
  o.time_ms = r.time_ms;
  return o;
}

void PrintRow(const ObjectResult& o, bool header) {
  if (header)  // with the first row: an error before it prints no table
    std::printf("%-20s %9s %9s %9s %8s %8s %8s %7s %5s %8s\n", "object", "x[m]", "y[m]", "z[m]", "roll", "pitch",
                "yaw", "weight", "iter", "time[ms]");
  std::printf("%-20s %9.4f %9.4f %9.4f %8.3f %8.3f %8.3f %7.3f %5d %8.0f\n", o.obj.c_str(), o.pose_base.x,
              o.pose_base.y, o.pose_base.z, o.pose_base.roll, o.pose_base.pitch, o.pose_base.yaw, o.weight,
              o.iterations, o.time_ms);
}

// The scene pass's table: the rows in the order the pass settles the objects (by their weight
// alone, best first).
void PrintScenePass(const std::vector<SceneEstimate>& est) {
  std::printf("scene pass (best first; weight alone -> without the pixels better estimates explain):\n");
  std::vector<std::size_t> order(est.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return est[a].pass.weight_alone > est[b].pass.weight_alone; });
  for (std::size_t i : order) {
    const ScenePassResult& p = est[i].pass;
    std::printf("  %-20s %.3f -> %.3f  %s (%.0f ms)\n", est[i].alone.obj.c_str(), p.weight_alone, p.weight_masked,
                p.replaced ? "re-estimated: new pose" : p.reestimated ? "re-estimated: pose kept" : "kept", p.time_ms);
  }
}

// Runs every job's filter, then (scene_pass, several objects on the shared prior) the joint
// scene pass (posefilter/estimate_scene.h), printing each object's row as it is estimated.
Estimated RunJobs(const SceneInput& scene, std::vector<SceneEstimateObject>& jobs, const Prior& prior,
                  const FilterOptions& opt, bool quiet, bool scene_pass) {
  // Each object's class, checked before any estimate.
  for (SceneEstimateObject& job : jobs) {
    const Prior& p = job.own_prior ? *job.own_prior : prior;
    job.cls = p.ClassIndex(job.mesh->name);
    if (job.cls < 0) throw Error("object '" + job.mesh->name + "' is not a class of the prior (see --classes)");
    if (!(p.ClassMass(job.cls) > 0)) throw Error("the prior holds no probability for '" + job.mesh->name + "'");
    job.progress = StderrProgress(job.mesh->name, opt.stop.max_iterations * opt.restarts, quiet);
  }
  Estimated out;
  EstimateSceneOptions so;
  so.scene_pass = scene_pass;
  std::vector<SceneEstimate> est = EstimateScene(scene, prior, jobs, opt, so, [&](std::size_t i, const SceneEstimate& e) {
    if (!quiet && isatty(fileno(stderr))) std::fprintf(stderr, "\n");
    PrintRow(ToObjectResult(e.alone), i == 0);
  });
  if (!est.empty() && est[0].passed) PrintScenePass(est);
  for (std::size_t i = 0; i < est.size(); ++i) {
    out.meshes.push_back(jobs[i].mesh);
    out.particles.push_back(std::move(est[i].particles));
    out.results.push_back(ToObjectResult(est[i].result));
  }
  return out;
}

// The command's file options (`view` names them differently: its --out is the page).
struct Paths {
  std::string depth, camera, out, overlay, rgb, view, gt, results;
  const char* out_option = "--out";   // the results JSON's option
  const char* view_option = "--view";  // the viewer page's option
};

// `view --results`: the page of a results JSON, without estimating (each result needs the
// --mesh of its class).
void ViewResults(const Paths& paths, const SceneInput& scene, const RgbImage* rgb, const std::vector<Mesh>& meshes,
                 const std::vector<GtObject>& gt, bool support_plane) {
  FrameView v;
  v.title = std::filesystem::path(paths.results).filename().string();
  v.scene = &scene;
  v.rgb = rgb;
  v.results = ReadResultsJson(paths.results);
  v.gt = gt;
  v.support_plane = support_plane;
  for (const ObjectResult& r : v.results) {
    const auto m = std::find_if(meshes.begin(), meshes.end(), [&](const Mesh& x) { return x.name == r.obj; });
    if (m == meshes.end())
      throw Error(paths.results + ": object '" + r.obj + "' has no --mesh (give --mesh " + r.obj + "=PATH)");
    v.meshes.push_back(&*m);
  }
  WriteFrameView(v, paths.view);
}

// The parsed command line of `estimate` / `view`.
struct EstimateArgs {
  Paths paths;
  PriorArgs pa{"none", {}, {}, {}};
  std::vector<std::string> mesh_args;
  double depth_scale = 0, unit_scale = 1.0;
  bool quiet = false, scene_pass = true;
  FilterOptions opt;
  CLI::Option* depth_scale_opt = nullptr;
};

// Every option of `estimate` (view_command false) or `view` (true) on `app`, into *a.
void AddEstimateOptions(CLI::App& app, EstimateArgs* a, bool view_command) {
  Paths& paths = a->paths;
  PriorArgs& pa = a->pa;
  app.add_option("--depth", paths.depth, "depth PNG (16-bit; metres = value x depth scale)")->required();
  app.add_option("--camera", paths.camera, "camera JSON (fx, fy, cx, cy, width, height, depth_scale)")->required();
  a->depth_scale_opt =
      app.add_option("--depth-scale", a->depth_scale, "metres per PNG unit (default: the camera JSON's depth_scale)");
  app.add_option("--mesh", a->mesh_args, "object mesh, NAME=PATH or PATH (repeatable; NAME = prior class)")->required();
  app.add_option("--unit-scale", a->unit_scale, "mesh units to metres (0.001 for millimetre meshes)")->capture_default_str();
  app.add_option("--prior", pa.prior_arg,
                 "stage-1 prior: detections JSON (*.json), raw pyramid file (15x20+30x40+60x80 cells x (classes+5) float32), "
                 "'auto' (no detector: candidate regions found in the depth image and PPF pose proposals in them) or "
                 "'none' (uniform)")
      ->capture_default_str();
  app.add_option("--mask", pa.mask_path,
                 "instance or label PNG (8/16-bit ids, 0 = background) of a segmentation front end: one estimate per "
                 "instance whose class has a --mesh, scored against its mask (instead of --prior)");
  app.add_option("--mask-classes", pa.mask_classes_path,
                 "class map of --mask: JSON {\"id\": \"class\"} or [class, ...] (ids from 1; default: YCB-Video's "
                 "label.png ids, 1..21 in the order of the 21 classes)");
  app.add_option("--classes", pa.classes_path, "class list (one per line) of a raw pyramid prior (default: the 21 YCB-Video classes)");
  app.add_option(paths.out_option, paths.out, "write the results JSON here");
  app.add_option("--overlay", paths.overlay, "write an overlay PNG of the estimated poses here");
  app.add_option(paths.view_option, paths.view,
                 "write the 3D viewer page here: one self-contained HTML file (point cloud, meshes in their poses, "
                 "ground truth, support plane, particles per iteration; docs/VIEWER.md)")
      ->required(view_command);
  app.add_option("--gt", paths.gt, "ground truth of the frame (gt.json), drawn in the viewer page");
  if (view_command)
    app.add_option("--results", paths.results,
                   "a results JSON of `estimate --out` to show instead of estimating (with --mesh for each object)");
  app.add_option("--rgb", paths.rgb, "RGB PNG: the overlay's background and the viewer's point cloud colours "
                                     "(default: shaded depth)");
  app.add_flag("--quiet", a->quiet, "no progress on stderr");
  app.add_flag("--scene-pass,!--no-scene-pass", a->scene_pass,
               "with several --mesh (not --mask): after the per-object estimates, the joint scene pass re-weighs each "
               "object against the pixels better estimates leave it and re-estimates one whose pixels another claims")
      ->default_str(a->scene_pass ? "true" : "false");
  AddFilterOptions(app, &a->opt);
}

}  // namespace

int RunEstimateCommand(int argc, char** argv, bool view_command) {
  CLI::App app{view_command ? "Write the 3D viewer page (HTML) of a frame: estimate its objects (the options of "
                              "`estimate`), or show a results JSON (--results)"
                            : "Estimate 6-DoF object poses with the particle filter",
               view_command ? "view" : "estimate"};
  EstimateArgs args;
  args.paths = {{}, {}, {}, {}, {}, {}, {}, {}, view_command ? "--json" : "--out", view_command ? "--out" : "--view"};
  AddEstimateOptions(app, &args, view_command);
  Paths& paths = args.paths;
  PriorArgs& pa = args.pa;
  const std::vector<std::string>& mesh_args = args.mesh_args;
  double &depth_scale = args.depth_scale, &unit_scale = args.unit_scale;
  bool &quiet = args.quiet, &scene_pass = args.scene_pass;
  FilterOptions& opt = args.opt;
  const CLI::Option* depth_scale_opt = args.depth_scale_opt;

  return RunApp(app, argc, argv, [&] {
    const bool view = !paths.view.empty();
    if (view) RequireViewer(paths.view_option);
    CheckFilterOptions(opt);
    if (!(unit_scale > 0)) throw Error("--unit-scale must be > 0");
    const auto mesh_list = ParseNamedPaths(mesh_args, "--mesh");
    const bool json_prior = std::filesystem::path(pa.prior_arg).extension() == ".json";
    const bool named_prior = pa.prior_arg == "none" || pa.prior_arg == "auto";  // no file
    if (!paths.results.empty() && (!named_prior || pa.prior_arg == "auto" || !pa.mask_path.empty() ||
                                   !paths.out.empty() || !paths.overlay.empty()))
      throw Error("--results shows a results JSON as it is: --prior, --mask, --json and --overlay do not apply");
    if (!pa.mask_path.empty() && pa.prior_arg != "none")
      throw Error("--mask and --prior: give one stage-1 prior (a mask's box is its detection)");
    if (pa.mask_path.empty() && !pa.mask_classes_path.empty()) throw Error("--mask-classes needs --mask");
    if (!pa.classes_path.empty() && (named_prior || json_prior || !pa.mask_path.empty()))
      throw Error("--classes names the classes of a raw pyramid --prior; it does not apply to " +
                  std::string(!pa.mask_path.empty() ? "--mask" : json_prior ? "a detections JSON" : "--prior " + pa.prior_arg));
    // The scene pass needs one prior shared by the objects (a --mask gives each instance its own).
    if (!pa.mask_path.empty()) scene_pass = false;
    if (!paths.rgb.empty() && paths.overlay.empty() && !view)
      throw Error("--rgb is the background of --overlay and the colour of " + std::string(paths.view_option) +
                  "'s point cloud; give one of them too");
    if (!paths.gt.empty() && !view) throw Error("--gt is the ground truth of the viewer page; give --view too");
    // Every output is checked before the work: writable, and none of the inputs.
    std::vector<NamedPath> inputs = {{paths.depth, "--depth"},          {paths.camera, "--camera"},
                                     {paths.rgb, "--rgb"},              {pa.mask_path, "--mask"},
                                     {pa.mask_classes_path, "--mask-classes"}, {pa.classes_path, "--classes"},
                                     {paths.gt, "--gt"},                {paths.results, "--results"}};
    if (!named_prior) inputs.push_back({pa.prior_arg, "--prior"});
    for (const auto& [name, path] : mesh_list) inputs.push_back({path, "--mesh"});
    CheckOutputPaths({{paths.out, paths.out_option}, {paths.overlay, "--overlay"}, {paths.view, paths.view_option}},
                     inputs);
    CameraFile cam = ReadCameraJson(paths.camera);
    if (depth_scale_opt->count() == 0) depth_scale = cam.depth_scale;
    if (!(depth_scale > 0) || !std::isfinite(depth_scale))
      throw Error("--depth-scale must be finite and > 0" +
                  std::string(depth_scale_opt->count() ? "" : " (the camera JSON's depth_scale)"));
    SceneInput scene{LoadDepthPng(paths.depth, depth_scale, cam.camera.width, cam.camera.height), cam.camera};
    ValidateScene(scene, paths.depth);
    // The overlay's background, read now so that a bad --rgb fails before the estimate.
    RgbImage background;
    if (!paths.rgb.empty()) {
      background = LoadRgbPng(paths.rgb);
      if (background.width != scene.camera.width || background.height != scene.camera.height)
        throw Error(paths.rgb + ": RGB image is " + std::to_string(background.width) + "x" +
                    std::to_string(background.height) + " but the camera is " + std::to_string(scene.camera.width) +
                    "x" + std::to_string(scene.camera.height) + " (--rgb)");
    }
    const std::vector<GtObject> gt = paths.gt.empty() ? std::vector<GtObject>{} : ReadGtJson(paths.gt);

    std::vector<Mesh> meshes;
    for (const auto& [name, path] : mesh_list) {
      meshes.push_back(LoadMesh(path, unit_scale));
      meshes.back().name = name;
    }
    const RgbImage* rgb = paths.rgb.empty() ? nullptr : &background;
    if (!paths.results.empty()) return ViewResults(paths, scene, rgb, meshes, gt, opt.support.plane);

    // The stage 1: the prior and, with a mask, one job per instance.
    Stage1 stage1;
    std::vector<SceneEstimateObject> jobs = MakeJobs(pa, scene, meshes, quiet, &stage1);
    opt.record_particles = opt.record_particles || view;
    const Estimated est = RunJobs(scene, jobs, stage1.prior, opt, quiet, scene_pass);
    if (!paths.out.empty()) WriteResultsJson(est.results, paths.out);
    if (view) {
      FrameView v{std::filesystem::path(paths.depth).parent_path().filename().string(), &scene, rgb, est.meshes,
                  est.results, est.particles, gt, opt.support.plane};
      WriteFrameView(v, paths.view);
    }
    if (!paths.overlay.empty()) {
      RgbImage img = paths.rgb.empty() ? ShadeDepth(scene.depth) : background;
      std::vector<LegendEntry> legend;
      for (std::size_t i = 0; i < est.results.size(); ++i) {
        DrawPoseOverlay(&img, *est.meshes[i], est.results[i].T_cam_obj, scene.camera, kEstimateColor);
        char weight[32];
        std::snprintf(weight, sizeof weight, " (weight %.2f)", est.results[i].weight);
        legend.push_back({"estimate " + est.results[i].obj + weight, kEstimateColor});
      }
      DrawLegend(&img, legend);
      SaveRgbPng(img, paths.overlay);
    }
  });
}

int RunEstimate(int argc, char** argv) { return RunEstimateCommand(argc, argv, false); }

}  // namespace posefilter::cli
