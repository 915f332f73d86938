// eval/bop_detections.cc — BOP detections (bop.h): the reader of a BOP detections JSON file,
// their conversion to the prior's detections, and the jittered ground-truth boxes of
// gt-detections. The reader is strict; every error is one line "<file>: <entry>: <what>".
#include "posefilter/bop.h"

#include <algorithm>
#include <cmath>

#include "eval/bop_io_internal.h"
#include "posefilter/error.h"
#include "posefilter/projection.h"

namespace posefilter {

namespace {

using bop_io_internal::Integer;
using bop_io_internal::json;
using bop_io_internal::Key;
using bop_io_internal::Number;
using bop_io_internal::Numbers;
using bop_io_internal::ReadJson;
using bop_io_internal::Where;

// Smallest width/height of a jittered ground-truth box, pixels (as gt-detections).
constexpr double kMinBoxPx = 4;

}  // namespace

std::vector<BopDetection> ReadBopDetections(const std::string& path) {
  const json root = ReadJson(path);
  const Where file{path, ""};
  const json* list = &root;
  if (root.is_object() && root.contains("detections")) list = &root["detections"];
  if (!list->is_array()) file.Fail("must be a JSON array of {scene_id, image_id, category_id, bbox, score}");
  std::vector<BopDetection> out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& e = (*list)[i];
    const Where w = file.Sub("entry " + std::to_string(i));
    BopDetection d;
    d.scene_id = Integer(Key(e, "scene_id", w), "scene_id", w);
    d.im_id = Integer(Key(e, "image_id", w), "image_id", w);
    d.obj_id = Integer(Key(e, "category_id", w), "category_id", w);
    d.score = Number(Key(e, "score", w), "score", w);
    if (d.score < 0 || d.score > 1) w.Fail("score must be in [0, 1]");
    const std::vector<double> b = Numbers(Key(e, "bbox", w), 4, "bbox", w);
    d.x = b[0];
    d.y = b[1];
    d.w = b[2];
    d.h = b[3];
    if (!(d.w > 0 && d.h > 0)) w.Fail("bbox width and height must be > 0");
    if (const auto it = e.find("time"); it != e.end()) d.time_s = Number(*it, "time", w);
    out.push_back(d);
  }
  return out;
}

std::vector<Detection> ToPriorDetections(const std::vector<BopDetection>& detections, const Dataset& dataset,
                                         const std::string& source) {
  std::vector<Detection> out;
  for (const auto& d : detections) {
    const DatasetModel* m = dataset.Model(d.obj_id);
    if (!m)
      throw Error(source + ": scene " + std::to_string(d.scene_id) + ", image " + std::to_string(d.im_id) +
                  ": category_id " + std::to_string(d.obj_id) + " has no model in the dataset");
    out.push_back({m->name, d.score, d.x, d.y, d.w, d.h});
  }
  return out;
}

GtBoxDetection JitteredGtBox(const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj, const Camera& camera,
                             const std::string& cls, double jitter_px, double score, Rng& rng) {
  if (!std::isfinite(jitter_px) || jitter_px < 0) throw Error("gt boxes: jitter must be finite and ≥ 0 pixels");
  if (!std::isfinite(score) || score < 0 || score > 1) throw Error("gt boxes: score must be in [0, 1]");
  const double jx = rng.Normal(), jy = rng.Normal(), jw = rng.Normal(), jh = rng.Normal();
  GtBoxDetection out;
  out.silhouette = ProjectedBox(mesh, T_cam_obj, camera);
  const Box& box = out.silhouette;
  out.in_view = box.w > 0 && box.h > 0;
  if (!out.in_view) return out;
  Box b = box;
  b.cx += std::clamp(jitter_px * jx, -0.25 * box.w, 0.25 * box.w);
  b.cy += std::clamp(jitter_px * jy, -0.25 * box.h, 0.25 * box.h);
  b.w = std::max(kMinBoxPx, box.w + jitter_px * jw);
  b.h = std::max(kMinBoxPx, box.h + jitter_px * jh);
  out.detection = {cls, score, b.cx - b.w / 2, b.cy - b.h / 2, b.w, b.h};
  return out;
}

}  // namespace posefilter
