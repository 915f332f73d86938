// apps/run_dataset_cmd.cc — `posefilter run-dataset`: estimate every target of every image of a
// dataset (BOP split or YCB-Video folder, bop.h) and append the poses to a BOP results CSV,
// resumably (RunDataset, posefilter/run_dataset.h): the options, the progress bar on stderr,
// the viewer pages (--view-dir) and the summary line.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/bop.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/filter.h"
#include "posefilter/run_dataset.h"
#include "view_cli.h"

namespace posefilter::cli {
namespace {

std::string Duration(double s) {
  char buf[32];
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else if (t >= 60)
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%lds", t);
  return buf;
}

// "[=====>    ] 3/10 images  scene 1 image 3  elapsed 12s  ETA 28s" on stderr: rewritten in
// place on a terminal, one line per image otherwise.
void PrintProgress(int done, int total, int scene_id, int im_id, double elapsed_s, bool tty) {
  constexpr int kWidth = 24;
  const int fill = total > 0 ? done * kWidth / total : kWidth;
  std::string bar(kWidth, ' ');
  for (int i = 0; i < fill; ++i) bar[i] = '=';
  if (fill < kWidth) bar[fill] = '>';
  const double eta = done > 0 ? elapsed_s / done * (total - done) : 0;
  std::fprintf(stderr, "%s[%s] %d/%d images  scene %d image %d  elapsed %s  ETA %s%s", tty ? "\r" : "", bar.c_str(),
               done, total, scene_id, im_id, Duration(elapsed_s).c_str(), Duration(eta).c_str(), tty ? "   " : "\n");
  std::fflush(stderr);
}

// --view-images: "SCENE:IMAGE" or "IMAGE" (that image id in every scene) → is `key` chosen?
bool ViewChosen(const std::vector<std::string>& ids, const std::pair<int, int>& key) {
  for (const std::string& id : ids) {
    const std::size_t colon = id.find(':');
    try {
      if (colon == std::string::npos ? std::stoi(id) == key.second
                                     : std::stoi(id.substr(0, colon)) == key.first && std::stoi(id.substr(colon + 1)) == key.second)
        return true;
    } catch (const std::exception&) {
      throw Error("--view-images: '" + id + "' is not IMAGE or SCENE:IMAGE (integers)");
    }
  }
  return false;
}

// The viewer page of one image (--view-dir): DIR/view_SSSSSS_IIIIII.html, with the image's
// estimates (rows, each with its mesh and particle sets), its ground truth and, where a
// colour image lies beside the depth (rgb.png for depth.png, rgb/ for depth/), its colours.
void WriteImageView(const std::string& dir, const Dataset& ds, const DatasetImage& im, const SceneInput& scene,
                    const std::vector<BopResult>& rows, const std::vector<const Mesh*>& meshes,
                    const std::vector<std::vector<ParticleSet>>& particles, bool support_plane) {
  char name[64];
  std::snprintf(name, sizeof name, "view_%06d_%06d.html", im.scene_id, im.im_id);
  FrameView v;
  v.title = "scene " + std::to_string(im.scene_id) + ", image " + std::to_string(im.im_id);
  v.scene = &scene;
  v.meshes = meshes;
  v.particles = particles;
  v.support_plane = support_plane;
  for (const BopResult& r : rows) {
    ObjectResult o;
    o.obj = ds.Model(r.obj_id)->name;
    o.T_cam_obj = r.T_cam_obj;
    o.weight = r.score;
    v.results.push_back(o);
  }
  for (const GtInstance& g : im.gt) v.gt.push_back({ds.Model(g.obj_id)->name, g.T_cam_obj});
  namespace fs = std::filesystem;
  const fs::path depth(im.depth_path);
  fs::path colour;  // YCB-Video: rgb.png beside depth.png; BOP: rgb/ beside depth/
  if (depth.filename() == "depth.png") colour = depth.parent_path() / "rgb.png";
  else if (depth.parent_path().filename() == "depth") colour = depth.parent_path().parent_path() / "rgb" / depth.filename();
  RgbImage rgb;
  std::error_code ec;
  if (!colour.empty() && fs::is_regular_file(colour, ec)) {
    rgb = LoadRgbPng(colour.string());
    if (rgb.width == scene.camera.width && rgb.height == scene.camera.height) v.rgb = &rgb;
  }
  WriteFrameView(v, (fs::path(dir) / name).string());
}

// The parsed command line of `run-dataset`.
struct RunDatasetArgs {
  RunDatasetOptions run;
  std::string view_dir;
  std::vector<std::string> view_images, images;
  bool uniform = false, auto_prior = false, quiet = false;
  int limit = -1;
  CLI::Option *det_opt = nullptr, *gt_opt = nullptr, *uni_opt = nullptr, *auto_opt = nullptr;
};

// Every option of `run-dataset` on `app`, into *a.
void AddRunDatasetOptions(CLI::App& app, RunDatasetArgs* a) {
  RunDatasetOptions& r = a->run;
  app.add_option("--dataset", r.dataset, "dataset folder (BOP: models/ + <split>/; or YCB-Video: scenes/ + models/)")
      ->required();
  app.add_option("--split", r.split, "BOP split folder (ignored for a YCB-Video folder)")->capture_default_str();
  a->det_opt = app.add_option("--detections", r.detections_path,
                              "BOP detections JSON [{scene_id, image_id, category_id, bbox, score}]");
  a->gt_opt = app.add_option("--gt-boxes", r.gt_jitter_px,
                             "prior from the ground-truth silhouette boxes jittered by this sigma (pixels)");
  a->uni_opt = app.add_flag("--uniform-prior", a->uniform, "no stage-1 prior (uniform over cells)");
  a->auto_opt = app.add_flag("--auto-prior", a->auto_prior,
                             "no detector: candidate regions found in the depth image and PPF pose proposals, for every target's object "
                             "(posefilter/auto_prior.h)");
  a->det_opt->excludes(a->gt_opt)->excludes(a->uni_opt)->excludes(a->auto_opt);
  a->gt_opt->excludes(a->uni_opt)->excludes(a->auto_opt);
  a->uni_opt->excludes(a->auto_opt);
  app.add_option("--gt-box-score", r.gt_box_score, "score of the ground-truth boxes, [0, 1]")->capture_default_str();
  app.add_option("--out", r.out, "results CSV (appended to; images already in it are skipped)")->required();
  app.add_option("--targets", r.targets_path,
                 "targets JSON (BOP test_targets_bop19 format; default: <dataset>/test_targets_bop19.json if "
                 "present, else every gt object)");
  app.add_option("--limit", a->limit, "only the first N images with targets (already done ones included)");
  app.add_option("--images", a->images,
                 "only these images (of those with targets): SCENE:IMAGE, comma-separated (a share of a run split "
                 "over machines)")
      ->delimiter(',');
  app.add_option("--view-dir", a->view_dir,
                 "write the 3D viewer page (docs/VIEWER.md) of each --view-images image into this folder, as "
                 "view_SCENE_IMAGE.html (6 digits each)");
  app.add_option("--view-images", a->view_images, "images whose viewer page is written: IMAGE or SCENE:IMAGE, comma-separated")
      ->delimiter(',');
  app.add_flag("--quiet", a->quiet, "no progress bar on stderr");
  app.add_flag("--scene-pass,!--no-scene-pass", r.scene_pass,
               "after an image's per-object estimates, the joint scene pass over those made with the image's prior "
               "(posefilter/scene_pass.h): an object whose pixels a better estimate explains is re-estimated without them")
      ->default_str(r.scene_pass ? "true" : "false");
  app.add_flag("--no-time", r.no_time,
               "write time -1 (BOP: not measured) instead of each image's wall time, so that runs of the same "
               "options write identical rows");
  AddFilterOptions(app, &r.filter);
  app.callback([a] {
    if (a->det_opt->count() + a->gt_opt->count() + a->uni_opt->count() + a->auto_opt->count() == 0)
      throw CLI::RequiredError("a prior: --detections FILE, --gt-boxes JITTER_PX, --uniform-prior or --auto-prior");
  });
}

// Checks the parsed arguments (before any work) and completes a->run from them.
void CheckRunDatasetArgs(const CLI::App& app, RunDatasetArgs* a) {
  RunDatasetOptions& r = a->run;
  CheckFilterOptions(r.filter);
  if (a->det_opt->count() == 0 && a->gt_opt->count() &&
      (!std::isfinite(r.gt_jitter_px) || r.gt_jitter_px < 0 || r.gt_jitter_px > 1000))
    throw Error("--gt-boxes must be in [0, 1000] pixels, got " + std::to_string(r.gt_jitter_px));
  if (!std::isfinite(r.gt_box_score) || r.gt_box_score < 0 || r.gt_box_score > 1)
    throw Error("--gt-box-score must be in [0, 1], got " + std::to_string(r.gt_box_score));
  if (app.count("--limit") && a->limit < 1) throw Error("--limit must be ≥ 1, got " + std::to_string(a->limit));
  r.limit = a->limit > 0 ? a->limit : 0;
  r.prior = a->det_opt->count()  ? DatasetPriorKind::kDetections
            : a->gt_opt->count() ? DatasetPriorKind::kGtBoxes
            : a->auto_prior      ? DatasetPriorKind::kAuto
                                 : DatasetPriorKind::kUniform;
  r.out_label = "--out";
  for (const std::string& id : a->images) {
    const std::size_t colon = id.find(':');
    std::size_t end_scene = 0, end_image = 0;
    try {
      if (colon == std::string::npos) throw std::invalid_argument(id);
      const int scene_id = std::stoi(id.substr(0, colon), &end_scene);
      const int im_id = std::stoi(id.substr(colon + 1), &end_image);
      if (end_scene != colon || end_image != id.size() - colon - 1) throw std::invalid_argument(id);
      r.images.emplace_back(scene_id, im_id);
    } catch (const std::exception&) {
      throw Error("--images: '" + id + "' is not SCENE:IMAGE (integers)");
    }
  }
  if (a->view_dir.empty() != a->view_images.empty()) throw Error("--view-dir and --view-images go together: give both");
  if (!a->view_dir.empty()) {
    RequireViewer("--view-dir");
    std::error_code ec;
    if (!std::filesystem::is_directory(a->view_dir, ec) || ::access(a->view_dir.c_str(), W_OK) != 0)
      throw Error("--view-dir " + a->view_dir + ": not a writable folder");
    ViewChosen(a->view_images, {0, 0});  // checks the ids' syntax before any work
  }
  // The CSV is appended to (it is its own resume state), never one of the other inputs.
  CheckOutputPaths({{r.out, "--out"}}, {{r.detections_path, "--detections"}, {r.targets_path, "--targets"}});
}

}  // namespace

int RunRunDataset(int argc, char** argv) {
  CLI::App app{"Estimate every target of a dataset (BOP split or YCB-Video folder) and append the poses "
               "to a BOP results CSV (resumable)",
               "run-dataset"};
  RunDatasetArgs a;
  AddRunDatasetOptions(app, &a);
  return RunApp(app, argc, argv, [&] {
    CheckRunDatasetArgs(app, &a);
    const bool tty = isatty(fileno(stderr)), quiet = a.quiet;
    RunDatasetCallbacks cb;
    if (!a.view_dir.empty()) cb.record = [&](int scene_id, int im_id) { return ViewChosen(a.view_images, {scene_id, im_id}); };
    cb.on_note = [&](const std::string& note) {
      if (!quiet) std::fprintf(stderr, "run-dataset: %s\n", note.c_str());
    };
    cb.on_warning = [&](const std::string& w) {
      std::fprintf(stderr, "%srun-dataset: warning: %s\n", tty && !quiet ? "\n" : "", w.c_str());
    };
    cb.on_image = [&](const DatasetImageDone& d) {
      if (!a.view_dir.empty() && ViewChosen(a.view_images, {d.image->scene_id, d.image->im_id}))
        WriteImageView(a.view_dir, *d.dataset, *d.image, *d.scene, *d.rows, *d.meshes, *d.particles,
                       a.run.filter.support.plane);
      if (!quiet) PrintProgress(d.done, d.total, d.image->scene_id, d.image->im_id, d.elapsed_s, tty);
    };
    const RunDatasetSummary sum = RunDataset(a.run, cb);
    if (!quiet && tty && sum.estimated > 0) std::fprintf(stderr, "\n");
    std::printf("%d image(s) estimated, %d skipped (already in %s), %d row(s) written", sum.estimated, sum.skipped,
                a.run.out.c_str(), sum.rows);
    if (sum.failed > 0) std::printf(", %d target instance(s) without an estimate", sum.failed);
    std::printf("\n");
  });
}

}  // namespace posefilter::cli
