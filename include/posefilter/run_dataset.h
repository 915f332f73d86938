// posefilter/run_dataset.h — estimate every target of a dataset (a BOP split or a YCB-Video
// folder, posefilter/bop.h) and append the poses to a BOP results CSV, resumably: what
// `posefilter run-dataset`, Python's `posefilter.run_dataset` and `posefilter.distributed`
// run.
//
// Per image (in (scene_id, im_id) order): the depth is loaded, the stage 1 is made
// (posefilter/stage1.h: the image's BOP detections, jittered ground-truth boxes — JitteredGtBox,
// the rule of `gt-detections` —, the no-detector proposals of `--prior auto`, or uniform) on the
// dataset's classes, and each target instance is estimated (posefilter/estimate_scene.h). A
// target with inst_count = 1 uses the prior of all the image's detections; with inst_count =
// k > 1 (detections or boxes), instance i uses a prior of the class's i-th best detection alone
// (no estimate when there are fewer than k). The estimates made with the image's prior then go
// through the joint scene pass (scene_pass). The image's rows are appended and flushed at once,
// all with the image's wall time (or -1, BOP's "not measured", with no_time: then two runs
// write identical rows).
//
// Resume: an image already in the CSV is skipped; a torn last row (a crash mid-append) is
// removed with its image's rows, which is then estimated again. One run writes a CSV at a
// time (an exclusive flock, held for the call). Random streams derive from the filter's seed,
// the scene, the image and the target, so a resumed (or split) run gives the rows an
// uninterrupted one would, in any order of images.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "posefilter/bop.h"
#include "posefilter/filter.h"
#include "posefilter/filter_options.h"
#include "posefilter/mesh.h"

namespace posefilter {

enum class DatasetPriorKind { kDetections, kGtBoxes, kUniform, kAuto };

struct RunDatasetOptions {
  std::string dataset;               // the dataset folder (OpenDataset)
  std::string split = "test";        // BOP split folder (ignored for a YCB-Video folder)
  std::string targets_path;          // targets JSON; "" = OpenDataset's default
  DatasetPriorKind prior = DatasetPriorKind::kUniform;
  std::string detections_path;       // kDetections: BOP detections JSON
  double gt_jitter_px = 0;           // kGtBoxes: box jitter sigma, pixels, [0, 1000]
  double gt_box_score = 0.9;         // kGtBoxes: the boxes' score, [0, 1]
  std::string out;                   // the results CSV (appended to)
  std::string out_label = "results CSV";  // names `out` in errors ("--out" for the CLI)
  int limit = 0;                     // only the first N images with targets (done ones included); 0 = all, ≥ 0
  // Only these (scene_id, im_id) of the images with targets (after `limit`); empty = all.
  std::vector<std::pair<int, int>> images;
  bool scene_pass = true;            // the joint scene pass over each image's shared-prior estimates
  bool no_time = false;              // time -1 in every row instead of the image's wall time, seconds
  FilterOptions filter;              // the estimates' options (filter.seed: the run's seed)
  bool IsValid(std::string* why) const;
};

// One image done, after its rows are appended.
struct DatasetImageDone {
  const Dataset* dataset = nullptr;
  const DatasetImage* image = nullptr;
  const SceneInput* scene = nullptr;            // its depth and camera
  const std::vector<BopResult>* rows = nullptr;  // the rows appended
  // With RunDatasetCallbacks::record for the image: each row's mesh and particle sets.
  const std::vector<const Mesh*>* meshes = nullptr;
  const std::vector<std::vector<ParticleSet>>* particles = nullptr;
  int done = 0, total = 0;                      // images done in this call, and to do
  double elapsed_s = 0;                         // since the first image started, seconds
};

struct RunDatasetCallbacks {
  // Whether to record the particle sets of an image's estimates (scene_id, im_id); empty: none.
  std::function<bool(int, int)> record;
  std::function<void(const DatasetImageDone&)> on_image;
  // A target instance without an estimate (the run goes on): "scene S, image I, obj_id O: no
  // estimate: <why>".
  std::function<void(const std::string&)> on_warning;
  // What resuming found: the images already in the CSV, a torn row removed.
  std::function<void(const std::string&)> on_note;
};

struct RunDatasetSummary {
  int images = 0;     // images with targets (after limit and images)
  int estimated = 0;  // images estimated in this call
  int skipped = 0;    // images already in the CSV
  int rows = 0;       // rows appended
  int failed = 0;     // target instances without an estimate
};

// Runs the dataset (see above). Throws Error on invalid options, an unreadable dataset or
// detections file, a dataset without targets, an `out` that is not a results CSV or that
// another run holds, a requested image without targets, and the image's own errors (depth,
// stage 1); an estimate's Error only skips its target (on_warning).
RunDatasetSummary RunDataset(const RunDatasetOptions& options, const RunDatasetCallbacks& callbacks = {});

// The images of `dataset` with targets, in (scene_id, im_id) order: what RunDataset estimates.
std::vector<std::pair<int, int>> DatasetTargetImages(const Dataset& dataset);

}  // namespace posefilter
