// posefilter/bop.h — pose-estimation datasets: the BOP format, the YCB-Video folder of
// $POSEFILTER_DATA/ycbv presented through the same interface, BOP detections and the BOP
// results CSV (docs/DATASETS.md has the full description and examples).
//
// Units: everything this header returns is in metres and radians (the BOP files are in
// millimetres and are converted on reading / writing). Poses map object → camera,
// x_cam = R·x_obj + t (BOP cam_R_m2c, cam_t_m2c). Pixel coordinates as camera.h / prior.h.
//
// BOP dataset folder (https://github.com/thodan/bop_toolkit/blob/master/docs/bop_datasets_format.md):
//   models/models_info.json   {"<obj_id>": {"diameter": mm, "symmetries_discrete": [[16 values,
//                             4×4 row-major, translation mm], ...], "symmetries_continuous":
//                             [{"axis": [3], "offset": [3] mm}, ...]}, ...}
//   models/obj_<obj_id 6 digits>.ply       mesh in millimetres
//   <split>/<scene_id 6 digits>/scene_camera.json   {"<im_id>": {"cam_K": [9 row-major],
//                                                    "depth_scale": mm per PNG unit}}
//   <split>/<scene_id>/scene_gt.json       {"<im_id>": [{"obj_id", "cam_R_m2c" [9 row-major],
//                                          "cam_t_m2c" [3] mm}, ...]}   (optional: no gt)
//   <split>/<scene_id>/scene_gt_info.json  {"<im_id>": [{"bbox_obj", "bbox_visib" [x,y,w,h],
//                                          "visib_fract"}, ...]}       (optional)
//   <split>/<scene_id>/depth/<im_id 6 digits>.png
//   camera.json (optional)                 {"width", "height"} of every image
//   test_targets_bop19.json (optional)     [{"scene_id", "im_id", "obj_id", "inst_count"}, ...]
// Every reader error is an Error naming the file and the entry ("scene_gt.json: image 3,
// entry 1: obj_id 99 not in models_info.json").
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/filter.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/rng.h"
#include "posefilter/scene_io.h"

namespace posefilter {

// A continuous rotational symmetry of a model: rotations by any angle about `axis` (unit,
// object frame) through the point `offset` (object frame, metres).
struct ContinuousSymmetry {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

// One object model of a dataset.
struct DatasetModel {
  int obj_id = 0;              // BOP object id (≥ 1)
  std::string name;            // class name used in priors and tables: "obj_000001" (BOP) or
                               // the file stem ("002_master_chef_can", YCB-Video folder)
  std::string mesh_path;       // the mesh file
  double mesh_unit_scale = 1;  // mesh coordinates × this = metres (0.001 for BOP models)
  std::string points_path;     // optional "x y z" metres point file for ADD/ADD-S ("" = mesh)
  double diameter_m = 0;       // model diameter, metres (> 0)
  // Symmetry transformations S (object frame, metres: the model looks the same at T·S as at
  // T); the identity is implied and not listed.
  std::vector<Eigen::Isometry3d> symmetries_discrete;
  std::vector<ContinuousSymmetry> symmetries_continuous;
};

// One annotated object instance of an image.
struct GtInstance {
  int obj_id = 0;
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera, metres
  // From scene_gt_info.json when present (else has_info = false): boxes [x, y, w, h] pixels,
  // visible fraction of the silhouette in [0, 1].
  bool has_info = false;
  double bbox_obj[4] = {0, 0, 0, 0};
  double bbox_visib[4] = {0, 0, 0, 0};
  double visib_fract = 1;
};

// One image of a split.
struct DatasetImage {
  int scene_id = 0, im_id = 0;
  std::string depth_path;
  double depth_scale_m = 0.001;  // metres per 16-bit PNG unit (BOP depth_scale / 1000)
  // Intrinsics; width/height are 0 when the dataset does not state them (then they come from
  // the depth PNG in LoadDatasetScene).
  Camera camera;
  bool has_gt = false;           // false when the split has no scene_gt.json
  std::vector<GtInstance> gt;    // scene_gt order
  std::string gt_source;         // the file the gt came from (for error messages)
};

// An estimation target: estimate `inst_count` instances of obj_id in the image.
struct DatasetTarget {
  int scene_id = 0, im_id = 0, obj_id = 0;
  int inst_count = 1;
};

struct Dataset {
  std::string root;       // the dataset folder
  std::string split;      // split folder ("" for the YCB-Video folder)
  std::string format;     // "bop" or "ycbv"
  std::vector<DatasetModel> models;    // ascending obj_id
  std::vector<DatasetImage> images;    // ascending (scene_id, im_id)
  // test_targets_bop19.json of the split's images (or the file given to OpenDataset) when
  // present; otherwise every gt object of every image (inst_count = its number of instances).
  std::vector<DatasetTarget> targets;
  std::string targets_source;          // the targets file, or "scene_gt" when derived from gt

