// The engine registry (src/filter/engine_registry.h) is the one list of engine names: what
// FilterOptions::engine (--engine) accepts, the option table's choices and engine bits, and
// each unavailable engine says why.
#include "filter/engine_registry.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/option_table.h"

namespace posefilter {
namespace {

std::vector<std::string> RegistryNames() {
  std::vector<std::string> names;
  for (const filter::EngineRow& row : filter::EngineRegistry()) names.push_back(row.name);
  return names;
}

TEST(EngineRegistry, NamesAreWhatTheEngineOptionAccepts) {
  const std::vector<std::string> names = RegistryNames();
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names.front(), "reference");  // the bench's baseline
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size()) << "a name twice";
  for (const filter::EngineRow& row : filter::EngineRegistry()) {
    SCOPED_TRACE(row.name);
    EXPECT_EQ(filter::FindEngine(row.name), &row);
    FilterOptions o;
    o.engine = row.name;
    std::string why;
    EXPECT_TRUE(o.IsValid(&why)) << why;  // whatever the build has: availability is the engine's own error
    EXPECT_NE(row.bit, 0u);
    EXPECT_EQ(EngineBit(row.name), row.bit);
    EXPECT_NE(row.make_runs, nullptr);
    EXPECT_NE(row.make_weigher, nullptr);
    EXPECT_NE(row.available, nullptr);
    EXPECT_NE(row.listed_by_default, nullptr);
    EXPECT_GT(std::string(row.summary).size(), 5u);
  }
  EXPECT_EQ(filter::FindEngine("nosuch"), nullptr);
  EXPECT_EQ(EngineBit("nosuch"), 0u);
  FilterOptions bad;
  bad.engine = "nosuch";
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find(filter::EngineChoices("|")), std::string::npos) << why;
}

TEST(EngineRegistry, OptionTableChoicesAndBitsComeFromIt) {
  const OptionInfo* engine = FindOption("engine");
  ASSERT_NE(engine, nullptr);
  const std::vector<std::string> choices = engine->Choices();
  const std::vector<std::string> names = RegistryNames();
  EXPECT_EQ(std::set<std::string>(choices.begin(), choices.end()), std::set<std::string>(names.begin(), names.end()));
  EXPECT_EQ(choices.front(), FilterOptions{}.engine);  // the default first
  EXPECT_EQ(&filter::DefaultEngine(), filter::FindEngine(FilterOptions{}.engine));
  // Every bit of every option row is some engine's; "all" is every engine's bit.
  unsigned all = 0;
  for (const filter::EngineRow& row : filter::EngineRegistry()) all |= row.bit;
  EXPECT_EQ(all, unsigned(kAllEngines));
  for (const OptionInfo& f : FilterOptionTable()) {
    SCOPED_TRACE(f.name);
    EXPECT_EQ(f.engines & ~all, 0u);
    if (f.engines == kAllEngines) continue;
    // EnginesText names registry rows only, each bit once (rtl reads the hw engine's options).
    std::string text = f.EnginesText();
    for (std::size_t start = 0; start <= text.size();) {
      const std::size_t comma = text.find(", ", start);
      const std::string name = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      const filter::EngineRow* row = filter::FindEngine(name);
      ASSERT_NE(row, nullptr) << name;
      EXPECT_NE(f.engines & row->bit, 0u) << name;
      if (comma == std::string::npos) break;
      start = comma + 2;
    }
  }
  EXPECT_EQ(EngineBit("rtl"), EngineBit("hw"));
}

// Every engine this build or machine cannot run says why (built without Vulkan or Verilator,
// no Vulkan device); the ones that always run (reference, cpu) are available, and so is hw in
// every build that has its C model (a build without it, POSEFILTER_HW=OFF, says so).
TEST(EngineRegistry, AnUnavailableEngineGivesItsReason) {
  for (const char* always : {"reference", "cpu"}) {
    std::string why;
    EXPECT_TRUE(filter::FindEngine(always)->available(&why)) << always << ": " << why;
  }
  if (std::string why; !filter::FindEngine("hw")->available(&why))
    EXPECT_NE(why.find("this build has no FPGA C model"), std::string::npos) << why;
  int unavailable = 0;
  for (const filter::EngineRow& row : filter::EngineRegistry()) {
    std::string why;
    if (row.available(&why)) continue;
    ++unavailable;
    EXPECT_GT(why.size(), 10u) << row.name << " is unavailable without a reason";
    EXPECT_FALSE(row.available(nullptr)) << row.name;  // the reason is optional to ask for
    EXPECT_FALSE(row.listed_by_default()) << row.name;
  }
  if (unavailable == 0) GTEST_SKIP() << "every engine runs in this build and on this machine";
}

}  // namespace
}  // namespace posefilter
