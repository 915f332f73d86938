// src/prior/auto_prior_options.cc — AutoPriorOptions' fields as rows (posefilter/option_rows.h)
// and its IsValid: the ranges come from the rows, the nested surfaces' and PPF options' from
// their own IsValid.
#include <cmath>
#include <string>
#include <vector>

#include "core/option_check.h"
#include "posefilter/auto_prior.h"

namespace posefilter {

std::span<const OptionInfo> AutoPriorOptionTable() {
  using O = AutoPriorOptions;
  const char* g = "Auto prior";
  static const std::vector<OptionInfo> rows = {
      MakeOptionRow("auto-min-height", POSEFILTER_OPTION_FIELD(O, min_height_m), g, AtLeastRange(0),
                    "points less than this above their support's band are the support's (m; < --auto-max-height)"),
      MakeOptionRow("auto-max-height", POSEFILTER_OPTION_FIELD(O, max_height_m), g, kPositiveRange,
                    "points higher than this above their support are not objects (m)"),
      MakeOptionRow("auto-max-step", POSEFILTER_OPTION_FIELD(O, max_step_fraction), g, kPositiveFractionRange,
                    "neighbours are in one region where their depth step is at most this fraction of their depth"),
      MakeOptionRow("auto-min-pixels", POSEFILTER_OPTION_FIELD(O, min_pixels), g, AtLeastRange(1),
                    "smaller regions are noise (pixels)"),
      MakeOptionRow("auto-fit-factor", POSEFILTER_OPTION_FIELD(O, fit_factor), g, AtLeastRange(1),
                    "a region within this many object sizes on both sides is one box"),
      MakeOptionRow("auto-min-fill", POSEFILTER_OPTION_FIELD(O, min_fill), g, kPositiveFractionRange,
                    "a tile is kept where region pixels fill this fraction of it"),
      MakeOptionRow("auto-fit-score", POSEFILTER_OPTION_FIELD(O, fit_score), g, kPositiveFractionRange,
                    "detection score of a region that fits an object"),
      MakeOptionRow("auto-tile-score", POSEFILTER_OPTION_FIELD(O, tile_score), g, kPositiveFractionRange,
                    "detection score of a tile of a larger region"),
      MakeOptionRow("auto-full-size", POSEFILTER_OPTION_FIELD(O, full_size), g, kPositiveRange,
                    "a fitting region spanning less than this many object sizes scores less, in proportion"),
      MakeOptionRow("auto-min-size-weight", POSEFILTER_OPTION_FIELD(O, min_size_weight), g, kPositiveFractionRange,
                    "the least fraction of the fit score a small fitting region keeps"),
      MakeOptionRow("auto-tile-weight-when-one-fits", POSEFILTER_OPTION_FIELD(O, tile_weight_when_one_fits), g,
                    kPositiveFractionRange, "tiles of a region that one of the objects fits whole score this fraction"),
      MakeOptionRow("auto-proposal-score", POSEFILTER_OPTION_FIELD(O, proposal_score), g, kPositiveFractionRange,
                    "detection score of an object's best PPF pose proposal"),
      MakeOptionRow("auto-max-seeds", POSEFILTER_OPTION_FIELD(O, max_seeds), g, AtLeastRange(1),
                    "pose seeds kept per object, most votes first"),
  };
  return rows;
}

bool AutoPriorOptions::IsValid(std::string* why) const {
  std::string p;
  if (!surfaces.IsValid(&p)) return Fail(why, "surfaces: " + p);
  if (!ValidateOptionRows(AutoPriorOptionTable(), *this, OptionNaming::kField, why)) return false;
  if (!(min_height_m < max_height_m)) return Fail(why, "min_height_m must be < max_height_m");
  if (!ppf.IsValid(&p)) return Fail(why, "ppf: " + p);
  return true;
}

}  // namespace posefilter