  const DatasetModel* Model(int obj_id) const;            // nullptr if absent
  const DatasetModel* ModelByName(const std::string& name) const;
  const DatasetImage* Image(int scene_id, int im_id) const;
  // Class names of all models in obj_id order (the class list of a dataset's priors).
  std::vector<std::string> ClassNames() const;
};

// Reads a BOP dataset split (layout above). `targets_path` overrides
// <root>/test_targets_bop19.json ("" = use it if present). Depth images are not opened (see
// LoadDatasetScene). Throws Error naming the file and entry on a missing/malformed file, an
// obj_id without a model, a non-finite value, an entry count mismatch between scene_gt.json
// and scene_gt_info.json, or a split without images.
Dataset ReadBopDataset(const std::string& root, const std::string& split,
                       const std::string& targets_path = "");

// Reads a YCB-Video style folder ($POSEFILTER_DATA/ycbv layout, README "Data"): scenes/<name>/{depth.png,
// camera.json, gt.json}, models/<name>.ply (metres), optional models/points/<name>.xyz.
// obj_id: the official YCB-Video id (1..21 in YcbVideoClassNames order) for the 21 YCB-Video
// names, 22, 23, … for other models in name order. scene_id/im_id: the two trailing numbers
// of the scene folder name ("ycbv_0000_000001" → scene 0, image 1); folders not named so get
// scene 0 and im_id = their 1-based position in name order. Diameter: over the points file when
// present, else the mesh's. No symmetries are known (MSSD/MSPD use the identity only).
Dataset ReadYcbvFolder(const std::string& root, const std::string& targets_path = "");

// ReadBopDataset when root has models/models_info.json and a <split> folder; ReadYcbvFolder
// when it has scenes/ and models/ (split ignored); Error naming the folder otherwise.
Dataset OpenDataset(const std::string& root, const std::string& split, const std::string& targets_path = "");

// The image's depth (metres) and camera (size from the PNG when the dataset has none).
// Throws Error naming the depth file, the scene and the image on a missing/corrupt PNG or a
// size that differs from the dataset's camera.
SceneInput LoadDatasetScene(const DatasetImage& image);
// The model's mesh in metres, named model.name.
Mesh LoadDatasetMesh(const DatasetModel& model);
// Model points for ADD/ADD-S/MSSD/MSPD: the points file when present, else the mesh's
// vertices (SamplePoints, at most max_points).
std::vector<Eigen::Vector3f> LoadDatasetPoints(const DatasetModel& model, int max_points = 2000);

// ---- Writing a BOP dataset (tests, converters). Units as above (metres in, mm in the files).

// Writes models/models_info.json for `models` (diameter, symmetries) and, for each model with
// a mesh in `meshes` (same order, nullptr = skip), models/obj_XXXXXX.ply in millimetres.
void WriteBopModels(const std::string& root, const std::vector<DatasetModel>& models,
                    const std::vector<const Mesh*>& meshes);
// Writes one scene: <root>/<split>/<scene 6 digits>/{scene_camera.json, scene_gt.json,
// scene_gt_info.json (only if every instance has_info), depth/XXXXXX.png}. `depths` holds one
// depth image per entry of `images` (metres); every image must have the same scene_id.
void WriteBopScene(const std::string& root, const std::string& split,
                   const std::vector<DatasetImage>& images, const std::vector<DepthImage>& depths);

// ---- Detections (BOP default-detections JSON: [{"scene_id", "image_id", "category_id",
// "bbox": [x, y, w, h] pixels, "score" in [0, 1], "time"?: seconds}, ...]).

struct BopDetection {
  int scene_id = 0, im_id = 0, obj_id = 0;
  double score = 0;
  double x = 0, y = 0, w = 0, h = 0;  // bbox, pixels
  double time_s = -1;                  // detector time of the image, -1 = unknown
};

// Errors name the file and the entry index (missing key, non-finite or w/h ≤ 0, score outside
// [0, 1], a non-integer id).
std::vector<BopDetection> ReadBopDetections(const std::string& path);

// The detections of one image as prior detections (class = the model's name). A category_id
// without a model → Error naming `source` and the id.
std::vector<Detection> ToPriorDetections(const std::vector<BopDetection>& detections, const Dataset& dataset,
                                         const std::string& source);

// ---- Stage-1 boxes from ground truth (the rule of `posefilter gt-detections`).

// Ground-truth box of one object: the silhouette box (ProjectedBox of the mesh alone at its gt
// pose) jittered like a detector's: centre and size + N(0, jitter_px²) px, the centre noise
// clamped to a quarter of the box, width/height ≥ 4 px. Always draws four rng.Normal() (centre
// x, centre y, width, height), even for an object out of view, so one object does not shift
// another's box. `in_view` is false (and detection unset) when no silhouette pixel is in the
// image.
struct GtBoxDetection {
  Box silhouette;          // the exact silhouette box, pixels
  bool in_view = false;
  Detection detection;     // class cls, the jittered box, `score`
};
GtBoxDetection JitteredGtBox(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera,
                             const std::string& cls, double jitter_px, double score, Rng& rng);

// ---- Results CSV (BOP 2019): header "scene_id,im_id,obj_id,score,R,t,time", one row per
// estimate: R = 9 space-separated values row-major, t = 3 space-separated values in mm, time =
// seconds for the whole image (the same on every row of an image; -1 = unknown).

inline constexpr const char* kBopCsvHeader = "scene_id,im_id,obj_id,score,R,t,time";

struct BopResult {
  int scene_id = 0, im_id = 0, obj_id = 0;
  double score = 0;
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera, metres
  double time_s = -1;
};

// One CSV row without the newline: R with %.9g, t in mm with %.6f, score and time with %.6f.
std::string FormatBopCsvRow(const BopResult& r);
// The largest results CSV ReadBopResultsCsv reads: 1 GiB (a row is about 200 bytes, so five
// million estimates; it is read line by line).
inline constexpr std::uintmax_t kMaxResultsCsvBytes = std::uintmax_t(1) << 30;
// Reads a results CSV: a regular file of at most kMaxResultsCsvBytes. Errors name the file and
// the 1-based line: a wrong header, a row without 7 fields, R without 9 / t without 3 numbers, a
// non-number or non-finite value, R not a rotation (‖RᵀR − I‖ > 1e-3 or det < 0), or two rows
// of one image with different times.
std::vector<BopResult> ReadBopResultsCsv(const std::string& path);
// Writes header + rows (replacing the file atomically, file_io.h).
void WriteBopResultsCsv(const std::vector<BopResult>& results, const std::string& path);
// Appends rows to `path` (the header first when the file is missing or empty) with one write,
// flushed to disk (AppendFileDurably), so a killed process leaves all of them or none; a failed
// write is undone. Throws Error naming the file on I/O failure, or when the file does not end
// with a newline (a torn last row: run-dataset removes it on resume).
void AppendBopResultsCsv(const std::vector<BopResult>& results, const std::string& path);

}  // namespace posefilter
