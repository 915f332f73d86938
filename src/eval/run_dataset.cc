// eval/run_dataset.cc — every target of a dataset into a BOP results CSV, resumably
// (posefilter/run_dataset.h).
#include "posefilter/run_dataset.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "core/option_check.h"
#include "posefilter/auto_prior.h"
#include "posefilter/error.h"
#include "posefilter/estimate_scene.h"
#include "posefilter/file_io.h"
#include "posefilter/ppf.h"
#include "posefilter/rng.h"
#include "posefilter/stage1.h"

namespace posefilter {

bool RunDatasetOptions::IsValid(std::string* why) const {
  if (dataset.empty()) return Fail(why, "dataset: no folder given");
  if (out.empty()) return Fail(why, "out: no results CSV given");
  if (prior == DatasetPriorKind::kDetections && detections_path.empty())
    return Fail(why, "detections_path: the detections prior needs a BOP detections JSON");
  if (!std::isfinite(gt_jitter_px) || gt_jitter_px < 0 || gt_jitter_px > 1000)
    return Fail(why, "gt_jitter_px must be in [0, 1000] pixels, got " + std::to_string(gt_jitter_px));
  if (!std::isfinite(gt_box_score) || gt_box_score < 0 || gt_box_score > 1)
    return Fail(why, "gt_box_score must be in [0, 1], got " + std::to_string(gt_box_score));
  if (limit < 0) return Fail(why, "limit must be >= 0 (0 = every image), got " + std::to_string(limit));
  return true;
}

std::vector<std::pair<int, int>> DatasetTargetImages(const Dataset& dataset) {
  std::set<std::pair<int, int>> keys;
  for (const DatasetTarget& t : dataset.targets) keys.insert({t.scene_id, t.im_id});
  return {keys.begin(), keys.end()};
}

namespace {

using RunClock = std::chrono::steady_clock;

// A seed for one (scene, image, object, instance), mixed from the run's seed.
std::uint64_t MixDatasetSeed(std::uint64_t seed, int scene_id, int im_id, int obj_id, int instance) {
  Rng r(seed ^ (std::uint64_t(std::uint32_t(scene_id)) << 32 | std::uint32_t(im_id)));
  std::uint64_t s = r.NextU64();
  Rng r2(s ^ (std::uint64_t(std::uint32_t(obj_id)) << 32 | std::uint32_t(instance)));
  return r2.NextU64();
}

// "scene_id,im_id" of a CSV row (its first two fields), or "" when the text has fewer.
std::string ImageKeyOfRow(const std::string& row) {
  const std::size_t a = row.find(',');
  if (a == std::string::npos) return "";
  const std::size_t b = row.find(',', a + 1);
  return b == std::string::npos ? "" : row.substr(0, b);
}

// An existing CSV is resumed only when it is a results CSV: its first line is the header.
// Checked before anything in the file changes (the torn-row repair below cuts the file).
void CheckResultsCsvHeader(const std::string& csv, const std::string& label) {
  std::error_code ec;
  if (!std::filesystem::exists(csv, ec) || std::filesystem::file_size(csv, ec) == 0) return;
  std::ifstream in(csv, std::ios::binary);
  if (!in) throw Error(label + " " + csv + ": cannot open it to resume");
  std::string first;
  std::getline(in, first);
  if (!first.empty() && first.back() == '\r') first.pop_back();
  if (first != kBopCsvHeader)
    throw Error(label + " " + csv + ": exists and is not a results CSV (line 1 is not \"" + std::string(kBopCsvHeader) +
                "\"); it is left as it is");
}

// One writer per results CSV: an exclusive advisory lock (flock) on the file, held while the
// run goes on (the kernel releases it when the process ends, also after a crash). A second run
// on the same file stops with an error instead of duplicating every row.
class CsvLock {
 public:
  CsvLock(const std::string& csv, const std::string& label) : fd_(Open(csv, label)) {}
  ~CsvLock() { ::close(fd_); }
  CsvLock(const CsvLock&) = delete;
  CsvLock& operator=(const CsvLock&) = delete;
  // The torn-row repair may replace the file (a new inode): then the lock moves to the new one.
  void Follow(const std::string& csv, const std::string& label) {
    struct stat locked {}, now {};
    if (::fstat(fd_, &locked) == 0 && ::stat(csv.c_str(), &now) == 0 && locked.st_ino != now.st_ino) {
      const int again = Open(csv, label);
      ::close(fd_);
      fd_ = again;
    }
  }

