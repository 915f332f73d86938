// The option table (posefilter/option_table.h): every row's range is what IsValid checks, names
// are unique and spelt three ways, ignored options are reported (docs/OPTIONS.md, its output with
// the other sets', is checked in tests/cli/option_flags_test.cc).
#include "posefilter/option_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <span>
#include <stdexcept>
#include <string>

#include "posefilter/filter.h"
#include "posefilter/tracker.h"

namespace posefilter {
namespace {

TEST(OptionTable, NamesAreUniqueAndSpeltThreeWays) {
  std::set<std::string> names, fields;
  for (const OptionInfo& f : FilterOptionTable()) {
    SCOPED_TRACE(f.name);
    EXPECT_TRUE(names.insert(f.name).second);
    EXPECT_TRUE(fields.insert(f.field).second);
    EXPECT_EQ(f.Name(OptionNaming::kCli), std::string("--") + f.name);
    EXPECT_EQ(f.Name(OptionNaming::kField), f.field);
    EXPECT_EQ(f.Name(OptionNaming::kPython).find('-'), std::string::npos);
    EXPECT_EQ(FindOption(f.name), &f);
    EXPECT_EQ(FindOption(f.field), &f);
    EXPECT_EQ(FindOption(f.Name(OptionNaming::kPython)), &f);
    EXPECT_NE(f.engines, 0u);
    EXPECT_GT(std::string(f.help).size(), 10u);
  }
  EXPECT_EQ(FindOption("no-such-option"), nullptr);
  EXPECT_EQ(FindOption("anneal.subsample")->Name(OptionNaming::kPython), "anneal_subsample");
  EXPECT_EQ(FindOption("num_particles")->Name(OptionNaming::kCli), "--particles");
}

// The value just outside a bound, and whether the bound is finite.
double Outside(double bound, bool open, bool below) {
  if (open) return bound;
  return below ? std::nextafter(bound, -std::numeric_limits<double>::infinity()) - (std::floor(bound) == bound ? 1 : 0)
               : std::nextafter(bound, std::numeric_limits<double>::infinity()) + (std::floor(bound) == bound ? 1 : 0);
}

// Sets a numeric field (of any numeric type) to v.
void SetNumber(const OptionInfo& f, FilterOptions& o, double v) {
  switch (f.type) {
    case OptionType::kInt: f.Of<int>(o) = static_cast<int>(v); break;
    case OptionType::kFloat: f.Of<float>(o) = static_cast<float>(v); break;
    case OptionType::kDouble: f.Of<double>(o) = v; break;
    case OptionType::kDoubles: f.Of<std::array<double, kNumMoves>>(o)[3] = v; break;
    default: FAIL() << f.name << " is not a number";
  }
}

TEST(OptionTable, EveryBoundIsCheckedAndNamed) {
  ASSERT_TRUE(FilterOptions{}.IsValid(nullptr));
  int checked = 0;
  for (const OptionInfo& f : FilterOptionTable()) {
    if (f.type == OptionType::kBool || f.type == OptionType::kString || f.type == OptionType::kUint64) continue;
    for (const bool below : {true, false}) {
      const double bound = below ? f.lo : f.hi;
      if (!std::isfinite(bound)) continue;
      SCOPED_TRACE(std::string(f.name) + (below ? " below " : " above ") + std::to_string(bound));
      FilterOptions o;
      SetNumber(f, o, Outside(bound, below ? f.lo_open : f.hi_open, below));
      for (const OptionNaming naming : {OptionNaming::kField, OptionNaming::kCli, OptionNaming::kPython}) {
        std::string why;
        EXPECT_FALSE(ValidateFilterOptions(o, naming, &why));
        EXPECT_EQ(why.rfind(f.Name(naming) + " must", 0), 0u) << why;
      }
      ++checked;
    }
    if (f.type == OptionType::kDouble) {
      FilterOptions o;
      SetNumber(f, o, std::nan(""));
      std::string why;
      EXPECT_FALSE(o.IsValid(&why)) << f.name;
    }
  }
  EXPECT_GT(checked, 60);
  std::string why;
  FilterOptions o;
  o.anneal.subsample = 7;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "anneal.subsample must be in [1, 4] (got 7)");
  o = {};
  o.engine = "vulkan";
  EXPECT_FALSE(ValidateFilterOptions(o, OptionNaming::kPython, &why));
  EXPECT_EQ(why, "engine must be one of cpu|reference|hw|gpu|rtl (got 'vulkan')");
}

TEST(OptionTable, ConstraintsBetweenOptionsAreNamed) {
  std::string why;
  FilterOptions o;
  o.num_elite = o.num_particles;
  EXPECT_FALSE(ValidateFilterOptions(o, OptionNaming::kCli, &why));
  EXPECT_EQ(why, "--elite must be < --particles (got 510 >= 510)");
  o = {};
  o.score.alpha = 0.5;
  EXPECT_FALSE(ValidateFilterOptions(o, OptionNaming::kPython, &why));
  EXPECT_EQ(why, "alpha + beta + gamma must equal 1");
  o = {};
  o.diffusion.move_probabilities.fill(0);
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "diffusion.move_probabilities: at least one must be > 0");
  o = {};
  o.render.lod_max_faces = 3;
  EXPECT_FALSE(o.IsValid(&why));
  o.render.lod_max_faces = 0;
  EXPECT_TRUE(o.IsValid(&why)) << why;
}

