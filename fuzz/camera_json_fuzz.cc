// Fuzz target: ReadCameraJson (include/posefilter/scene_io.h), the camera.json reader of
// `estimate`, `gt-detections` and the YCB-Video folders. Seeds: fuzz/corpus/camera_json_fuzz/;
// dictionary: fuzz/json.dict.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.h"
#include "posefilter/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("camera", ".json");
  const std::string& path = file.Write(data, size);
  posefilter_fuzz::ReadOrError(path, [&] {
    const posefilter::CameraFile cf = posefilter::ReadCameraJson(path);
    std::string why;
    posefilter_fuzz::Require(cf.camera.IsValid(&why), "a read camera is valid (Camera::IsValid)");
    posefilter_fuzz::Require(std::isfinite(cf.depth_scale) && cf.depth_scale > 0,
                             "depth_scale is finite and > 0");
  });
  return 0;
}
