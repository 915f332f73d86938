// posefilter/scene_io.h — JSON files for cameras, ground truth and results (nlohmann-json).
//
// camera.json (same keys as the YCB-Video frames of $POSEFILTER_DATA/ycbv): {"fx","fy","cx","cy","width","height",
//   "depth_scale" (metres per PNG unit), optional "base_to_camera": 4×4 row-major nested array}.
// gt.json: {"objects": [{"obj": name, "R": 3×3 row-major (nested or flat 9), "t": [x,y,z] m}]},
//   x_cam = R·x_model + t.
// results.json: {"objects": [ObjectResult...]} as written by WriteResultsJson.
// Every reader throws Error naming the file (and key) on a missing file, malformed JSON,
// a missing key, a non-number or a NaN/inf.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/pose.h"

namespace posefilter {

struct CameraFile {
  Camera camera;
  double depth_scale = 0.001;  // metres per 16-bit PNG unit
};

struct GtObject {
  std::string obj;                                             // object name
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera
};

// One estimated object, as the CLI reports it.
struct ObjectResult {
  std::string obj;
  Pose6 pose_base;                                             // object → base (x..yaw)
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera (R, t)
  double weight = 0;       // best particle weight, eq. 7.4 [ALGORITHM.md], in [0, 1]
  int iterations = 0;      // filter iterations run
  double time_ms = 0;      // wall time for this object
};

CameraFile ReadCameraJson(const std::string& path);
void WriteCameraJson(const CameraFile& cam, const std::string& path);
std::vector<GtObject> ReadGtJson(const std::string& path);
void WriteGtJson(const std::vector<GtObject>& objects, const std::string& path);
std::vector<ObjectResult> ReadResultsJson(const std::string& path);
void WriteResultsJson(const std::vector<ObjectResult>& results, const std::string& path);

}  // namespace posefilter