TEST(OptionTable, OptionsTheEngineIgnoresAreReported) {
  FilterOptions o;
  for (const char* e : {"reference", "cpu", "hw", "gpu"}) {
    o.engine = e;
    EXPECT_TRUE(IgnoredOptions(o, OptionNaming::kCli).empty()) << e;  // defaults: nothing to say
  }
  o.engine = "hw";
  o.anneal.subsample = 2;
  o.record_particles = true;
  o.cpu_isa = "portable";  // every engine's polish reads it
  o.num_particles = 300;   // read by every engine
  const std::vector<std::string> hw = IgnoredOptions(o, OptionNaming::kCli);
  ASSERT_EQ(hw.size(), 2u);
  EXPECT_EQ(hw[0], "--record-particles is ignored by the hw engine");
  EXPECT_EQ(hw[1], "--anneal-subsample is ignored by the hw engine");
  EXPECT_EQ(IgnoredOptions(o, OptionNaming::kPython)[1], "anneal_subsample is ignored by the hw engine");
  for (const char* e : {"reference", "cpu"}) {
    o.engine = e;
    EXPECT_TRUE(IgnoredOptions(o, OptionNaming::kPython).empty()) << e;
  }
}

TEST(OptionTable, ValueTextReadsBack) {
  const FilterOptions d;
  EXPECT_EQ(FindOption("anneal")->ValueText(d), "0.02");
  EXPECT_EQ(FindOption("inlier-thr")->ValueText(d), "0.00390625");
  EXPECT_EQ(FindOption("hard-inlier-thr")->ValueText(d), "0.005");  // a float, printed as one
  EXPECT_EQ(FindOption("particles")->RangeText(), "[2, 1000000]");
  EXPECT_EQ(FindOption("pool")->RangeText(), "(0, 1]");
  EXPECT_EQ(FindOption("near")->RangeText(), "> 0");
  EXPECT_EQ(FindOption("cpu-isa")->EnginesText(), "all");
  EXPECT_EQ(FindOption("seed-start")->EnginesText(), "reference, cpu, gpu");
  EXPECT_EQ(FindOption("anneal-subsample")->EnginesText(), "reference, cpu, gpu");
}

