// src/synth/synth_options.cc — SynthOptions' fields as rows (posefilter/option_rows.h) and its
// IsValid: the ranges come from the rows; the camera, the target and the order of the two
// distances are checked here.
#include <algorithm>
#include <string>
#include <vector>

#include "core/option_check.h"
#include "posefilter/synth.h"

namespace posefilter {

std::span<const OptionInfo> SynthOptionTable() {
  using O = SynthOptions;
  const char* g = "Synthetic scenes";
  static const std::vector<OptionInfo> rows = [&] {
    std::vector<OptionInfo> r = {
        MakeOptionRow("depth-scale", POSEFILTER_OPTION_FIELD(O, depth_scale), g, kPositiveRange,
                      "metres per depth PNG unit (m; 0.0001 = 0.1 mm, depths up to 6.55 m)"),
        MakeOptionRow("target", POSEFILTER_OPTION_FIELD(O, target), g, kAnyRange,
                      "object kind: box, cylinder, lshape or torus (a target mesh replaces it)"),
        MakeOptionRow("min-distance", POSEFILTER_OPTION_FIELD(O, min_distance_m), g, ClosedRange(0.2, 5),
                      "min camera→target distance (m; <= the max)"),
        MakeOptionRow("max-distance", POSEFILTER_OPTION_FIELD(O, max_distance_m), g, ClosedRange(0.2, 5),
                      "max camera→target distance (m)"),
        MakeOptionRow("occlusion", POSEFILTER_OPTION_FIELD(O, occlusion), g, ClosedRange(0, 0.9),
                      "fraction of the target hidden by an occluder panel (achieved within 0.1)"),
        MakeOptionRow("clutter", POSEFILTER_OPTION_FIELD(O, clutter), g, ClosedRange(0, 20),
                      "clutter objects on the table around the target"),
        MakeOptionRow("noise", POSEFILTER_OPTION_FIELD(O, noise_sigma_m), g, ClosedRange(0, 0.05),
                      "depth noise σ at 1 m (m; σ grows with z²)"),
        MakeOptionRow("holes", POSEFILTER_OPTION_FIELD(O, hole_fraction), g, ClosedRange(0, 0.5),
                      "fraction of pixels dropped in blobs"),
        MakeOptionRow("missing-edges", POSEFILTER_OPTION_FIELD(O, missing_edges), g, kAnyRange,
                      "drop pixels at depth discontinuities (a 4-neighbour step > 2 cm), as sensors do"),
        MakeOptionRow("box-jitter", POSEFILTER_OPTION_FIELD(O, box_jitter_px), g, ClosedRange(0, 100),
                      "σ of the detection box noise (pixels)"),
        MakeOptionRow("miss-prob", POSEFILTER_OPTION_FIELD(O, miss_probability), g, kFractionRange,
                      "probability that the target is not detected"),
        MakeOptionRow("false-positives", POSEFILTER_OPTION_FIELD(O, false_positives), g, ClosedRange(0, 100),
                      "extra false detections per scene, of random classes, places and scores"),
    };
    for (OptionInfo& f : r) f.python = f.field;  // make_synth_scene's keywords are the fields
    return r;
  }();
  return rows;
}

bool SynthOptions::IsValid(std::string* why) const {
  std::string sub;
  if (!camera.IsValid(&sub)) return Fail(why, "camera: " + sub);
  if (camera.width < 80 || camera.height < 60)
    return Fail(why, "camera: image must be at least 80×60 pixels (the prior pyramid's finest level)");
  if (target_mesh != nullptr) {
    if (!target_mesh->IsValid(&sub)) return Fail(why, "target_mesh: " + sub);
    if (target_mesh->name.empty()) return Fail(why, "target_mesh: the mesh needs a name (its class)");
  } else if (const std::vector<std::string> kinds = SynthClassNames();
             std::find(kinds.begin(), kinds.end(), target) == kinds.end()) {
    std::string list;
    for (const std::string& k : kinds) list += (list.empty() ? "" : ", ") + k;
    return Fail(why, "target must be one of " + list + " (got '" + target + "')");
  }
  if (!ValidateOptionRows(SynthOptionTable(), *this, OptionNaming::kField, why)) return false;
  if (min_distance_m > max_distance_m) return Fail(why, "min_distance_m must be <= max_distance_m");
  return true;
}

}  // namespace posefilter
