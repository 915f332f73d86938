// The option tables cover their structs (every field of FilterOptions and of the other option
// sets has a row, counted from the structs themselves), the heuristic ranges are written once,
// and the other sets' IsValid, names and Markdown come from their rows.
#include "posefilter/option_rows.h"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "posefilter/auto_prior.h"
#include "posefilter/heuristics.h"
#include "posefilter/option_table.h"
#include "posefilter/scene_pass.h"
#include "posefilter/synth.h"
#include "posefilter/tracker.h"

namespace posefilter {
namespace {

// Converts to a reference to any type: initialises one member of an aggregate (declared only;
// used in unevaluated braced initialisers).
struct AnyMember {
  template <class T>
  operator T&() const noexcept;
};

template <class T, std::size_t... I>
constexpr bool InitialisableFromMembers(std::index_sequence<I...>) {
  return requires { T{(static_cast<void>(I), AnyMember{})...}; };
}

// The number of direct data members of the aggregate T: the most initialisers T{…} takes (a
// member that is itself a struct counts once; AnyMember initialises it whole).
template <class T, std::size_t N = 0>
constexpr std::size_t DirectFieldCount() {
  if constexpr (N < 64 && InitialisableFromMembers<T>(std::make_index_sequence<N + 1>{}))
    return DirectFieldCount<T, N + 1>();
  else
    return N;
}

// The count works: known structs.
struct ThreeFields {
  int a = 1;
  std::string b;
  std::array<double, 4> c{};
};
static_assert(DirectFieldCount<ThreeFields>() == 3);
static_assert(DirectFieldCount<InlierParams>() == 3);
static_assert(DirectFieldCount<ScenePassOptions>() == 2);

// For each struct path prefix of a table ("" the struct itself, "score." its member score, …),
// the number of direct members of that struct.
using StructFieldCounts = std::map<std::string, std::size_t>;

// Checks that under each prefix the rows name exactly as many distinct members as the struct
// has, except the members in `elsewhere` (nested option sets with their own table), and that
// every struct the rows reach is listed in `counts`.
void ExpectRowsCoverStruct(std::span<const OptionInfo> rows, const StructFieldCounts& counts,
                           const std::set<std::string>& elsewhere) {
  std::map<std::string, std::set<std::string>> members;  // prefix → member names under it
  for (const OptionInfo& f : rows) {
    const std::string field = f.field;
    std::size_t at = 0;
    for (;;) {
      const std::size_t dot = field.find('.', at);
      const std::string prefix = field.substr(0, at);
      members[prefix].insert(field.substr(at, dot == std::string::npos ? dot : dot - at));
      if (dot == std::string::npos) break;
      at = dot + 1;
    }
  }
  for (const std::string& e : elsewhere) {
    const std::size_t dot = e.rfind('.');
    members[dot == std::string::npos ? "" : e.substr(0, dot + 1)].insert(
        e.substr(dot == std::string::npos ? 0 : dot + 1));
  }
  for (const auto& [prefix, names] : members) {
    SCOPED_TRACE("struct at '" + prefix + "'");
    const auto c = counts.find(prefix);
    ASSERT_NE(c, counts.end()) << "the rows reach a struct the test does not count: add it to the counts";
    EXPECT_EQ(names.size(), c->second) << "a field of this struct has no row (or a row names no field)";
  }
  EXPECT_EQ(members.size(), counts.size()) << "a counted struct has no row";
}

TEST(OptionRows, EveryFilterOptionsFieldHasARow) {
  const StructFieldCounts counts = {
      {"", DirectFieldCount<FilterOptions>()},
      {"score.", DirectFieldCount<ScoreOptions>()},
      {"score.inlier.", DirectFieldCount<InlierParams>()},
      {"support.", DirectFieldCount<SupportOptions>()},
      {"render.", DirectFieldCount<RenderOptions>()},
      {"anneal.", DirectFieldCount<AnnealOptions>()},
      {"niches.", DirectFieldCount<NicheOptions>()},
      {"diffusion.", DirectFieldCount<DiffusionOptions>()},
      {"stop.", DirectFieldCount<StopOptions>()},
      {"polish.", DirectFieldCount<PolishOptions>()},
      {"heuristics.", DirectFieldCount<HeuristicOptions>()},
  };
  EXPECT_EQ(counts.at(""), 22u);
  ExpectRowsCoverStruct(FilterOptionTable(), counts, {});
  // The negative control: a table without one row fails.
  std::vector<OptionInfo> fewer(FilterOptionTable().begin(), FilterOptionTable().end());
  fewer.erase(fewer.begin() + 20);
  EXPECT_NONFATAL_FAILURE(ExpectRowsCoverStruct(fewer, counts, {}), "has no row");
}

TEST(OptionRows, EveryFieldOfTheOtherSetsHasARow) {
  ExpectRowsCoverStruct(HeuristicOptionTable(), {{"", DirectFieldCount<HeuristicOptions>()}}, {});
  ExpectRowsCoverStruct(TrackOptionTable(), {{"", DirectFieldCount<TrackOptions>()}}, {"filter", "init"});
  ExpectRowsCoverStruct(ScenePassOptionTable(), {{"", DirectFieldCount<ScenePassOptions>()}}, {});
  ExpectRowsCoverStruct(AutoPriorOptionTable(), {{"", DirectFieldCount<AutoPriorOptions>()}}, {"surfaces", "ppf"});
  // SynthOptions: every field but the camera and the target mesh (a pointer) is a row.
  EXPECT_EQ(DirectFieldCount<SynthOptions>(), 14u);
  ExpectRowsCoverStruct(SynthOptionTable(), {{"", DirectFieldCount<SynthOptions>()}}, {"camera", "target_mesh"});
  std::vector<OptionInfo> fewer(SynthOptionTable().begin(), SynthOptionTable().end());
  fewer.pop_back();
  EXPECT_NONFATAL_FAILURE(
      ExpectRowsCoverStruct(fewer, {{"", DirectFieldCount<SynthOptions>()}}, {"camera", "target_mesh"}), "has no row");
}

// The heuristic volumes' ranges and help are HeuristicOptionTable's: the filter's heuristics-*
// rows are copies, and both IsValid reject the same values.
TEST(OptionRows, HeuristicRangesAreWrittenOnce) {
  int rows = 0;
  for (const OptionInfo& h : HeuristicOptionTable()) {
    SCOPED_TRACE(h.name);
    const OptionInfo* f = FindOption(std::string("heuristics.") + h.field);
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(f->Name(OptionNaming::kCli), std::string("--heuristics-") + h.name);
    EXPECT_EQ(f->RangeText(), h.RangeText());
    EXPECT_EQ(f->lo_open, h.lo_open);
    EXPECT_EQ(f->hi_open, h.hi_open);
    for (const double v : {h.lo, h.hi, -1.0, 0.0, 0.5, 1.0, 2.0, std::nan("")}) {
      HeuristicOptions ho;
      FilterOptions fo;
      if (h.type == OptionType::kInt) {
        if (!(std::fabs(v) < 1e9)) continue;
        h.Of<int>(ho) = int(v);
        f->Of<int>(fo) = int(v);
      } else {
        h.Of<double>(ho) = v;
        f->Of<double>(fo) = v;
      }
      if (std::string(h.name) == "percentile-lo") ho.percentile_hi = fo.heuristics.percentile_hi = 1;
      if (std::string(h.name) == "percentile-hi") ho.percentile_lo = fo.heuristics.percentile_lo = 0;
      EXPECT_EQ(ho.IsValid(nullptr), fo.IsValid(nullptr)) << v;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
  HeuristicOptions h;
  h.max_samples = 0;
  std::string why;
  EXPECT_FALSE(h.IsValid(&why));
  EXPECT_EQ(why, "max_samples must be >= 1 (got 0)");
  h = {};
  h.percentile_lo = 0.95;
  EXPECT_FALSE(h.IsValid(&why));
  EXPECT_EQ(why, "percentile_lo must be <= percentile_hi");
}

// Each bound of a set's rows is what its IsValid checks, and the message names the field.
template <class Options>
void ExpectBoundsChecked(std::span<const OptionInfo> rows, const Options& valid) {
  std::string why;
  ASSERT_TRUE(valid.IsValid(&why)) << why;
  for (const OptionInfo& f : rows) {
    if (f.type != OptionType::kInt && f.type != OptionType::kDouble) continue;
    for (const bool below : {true, false}) {
      const double bound = below ? f.lo : f.hi;
      if (!std::isfinite(bound)) continue;
      const bool open = below ? f.lo_open : f.hi_open;
      const double step = f.type == OptionType::kInt ? 1 : 1e-6;
      const double outside = open ? bound : bound + (below ? -step : step);
      SCOPED_TRACE(std::string(f.name) + " = " + std::to_string(outside));
      Options o = valid;
      if (f.type == OptionType::kInt)
        f.Of<int>(o) = int(outside);
      else
        f.Of<double>(o) = outside;
      EXPECT_FALSE(o.IsValid(&why));
      EXPECT_EQ(why.rfind(f.Name(OptionNaming::kField) + " must be", 0), 0u) << why;
      EXPECT_FALSE(ValidateOptionRows(rows, o, OptionNaming::kCli, &why));
      EXPECT_EQ(why.rfind(f.Name(OptionNaming::kCli) + " must be", 0), 0u) << why;
    }
  }
}

TEST(OptionRows, TheOtherSetsCheckTheirRowsRanges) {
  ExpectBoundsChecked(TrackOptionTable(), TrackOptions{});
  ExpectBoundsChecked(ScenePassOptionTable(), ScenePassOptions{});
  AutoPriorOptions a;
  ExpectBoundsChecked(AutoPriorOptionTable(), a);
  ExpectBoundsChecked(HeuristicOptionTable(), HeuristicOptions{});
  ExpectBoundsChecked(SynthOptionTable(), SynthOptions{});
  TrackOptions t;
  t.search_r_rad = 4;
  std::string why;
  EXPECT_FALSE(t.IsValid(&why));
  EXPECT_EQ(why, "search_r_rad must be in [0, pi] (got 4)");
  a = {};
  a.min_height_m = a.max_height_m;
  EXPECT_FALSE(a.IsValid(&why));
  EXPECT_EQ(why, "min_height_m must be < max_height_m");
  SynthOptions so;
  so.min_distance_m = 1.5;  // in range, above max_distance_m
  EXPECT_FALSE(so.IsValid(&why));
  EXPECT_EQ(why, "min_distance_m must be <= max_distance_m");
  so = {};
  so.noise_sigma_m = NAN;
  EXPECT_FALSE(so.IsValid(&why));
  EXPECT_EQ(why, "noise_sigma_m must be in [0, 0.05] (got nan)");
}

TEST(OptionRows, TheOtherSetsAreNamedThreeWaysAndReadBack) {
  std::set<std::string> cli;
  for (const OptionInfo& f : FilterOptionTable()) cli.insert(f.name);
  for (const std::span<const OptionInfo> rows :
       {TrackOptionTable(), ScenePassOptionTable(), AutoPriorOptionTable(), SynthOptionTable()}) {
    for (const OptionInfo& f : rows) {
      SCOPED_TRACE(f.name);
      EXPECT_TRUE(cli.insert(f.name).second) << "a CLI flag of two options";
      EXPECT_EQ(FindOptionRow(rows, f.field), &f);
      EXPECT_EQ(FindOptionRow(rows, f.Name(OptionNaming::kPython)), &f);
      EXPECT_EQ(f.Name(OptionNaming::kPython).find('-'), std::string::npos);
      EXPECT_EQ(f.engines, 0u);
      EXPECT_GT(std::string(f.help).size(), 10u);
    }
  }
  // The Python keywords the tracker has always taken, then the confirmation's.
  std::vector<std::string> keywords;
  for (const OptionInfo& f : TrackOptionTable()) keywords.push_back(f.Name(OptionNaming::kPython));
  EXPECT_EQ(keywords, (std::vector<std::string>{"lost_weight", "refresh_weight", "search_t", "search_r",
                                                "constant_velocity", "scene_pass", "window_margin", "confirm",
                                                "confirm_margin"}));
  TrackOptions t;
  std::string why;
  const OptionInfo& margin = *FindOptionRow(TrackOptionTable(), "window-margin");
  EXPECT_EQ(margin.ValueText(t), "0.25");
  ASSERT_TRUE(margin.SetFromText(t, "0.5", &why)) << why;
  EXPECT_EQ(t.window_margin, 0.5);
  EXPECT_EQ(margin.RangeText(), "(0, 2]");
  // make_synth_scene's keywords are SynthOptions' fields, in the struct's order.
  keywords.clear();
  for (const OptionInfo& f : SynthOptionTable()) {
    EXPECT_EQ(f.Name(OptionNaming::kPython), f.field);
    keywords.push_back(f.Name(OptionNaming::kPython));
  }
  EXPECT_EQ(keywords, (std::vector<std::string>{"depth_scale", "target", "min_distance_m", "max_distance_m",
                                                "occlusion", "clutter", "noise_sigma_m", "hole_fraction",
                                                "missing_edges", "box_jitter_px", "miss_probability",
                                                "false_positives"}));
  const OptionInfo& noise = *FindOptionRow(SynthOptionTable(), "noise");
  SynthOptions so;
  EXPECT_EQ(FindOptionRow(SynthOptionTable(), "depth-scale")->ValueText(so), "0.0001");
  ASSERT_TRUE(noise.SetFromText(so, "0.002", &why)) << why;
  EXPECT_EQ(so.noise_sigma_m, 0.002);
  EXPECT_EQ(noise.RangeText(), "[0, 0.05]");
}

}  // namespace
}  // namespace posefilter
