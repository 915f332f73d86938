// posefilter/table_world.h — a synthetic world of real object meshes on a table, seen by a
// structured-light depth sensor: the realistic benchmark behind `posefilter suite --world
// ycbv` (docs/ALGORITHM.md, "The YCB table-top benchmark").
//
// A scene: several objects (distinct classes of the world) rest on a table in their stable
// poses (stable_poses.h), drawn by probability, turned about the table normal, placed side
// by side so that they touch or nearly touch and occlude each other from the camera; the
// camera looks down at the group from 0.6–1.3 m (YCB-Video intrinsics by default); the
// depth image goes through a structured-light sensor model; every object seen well enough
// is a target, with a jittered detection box (and false boxes) and a noisy instance mask.
//
// Frames and units: metres and radians. The table frame has z up and the table top at
// z = 0; objects' poses are given object → camera (OpenCV camera frame). Everything is
// deterministic per seed (posefilter::Rng, one split stream per stage).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/stable_poses.h"

namespace posefilter {

// The YCB-Video camera (asus-uw): 640×480, fx 1066.778, fy 1067.487, cx 312.9869, cy 241.3109.
Camera YcbVideoCamera();

// A structured-light depth sensor (Kinect v1 / Asus Xtion class): a projector beside the
// camera, depth from the disparity between projected and seen pattern.
//   - projector shadows: surfaces the projector cannot see (beside the objects, on the side
//     away from the projector) get no depth;
//   - disparity noise and quantisation: disparity δ = f·b / z gets per-pixel and smooth
//     (spatially correlated) Gaussian noise and is rounded to disparity_step_px, so depth
//     noise and depth steps grow with z² (≈ 1.5 mm noise and 3 mm steps at 1 m);
//   - missing depth at depth edges (1–2 px), on surfaces seen at grazing angles, in random
//     holes, and in patches of some objects (dark or shiny material); out-of-range readings;
//   - the result is registered depth rounded to output_step_m (YCB-Video: 1 mm).
struct SensorModel {
  double baseline_m = 0.075;            // projector ↔ camera, along the camera's x axis, metres
  double focal_px = 580;                // the sensor's own focal length (disparity), pixels
  double disparity_noise_px = 0.05;     // per-pixel σ of the disparity, pixels
  double disparity_smooth_px = 0.05;    // σ of a smooth noise field (≈ 30 px correlation)
  double disparity_step_px = 0.125;     // disparity quantisation (1/8 px), pixels; 0 = none
  double min_range_m = 0.35, max_range_m = 3.5;  // readings outside are missing
  double shadow_tolerance = 0.015;      // projector-visibility test: depth tolerance ÷ z
  double grazing_start_deg = 72, grazing_end_deg = 85;  // dropout probability 0 → 1 between
  double edge_jump_m = 0.02;            // a 4-neighbour depth step above this is an edge
  double edge_second_ring_probability = 0.4;  // an edge pixel's neighbours also go missing
  double hole_fraction = 0.005;         // random disc holes, fraction of all pixels
  double object_patch_probability = 0.3;  // an object loses a few patches of its surface
  double output_step_m = 0.001;         // registered depth rounding, metres (0 = none)
  bool IsValid(std::string* why) const;
};

struct TableSceneOptions {
  Camera camera = YcbVideoCamera();
  double depth_scale = 0.0001;          // metres per PNG unit when written
  int min_objects = 3, max_objects = 6; // objects per scene (distinct classes), ≥ 1
  double min_distance_m = 0.6, max_distance_m = 1.3;  // camera → the group's centre
  double min_elevation_deg = 25, max_elevation_deg = 65;  // optical axis above the table
  // Objects are placed side by side; each is pushed against a neighbour (touching) with
  // this probability, else left 1–8 cm from it.
  double touch_probability = 0.6;
  // An object is a target when at least this fraction of its silhouette is visible and at
  // least min_visible_px of its pixels are (BOP's targets use 10 %).
  double min_visible_fraction = 0.1;
  int min_visible_px = 100;
  SensorModel sensor;
  // Stage-1 prior of the targets: full-silhouette boxes with centre and size noise
  // N(0, box_jitter_px²) (centre noise clamped to a quarter of the box) and a random scale
  // in [box_scale_min, box_scale_max]; false_positives extra boxes of random classes, half of
  // them on another object of the scene, half anywhere.
  double box_jitter_px = 8;
  double box_scale_min = 1.0, box_scale_max = 1.0;
  int false_positives = 2;
  // Instance masks: the visible silhouette, its outline moved in or out by up to this many
  // pixels per object and ragged pixel by pixel (a segmentation network's error).
  double mask_boundary_px = 2;
  bool IsValid(std::string* why) const;
};

struct TableObject {
  std::string cls;              // class (mesh name)
  int model = -1;               // index into TableWorld::models()
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera
  int stable_pose = -1;         // index into the model's stable poses
  double visible_fraction = 0;  // visible pixels / pixels of the object rendered alone
  int visible_px = 0;
  Box box;                      // the full (unoccluded) silhouette's box, pixels
  bool target = false;
  int support = 0;              // index into TableScene::supports: the surface it rests on
};

struct TableScene {
  Camera camera;
  double depth_scale = 0.0001;
  DepthImage depth;             // camera z, metres, 0 = missing (after the sensor model)
  DepthImage clean_depth;       // the rendered depth before the sensor model
  // Per pixel: 0 table/floor, i + 1 for objects[i] (visible surface, before dropouts).
  std::vector<int> labels;
  // Per pixel: the instance mask a segmentation front end would give: 0 none, i + 1 for
  // targets' objects[i] (noisy outline; non-targets get no mask).
  std::vector<std::uint16_t> masks;
  std::vector<TableObject> objects;
  std::vector<Detection> detections;  // targets' (first, in object order) then false ones
  std::vector<std::string> classes;   // the world's classes (the prior's class list)
  Eigen::Vector4d table_plane = Eigen::Vector4d::Zero();  // camera frame: n·x + d = 0, n up
  // The surfaces the objects rest on, camera frame, n·x + d = 0 with n up (the table world:
  // the table alone; the room world: one or two raised surfaces), and the fraction of the
  // image's pixels each covers (seen, before the sensor model).
  std::vector<Eigen::Vector4d> supports;
  std::vector<double> support_view_fractions;
  Eigen::Vector4d floor_plane = Eigen::Vector4d::Zero();  // camera frame, n up, as table_plane
  double distance_m = 0, elevation_deg = 0;
};

struct TableModel {
  Mesh mesh;                       // name = class
  std::vector<StablePose> poses;   // most probable first
  double diameter = 0;             // metres
};

class TableWorld {
 public:
  // One model per mesh (names must be distinct and non-empty); stable poses computed here.
  // Throws Error naming a mesh without volume or a repeated name.
  explicit TableWorld(std::vector<Mesh> meshes);
  // The 21 YCB-Video meshes <dir>/<class>.ply (metres), in YcbVideoClassNames() order.
  // Throws Error naming the folder or the missing file.
  static TableWorld LoadYcbVideo(const std::string& models_dir);

  const std::vector<TableModel>& models() const { return models_; }
  std::vector<std::string> ClassNames() const;
  // Throws Error if !opt.IsValid (naming the option), or max_objects exceeds the models.
  TableScene MakeScene(const TableSceneOptions& opt, std::uint64_t seed) const;

 private:
  std::vector<TableModel> models_;
};

// Writes a scene to `dir` (created): depth.png (16-bit, depth_scale), camera.json, gt.json
// (every object), detections.json, prior.pyr with classes.txt (the detections as a raw
// pyramid over the world's classes), mask.png (16-bit instance ids) and
// mask_classes.json ({"id": class}), label.png (visible objects, 8-bit), rgb.png (shaded
// depth for humans), scene.json (targets, visible fractions, the table plane).
// Throws Error naming the path on I/O failure.
void WriteTableScene(const TableScene& scene, const std::string& dir);

}  // namespace posefilter
