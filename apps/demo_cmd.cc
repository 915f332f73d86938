// posefilter demo — builds a synthetic scene with ground truth (an L-shaped object on a table
// with clutter, a partial occluder and a noisy detection prior), estimates the object's pose
// with the default settings and prints the error against the ground truth.
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/metrics.h"
#include "posefilter/overlay.h"
#include "posefilter/synth.h"
#include "view_cli.h"

namespace posefilter::cli {

int RunDemo(int argc, char** argv) {
  CLI::App app{"Estimate a pose on a built-in synthetic scene and compare with the ground truth", "demo"};
  std::string out_dir = "demo", view_path;
  std::uint64_t scene_seed = 7;
  SynthOptions synth;
  synth.target = "lshape";
  synth.occlusion = 0.3;
  bool quiet = false;
  FilterOptions opt;
  app.add_option("--out", out_dir, "folder for the scene files, results and overlay")->capture_default_str();
  app.add_option("--scene-seed", scene_seed, "seed of the synthetic scene")->capture_default_str()->transform(SeedValidator());
  app.add_option("--target", synth.target, "object kind: box, cylinder, lshape or torus")->capture_default_str();
  app.add_option("--occlusion", synth.occlusion, "fraction of the object hidden by an occluder")->capture_default_str();
  app.add_option("--view", view_path,
                 "also write the 3D viewer page here (HTML: point cloud, estimate, ground truth, support plane, "
                 "particles per iteration; docs/VIEWER.md)");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  AddFilterOptions(app, &opt);

  return RunApp(app, argc, argv, [&] {
    CheckFilterOptions(opt);
    if (!view_path.empty()) {
      RequireViewer("--view");
      opt.record_particles = true;
    }
    std::string why;
    if (!synth.IsValid(&why)) throw Error("invalid scene option: " + why);
    // The scene's files and the overlay go into --out; --view is none of them.
    MakeOutputFolder(out_dir, "--out");
    std::vector<NamedPath> outputs = {{view_path, "--view"}};
    for (const std::string& f : SynthSceneFileNames(synth.target))
      outputs.push_back({(std::filesystem::path(out_dir) / f).string(), "--out (" + f + ")"});
    outputs.push_back({(std::filesystem::path(out_dir) / "overlay.png").string(), "--out (overlay.png)"});
    CheckOutputPaths(outputs, {});
    const SynthScene scene = MakeSynthScene(synth, scene_seed);
    WriteSynthScene(scene, out_dir);
    std::printf("scene: %s (%s at %.2f m, %.0f%% occluded, %zu detections) written to %s/\n", synth.target.c_str(),
                scene.target.name.c_str(), scene.distance_m, 100 * scene.occlusion_achieved, scene.detections.size(),
                out_dir.c_str());

    const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
    const SceneInput input{scene.depth, scene.camera};
    const int cls = prior.ClassIndex(scene.target.name);
    const EstimateResult r =
        EstimatePose(input, scene.target, prior, cls, opt, StderrProgress(scene.target.name, opt.stop.max_iterations * opt.restarts, quiet));
    if (!quiet && isatty(fileno(stderr))) std::fprintf(stderr, "\n");

    const double diameter = scene.target.Diameter();
    const PoseErrors e = ComputePoseErrors(SamplePoints(scene.target), diameter, r.T_cam_obj, scene.gt[0].T_cam_obj);
    std::printf("estimate: weight %.3f after %d iterations in %.0f ms (%s)\n", r.weight, r.iterations, r.time_ms,
                r.converged ? "converged" : "confidence not reached: runs ended at their iteration limit or stall");
    std::printf("error vs ground truth: ADD-S %.1f mm = %.1f%% of the %.0f mm diameter (%s), ADD %.1f mm, "
                "rotation %.1f deg, translation %.1f mm\n",
                1000 * e.adds, 100 * e.adds / diameter, 1000 * diameter, e.adds_ok ? "found" : "NOT found",
                1000 * e.add, e.rot_deg, 1000 * e.trans_m);

    RgbImage img = ShadeDepth(scene.depth);
    DrawPoseOverlay(&img, scene.target, scene.gt[0].T_cam_obj, scene.camera, kGroundTruthColor);
    DrawPoseOverlay(&img, scene.target, r.T_cam_obj, scene.camera, kEstimateColor);
    DrawLegend(&img, {{"estimate", kEstimateColor}, {"ground truth", kGroundTruthColor}});
    const std::string overlay = (std::filesystem::path(out_dir) / "overlay.png").string();
    SaveRgbPng(img, overlay);
    std::printf("overlay (green: estimate, blue: ground truth): %s\n", overlay.c_str());
    if (!view_path.empty()) {
      ObjectResult o;
      o.obj = scene.target.name;
      o.T_cam_obj = r.T_cam_obj;
      o.weight = r.weight;
      WriteFrameView({"demo scene " + std::to_string(scene_seed), &input, nullptr, {&scene.target}, {o},
                      {r.particle_history}, {{scene.target.name, scene.gt[0].T_cam_obj}}, opt.support.plane},
                     view_path);
      std::printf("viewer page: %s\n", view_path.c_str());
    }
  });
}

}  // namespace posefilter::cli
