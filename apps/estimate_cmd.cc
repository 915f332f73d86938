// posefilter estimate — poses of one or more objects from a depth PNG, a camera, meshes and a
// stage-1 prior (raw pyramid file, detections JSON, or none).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
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

}  // namespace

int RunEstimate(int argc, char** argv) {
  CLI::App app{"Estimate 6-DoF object poses with the particle filter", "estimate"};
  std::string depth_path, camera_path, prior_arg = "none", classes_path, out_path, overlay_path, rgb_path;
  std::string mask_path, mask_classes_path;
  std::vector<std::string> mesh_args;
  double depth_scale = 0, unit_scale = 1.0;
  bool quiet = false, scene_pass = true;
  FilterOptions opt;
  app.add_option("--depth", depth_path, "depth PNG (16-bit; metres = value x depth scale)")->required();
  app.add_option("--camera", camera_path, "camera JSON (fx, fy, cx, cy, width, height, depth_scale)")->required();
  auto* depth_scale_opt =
      app.add_option("--depth-scale", depth_scale, "metres per PNG unit (default: the camera JSON's depth_scale)");
  app.add_option("--mesh", mesh_args, "object mesh, NAME=PATH or PATH (repeatable; NAME = prior class)")->required();
  app.add_option("--unit-scale", unit_scale, "mesh units to metres (0.001 for millimetre meshes)")->capture_default_str();
  app.add_option("--prior", prior_arg,
                 "stage-1 prior: detections JSON (*.json), raw pyramid file (15x20+30x40+60x80 cells x (classes+5) float32), "
                 "'auto' (no detector: candidate regions found in the depth image and PPF pose proposals in them) or "
                 "'none' (uniform)")
      ->capture_default_str();
  app.add_option("--mask", mask_path,
                 "instance or label PNG (8/16-bit ids, 0 = background) of a segmentation front end: one estimate per "
                 "instance whose class has a --mesh, scored against its mask (instead of --prior)");
  app.add_option("--mask-classes", mask_classes_path,
                 "class map of --mask: JSON {\"id\": \"class\"} or [class, ...] (ids from 1; default: YCB-Video's "
                 "label.png ids, 1..21 in the order of the 21 classes)");
  app.add_option("--classes", classes_path, "class list (one per line) of a raw pyramid prior (default: the 21 YCB-Video classes)");
  app.add_option("--out", out_path, "write the results JSON here");
  app.add_option("--overlay", overlay_path, "write an overlay PNG of the estimated poses here");
  app.add_option("--rgb", rgb_path, "RGB PNG to draw the overlay on (default: shaded depth)");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  app.add_flag("--scene-pass,!--no-scene-pass", scene_pass,
               "with several --mesh (not --mask): after the per-object estimates, the joint scene pass re-weighs each "
               "object against the pixels better estimates leave it and re-estimates one whose pixels another claims")
      ->default_str(scene_pass ? "true" : "false");
  AddFilterOptions(app, &opt);

  return RunApp(app, argc, argv, [&] {
    CheckFilterOptions(opt);
    if (!(unit_scale > 0)) throw Error("--unit-scale must be > 0");
    const auto mesh_list = ParseNamedPaths(mesh_args, "--mesh");
    const bool json_prior = std::filesystem::path(prior_arg).extension() == ".json";
    if (!mask_path.empty() && prior_arg != "none")
      throw Error("--mask and --prior: give one stage-1 prior (a mask's box is its detection)");
    if (mask_path.empty() && !mask_classes_path.empty()) throw Error("--mask-classes needs --mask");
    const bool named_prior = prior_arg == "none" || prior_arg == "auto";  // no file
    if (!classes_path.empty() && (named_prior || json_prior || !mask_path.empty()))
      throw Error("--classes names the classes of a raw pyramid --prior; it does not apply to " +
                  std::string(!mask_path.empty() ? "--mask" : json_prior ? "a detections JSON" : "--prior " + prior_arg));
    // The scene pass needs one prior shared by the objects (a --mask gives each instance its own).
    if (!mask_path.empty()) scene_pass = false;
    if (!rgb_path.empty() && overlay_path.empty()) throw Error("--rgb is the background of --overlay; give --overlay too");
    // Every output is checked before the work: writable, and none of the inputs.
    std::vector<NamedPath> inputs = {{depth_path, "--depth"}, {camera_path, "--camera"},
                                     {rgb_path, "--rgb"},     {mask_path, "--mask"},
                                     {mask_classes_path, "--mask-classes"}, {classes_path, "--classes"}};
    if (!named_prior) inputs.push_back({prior_arg, "--prior"});
    for (const auto& [name, path] : mesh_list) inputs.push_back({path, "--mesh"});
    CheckOutputPaths({{out_path, "--out"}, {overlay_path, "--overlay"}}, inputs);
    CameraFile cam = ReadCameraJson(camera_path);
    if (depth_scale_opt->count() == 0) depth_scale = cam.depth_scale;
    if (!(depth_scale > 0) || !std::isfinite(depth_scale))
      throw Error("--depth-scale must be finite and > 0" +
                  std::string(depth_scale_opt->count() ? "" : " (the camera JSON's depth_scale)"));
    SceneInput scene{LoadDepthPng(depth_path, depth_scale), cam.camera};
    ValidateScene(scene, depth_path);
    // The overlay's background, read now so that a bad --rgb fails before the estimate.
    RgbImage background;
    if (!rgb_path.empty()) {
      background = LoadRgbPng(rgb_path);
      if (background.width != scene.camera.width || background.height != scene.camera.height)
        throw Error(rgb_path + ": RGB image is " + std::to_string(background.width) + "x" +
                    std::to_string(background.height) + " but the camera is " + std::to_string(scene.camera.width) +
                    "x" + std::to_string(scene.camera.height) + " (--rgb)");
    }

    std::vector<Mesh> meshes;
    for (const auto& [name, path] : mesh_list) {
      meshes.push_back(LoadMesh(path, unit_scale));
      meshes.back().name = name;
    }

    // The prior and its class list.
    const int W = scene.camera.width, H = scene.camera.height;
    // With a mask: one job per instance of a class with a mesh, each with its own prior.
    struct Job {
      const Mesh* mesh;
      std::vector<std::uint8_t> mask;
      Prior prior;
    };
    std::vector<Job> jobs;
    Prior prior;
    std::map<const Mesh*, std::vector<PoseSeed>> seeds_of;  // --prior auto: each mesh's pose seeds
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

    std::vector<ObjectResult> results;
    if (jobs.empty())
      for (const Mesh& mesh : meshes) jobs.push_back({&mesh, {}, prior});
    std::vector<const Mesh*> job_meshes;
    std::vector<SceneObject> estimates;  // --scene-pass
    for (Job& job : jobs) {
      const Mesh& mesh = *job.mesh;
      job_meshes.push_back(&mesh);
      const int cls = job.prior.ClassIndex(mesh.name);
      if (cls < 0) throw Error("object '" + mesh.name + "' is not a class of the prior (see --classes)");
      if (!(job.prior.ClassMass(cls) > 0)) throw Error("the prior holds no probability for '" + mesh.name + "'");
      scene.mask = std::move(job.mask);
      scene.seeds = seeds_of.count(&mesh) ? seeds_of[&mesh] : std::vector<PoseSeed>{};
      const EstimateResult r = EstimatePose(scene, mesh, job.prior, cls, opt, StderrProgress(mesh.name, opt.stop.max_iterations * opt.restarts, quiet));
      estimates.push_back({&mesh, cls, r});
      if (!quiet && isatty(fileno(stderr))) std::fprintf(stderr, "\n");
      ObjectResult o;
      o.obj = mesh.name;
      o.pose_base = r.pose_base;
      o.T_cam_obj = r.T_cam_obj;
      o.weight = r.weight;
      o.iterations = r.iterations;
      o.time_ms = r.time_ms;
      results.push_back(o);
      if (results.size() == 1)  // the header with the first row: an error before it prints no table
        std::printf("%-20s %9s %9s %9s %8s %8s %8s %7s %5s %8s\n", "object", "x[m]", "y[m]", "z[m]", "roll", "pitch",
                    "yaw", "weight", "iter", "time[ms]");
      std::printf("%-20s %9.4f %9.4f %9.4f %8.3f %8.3f %8.3f %7.3f %5d %8.0f\n", o.obj.c_str(), o.pose_base.x,
                  o.pose_base.y, o.pose_base.z, o.pose_base.roll, o.pose_base.pitch, o.pose_base.yaw, o.weight,
                  o.iterations, o.time_ms);
    }
    if (scene_pass && estimates.size() > 1) {
      scene.mask.clear();
      scene.seeds.clear();
      const std::vector<ScenePassResult> passed = RunScenePass(scene, prior, estimates, opt);
      std::printf("scene pass (best first; weight alone -> without the pixels better estimates explain):\n");
      for (std::size_t i = 0; i < passed.size(); ++i) {
        const ScenePassResult& p = passed[i];
        std::printf("  %-20s %.3f -> %.3f  %s (%.0f ms)\n", results[i].obj.c_str(), p.weight_alone, p.weight_masked,
                    p.replaced ? "re-estimated: new pose" : p.reestimated ? "re-estimated: pose kept" : "kept", p.time_ms);
        if (p.replaced) {
          results[i].pose_base = p.estimate.pose_base;
          results[i].T_cam_obj = p.estimate.T_cam_obj;
          results[i].weight = p.estimate.weight;
          results[i].iterations += p.estimate.iterations;
        }
        results[i].time_ms += p.time_ms;
      }
    }
    if (!out_path.empty()) WriteResultsJson(results, out_path);
    if (!overlay_path.empty()) {
      RgbImage img = rgb_path.empty() ? ShadeDepth(scene.depth) : std::move(background);
      std::vector<LegendEntry> legend;
      for (std::size_t i = 0; i < results.size(); ++i) {
        DrawPoseOverlay(&img, *job_meshes[i], results[i].T_cam_obj, scene.camera, kEstimateColor);
        char weight[32];
        std::snprintf(weight, sizeof weight, " (weight %.2f)", results[i].weight);
        legend.push_back({"estimate " + results[i].obj + weight, kEstimateColor});
      }
      DrawLegend(&img, legend);
      SaveRgbPng(img, overlay_path);
    }
  });
}

}  // namespace posefilter::cli
