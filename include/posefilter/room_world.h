// posefilter/room_world.h — real object meshes in a room: the benchmark behind `posefilter
// suite --world room` (docs/SYNTHETIC.md, "The room world").
//
// Where robots meet objects there is rarely one table filling the view: the objects stand on
// a small raised surface — a classroom chair's writing tablet, a stool, a side table, a crate,
// a shelf's board — with the floor, walls and other furniture around, so that the largest
// plane in view is often the floor or a wall, not the surface the objects rest on.
//
// A scene, in the room frame R (z up, the floor at z = 0):
//   - the support: one raised surface (20–60 cm sides, 0.4–1.2 m above the floor) or a
//     shelf's board; sometimes a second raised surface beside it at another height;
//   - objects of the world (distinct classes) resting on the support surfaces in their
//     stable poses, touching or apart (the table world's placement, kept on the surface);
//   - distractors that are no targets: YCB-size boxes and cylinders and meshes of classes the
//     scene's objects do not use, on other furniture, on the floor and sometimes beside the
//     objects;
//   - furniture around: chairs with writing tablets, desks, shelves with two or three boards,
//     stools and boxes, kept out of the line of sight to the objects;
//   - a floor and one to three walls, up to about 5 m away;
//   - a camera 0.5–1.5 m from the objects looking down at them 15–60°, YCB-Video intrinsics,
//     the table world's structured-light sensor model, the same targets, boxes and masks.
// Views are redrawn until the support surfaces cover min_surface_view–max_surface_view of the
// image and an object is a target (at most 40 views; then the first view with a target).
//
// Frames and units: metres and radians; poses object → camera (OpenCV camera frame).
// Deterministic per seed (posefilter::Rng, one split stream per stage).
#pragma once

#include <cstdint>
#include <string>

#include "posefilter/table_world.h"

namespace posefilter {

struct RoomSceneOptions {
  Camera camera = YcbVideoCamera();
  double depth_scale = 0.0001;            // metres per PNG unit when written
  int min_objects = 2, max_objects = 4;   // objects on the support surfaces (distinct classes), ≥ 1
  double min_distance_m = 0.5, max_distance_m = 1.5;      // camera → the objects' centre, metres
  double min_elevation_deg = 15, max_elevation_deg = 60;  // optical axis below the horizontal
  // The support surfaces: their height above the floor (metres) and, for the raised surfaces
  // (not a shelf's board, which is 0.5–1 m wide), their sides (metres).
  double min_surface_height_m = 0.4, max_surface_height_m = 1.2;
  double min_surface_size_m = 0.2, max_surface_size_m = 0.6;
  // Fraction of the image the support surfaces cover (seen), [0, 1].
  double min_surface_view = 0.05, max_surface_view = 0.4;
  double shelf_probability = 0.25;        // the objects rest on a shelf's board, [0, 1]
  double two_surfaces_probability = 0.3;  // a second raised surface holds some of them, [0, 1]
  int min_furniture = 2, max_furniture = 6;      // furniture besides the supports', [0, 20]
  int min_distractors = 2, max_distractors = 6;  // objects that are no targets, [0, 30]
  double touch_probability = 0.5;         // an object is pushed against a neighbour, else 1–8 cm apart
  double min_visible_fraction = 0.1;      // targets: as TableSceneOptions
  int min_visible_px = 100;
  SensorModel sensor;
  double box_jitter_px = 8;               // stage-1 boxes and masks: as TableSceneOptions
  double box_scale_min = 1.0, box_scale_max = 1.0;
  int false_positives = 2;
  double mask_boundary_px = 2;
  bool IsValid(std::string* why) const;
};

// One room scene of `world`'s meshes (TableScene: objects are the meshes on the support
// surfaces, supports their planes, table_plane the first support's). A layout where no object
// fits on the supports, or no view shows one well enough, is drawn again from later streams
// of the seed (at most 8 layouts; the first layout of every seed is the one drawn from the
// seed's first streams). Throws Error if !opt.IsValid (naming the option), if max_objects
// exceeds the world's classes, or when none of the 8 layouts gives a scene.
TableScene MakeRoomScene(const TableWorld& world, const RoomSceneOptions& opt, std::uint64_t seed);

}  // namespace posefilter
