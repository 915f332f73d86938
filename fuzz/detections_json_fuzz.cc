// Fuzz target: ReadDetectionsJson (include/posefilter/prior.h, src/prior/detections.cc), the
// stage-1 detections reader of `estimate --prior x.json`. The first byte picks allow_empty; the
// rest is the file. Seeds: fuzz/corpus/detections_json_fuzz/; dictionary: fuzz/json.dict.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fuzz_util.h"
#include "posefilter/prior.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static posefilter_fuzz::ScratchFile file("detections", ".json");
  if (size < 1) return 0;
  const bool allow_empty = (data[0] & 1) != 0;
  const std::string& path = file.Write(data + 1, size - 1);
  posefilter_fuzz::ReadOrError(path, [&] {
    const std::vector<posefilter::Detection> dets = posefilter::ReadDetectionsJson(path, allow_empty);
    posefilter_fuzz::Require(allow_empty || !dets.empty(), "an empty list throws unless allow_empty");
    for (const posefilter::Detection& d : dets) {
      posefilter_fuzz::Require(!d.cls.empty(), "class is not empty");
      posefilter_fuzz::Require(std::isfinite(d.score) && d.score >= 0 && d.score <= 1, "score in [0, 1]");
      posefilter_fuzz::Require(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.w) &&
                                   std::isfinite(d.h) && d.w > 0 && d.h > 0,
                               "bbox finite with w, h > 0");
    }
  });
  return 0;
}