 private:
  static int Open(const std::string& csv, const std::string& label) {
    const int fd = ::open(csv.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0666);
    if (fd < 0) throw Error(label + " " + csv + ": cannot open it (" + std::strerror(errno) + ")");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      throw Error(label + " " + csv + ": another run-dataset is writing it (it holds the file's lock); wait for it to "
                  "end or give another " + label);
    }
    return fd;
  }
  int fd_;
};

// Appends write an image's rows with one write and undo a failed one, so only a crash of the
// machine mid-write can leave a torn last row. It is cut off, and so are the complete rows of
// its image (or, when the fragment is too short to name its image, those of the last image),
// so that image is estimated again, whole. Returns the note saying so ("" when none was torn).
std::string DropTornImage(const std::string& csv) {
  const std::string torn = TrimTornLastLine(csv);
  if (torn.empty()) return "";
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
  return csv + " ended in a torn row (" + std::to_string(torn.size()) + " bytes, a crash while writing); removed it and " +
         std::to_string(dropped) + " complete row(s) of its image, which is estimated again";
}

// What a run keeps across images: the dataset, its detections, and the meshes and PPF models
// loaded so far.
struct DatasetRun {
  const RunDatasetOptions& opt;
  Dataset ds;
  std::vector<std::string> classes;
  std::map<std::pair<int, int>, std::vector<DatasetTarget>> targets;
  std::map<std::pair<int, int>, std::vector<BopDetection>> dets_by_image;
  std::map<int, Mesh> meshes;
  std::map<int, PpfModel> ppf_models;

