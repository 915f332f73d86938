// posefilter/view.h — a frame and its estimates as one self-contained HTML file: a 3D viewer
// for the browser (docs/VIEWER.md).
//
// The file needs no server and no network: three.js (Debian's libjs-three, read at build
// time) and the viewer's own script are inlined, the data is base64 inside the page. It shows
// the depth image as a point cloud (coloured by an RGB image, else shaded by depth), each
// estimated mesh in its pose, the ground truth where known, the support plane(s), and each
// object's recorded particle sets (FilterOptions::record_particles) with a slider over the
// iterations, weights as colours. The mouse turns (drag), pans (right drag) and zooms (wheel).
//
// Frames and units: camera frame (OpenCV: x right, y down, z forward), metres; poses object →
// camera, particle poses object → base as the filter records them.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/filter.h"
#include "posefilter/mesh.h"
#include "posefilter/support_plane.h"

namespace posefilter {

struct ViewObject {
  std::string name;
  Mesh mesh;                                                    // object frame, metres
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // the estimate, object → camera
  double weight = 0;                                            // its weight, eq. 7.4 [ALGORITHM.md]
  std::optional<Eigen::Isometry3d> gt_T_cam_obj;                // ground truth, object → camera
  std::vector<ParticleSet> particles;  // EstimateResult::particle_history (may be empty)
};

struct ViewScene {
  std::string title;
  DepthImage depth;                    // metres, 0 = missing; the camera's size
  Camera camera;
  RgbImage rgb;                        // empty, or the camera's size: the point cloud's colours
  std::vector<SupportPlane> planes;    // drawn where found, over the pixels on them
  std::vector<ViewObject> objects;
};

struct ViewOptions {
  // Point cloud: every s-th pixel of every s-th row, s the smallest stride that leaves at most
  // this many pixels (a 640 × 480 frame: s = 2, 76,800 pixels).
  int max_points = 80000;
  // Meshes above this many faces are simplified for the file (SimplifyMesh).
  int max_mesh_faces = 3000;
  // Per recorded set, the best this many particles are also drawn as meshes.
  int top_poses = 5;
  // At most this many particles are stored over all objects and sets: above it, each set keeps
  // its best same fraction of particles.
  int max_particles = 100000;
  bool IsValid(std::string* why) const;
};

// Whether this build has the viewer (false when libjs-three was not found at configure time).
bool ViewerAvailable();

// The page. Throws Error when the build has no viewer, the options are invalid, or the depth
// or RGB image does not have the camera's size.
std::string ViewHtml(const ViewScene& scene, const ViewOptions& options = {});

// ViewHtml written atomically to `path` (WriteFileAtomically); Error names the path.
void WriteViewHtml(const ViewScene& scene, const std::string& path, const ViewOptions& options = {});

}  // namespace posefilter
