// apps/run_dataset_cmd.cc — `posefilter run-dataset`: estimate every target of every image of a
// dataset (BOP split or YCB-Video folder, bop.h) and append the poses to a BOP results CSV.
//
// Per image: the depth is loaded, a stage-1 prior is built (BOP detections of the image,
// jittered ground-truth boxes — JitteredGtBox, the rule of `gt-detections` — or uniform), and
// the filter runs once per target instance. A target with inst_count = 1 uses the prior of all
// the image's detections; with inst_count = k > 1, instance i uses a prior of the class's i-th
// best detection alone (no estimate when there are fewer than k). Rows of an image are appended
// and flushed when the image is done, all with the image's wall time (or -1, BOP's "not
// measured", with --no-time: then two runs write identical rows); an image already in the
// CSV is skipped, so a run can be interrupted and resumed. Random streams derive from --seed,
// the scene, the image and the target, so a resumed run gives the rows an uninterrupted one
// would. The estimates made with an image's prior then go through the joint scene pass
// (--no-scene-pass: not) before the rows are written.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
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
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/bop.h"
#include "posefilter/scene_pass.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/filter.h"
#include "posefilter/auto_prior.h"
#include "posefilter/prior.h"
#include "posefilter/rng.h"
#include "view_cli.h"

namespace posefilter::cli {
namespace {

using Clock = std::chrono::steady_clock;

// A seed for one (scene, image, object, instance), mixed from the user's seed.
std::uint64_t MixSeed(std::uint64_t seed, int scene_id, int im_id, int obj_id, int instance) {
  Rng r(seed ^ (std::uint64_t(std::uint32_t(scene_id)) << 32 | std::uint32_t(im_id)));
  std::uint64_t s = r.NextU64();
  Rng r2(s ^ (std::uint64_t(std::uint32_t(obj_id)) << 32 | std::uint32_t(instance)));
  return r2.NextU64();
}

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

// "scene_id,im_id" of a CSV row (its first two fields), or "" when the text has fewer.
std::string ImageKeyOfRow(const std::string& row) {
  const std::size_t a = row.find(',');
  if (a == std::string::npos) return "";
  const std::size_t b = row.find(',', a + 1);
  return b == std::string::npos ? "" : row.substr(0, b);
}

// An existing --out is resumed only when it is a results CSV: its first line is the header.
// Checked before anything in the file changes (the torn-row repair below cuts the file).
void CheckResultsCsvHeader(const std::string& csv) {
  std::error_code ec;
  if (!std::filesystem::exists(csv, ec) || std::filesystem::file_size(csv, ec) == 0) return;
  std::ifstream in(csv, std::ios::binary);
  if (!in) throw Error("--out " + csv + ": cannot open it to resume");
  std::string first;
  std::getline(in, first);
  if (!first.empty() && first.back() == '\r') first.pop_back();
  if (first != kBopCsvHeader)
    throw Error("--out " + csv + ": exists and is not a results CSV (line 1 is not \"" + std::string(kBopCsvHeader) +
                "\"); it is left as it is");
}

// One writer per results CSV: an exclusive advisory lock (flock) on the file, held until the
// process ends (the kernel releases it, also after a crash). A second run on the same file stops
// with an error instead of duplicating every row. Returns the descriptor that holds the lock.
int LockResultsCsv(const std::string& csv) {
  const int fd = ::open(csv.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd < 0) throw Error("--out " + csv + ": cannot open it (" + std::strerror(errno) + ")");
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    throw Error("--out " + csv + ": another run-dataset is writing it (it holds the file's lock); wait for it to end or "
                "give another --out");
  }
  return fd;
}

// Appends write an image's rows with one write and undo a failed one, so only a crash of the
// machine mid-write can leave a torn last row. It is cut off, and so are the complete rows of
// its image (or, when the fragment is too short to name its image, those of the last image),
// so that image is estimated again, whole.
void DropTornImage(const std::string& csv, bool quiet) {
  const std::string torn = TrimTornLastLine(csv);
  if (torn.empty()) return;
  std::vector<std::string> lines;
  {
    std::ifstream in(csv, std::ios::binary);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  std::string key = ImageKeyOfRow(torn);
  if (key.empty() && lines.size() > 1) key = ImageKeyOfRow(lines.back());
  std::size_t dropped = 0;
  if (!key.empty()) {
    std::vector<std::string> kept;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (i > 0 && ImageKeyOfRow(lines[i]) == key) {
        ++dropped;
        continue;
      }
      kept.push_back(lines[i]);
    }
    if (dropped > 0)
      WriteFileAtomically(csv, [&](std::ostream& out) {
        for (const auto& l : kept) out << l << "\n";
      });
  }
  if (!quiet)
    std::fprintf(stderr,
                 "run-dataset: %s ended in a torn row (%zu bytes, a crash while writing); removed it and %zu "
                 "complete row(s) of its image, which is estimated again\n",
                 csv.c_str(), torn.size(), dropped);
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

}  // namespace

int RunRunDataset(int argc, char** argv) {
  CLI::App app{"Estimate every target of a dataset (BOP split or YCB-Video folder) and append the poses "
               "to a BOP results CSV (resumable)",
               "run-dataset"};
  std::string dataset_dir, split = "test", detections_path, out_path, targets_path, view_dir;
  std::vector<std::string> view_images;
  double jitter_px = 0;
  double gt_box_score = 0.9;
  bool uniform = false, auto_prior = false, quiet = false, no_time = false, scene_pass = true;
  int limit = -1;
  FilterOptions opt;
  app.add_option("--dataset", dataset_dir, "dataset folder (BOP: models/ + <split>/; or YCB-Video: scenes/ + models/)")
      ->required();
  app.add_option("--split", split, "BOP split folder (ignored for a YCB-Video folder)")->capture_default_str();
  auto* det_opt = app.add_option("--detections", detections_path,
                                 "BOP detections JSON [{scene_id, image_id, category_id, bbox, score}]");
  auto* gt_opt = app.add_option("--gt-boxes", jitter_px,
                                "prior from the ground-truth silhouette boxes jittered by this sigma (pixels)");
  auto* uni_opt = app.add_flag("--uniform-prior", uniform, "no stage-1 prior (uniform over cells)");
  auto* auto_opt = app.add_flag("--auto-prior", auto_prior,
                                "no detector: candidate regions found in the depth image and PPF pose proposals, for every target's object "
                                "(posefilter/auto_prior.h)");
  det_opt->excludes(gt_opt)->excludes(uni_opt)->excludes(auto_opt);
  gt_opt->excludes(uni_opt)->excludes(auto_opt);
  uni_opt->excludes(auto_opt);
  app.add_option("--gt-box-score", gt_box_score, "score of the ground-truth boxes, [0, 1]")->capture_default_str();
  app.add_option("--out", out_path, "results CSV (appended to; images already in it are skipped)")->required();
  app.add_option("--targets", targets_path,
                 "targets JSON (BOP test_targets_bop19 format; default: <dataset>/test_targets_bop19.json if "
                 "present, else every gt object)");
  app.add_option("--limit", limit, "only the first N images with targets (already done ones included)");
  app.add_option("--view-dir", view_dir,
                 "write the 3D viewer page (docs/VIEWER.md) of each --view-images image into this folder, as "
                 "view_SCENE_IMAGE.html (6 digits each)");
  app.add_option("--view-images", view_images, "images whose viewer page is written: IMAGE or SCENE:IMAGE, comma-separated")
      ->delimiter(',');
  app.add_flag("--quiet", quiet, "no progress bar on stderr");
  app.add_flag("--scene-pass,!--no-scene-pass", scene_pass,
               "after an image's per-object estimates, the joint scene pass over those made with the image's prior "
               "(posefilter/scene_pass.h): an object whose pixels a better estimate explains is re-estimated without them")
      ->default_str(scene_pass ? "true" : "false");
  app.add_flag("--no-time", no_time,
               "write time -1 (BOP: not measured) instead of each image's wall time, so that runs of the same "
               "options write identical rows");
  AddFilterOptions(app, &opt);
  app.callback([&] {
    if (det_opt->count() + gt_opt->count() + uni_opt->count() + auto_opt->count() == 0)
      throw CLI::RequiredError("a prior: --detections FILE, --gt-boxes JITTER_PX, --uniform-prior or --auto-prior");
  });

  return RunApp(app, argc, argv, [&] {
    CheckFilterOptions(opt);
    if (det_opt->count() == 0 && gt_opt->count() && (!std::isfinite(jitter_px) || jitter_px < 0 || jitter_px > 1000))
      throw Error("--gt-boxes must be in [0, 1000] pixels, got " + std::to_string(jitter_px));
    if (!std::isfinite(gt_box_score) || gt_box_score < 0 || gt_box_score > 1)
      throw Error("--gt-box-score must be in [0, 1], got " + std::to_string(gt_box_score));
    if (app.count("--limit") && limit < 1) throw Error("--limit must be ≥ 1, got " + std::to_string(limit));
    const bool use_dets = det_opt->count() > 0, use_gt = gt_opt->count() > 0;
    if (view_dir.empty() != view_images.empty()) throw Error("--view-dir and --view-images go together: give both");
    if (!view_dir.empty()) {
      RequireViewer("--view-dir");
      std::error_code ec;
      if (!std::filesystem::is_directory(view_dir, ec) || ::access(view_dir.c_str(), W_OK) != 0)
        throw Error("--view-dir " + view_dir + ": not a writable folder");
      ViewChosen(view_images, {0, 0});  // checks the ids' syntax before any work
    }
    // The CSV is appended to (it is its own resume state), never one of the other inputs.
    CheckOutputPaths({{out_path, "--out"}}, {{detections_path, "--detections"}, {targets_path, "--targets"}});

    const Dataset ds = OpenDataset(dataset_dir, split, targets_path);
    if (ds.targets.empty())
      throw Error(dataset_dir + ": no targets (no " + (targets_path.empty() ? "test_targets_bop19.json" : targets_path) +
                  " and no ground truth)");

    std::map<std::pair<int, int>, std::vector<BopDetection>> dets_by_image;
    if (use_dets) {
      const std::vector<BopDetection> all = ReadBopDetections(detections_path);
      if (all.empty()) throw Error(detections_path + ": holds no detections (--detections)");
      for (const BopDetection& d : all) dets_by_image[{d.scene_id, d.im_id}].push_back(d);
    }

    // Images with targets, in order; then --limit.
    std::map<std::pair<int, int>, std::vector<DatasetTarget>> targets;
    for (const auto& t : ds.targets) targets[{t.scene_id, t.im_id}].push_back(t);
    std::vector<std::pair<int, int>> images;
    for (const auto& [key, t] : targets) images.push_back(key);
    if (limit > 0 && int(images.size()) > limit) images.resize(limit);

    // Resume: a torn last row (a crash mid-append) is removed with its image's rows, then the
    // images already in the CSV are skipped.
    CheckResultsCsvHeader(out_path);
    int lock_fd = LockResultsCsv(out_path);
    DropTornImage(out_path, quiet);
    // The repair may have replaced the file (a new inode): then hold the lock on the new one.
    struct stat locked {}, now {};
    if (::fstat(lock_fd, &locked) == 0 && ::stat(out_path.c_str(), &now) == 0 && locked.st_ino != now.st_ino) {
      const int again = LockResultsCsv(out_path);
      ::close(lock_fd);
      lock_fd = again;
    }
    std::set<std::pair<int, int>> done;
    std::error_code ec;
    if (std::filesystem::exists(out_path, ec) && std::filesystem::file_size(out_path, ec) > 0)
      for (const BopResult& r : ReadBopResultsCsv(out_path)) done.insert({r.scene_id, r.im_id});
    std::vector<std::pair<int, int>> todo;
    for (const auto& key : images)
      if (!done.count(key)) todo.push_back(key);
    const int skipped = static_cast<int>(images.size() - todo.size());
    if (!quiet && skipped > 0)
      std::fprintf(stderr, "run-dataset: %d of %zu image(s) already in %s, skipped\n", skipped, images.size(),
                   out_path.c_str());

    const std::vector<std::string> classes = ds.ClassNames();
    std::map<int, Mesh> meshes;
    auto mesh_of = [&](int obj_id) -> const Mesh& {
      auto it = meshes.find(obj_id);
      if (it == meshes.end()) it = meshes.emplace(obj_id, LoadDatasetMesh(*ds.Model(obj_id))).first;
      return it->second;
    };
    // --auto-prior: each model's PPF model (with the mesh's own diameter, Mesh::Diameter, the
    // size the filter works with), built or loaded once.
    std::map<int, PpfModel> ppf_models;
    auto ppf_of = [&](int obj_id) -> const PpfModel& {
      auto it = ppf_models.find(obj_id);
      if (it == ppf_models.end())
        it = ppf_models.emplace(obj_id, LoadOrBuildPpfModel(mesh_of(obj_id), {}, DefaultPpfCacheDir())).first;
      return it->second;
    };

    const bool tty = isatty(fileno(stderr));
    const auto t_start = Clock::now();
    int rows_written = 0, n_done = 0, n_failed = 0;
    for (const auto& key : todo) {
      const auto t_image = Clock::now();
      const DatasetImage* im = ds.Image(key.first, key.second);
      const std::string where = "scene " + std::to_string(im->scene_id) + ", image " + std::to_string(im->im_id);
      SceneInput scene = LoadDatasetScene(*im);
      ValidateScene(scene, im->depth_path);
      const PyramidLayout layout = PyramidLayout::Thesis(scene.camera.width, scene.camera.height, int(classes.size()));

      // The image's detections (and, --auto-prior, each class's pose seeds).
      std::vector<Detection> dets;
      std::map<std::string, std::vector<PoseSeed>> seeds_of;
      if (use_dets) {
        if (const auto it = dets_by_image.find(key); it != dets_by_image.end())
          dets = ToPriorDetections(it->second, ds, detections_path);
      } else if (auto_prior) {
        std::vector<AutoObject> wanted;  // the image's target objects
        for (const DatasetTarget& t : targets.at(key)) {
          const PpfModel& m = ppf_of(t.obj_id);
          wanted.push_back({ds.Model(t.obj_id)->name, m.diameter, &m});
        }
        AutoProposals proposals = ProposeAuto(scene.depth, scene.camera, wanted);
        dets = std::move(proposals.detections);
        for (std::size_t k = 0; k < wanted.size(); ++k) seeds_of[wanted[k].name] = std::move(proposals.seeds[k]);
      } else if (use_gt) {
        if (!im->has_gt) throw Error(where + ": --gt-boxes needs ground truth, the dataset has none for it");
        Rng rng(MixSeed(opt.seed, im->scene_id, im->im_id, 0, -1));
        for (const GtInstance& g : im->gt) {
          const GtBoxDetection b = JitteredGtBox(mesh_of(g.obj_id), g.T_cam_obj, scene.camera, ds.Model(g.obj_id)->name,
                                                 jitter_px, gt_box_score, rng);
          if (b.in_view) dets.push_back(b.detection);
        }
      }
      const Prior image_prior =
          uniform ? UniformPrior(layout, classes) : PriorFromDetections(dets, layout, classes);

      const bool view = !view_dir.empty() && ViewChosen(view_images, key);
      std::vector<const Mesh*> row_meshes;                 // --view-dir: each row's mesh and particles
      std::vector<std::vector<ParticleSet>> row_particles;
      std::vector<BopResult> rows;
      std::vector<SceneObject> shared;  // --scene-pass: the estimates made with the image's prior
      std::vector<std::size_t> shared_row;
      for (const DatasetTarget& t : targets.at(key)) {
        const DatasetModel& model = *ds.Model(t.obj_id);
        const int cls = image_prior.ClassIndex(model.name);
        // One prior per instance: the image's prior for a single instance, else the class's
        // detections one by one (best score first).
        std::vector<const Detection*> own;
        for (const auto& d : dets)
          if (d.cls == model.name) own.push_back(&d);
        std::stable_sort(own.begin(), own.end(), [](const Detection* a, const Detection* b) { return a->score > b->score; });
        for (int inst = 0; inst < t.inst_count; ++inst) {
          Prior single;
          const Prior* prior = &image_prior;
          if (t.inst_count > 1 && !uniform && !auto_prior) {
            if (inst >= int(own.size())) break;
            single = PriorFromDetections({*own[inst]}, layout, classes);
            prior = &single;
          }
          FilterOptions o = opt;
          o.seed = MixSeed(opt.seed, t.scene_id, t.im_id, t.obj_id, inst);
          o.record_particles = o.record_particles || view;
          scene.seeds = seeds_of.count(model.name) ? seeds_of[model.name] : std::vector<PoseSeed>{};
          try {
            EstimateResult r = EstimatePose(scene, mesh_of(t.obj_id), *prior, cls, o);
            if (view) row_meshes.push_back(&mesh_of(t.obj_id)), row_particles.push_back(std::move(r.particle_history));
            r.particle_history.clear();
            BopResult row;
            row.scene_id = t.scene_id;
            row.im_id = t.im_id;
            row.obj_id = t.obj_id;
            row.score = r.weight;
            row.T_cam_obj = r.T_cam_obj;
            if (prior == &image_prior) shared.push_back({&mesh_of(t.obj_id), cls, r}), shared_row.push_back(rows.size());
            rows.push_back(row);
          } catch (const Error& e) {
            ++n_failed;
            std::fprintf(stderr, "%srun-dataset: warning: %s, obj_id %d: no estimate: %s\n", tty && !quiet ? "\n" : "",
                         where.c_str(), t.obj_id, e.what());
          }
        }
      }
      if (scene_pass && shared.size() > 1) {
        scene.seeds.clear();
        FilterOptions o = opt;
        o.seed = MixSeed(opt.seed, im->scene_id, im->im_id, 0, -2);
        const std::vector<ScenePassResult> passed = RunScenePass(scene, image_prior, shared, o);
        for (std::size_t k = 0; k < passed.size(); ++k) {
          rows[shared_row[k]].T_cam_obj = passed[k].estimate.T_cam_obj;
          rows[shared_row[k]].score = passed[k].replaced ? passed[k].estimate.weight : rows[shared_row[k]].score;
        }
      }
      const double image_s = std::chrono::duration<double>(Clock::now() - t_image).count();
      for (auto& r : rows) r.time_s = no_time ? -1.0 : image_s;
      AppendBopResultsCsv(rows, out_path);
      if (view) WriteImageView(view_dir, ds, *im, scene, rows, row_meshes, row_particles, opt.support.plane);
      rows_written += static_cast<int>(rows.size());
      ++n_done;
      if (!quiet)
        PrintProgress(n_done, static_cast<int>(todo.size()), im->scene_id, im->im_id,
                      std::chrono::duration<double>(Clock::now() - t_start).count(), tty);
    }
    if (!quiet && tty && n_done > 0) std::fprintf(stderr, "\n");
    std::printf("%d image(s) estimated, %d skipped (already in %s), %d row(s) written", n_done, skipped,
                out_path.c_str(), rows_written);
    if (n_failed > 0) std::printf(", %d target instance(s) without an estimate", n_failed);
    std::printf("\n");
  });
}

}  // namespace posefilter::cli