  const Mesh& MeshOf(int obj_id) {
    auto it = meshes.find(obj_id);
    if (it == meshes.end()) it = meshes.emplace(obj_id, LoadDatasetMesh(*ds.Model(obj_id))).first;
    return it->second;
  }
  // kAuto: each model's PPF model (with the mesh's own diameter, the size the filter works
  // with), built or loaded once.
  const PpfModel& PpfOf(int obj_id) {
    auto it = ppf_models.find(obj_id);
    if (it == ppf_models.end())
      it = ppf_models.emplace(obj_id, LoadOrBuildPpfModel(MeshOf(obj_id), {}, DefaultPpfCacheDir())).first;
    return it->second;
  }
};

// The stage 1 of one image on the dataset's classes; *dets receives its detections (for the
// per-instance priors).
Stage1 DatasetImageStage1(DatasetRun& run, const DatasetImage& im, const SceneInput& scene,
                          std::vector<Detection>* dets) {
  const RunDatasetOptions& opt = run.opt;
  const std::pair<int, int> key{im.scene_id, im.im_id};
  Stage1Options so;
  so.classes = run.classes;
  std::vector<Stage1Object> objects;
  if (opt.prior == DatasetPriorKind::kDetections) {
    if (const auto it = run.dets_by_image.find(key); it != run.dets_by_image.end())
      *dets = ToPriorDetections(it->second, run.ds, opt.detections_path);
  } else if (opt.prior == DatasetPriorKind::kAuto) {
    for (const DatasetTarget& t : run.targets.at(key)) {  // the image's target objects
      const PpfModel& m = run.PpfOf(t.obj_id);
      objects.push_back({run.ds.Model(t.obj_id)->name, nullptr, &m});
    }
    so.kind = Stage1Kind::kAuto;
    so.what = "--auto-prior";
    so.require_candidates = false;
  } else if (opt.prior == DatasetPriorKind::kGtBoxes) {
    if (!im.has_gt)
      throw Error("scene " + std::to_string(im.scene_id) + ", image " + std::to_string(im.im_id) +
                  ": --gt-boxes needs ground truth, the dataset has none for it");
    Rng rng(MixDatasetSeed(opt.filter.seed, im.scene_id, im.im_id, 0, -1));
    for (const GtInstance& g : im.gt) {
      const GtBoxDetection b = JitteredGtBox(run.MeshOf(g.obj_id), g.T_cam_obj, scene.camera, run.ds.Model(g.obj_id)->name,
                                             opt.gt_jitter_px, opt.gt_box_score, rng);
      if (b.in_view) dets->push_back(b.detection);
    }
  }
  if (opt.prior == DatasetPriorKind::kDetections || opt.prior == DatasetPriorKind::kGtBoxes) {
    so.kind = Stage1Kind::kDetections;
    so.detections = *dets;
  }
  return BuildStage1(scene, objects, so);
}

// One image: its stage 1, its targets' estimates and the scene pass; the rows (and, recorded,
// each row's mesh and particle sets) for the CSV.
struct DatasetImageRows {
  std::vector<BopResult> rows;
  std::vector<const Mesh*> meshes;
  std::vector<std::vector<ParticleSet>> particles;
  int failed = 0;
};
DatasetImageRows EstimateDatasetImage(DatasetRun& run, const DatasetImage& im, const SceneInput& scene, bool record,
                                      const RunDatasetCallbacks& cb) {
  const RunDatasetOptions& opt = run.opt;
  const std::string where = "scene " + std::to_string(im.scene_id) + ", image " + std::to_string(im.im_id);
  std::vector<Detection> dets;
  const Stage1 stage1 = DatasetImageStage1(run, im, scene, &dets);
  const PyramidLayout layout = PyramidLayout::Thesis(scene.camera.width, scene.camera.height, int(run.classes.size()));
  const bool shared_only = opt.prior == DatasetPriorKind::kUniform || opt.prior == DatasetPriorKind::kAuto;
  std::deque<Prior> single;  // per-instance priors (inst_count > 1)
  std::vector<SceneEstimateObject> objects;
  std::vector<int> obj_ids;
  DatasetImageRows out;
  const std::vector<DatasetTarget>& targets = run.targets.at({im.scene_id, im.im_id});
  for (std::size_t k = 0; k < targets.size(); ++k) {
    const DatasetTarget& t = targets[k];
    const DatasetModel& model = *run.ds.Model(t.obj_id);
    const int cls = stage1.prior.ClassIndex(model.name);
    // One prior per instance: the image's prior for a single instance, else the class's
    // detections one by one (best score first).
    std::vector<const Detection*> own;
    for (const auto& d : dets)
      if (d.cls == model.name) own.push_back(&d);
    std::stable_sort(own.begin(), own.end(), [](const Detection* a, const Detection* b) { return a->score > b->score; });
    for (int inst = 0; inst < t.inst_count; ++inst) {
      SceneEstimateObject x;
      if (t.inst_count > 1 && !shared_only) {
        if (inst >= int(own.size())) break;
        single.push_back(PriorFromDetections({*own[inst]}, layout, run.classes));
        x.own_prior = &single.back();
      }
      try {
        x.mesh = &run.MeshOf(t.obj_id);
      } catch (const Error& e) {
        ++out.failed;
        if (cb.on_warning) cb.on_warning(where + ", obj_id " + std::to_string(t.obj_id) + ": no estimate: " + e.what());
        continue;
      }
      x.cls = cls;
      x.seed = MixDatasetSeed(opt.filter.seed, t.scene_id, t.im_id, t.obj_id, inst);
      if (opt.prior == DatasetPriorKind::kAuto) x.seeds = stage1.seeds[k];  // the stage 1's objects are the targets
      objects.push_back(std::move(x));
      obj_ids.push_back(t.obj_id);
    }
  }
  FilterOptions o = opt.filter;
  o.record_particles = o.record_particles || record;
  EstimateSceneOptions so;
  so.scene_pass = opt.scene_pass;
  so.pass_seed = MixDatasetSeed(opt.filter.seed, im.scene_id, im.im_id, 0, -2);
  so.keep_going = true;
  std::vector<SceneEstimate> est = EstimateScene(scene, stage1.prior, objects, o, so, [&](std::size_t k, const SceneEstimate& e) {
    if (e.estimated) return;
    ++out.failed;
    if (cb.on_warning) cb.on_warning(where + ", obj_id " + std::to_string(obj_ids[k]) + ": no estimate: " + e.error);
  });
  for (std::size_t k = 0; k < est.size(); ++k) {
    if (!est[k].estimated) continue;
    const EstimateResult& r = est[k].passed ? est[k].pass.estimate : est[k].alone;
    BopResult row;
    row.scene_id = im.scene_id;
    row.im_id = im.im_id;
    row.obj_id = obj_ids[k];
    row.score = est[k].passed && est[k].pass.replaced ? r.weight : est[k].alone.weight;
    row.T_cam_obj = r.T_cam_obj;
    out.rows.push_back(row);
    if (record) out.meshes.push_back(objects[k].mesh), out.particles.push_back(std::move(est[k].particles));
  }
  return out;
}

// Opens the dataset and its detections, and lists the images to run (limit, images).
std::vector<std::pair<int, int>> OpenDatasetRun(DatasetRun& run) {
  const RunDatasetOptions& opt = run.opt;
  run.ds = OpenDataset(opt.dataset, opt.split, opt.targets_path);
  if (run.ds.targets.empty())
    throw Error(opt.dataset + ": no targets (no " + (opt.targets_path.empty() ? "test_targets_bop19.json" : opt.targets_path) +
                " and no ground truth)");
  if (opt.prior == DatasetPriorKind::kDetections) {
    const std::vector<BopDetection> all = ReadBopDetections(opt.detections_path);
    if (all.empty()) throw Error(opt.detections_path + ": holds no detections (--detections)");
    for (const BopDetection& d : all) run.dets_by_image[{d.scene_id, d.im_id}].push_back(d);
  }
  for (const auto& t : run.ds.targets) run.targets[{t.scene_id, t.im_id}].push_back(t);
  std::vector<std::pair<int, int>> images = DatasetTargetImages(run.ds);
  if (opt.limit > 0 && int(images.size()) > opt.limit) images.resize(std::size_t(opt.limit));
  if (!opt.images.empty()) {
    for (const auto& key : opt.images)
      if (!run.targets.count(key))
        throw Error(opt.dataset + ": scene " + std::to_string(key.first) + ", image " + std::to_string(key.second) +
                    " has no targets (images)");
    std::vector<std::pair<int, int>> chosen;
    for (const auto& key : images)
      if (std::find(opt.images.begin(), opt.images.end(), key) != opt.images.end()) chosen.push_back(key);
    images = std::move(chosen);
  }
  run.classes = run.ds.ClassNames();
  return images;
}

}  // namespace

