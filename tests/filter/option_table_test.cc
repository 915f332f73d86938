// The option table (posefilter/option_table.h): every row's range is what IsValid checks, names
// are unique and spelt three ways, ignored options are reported, docs/OPTIONS.md is its output.
#include "posefilter/option_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include "posefilter/filter.h"

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
    case OptionType::kMoveProbabilities: f.Of<std::array<double, kNumMoves>>(o)[3] = v; break;
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
  o.cpu_isa = "portable";
  o.num_particles = 300;  // read by every engine
  const std::vector<std::string> hw = IgnoredOptions(o, OptionNaming::kCli);
  ASSERT_EQ(hw.size(), 2u);
  EXPECT_EQ(hw[0], "--cpu-isa is ignored by the hw engine");
  EXPECT_EQ(hw[1], "--anneal-subsample is ignored by the hw engine");
  o.engine = "reference";
  EXPECT_EQ(IgnoredOptions(o, OptionNaming::kPython), std::vector<std::string>{"cpu_isa is ignored by the reference engine"});
  o.engine = "cpu";
  EXPECT_TRUE(IgnoredOptions(o, OptionNaming::kPython).empty());
}

TEST(OptionTable, ValueTextReadsBack) {
  const FilterOptions d;
  EXPECT_EQ(FindOption("anneal")->ValueText(d), "0.02");
  EXPECT_EQ(FindOption("inlier-thr")->ValueText(d), "0.00390625");
  EXPECT_EQ(FindOption("hard-inlier-thr")->ValueText(d), "0.005");  // a float, printed as one
  EXPECT_EQ(FindOption("particles")->RangeText(), "[2, 1000000]");
  EXPECT_EQ(FindOption("pool")->RangeText(), "(0, 1]");
  EXPECT_EQ(FindOption("near")->RangeText(), "> 0");
  EXPECT_EQ(FindOption("cpu-isa")->EnginesText(), "cpu, gpu");
  EXPECT_EQ(FindOption("anneal-subsample")->EnginesText(), "reference, cpu, gpu");
}

TEST(OptionTable, DocsOptionsMdIsTheTable) {
  std::ifstream in(std::string(POSEFILTER_SOURCE_DIR) + "/docs/OPTIONS.md");
  ASSERT_TRUE(in) << "docs/OPTIONS.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), OptionTableMarkdown()) << "regenerate: posefilter options --markdown > docs/OPTIONS.md";
}

}  // namespace
}  // namespace posefilter
