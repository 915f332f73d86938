// src/filter/option_sets.cc — the tracker's and the scene pass's options as rows
// (posefilter/option_rows.h) and their IsValid: the ranges come from the rows.
#include <cmath>
#include <string>
#include <vector>

#include "core/option_check.h"
#include "filter/engine_registry.h"
#include "posefilter/option_table.h"
#include "posefilter/scene_pass.h"
#include "posefilter/tracker.h"

namespace posefilter {

std::span<const OptionInfo> TrackOptionTable() {
  using O = TrackOptions;
  const char* g = "Tracker";
  static const std::vector<OptionInfo> rows = [&] {
    std::vector<OptionInfo> r = {
        MakeOptionRow("lost-weight", POSEFILTER_OPTION_FIELD(O, lost_weight), g, kFractionRange,
                      "an object whose best weight falls below this is lost (eq. 7.4 units)"),
        MakeOptionRow("refresh-weight", POSEFILTER_OPTION_FIELD(O, refresh_weight), g, kFractionRange,
                      "a tracked object below this weight is also estimated from the frame's stage 1; the heavier "
                      "pose wins (0 = only lost objects)"),
        MakeOptionRow("search-t", POSEFILTER_OPTION_FIELD(O, search_t_m), g, ClosedRange(0, 1),
                      "sigma of the initial particles' translation about the predicted pose (m)"),
        MakeOptionRow("search-r", POSEFILTER_OPTION_FIELD(O, search_r_rad), g, ClosedRange(0, M_PI),
                      "sigma of their rotation (rad)"),
        MakeOptionRow("velocity", POSEFILTER_OPTION_FIELD(O, constant_velocity), g, kAnyRange,
                      "predict the last pose moved by the last frame-to-frame motion (off: the last pose)"),
        MakeOptionRow("scene-pass", POSEFILTER_OPTION_FIELD(O, scene_pass), g, kAnyRange,
                      "objects estimated from one frame's stage 1 go through the joint scene pass together"),
        MakeOptionRow("window-margin", POSEFILTER_OPTION_FIELD(O, window_margin), g, {0, 2, true, false},
                      "search window: the poses' boxes grown by this fraction per side"),
        MakeOptionRow("confirm", POSEFILTER_OPTION_FIELD(O, confirm), g, kAnyRange,
                      "confirm the prediction before searching: the predicted pose, polished alone, is the frame's "
                      "pose when it weighs enough (off: every frame runs the particle search)"),
        MakeOptionRow("confirm-margin", POSEFILTER_OPTION_FIELD(O, confirm_margin), g, kFractionRange,
                      "a confirmed prediction weighs at least the object's reference weight less this (eq. 7.4 units)"),
    };
    r[4].python = "constant_velocity";
    return r;
  }();
  return rows;
}

bool TrackOptions::IsValid(std::string* why) const {
  if (!ValidateOptionRows(TrackOptionTable(), *this, OptionNaming::kField, why)) return false;
  std::string w;
  if (!ValidateFilterOptions(filter, OptionNaming::kField, &w)) return Fail(why, "filter." + w);
  if (!ValidateFilterOptions(init, OptionNaming::kField, &w)) return Fail(why, "init." + w);
  if (const filter::EngineRow* row = filter::FindEngine(filter.engine); row != nullptr && !row->float_filter) {
    std::string floats;
    for (const filter::EngineRow& r : filter::EngineRegistry())
      if (r.float_filter) floats += std::string(floats.empty() ? "" : ", ") + r.name;
    return Fail(why, "filter.engine must be a float engine (" + floats + "): the " + filter.engine +
                         " engine does not read pose seeds");
  }
  return true;
}

std::span<const OptionInfo> ScenePassOptionTable() {
  using O = ScenePassOptions;
  const char* g = "Scene pass";
  static const std::vector<OptionInfo> rows = {
      MakeOptionRow("scene-pass-band", POSEFILTER_OPTION_FIELD(O, band_m), g, kPositiveRange,
                    "a pixel is explained by an estimate whose rendered depth lies within this of the measured depth "
                    "(m)"),
      MakeOptionRow("scene-pass-conflict-drop", POSEFILTER_OPTION_FIELD(O, conflict_drop), g, kPositiveFractionRange,
                    "re-estimate an object whose weight with the pixels better estimates explain masked out is this "
                    "much below its own (eq. 7.4 units)"),
  };
  return rows;
}

bool ScenePassOptions::IsValid(std::string* why) const {
  return ValidateOptionRows(ScenePassOptionTable(), *this, OptionNaming::kField, why);
}

}  // namespace posefilter
