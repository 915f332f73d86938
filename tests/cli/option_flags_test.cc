// The option sets' CLI flags (apps/filter_cli.h) come from their tables: every row is a flag
// that sets its field, a switch has its --no- form, and the checks name the flag and the field;
// docs/OPTIONS.md is every table.
#include <gtest/gtest.h>

#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
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
  SynthOptions synth;
  AddTrackOptions(app, &track);
  AddScenePassOptions(app, &pass);
  AddAutoPriorOptions(app, &autop);
  AddSynthOptions(app, &synth);
  for (const std::span<const OptionInfo> rows :
       {TrackOptionTable(), ScenePassOptionTable(), AutoPriorOptionTable(), SynthOptionTable()})
    for (const OptionInfo& f : rows) EXPECT_NE(app.get_option_no_throw(f.Name(OptionNaming::kCli)), nullptr) << f.name;
  ParseFlags(app, {"--lost-weight", "0.3", "--no-velocity", "--no-scene-pass", "--window-margin", "0.5",
                   "--scene-pass-band", "0.02", "--auto-min-pixels", "10", "--auto-max-height", "0.4",
                   "--confirm-margin", "0.1", "--no-confirm", "--target", "torus", "--noise", "0.002",
                   "--no-missing-edges", "--clutter", "5", "--depth-scale", "0.001"});
  EXPECT_EQ(track.lost_weight, 0.3);
  EXPECT_FALSE(track.constant_velocity);
  EXPECT_FALSE(track.scene_pass);
  EXPECT_EQ(track.window_margin, 0.5);
  EXPECT_EQ(track.refresh_weight, TrackOptions{}.refresh_weight);
  EXPECT_EQ(pass.band_m, 0.02);
  EXPECT_EQ(autop.min_pixels, 10);
  EXPECT_EQ(autop.max_height_m, 0.4);
  EXPECT_EQ(track.confirm_margin, 0.1);
  EXPECT_FALSE(track.confirm);
  EXPECT_EQ(synth.target, "torus");
  EXPECT_EQ(synth.noise_sigma_m, 0.002);
  EXPECT_FALSE(synth.missing_edges);
  EXPECT_EQ(synth.clutter, 5);
  EXPECT_EQ(synth.depth_scale, 0.001);
  EXPECT_EQ(synth.hole_fraction, SynthOptions{}.hole_fraction);
  EXPECT_NO_THROW(CheckTrackOptions(track));
  EXPECT_NO_THROW(CheckScenePassOptions(pass));
  EXPECT_NO_THROW(CheckAutoPriorOptions(autop));
  EXPECT_NO_THROW(CheckSynthOptions(synth));
  // A switch's two forms: the last one given wins.
  CLI::App again;
  SynthOptions edges;
  AddSynthOptions(again, &edges);
  ParseFlags(again, {"--no-missing-edges", "--missing-edges"});
  EXPECT_TRUE(edges.missing_edges);
}

// The message of the Error that `check` throws; "" when it throws none.
template <class Check>
std::string CheckMessage(Check check) {
  try {
    check();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(OptionFlags, ChecksNameTheFlagAndTheField) {
  TrackOptions track;
  track.lost_weight = 3;
  EXPECT_EQ(CheckMessage([&] { CheckTrackOptions(track); }),
            "invalid track option: --lost-weight (lost_weight): must be in [0, 1] (got 3)");
  ScenePassOptions pass;
  pass.conflict_drop = 0;
  EXPECT_THROW(CheckScenePassOptions(pass), Error);
  AutoPriorOptions autop;
  autop.min_height_m = 1;  // above max_height_m: a constraint between two fields
  EXPECT_EQ(CheckMessage([&] { CheckAutoPriorOptions(autop); }),
            "invalid auto prior option: --auto-min-height (min_height_m): must be < max_height_m");
  SynthOptions synth;
  synth.clutter = 21;
  EXPECT_EQ(CheckMessage([&] { CheckSynthOptions(synth); }),
            "invalid synth option: --clutter (clutter): must be in [0, 20] (got 21)");
  synth = {};
  synth.min_distance_m = 2;  // above max_distance_m
  EXPECT_EQ(CheckMessage([&] { CheckSynthOptions(synth); }),
            "invalid synth option: --min-distance (min_distance_m): must be <= max_distance_m");
  EXPECT_EQ(CheckMessage([&] { CheckSynthOptions(SynthOptions{}); }), "");
  // suite's naming of the same messages; a message that starts with no row's field stays.
  EXPECT_EQ(NameSynthOption("noise_sigma_m must be in [0, 0.05] (got 1)"),
            "--noise (noise_sigma_m): must be in [0, 0.05] (got 1)");
  EXPECT_EQ(NameSynthOption("camera: fx must be > 0"), "camera: fx must be > 0");
}

TEST(OptionFlags, DocsOptionsMdIsEveryTable) {
  std::ifstream in(std::string(POSEFILTER_SOURCE_DIR) + "/docs/OPTIONS.md");
  ASSERT_TRUE(in) << "docs/OPTIONS.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  const std::string md = OptionsMarkdown();
  EXPECT_EQ(text.str(), md) << "regenerate: posefilter options --markdown > docs/OPTIONS.md";
  EXPECT_EQ(md.rfind(OptionTableMarkdown(), 0), 0u);
  for (const OptionInfo& f : SynthOptionTable())
    EXPECT_NE(md.find("| `" + f.Name(OptionNaming::kCli) + "` | `" + f.field + "` | `" + f.field + "` |"),
              std::string::npos)
        << f.name;
}

}  // namespace
}  // namespace posefilter::cli
