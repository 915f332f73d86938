// apps/gt_detections_cmd.cc — `posefilter gt-detections`: a stage-1 prior for frames with
// ground truth. Each gt object's mesh is rendered alone at its gt pose (ProjectedBox: the box
// of the full, unoccluded silhouette), the box is jittered like a detector's (centre and size
// + N(0, σ²) px, centre noise clamped to a quarter of the box, size ≥ 4 px; posefilter::Rng,
// four normals per object in gt order: centre x, centre y, width, height) and written as a
// detections JSON for `estimate --prior`. Objects not in view get a warning and no detection.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/bop.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/projection.h"
#include "posefilter/rng.h"
#include "posefilter/scene_io.h"

namespace posefilter::cli {
namespace {

// "NAME=PATH" or "PATH" (name = the file's stem) → name → path; a name given twice → Error.
}  // namespace

int RunGtDetections(int argc, char** argv) {
  CLI::App app{"Make a stage-1 detections JSON from ground-truth poses: each object's projected "
               "silhouette box, jittered",
               "gt-detections"};
  std::string gt_path, camera_path, models_dir, out_path;
  std::vector<std::string> mesh_args;
  double unit_scale = 1.0, jitter_px = 8, score = 0.9;
  std::uint64_t seed = 1;
  bool quiet = false;
  app.add_option("--gt", gt_path, "gt.json: {objects: [{obj, R, t}]}, object → camera, metres")->required();
  app.add_option("--camera", camera_path, "camera JSON (fx, fy, cx, cy, width, height)")->required();
  app.add_option("--mesh", mesh_args, "mesh of a gt object, NAME=PATH or PATH (name = file stem; repeatable)");
  app.add_option("--models-dir", models_dir, "folder with <obj>.ply for every gt object without a --mesh");
  app.add_option("--unit-scale", unit_scale, "mesh coordinates × this = metres (0.001 for mm meshes)")
      ->capture_default_str();
  app.add_option("--jitter", jitter_px, "σ of the box centre and size noise, pixels (0 = exact boxes)")
      ->capture_default_str();
  app.add_option("--seed", seed, "seed of the jitter (same seed, same boxes)")->capture_default_str()->transform(SeedValidator());
  app.add_option("--score", score, "score of every detection, [0, 1]")->capture_default_str();
  app.add_option("--out", out_path, "write the detections JSON here")->required();
  app.add_flag("--quiet", quiet, "print nothing on stdout");

  return RunApp(app, argc, argv, [&] {
    if (!std::isfinite(unit_scale) || unit_scale <= 0) throw Error("--unit-scale must be finite and > 0");
    if (!std::isfinite(jitter_px) || jitter_px < 0 || jitter_px > 1000)
      throw Error("--jitter must be in [0, 1000] pixels, got " + std::to_string(jitter_px));
    if (!std::isfinite(score) || score < 0 || score > 1)
      throw Error("--score must be in [0, 1], got " + std::to_string(score));
    std::map<std::string, std::string> mesh_paths;
    std::vector<NamedPath> inputs = {{gt_path, "--gt"}, {camera_path, "--camera"}, {models_dir, "--models-dir"}};
    for (const auto& [name, path] : ParseNamedPaths(mesh_args, "--mesh")) {
      mesh_paths[name] = path;
      inputs.push_back({path, "--mesh"});
    }
    CheckOutputPaths({{out_path, "--out"}}, inputs);

    const CameraFile cam = ReadCameraJson(camera_path);
    std::string why;
    if (!cam.camera.IsValid(&why)) throw Error(camera_path + ": invalid camera: " + why);
    const std::vector<GtObject> gt = ReadGtJson(gt_path);
    if (gt.empty()) throw Error(gt_path + ": holds no objects");

    // Every gt object needs a mesh; check all before loading any.
    std::map<std::string, std::string> paths;
    for (const auto& g : gt) {
      if (paths.count(g.obj)) continue;
      if (const auto it = mesh_paths.find(g.obj); it != mesh_paths.end()) {
        paths[g.obj] = it->second;
      } else if (!models_dir.empty()) {
        paths[g.obj] = (std::filesystem::path(models_dir) / (g.obj + ".ply")).string();
      } else {
        throw Error("no mesh for gt object '" + g.obj + "' (" + gt_path + "): give --mesh " + g.obj +
                    "=PATH or --models-dir");
      }
    }
    for (const auto& [name, path] : mesh_paths)
      if (!paths.count(name))
        std::cerr << "posefilter gt-detections: warning: --mesh " << name << " is not a gt object of " << gt_path
                  << " (ignored)\n";
    std::map<std::string, Mesh> meshes;
    for (const auto& [name, path] : paths) {
      Mesh m = LoadMesh(path, unit_scale);
      m.name = name;
      meshes.emplace(name, std::move(m));
    }

    Rng rng(seed);
    std::vector<Detection> dets;
    for (std::size_t i = 0; i < gt.size(); ++i) {
      const GtObject& g = gt[i];
      // JitteredGtBox (bop.h) always draws its four normals, so one object out of view does not
      // shift the others' boxes.
      const GtBoxDetection gb = JitteredGtBox(meshes.at(g.obj), g.T_cam_obj, cam.camera, g.obj, jitter_px, score, rng);
      const Box& box = gb.silhouette;
      if (!gb.in_view) {
        std::cerr << "posefilter gt-detections: warning: " << gt_path << ": objects[" << i << "] '" << g.obj
                  << "' is not in view (no silhouette pixel in the image); no detection\n";
        continue;
      }
      const Box b = DetectionBox(gb.detection);
      dets.push_back(gb.detection);
      if (!quiet)
        std::printf("%-24s silhouette [%.1f %.1f %.1f %.1f]  detection [%.1f %.1f %.1f %.1f]  IoU %.2f\n",
                    g.obj.c_str(), box.cx - box.w / 2, box.cy - box.h / 2, box.w, box.h, dets.back().x,
                    dets.back().y, b.w, b.h, BoxIoU(box, b));
    }
    if (dets.empty()) throw Error(gt_path + ": no gt object is in view of " + camera_path + "; nothing written");
    WriteDetectionsJson(dets, out_path);
    if (!quiet) std::printf("%zu detection(s) written to %s\n", dets.size(), out_path.c_str());
  });
}

}  // namespace posefilter::cli
