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
#include "posefilter/auto_prior.h"
#include "posefilter/scene_pass.h"
#include "posefilter/overlay.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
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

// One estimate: an object's mesh, and with a mask its instance's pixels and prior.
struct Job {
  const Mesh* mesh;
  std::vector<std::uint8_t> mask;
  Prior prior;
};

struct PriorArgs {
  std::string prior_arg, mask_path, mask_classes_path, classes_path;
};

// The stage 1 of `estimate`: the shared prior (and with --prior auto each mesh's pose seeds) in
// *prior and *seeds_of, or with --mask one job per instance of a class with a mesh.
std::vector<Job> MakeJobs(const PriorArgs& in, const SceneInput& scene, const std::vector<Mesh>& meshes, bool quiet,
                          Prior* prior_out, std::map<const Mesh*, std::vector<PoseSeed>>* seeds_out) {
  const std::string &prior_arg = in.prior_arg, &mask_path = in.mask_path, &mask_classes_path = in.mask_classes_path,
                    &classes_path = in.classes_path;
  const bool json_prior = std::filesystem::path(prior_arg).extension() == ".json";
  const int W = scene.camera.width, H = scene.camera.height;
  std::vector<Job> jobs;
  Prior& prior = *prior_out;
  std::map<const Mesh*, std::vector<PoseSeed>>& seeds_of = *seeds_out;
  if (!mask_path.empty()) {
    const LabelImage labels = LoadLabelPng(mask_path);
    if (labels.width != W || labels.height != H)
      throw Error(mask_path + ": mask image is " + std::to_string(labels.width) + "x" + std::to_string(labels.height) +
                  " but the camera is " + std::to_string(W) + "x" + std::to_string(H));
    const auto classes_of = mask_classes_path.empty() ? YcbVideoMaskClasses() : ReadMaskClasses(mask_classes_path);
    const std::vector<InstanceMask> instances = MasksFromLabels(labels, classes_of, mask_path);
    std::vector<std::string> classes;
    for (const auto& m : meshes) classes.push_back(m.name);
    const PyramidLayout layout = PyramidLayout::Thesis(W, H, int(classes.size()));
    for (const Mesh& mesh : meshes) {
      bool any = false;
      for (const InstanceMask& m : instances) {
        if (m.cls != mesh.name) continue;
        jobs.push_back({&mesh, m.pixels, PriorFromDetections({MaskDetection(m)}, layout, classes)});
        any = true;
      }
      if (!any) throw Error(mask_path + ": no instance of '" + mesh.name + "' (a --mesh class) in the mask");
    }
  } else if (prior_arg == "auto") {
    std::vector<const Mesh*> ms;
    std::vector<std::string> names;
    for (const auto& m : meshes) ms.push_back(&m), names.push_back(m.name);
    const std::string cache_dir = DefaultPpfCacheDir();
    std::vector<std::string> cache_status;
    const auto t_stage1 = std::chrono::steady_clock::now();
    AutoStage1 stage1 =
        AutoPriorForMeshes(scene.depth, scene.camera, ms, names, "--prior auto", cache_dir, {}, &cache_status);
    if (!quiet) {
      for (std::size_t k = 0; k < names.size(); ++k)
        std::fprintf(stderr, "posefilter estimate: PPF model of '%s': %s%s\n", names[k].c_str(), cache_status[k].c_str(),
                     cache_dir.empty() ? " (no cache folder: set POSEFILTER_CACHE_DIR)" : (" (cache " + cache_dir + ")").c_str());
      std::fprintf(stderr, "posefilter estimate: --prior auto: stage 1 in %.0f ms\n",
                   std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_stage1).count());
    }
    prior = std::move(stage1.prior);
    for (std::size_t k = 0; k < meshes.size(); ++k) seeds_of[&meshes[k]] = std::move(stage1.seeds[k]);
  } else if (prior_arg == "none") {
    std::vector<std::string> classes;
    for (const auto& m : meshes) classes.push_back(m.name);
    prior = UniformPrior(PyramidLayout::Thesis(W, H, int(classes.size())), classes);
  } else if (json_prior) {
    const std::vector<Detection> dets = ReadDetectionsJson(prior_arg);
    std::vector<std::string> names;
    for (const auto& m : meshes) names.push_back(m.name);
    for (const auto& w : CheckDetectionsForObjects(dets, names, W, H, prior_arg))
      std::fprintf(stderr, "posefilter estimate: warning: %s\n", w.c_str());
    const std::vector<std::string> classes = ClassesForObjects(names, dets);
    prior = PriorFromDetections(dets, PyramidLayout::Thesis(W, H, int(classes.size())), classes);
  } else {
    const std::vector<std::string> classes = classes_path.empty() ? YcbVideoClassNames() : ReadClassList(classes_path);
    const PyramidLayout layout = PyramidLayout::Thesis(W, H, int(classes.size()));
    prior = PostProcessPyramid(ReadRawPyramid(prior_arg, layout), layout, classes);
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

void PrintRow(const ObjectResult& o, bool header) {
  if (header)  // with the first row: an error before it prints no table
    std::printf("%-20s %9s %9s %9s %8s %8s %8s %7s %5s %8s\n", "object", "x[m]", "y[m]", "z[m]", "roll", "pitch",
                "yaw", "weight", "iter", "time[ms]");
  std::printf("%-20s %9.4f %9.4f %9.4f %8.3f %8.3f %8.3f %7.3f %5d %8.0f\n", o.obj.c_str(), o.pose_base.x,
              o.pose_base.y, o.pose_base.z, o.pose_base.roll, o.pose_base.pitch, o.pose_base.yaw, o.weight,
              o.iterations, o.time_ms);
}

// Runs every job's filter, then (scene_pass, several objects) the joint scene pass.
Estimated RunJobs(SceneInput& scene, std::vector<Job>& jobs, const Prior& prior,
                  std::map<const Mesh*, std::vector<PoseSeed>>& seeds_of, const FilterOptions& opt, bool quiet,
                  bool scene_pass) {
  Estimated out;
  std::vector<SceneObject> estimates;  // --scene-pass
  for (Job& job : jobs) {
    const Mesh& mesh = *job.mesh;
    out.meshes.push_back(&mesh);
    const int cls = job.prior.ClassIndex(mesh.name);
    if (cls < 0) throw Error("object '" + mesh.name + "' is not a class of the prior (see --classes)");
    if (!(job.prior.ClassMass(cls) > 0)) throw Error("the prior holds no probability for '" + mesh.name + "'");
    scene.mask = std::move(job.mask);
    scene.seeds = seeds_of.count(&mesh) ? seeds_of[&mesh] : std::vector<PoseSeed>{};
    EstimateResult r = EstimatePose(scene, mesh, job.prior, cls, opt,
                                    StderrProgress(mesh.name, opt.stop.max_iterations * opt.restarts, quiet));
    out.particles.push_back(std::move(r.particle_history));
    r.particle_history.clear();
    estimates.push_back({&mesh, cls, r});
    if (!quiet && isatty(fileno(stderr))) std::fprintf(stderr, "\n");
    ObjectResult o;
    o.obj = mesh.name;
    o.pose_base = r.pose_base;
    o.T_cam_obj = r.T_cam_obj;
    o.weight = r.weight;
    o.iterations = r.iterations;
    o.time_ms = r.time_ms;
    out.results.push_back(o);
    PrintRow(o, out.results.size() == 1);
  }
  if (scene_pass && estimates.size() > 1) {
    scene.mask.clear();
    scene.seeds.clear();
    const std::vector<ScenePassResult> passed = RunScenePass(scene, prior, estimates, opt);
    std::printf("scene pass (best first; weight alone -> without the pixels better estimates explain):\n");
    // The rows in the order the pass settles the objects: by their weight alone, best first.
    std::vector<std::size_t> order(passed.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return passed[a].weight_alone > passed[b].weight_alone; });
    for (std::size_t i : order) {
      const ScenePassResult& p = passed[i];
      ObjectResult& res = out.results[i];
      std::printf("  %-20s %.3f -> %.3f  %s (%.0f ms)\n", res.obj.c_str(), p.weight_alone, p.weight_masked,
                  p.replaced ? "re-estimated: new pose" : p.reestimated ? "re-estimated: pose kept" : "kept", p.time_ms);
      if (p.replaced) {
        res.pose_base = p.estimate.pose_base;
        res.T_cam_obj = p.estimate.T_cam_obj;
        res.weight = p.estimate.weight;
        res.iterations += p.estimate.iterations;
      }
      res.time_ms += p.time_ms;
    }
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

    // The prior and its class list; with a mask, one job per instance.
    Prior prior;
    std::map<const Mesh*, std::vector<PoseSeed>> seeds_of;  // --prior auto: each mesh's pose seeds
    std::vector<Job> jobs = MakeJobs(pa, scene, meshes, quiet, &prior, &seeds_of);
    if (jobs.empty())
      for (const Mesh& mesh : meshes) jobs.push_back({&mesh, {}, prior});
    opt.record_particles = opt.record_particles || view;
    const Estimated est = RunJobs(scene, jobs, prior, seeds_of, opt, quiet, scene_pass);
    if (!paths.out.empty()) WriteResultsJson(est.results, paths.out);
    if (view) {
      scene.mask.clear();
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