// The thesis column: ThesisFilterOptions is the thesis's configuration that hw-report used to
// write by hand (each extension of ours off), at the caller's scale.
TEST(OptionTable, ThesisColumnIsTheThesisConfiguration) {
  FilterOptions scale;  // a caller's scale and thresholds, away from the defaults
  scale.num_particles = 100;
  scale.stop.max_iterations = 50;
  scale.render.max_window_px = 120;
  scale.render.min_window_diameters = 4;
  scale.score.inlier.thr1_m = 0.005;
  scale.seed = 7;
  FilterOptions expected = scale;
  expected.render.zbuffer = false;
  expected.render.adaptive_resolution = false;
  expected.render.grow_window = false;
  expected.score.occlusion_aware = false;
  expected.score.delta = 0;
  expected.support.plane = false;
  expected.support.contact = 0;
  expected.support.stable_start = 0;
  expected.anneal.start_m = 0;
  expected.anneal.subsample = 1;
  expected.anneal.simplify = false;
  expected.niches.region_cap = 1;
  expected.niches.rotation_cap = 1;
  expected.diffusion.min_sigma_fraction = 0;
  for (int m = 0; m < kNumMoves; ++m) expected.diffusion.move_probabilities[m] = m < int(Move::kAlignDepth) ? 1.0 : 0.0;
  expected.polish.steps = 0;
  expected.init_oversample = 1;
  expected.seed_start = 0;
  expected.fine_particle_fraction = 1;
  expected.stop.stall_iterations = 0;
  expected.stop.restart_agree_m = 0;
  const FilterOptions thesis = ThesisFilterOptions(scale);
  std::string why;
  EXPECT_TRUE(thesis.IsValid(&why)) << why;
  for (const OptionInfo& f : FilterOptionTable())
    EXPECT_TRUE(f.SameValue(thesis, expected)) << f.name << ": " << f.ValueText(thesis) << " vs " << f.ValueText(expected);
  int set = 0, kept = 0;
  for (const OptionInfo& f : FilterOptionTable()) {
    if (f.thesis == nullptr) {
      EXPECT_FALSE(f.thesis_kept) << f.name;
      continue;
    }
    SCOPED_TRACE(f.name);
    // The value reads back as the field's type, is in range, and is what the column says.
    FilterOptions o;
    ASSERT_TRUE(f.SetFromText(o, f.thesis, &why)) << why;
    EXPECT_EQ(f.ValueText(o), f.thesis);
    EXPECT_TRUE(ValidateOptionRows(std::span<const OptionInfo>(&f, 1), o, OptionNaming::kField, &why)) << why;
    if (f.thesis_kept) {
      EXPECT_TRUE(f.SameValue(thesis, scale));  // a thesis configuration keeps the caller's value
      ++kept;
    } else {
      EXPECT_EQ(f.ValueText(thesis), f.thesis);
      ++set;
    }
  }
  EXPECT_EQ(set, 21);
  EXPECT_GE(kept, 9);
  // The thesis's figures the column states and keeps: N = 510, 32 tracker entries, 200 px windows.
  EXPECT_STREQ(FindOption("particles")->thesis, "510");
  EXPECT_STREQ(FindOption("tracker-bins")->thesis, "32");
  EXPECT_STREQ(FindOption("window")->thesis, "200");
  EXPECT_STREQ(FindOption("inlier-thr")->thesis, "0.00390625");
}

TEST(OptionTable, SetFromTextRejectsWhatDoesNotRead) {
  FilterOptions o;
  std::string why;
  EXPECT_FALSE(FindOption("particles")->SetFromText(o, "5x", &why));
  EXPECT_EQ(why, "num_particles: '5x' does not read as its value");
  EXPECT_FALSE(FindOption("zbuffer")->SetFromText(o, "yes", &why));
  EXPECT_FALSE(FindOption("move-probabilities")->SetFromText(o, "1,2", &why));
  EXPECT_TRUE(FindOption("alpha")->SetFromText(o, "0.25", &why));
  EXPECT_EQ(o.score.alpha, 0.25);
  EXPECT_TRUE(FindOption("hard-inlier-thr")->SetFromText(o, "0.004", &why));
  EXPECT_EQ(o.score.inlier.hard_thr_m, 0.004f);
  // A row used on another struct is a programming error, caught.
  TrackOptions t;
  EXPECT_THROW(FindOption("particles")->ValueText(t), std::logic_error);
}

}  // namespace
}  // namespace posefilter
