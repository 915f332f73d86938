// The option sets' CLI flags (apps/filter_cli.h) come from their tables: every row is a flag
// that sets its field, a switch has its --no- form, and the checks name the flag and the field.
#include <gtest/gtest.h>

#include <span>
#include <string>
#include <vector>

#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/option_table.h"

namespace posefilter::cli {
namespace {

// Parses `args` (without the program name) on `app`.
void ParseFlags(CLI::App& app, std::vector<std::string> args) {
  std::vector<char*> argv;
  std::string prog = "test";
  argv.push_back(prog.data());
  for (std::string& a : args) argv.push_back(a.data());
  app.parse(int(argv.size()), argv.data());
}

TEST(OptionFlags, EveryRowOfEachSetIsAFlag) {
  CLI::App app;
  TrackOptions track;
  ScenePassOptions pass;
  AutoPriorOptions autop;
  AddTrackOptions(app, &track);
  AddScenePassOptions(app, &pass);
  AddAutoPriorOptions(app, &autop);
  for (const std::span<const OptionInfo> rows : {TrackOptionTable(), ScenePassOptionTable(), AutoPriorOptionTable()})
    for (const OptionInfo& f : rows) EXPECT_NE(app.get_option_no_throw(f.Name(OptionNaming::kCli)), nullptr) << f.name;
  ParseFlags(app, {"--lost-weight", "0.3", "--no-velocity", "--no-scene-pass", "--window-margin", "0.5",
                   "--scene-pass-band", "0.02", "--auto-min-pixels", "10", "--auto-max-height", "0.4"});
  EXPECT_EQ(track.lost_weight, 0.3);
  EXPECT_FALSE(track.constant_velocity);
  EXPECT_FALSE(track.scene_pass);
  EXPECT_EQ(track.window_margin, 0.5);
  EXPECT_EQ(track.refresh_weight, TrackOptions{}.refresh_weight);
  EXPECT_EQ(pass.band_m, 0.02);
  EXPECT_EQ(autop.min_pixels, 10);
  EXPECT_EQ(autop.max_height_m, 0.4);
  EXPECT_NO_THROW(CheckTrackOptions(track));
  EXPECT_NO_THROW(CheckScenePassOptions(pass));
  EXPECT_NO_THROW(CheckAutoPriorOptions(autop));
}

TEST(OptionFlags, ChecksNameTheFlagAndTheField) {
  TrackOptions track;
  track.lost_weight = 3;
  try {
    CheckTrackOptions(track);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "invalid track option: --lost-weight (lost_weight): must be in [0, 1] (got 3)");
  }
  ScenePassOptions pass;
  pass.conflict_drop = 0;
  EXPECT_THROW(CheckScenePassOptions(pass), Error);
  AutoPriorOptions autop;
  autop.min_height_m = 1;  // above max_height_m: a constraint between two fields
  try {
    CheckAutoPriorOptions(autop);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "invalid auto prior option: --auto-min-height (min_height_m): must be < max_height_m");
  }
}

}  // namespace
}  // namespace posefilter::cli