RunDatasetSummary RunDataset(const RunDatasetOptions& opt, const RunDatasetCallbacks& cb) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("invalid run-dataset option: " + why);
  DatasetRun run{opt, {}, {}, {}, {}, {}, {}};
  const std::vector<std::pair<int, int>> images = OpenDatasetRun(run);
  RunDatasetSummary sum;
  sum.images = int(images.size());

  // Resume: a torn last row (a crash mid-append) is removed with its image's rows, then the
  // images already in the CSV are skipped.
  CheckResultsCsvHeader(opt.out, opt.out_label);
  CsvLock lock(opt.out, opt.out_label);
  if (const std::string note = DropTornImage(opt.out); !note.empty() && cb.on_note) cb.on_note(note);
  lock.Follow(opt.out, opt.out_label);
  std::set<std::pair<int, int>> done;
  std::error_code ec;
  if (std::filesystem::exists(opt.out, ec) && std::filesystem::file_size(opt.out, ec) > 0)
    for (const BopResult& r : ReadBopResultsCsv(opt.out)) done.insert({r.scene_id, r.im_id});
  std::vector<std::pair<int, int>> todo;
  for (const auto& key : images)
    if (!done.count(key)) todo.push_back(key);
  sum.skipped = static_cast<int>(images.size() - todo.size());
  if (sum.skipped > 0 && cb.on_note)
    cb.on_note(std::to_string(sum.skipped) + " of " + std::to_string(images.size()) + " image(s) already in " + opt.out +
               ", skipped");

  const auto t_start = RunClock::now();
  for (const auto& key : todo) {
    const auto t_image = RunClock::now();
    const DatasetImage* im = run.ds.Image(key.first, key.second);
    const SceneInput scene = LoadDatasetScene(*im);
    ValidateScene(scene, im->depth_path);
    const bool record = cb.record && cb.record(key.first, key.second);
    DatasetImageRows image = EstimateDatasetImage(run, *im, scene, record, cb);
    const double image_s = std::chrono::duration<double>(RunClock::now() - t_image).count();
    for (auto& r : image.rows) r.time_s = opt.no_time ? -1.0 : image_s;
    AppendBopResultsCsv(image.rows, opt.out);
    sum.rows += static_cast<int>(image.rows.size());
    sum.failed += image.failed;
    ++sum.estimated;
    if (cb.on_image)
      cb.on_image({&run.ds, im, &scene, &image.rows, &image.meshes, &image.particles, sum.estimated, int(todo.size()),
                   std::chrono::duration<double>(RunClock::now() - t_start).count()});
  }
  return sum;
}

}  // namespace posefilter
