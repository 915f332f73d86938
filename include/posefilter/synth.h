// posefilter/synth.h — a synthetic world with ground truth: procedural meshes, table-top
// scenes (table plane, clutter, an occluder, sensor noise, holes, missing edges) and a
// stage-1 prior for each scene (detection list + raw pyramid), with controllable noise,
// missed detections and false positives. Used by `posefilter synth`, the demo, the tests and
// the accuracy suite.
//
// Frames and units: metres and radians; camera frame OpenCV (x right, y down, z forward);
// meshes in their object frame, centred at the bounding-box centre, faces CCW from outside.
// Everything is deterministic per seed (posefilter::Rng).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"
#include "posefilter/option_rows.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"

namespace posefilter {

// ---- Procedural meshes (object frame at the bounding-box centre, metres, closed, CCW
// outward faces). Sizes must be finite and > 0, counts ≥ 3; otherwise Error.

// Axis-aligned box with side lengths sx × sy × sz (8 vertices, 12 triangles).
Mesh MakeBox(double sx, double sy, double sz, const std::string& name = "box");
// Cylinder along z: radius, height, `segments` sides (2·segments+2 vertices, 4·segments faces).
Mesh MakeCylinder(double radius, double height, int segments = 32,
                  const std::string& name = "cylinder");
// Non-convex extruded "L": the L lies in the x–y plane inside a size × size square, legs
// `thickness` wide (thickness < size), extruded `depth` along z.
Mesh MakeLShape(double size, double thickness, double depth, const std::string& name = "lshape");
// Torus around z: major radius (centre of the tube), minor radius (< major), nu segments
// around z, nv around the tube (nu·nv vertices, 2·nu·nv faces; 32×32 → 2048 triangles).
Mesh MakeTorus(double major_r, double minor_r, int nu = 32, int nv = 32,
               const std::string& name = "torus");
// One of SynthClassNames() with default sizes (8–20 cm):
//   box 12×8×16 cm; cylinder r 4 cm, h 14 cm; lshape 14 cm, legs 5 cm, 6 cm deep;
//   torus R 6 cm, r 2.5 cm (17 cm across), 32×32.
// Unknown kind → Error listing the kinds.
Mesh MakeShape(const std::string& kind);
// The class list of the synthetic world: {"box", "cylinder", "lshape", "torus"}.
std::vector<std::string> SynthClassNames();

// ---- Scenes.

struct SynthOptions {
  Camera camera;                       // default: thesis camera 640×480, base_to_camera = I
  double depth_scale = 0.0001;         // metres per 16-bit PNG unit (0.1 mm; max 6.55 m)
  std::string target = "lshape";       // a kind of SynthClassNames(); ignored if target_mesh
  const Mesh* target_mesh = nullptr;   // optional user mesh (its name = its class), not owned
  double min_distance_m = 0.6;         // camera → target bbox-centre distance range, metres,
                                       // within [0.2, 5]; occlusion needs room for the panel
  double max_distance_m = 1.0;
  double occlusion = 0.0;     // fraction of the target's silhouette to hide behind an occluder
                              // panel, [0, 0.9]; achieved within ±0.1 (see occlusion_achieved)
  int clutter = 3;            // other objects on the table around the target, [0, 20]
  double noise_sigma_m = 0.001;  // depth noise σ = noise_sigma_m·(z / 1 m)², metres, [0, 0.05];
                                 // then depth is quantised to depth_scale
  double hole_fraction = 0.01;   // fraction of all pixels dropped in random blobs, [0, 0.5]
  bool missing_edges = true;     // drop pixels with a 4-neighbour |Δz| > 2 cm (as sensors do)
  // Stage-1 prior.
  double box_jitter_px = 8;       // σ of detection box centre and size noise, pixels, [0, 100]
  double miss_probability = 0.0;  // probability that the target's detection is missing, [0, 1]
  int false_positives = 2;        // extra detections of random classes at random places with
                                  // random scores, [0, 100]
  // True when the camera is valid (at least 80×60 pixels), target a known kind or target_mesh
  // valid and named, every field of SynthOptionTable in its row's range and min_distance_m ≤
  // max_distance_m. `why` names the violated constraint by field ("clutter must be in [0, 20]
  // (got 21)").
  bool IsValid(std::string* why) const;
};

// SynthOptions' fields but the camera and the target mesh as rows (posefilter/option_rows.h):
// the CLI flag of `posefilter synth` (--min-distance, --noise, …), range, unit and help; the
// Python keyword of make_synth_scene is the field ("min_distance_m"). IsValid checks their
// ranges.
std::span<const OptionInfo> SynthOptionTable();

struct SynthScene {
  Camera camera;
  double depth_scale = 0.0001;  // metres per PNG unit (depth values are multiples of it)
  DepthImage depth;             // camera z, metres, 0 = missing (noise, holes, edges applied)
  // Per pixel (width×height, row-major): which surface the renderer put there, before the
  // sensor dropouts: 0 background/table, 1 target, 2 occluder, 3.. clutter objects.
  std::vector<int> labels;
  std::vector<GtObject> gt;     // the target: obj = class name, T_cam_obj object → camera
  Mesh target;                  // its mesh (name = class)
  std::vector<std::string> classes;   // prior classes: SynthClassNames() (+ user mesh name)
  std::vector<Detection> detections;  // stage-1 detection list (target first unless missed)
  PyramidLayout layout;               // PyramidLayout::Thesis(width, height, classes.size())
  std::vector<float> raw_pyramid;     // DetectionsToRawPyramid(detections, layout, classes)
  Box gt_box;                         // bbox of the target's full (unoccluded) silhouette, px
  double distance_m = 0;              // camera → target bbox centre, metres
  double table_angle_rad = 0;         // angle between optical axis and the table plane
  double occlusion_achieved = 0;      // 1 − visible target pixels / target pixels rendered alone
  bool target_detected = true;        // false when the target's detection was dropped
};

// Builds a scene (deterministic per seed). Throws Error if !opt.IsValid() (naming the
// option) or if the target cannot be placed in view.
SynthScene MakeSynthScene(const SynthOptions& opt, std::uint64_t seed);

// The target's motion in a synthetic sequence (MakeSynthSequence): a pushed object. It slides
// along a random direction of the table plane and turns about the table's normal through its
// footprint centre, by the same amount every frame; from jump_frame on it is also displaced
// by jump_m along the slide (a jump a tracker cannot follow). Table, clutter and camera stay.
struct SynthMotion {
  int frames = 10;          // [1, 1000]
  double speed_m = 0.01;    // slide per frame, metres, [0, 0.5]
  double turn_rad = 0.05;   // turn per frame, radians, [−π, π]
  int jump_frame = -1;      // −1 = no jump, else in [1, frames)
  double jump_m = 0;        // [0, 1] metres
  bool IsValid(std::string* why) const;
};

// The frames of a sequence: frame 0 is MakeSynthScene(opt, seed), except that clutter keeps
// clear of the target's whole path (an object the single scene puts on the path is placed
// elsewhere; the table, the target's pose and the detections stay); in frame t the target has
// moved as `motion` says (gt, gt_box, detections, labels and occlusion_achieved follow it),
// and the sensor noise, holes and detection jitter are drawn anew. A target that leaves the
// image is rendered as it is (gt still holds it).
// Throws Error for invalid options or motion (naming the field), or occlusion > 0 (a sequence
// has no occluder panel).
std::vector<SynthScene> MakeSynthSequence(const SynthOptions& opt, const SynthMotion& motion, std::uint64_t seed);

// Creates `dir` (and parents) and writes: depth.png (16-bit, depth_scale), camera.json (with
// depth_scale), gt.json, <target>.ply, detections.json, prior.pyr (raw pyramid, float32),
// classes.txt (one class per line), label.png (8-bit gray, raw label values), rgb.png (a
// shaded depth preview for humans) and synth.json (target, distance, occlusion, box, classes). Throws Error naming the path on I/O failure.
void WriteSynthScene(const SynthScene& scene, const std::string& dir);
// The names of the files WriteSynthScene writes into its folder for a scene whose target is
// named `target_name` (the mesh is <target_name>.ply).
std::vector<std::string> SynthSceneFileNames(const std::string& target_name);

// Writes a sequence as a YCB-Video-style dataset folder (posefilter/bop.h, ReadYcbvFolder) that
// `track`, `run-dataset` and `estimate` read: dir/models/<target>.ply and, per frame t (from
// 0), dir/scenes/<name>_0000_<t+1, 6 digits>/ as WriteSynthScene writes a scene. `name` must be
// a plain file-name stem. Throws Error naming the path on I/O failure.
void WriteSynthSequence(const std::vector<SynthScene>& frames, const std::string& dir, const std::string& name = "synth");

}  // namespace posefilter
