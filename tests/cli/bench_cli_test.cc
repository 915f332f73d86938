// `posefilter bench` end to end (the built binary): bad options each give a non-zero exit and
// one line naming the option, before any measurement; a tiny real run (128 particles, 2
// iterations, 1 repeat, 1 thread) prints the table and writes a JSON with every field, and the
// engines measured agree on the fragments of the check run (the gpu engine too, on the
// machine's Vulkan device). No timing is asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "posefilter/filter.h"
#include "render/cpu_kernel.h"
#include "filter/engine_registry.h"
#include "render/gpu_kernel.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::Lines;
using testing_util::ReadFile;
using testing_util::RunResult;
using testing_util::ScratchDir;

// The bench's default set: the engine registry's rows that FilterOptions::IsValid accepts, that
// this build and machine can run and that default lists take (the gpu engine only where it
// runs on a GPU, not on a CPU Vulkan driver such as lavapipe; never rtl).
std::vector<std::string> AvailableEngines() {
  std::vector<std::string> out;
  for (const filter::EngineRow& row : filter::EngineRegistry()) {
    FilterOptions o;
    o.engine = row.name;
    if (o.IsValid(nullptr) && row.available(nullptr) && row.listed_by_default()) out.push_back(row.name);
  }
  return out;
}

struct BadOption {
  std::vector<std::string> args;
  std::vector<std::string> words;  // the message must name these
};

TEST(BenchCli, BadOptionsFailWithOneLineNamingTheOption) {
  ScratchDir dir("bench_cli");
  const std::vector<BadOption> cases = {
      {{"--particles", "127"}, {"--particles", "[128, 8192]"}},
      {{"--particles", "8193"}, {"--particles", "8193"}},
      {{"--iterations", "0"}, {"--iterations"}},
      {{"--repeats", "0"}, {"--repeats"}},
      {{"--repeats", "101"}, {"--repeats"}},
      {{"--threads", "-1"}, {"--threads"}},
      {{"--zbuffer", "maybe"}, {"--zbuffer", "maybe"}},
      {{"--lod", "3"}, {"--lod"}},
      {{"--lod", "-1"}, {"--lod"}},
      {{"--engines", "nosuch"}, {"--engines", "nosuch"}},
      {{"--engines", "cpu/avx9"}, {"--engines", "cpu/avx9", "portable"}},
      {{"--engines", "reference/portable"}, {"--engines", "reference/portable"}},
      {{"--engines", "reference,reference"}, {"--engines", "twice"}},
      {{"--target", "sphere"}, {"--target"}},
      {{"--json", dir.Path("no/such/dir/out.json")}, {"--json", "no/such/dir/out.json"}},
  };
  int n = 0;
  for (const auto& c : cases) {
    std::vector<std::string> args = {"bench"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    SCOPED_TRACE(c.args[0] + " " + c.args[1]);
    const RunResult r = testing_util::RunCli(args, dir.dir() / ("run" + std::to_string(n++)));
    EXPECT_EQ(r.code, 1) << r.err;
    const auto lines = Lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("posefilter bench: error: ", 0), 0u) << lines[0];
    for (const auto& w : c.words) EXPECT_NE(lines[0].find(w), std::string::npos) << lines[0] << "\nmissing: " << w;
    EXPECT_EQ(r.out, "") << "the workload must not run with a bad option";
  }
}

TEST(BenchCli, MalformedOptionsAreUsageErrors) {
  ScratchDir dir("bench_cli");
  int n = 0;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"bench", "--particles", "many"}, {"bench", "--bogus"}, {"bench", "--seed", "-x"}}) {
    const RunResult r = testing_util::RunCli(args, dir.dir() / ("run" + std::to_string(n++)));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find(args[1]), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
}

TEST(BenchCli, TinyRunWritesTableAndJson) {
  ScratchDir dir("bench_cli");
  const std::vector<std::string> engines = AvailableEngines();
  ASSERT_FALSE(engines.empty());
  ASSERT_EQ(engines[0], "reference");
  const std::string json_path = dir.Path("bench.json");
  const RunResult r = testing_util::RunCli({"bench", "--particles", "128", "--iterations", "2", "--repeats", "1",
                                            "--threads", "1", "--seed", "2", "--quiet", "--json", json_path},
                                           dir.dir() / "run");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // --quiet
  // One table row per engine, the baseline at 1.00x.
  for (const auto& e : engines) {
    bool row = false;
    for (const auto& l : Lines(r.out)) row = row || l.rfind(e + " ", 0) == 0;
    EXPECT_TRUE(row) << "no row for " << e << " in\n" << r.out;
  }
  EXPECT_NE(r.out.find("1.00x"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("fragments agree"), std::string::npos) << r.out;

  const nlohmann::json j = nlohmann::json::parse(ReadFile(json_path));
  const auto& w = j.at("workload");
  EXPECT_EQ(w.at("particles"), 128);
  EXPECT_EQ(w.at("iterations"), 2);
  EXPECT_EQ(w.at("repeats"), 1);
  EXPECT_EQ(w.at("threads"), 1);
  EXPECT_EQ(w.at("zbuffer"), true);
  EXPECT_EQ(w.at("anneal_subsample"), 1);  // every pixel and every particle in every iteration
  EXPECT_EQ(w.at("fine_particle_fraction"), 1.0);
  EXPECT_EQ(w.at("target"), "torus");
  // The instruction set `cpu` runs on this machine, in the JSON and on the workload line.
  const std::string isa = render::CpuTargetName(render::BestCpuTarget());
  EXPECT_EQ(w.at("cpu_isa"), isa);
  EXPECT_NE(r.out.find("cpu engine: " + isa + ";"), std::string::npos) << r.out;
  EXPECT_EQ(w.at("mesh_faces"), 2048);  // the ~2000-triangle non-convex default
  EXPECT_EQ(w.at("rendered_faces"), 2048);
  EXPECT_EQ(w.at("image_width"), 640);
  EXPECT_EQ(w.at("image_height"), 480);
  EXPECT_GE(w.at("distance_m").get<double>(), 0.6);
  EXPECT_LE(w.at("distance_m").get<double>(), 1.0);
  EXPECT_EQ(j.at("baseline"), engines[0]);
  EXPECT_EQ(j.at("engines_agree"), true);
  const auto& rows = j.at("engines");
  ASSERT_EQ(rows.size(), engines.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& e = rows[i];
    SCOPED_TRACE(engines[i]);
    EXPECT_EQ(e.at("engine"), engines[i]);
    const double ms = e.at("ms_per_iteration_median");
    EXPECT_GT(ms, 0);
    EXPECT_LE(e.at("ms_per_iteration_min").get<double>(), ms);
    EXPECT_EQ(e.at("ms_per_iteration_repeats").size(), 1u);
    // The CPU time of iteration 2 was measured (its value is not asserted: no timed tests).
    EXPECT_GT(e.at("cpu_ms_per_iteration_median").get<double>(), 0);
    EXPECT_EQ(e.at("cpu_ms_per_iteration_repeats").size(), 1u);
    // Annealing re-weighs every particle in both iterations: 2 × 128 weighings; the float
    // engines also weigh again the parents of the children that drew the ICP move (the same
    // ones in both: same random streams). The hw engine has no ICP move.
    const std::int64_t weighings = e.at("weighings");
    if (engines[i] == "hw") {
      EXPECT_EQ(weighings, 256);
    } else {
      EXPECT_GE(weighings, 256);
      EXPECT_LT(weighings, 256 + 128);
      EXPECT_EQ(weighings, rows[0].at("weighings").get<std::int64_t>());
    }
    EXPECT_GT(e.at("fragments").get<std::int64_t>(), 0);
    EXPECT_GT(e.at("check_fragments").get<std::int64_t>(), 0);
    EXPECT_LT(e.at("check_fragments").get<std::int64_t>(), e.at("fragments").get<std::int64_t>());
    if (engines[i] != "hw")  // the float engines weigh the same initial set: exactly equal
      EXPECT_EQ(e.at("check_fragments"), rows[0].at("check_fragments"));
    EXPECT_GT(e.at("particles_per_s").get<double>(), 0);
    EXPECT_GT(e.at("fragments_per_s").get<double>(), e.at("particles_per_s").get<double>());
    EXPECT_EQ(e.at("faces_per_weighing"), 2048.0);
    const double front = e.at("rendered_faces_per_weighing");
    EXPECT_GT(front, 0);
    EXPECT_LT(front, 2048);  // back faces culled
    EXPECT_TRUE(e.at("deterministic").get<bool>());
    EXPECT_GT(e.at("speedup_vs_baseline").get<double>(), 0);
    EXPECT_GE(e.at("best_weight").get<double>(), 0);
  }
  EXPECT_DOUBLE_EQ(rows[0].at("speedup_vs_baseline").get<double>(), 1.0);
}

TEST(BenchCli, CpuInstructionSetsAreEnginesOfTheirOwnAndCountTheSameFragments) {
  // cpu/<isa> forces the cpu engine's variant (FilterOptions::cpu_isa); every variant this
  // machine runs (portable always) weighs the same initial set to exactly the same fragments.
  ScratchDir dir("bench_cli");
  std::vector<std::string> engines = {"cpu"};
  for (const char* isa : {"portable", "avx2", "avx512"}) {
    FilterOptions o;
    o.cpu_isa = isa;
    if (o.IsValid(nullptr)) engines.push_back(std::string("cpu/") + isa);
  }
  ASSERT_GE(engines.size(), 2u);
  std::string list;
  for (const auto& e : engines) list += (list.empty() ? "" : ",") + e;
  const std::string json_path = dir.Path("isa.json");
  const RunResult r = testing_util::RunCli({"bench", "--engines", list, "--particles", "128", "--iterations", "1",
                                            "--repeats", "1", "--threads", "1", "--quiet", "--json", json_path},
                                           dir.dir() / "run");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_EQ(j.at("engines_agree"), true);
  const auto& rows = j.at("engines");
  ASSERT_EQ(rows.size(), engines.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].at("engine"), engines[i]);
    EXPECT_EQ(rows[i].at("check_fragments"), rows[0].at("check_fragments")) << engines[i];
    EXPECT_GT(rows[i].at("check_fragments").get<std::int64_t>(), 0);
  }
}

TEST(BenchCli, LodAndCullingOnlyModeChangeTheWorkload) {
  ScratchDir dir("bench_cli");
  const std::string json_path = dir.Path("bench.json");
  const RunResult r = testing_util::RunCli({"bench", "--engines", "reference", "--particles", "128", "--iterations",
                                            "1", "--repeats", "1", "--threads", "1", "--lod", "500", "--zbuffer",
                                            "off", "--quiet", "--json", json_path},
                                           dir.dir() / "run");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(ReadFile(json_path));
  EXPECT_EQ(j.at("workload").at("zbuffer"), false);
  EXPECT_EQ(j.at("workload").at("lod_max_faces"), 500);
  EXPECT_EQ(j.at("workload").at("mesh_faces"), 2048);
  const int rendered = j.at("workload").at("rendered_faces");
  EXPECT_LE(rendered, 500);
  EXPECT_GT(rendered, 250);
  ASSERT_EQ(j.at("engines").size(), 1u);
  EXPECT_EQ(j.at("engines")[0].at("faces_per_weighing"), double(rendered));
  EXPECT_TRUE(j.at("engines")[0].at("cpu_ms_per_iteration_median").is_null());  // 1 iteration: no CPU figure
  EXPECT_NE(r.out.find(" - "), std::string::npos) << r.out;
}

}  // namespace
}  // namespace posefilter

namespace posefilter {
namespace {

// The bench's engine list is the registry's: `--help` lists every available row, and an
// engine the build or machine cannot run is refused with the row's reason.
TEST(BenchCli, EngineListIsTheRegistrysAndAnUnavailableOneSaysWhy) {
  ScratchDir dir("bench_registry");
  const RunResult help = testing_util::RunCli({"bench", "--help"}, dir.dir() / "help");
  ASSERT_EQ(help.code, 0) << help.err;
  std::string available, defaults;
  for (const filter::EngineRow& row : filter::EngineRegistry()) {
    if (!row.available(nullptr)) continue;
    available += (available.empty() ? "" : ",") + std::string(row.name);
    if (row.listed_by_default()) defaults += (defaults.empty() ? "" : ",") + std::string(row.name);
  }
  std::string flat;  // CLI11 wraps the help text
  for (char c : help.out)
    if (c != '\n' && c != ' ') flat += c;
  EXPECT_NE(flat.find("available:" + available + ")"), std::string::npos) << help.out;
  EXPECT_NE(flat.find("(default:" + defaults + ";"), std::string::npos) << help.out;
  for (const filter::EngineRow& row : filter::EngineRegistry()) {
    std::string why;
    if (row.available(&why)) continue;
    SCOPED_TRACE(row.name);
    const RunResult r = testing_util::RunCli({"bench", "--engines", row.name, "--particles", "128", "--iterations", "1",
                                              "--repeats", "1", "--quiet"},
                                             dir.dir() / row.name);
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(Lines(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find(std::string("engine '") + row.name + "' is not available"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
  }
}

// The gpu engine in the bench beside the float engines: its check run counts the fragments
// they count, and the workload names its device. Without a device (the Vulkan loader pointed
// at no driver) or without the engine in the build, asking for it is a one-line error that
// says why, from bench and from the filter commands alike.
TEST(BenchCli, GpuEngineAgreesWithTheFloatEnginesOrSaysWhyNot) {
  ScratchDir dir("bench_gpu");
  if (render::GpuBuilt()) {
    std::string why;
    ASSERT_TRUE(render::GpuAvailable(&why)) << why;  // setup.sh installs lavapipe
    const std::string json_path = dir.Path("bench.json");
    const RunResult r = testing_util::RunCli({"bench", "--engines", "reference,cpu,gpu", "--particles", "128",
                                              "--iterations", "1", "--repeats", "1", "--quiet", "--json", json_path},
                                             dir.dir() / "run");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("fragments agree"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("gpu engine: " + render::GpuDeviceName()), std::string::npos) << r.out;
    const nlohmann::json j = nlohmann::json::parse(ReadFile(json_path));
    EXPECT_EQ(j.at("engines_agree"), true);
    EXPECT_EQ(j.at("workload").at("gpu_device"), render::GpuDeviceName());
    ASSERT_EQ(j.at("engines").size(), 3u);
    EXPECT_GT(j.at("engines")[2].at("check_fragments").get<std::int64_t>(), 10000);
  }
  // No driver: the loader finds no device (both of its variables, old and new loaders).
  const std::string no_driver = "VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json ";
  const std::string cli = testing_util::ShellQuote(POSEFILTER_CLI_PATH);
  for (const std::string& args : {std::string("bench --engines gpu --particles 128 --iterations 1 --repeats 1"),
                                  "demo --engine gpu --quiet --out " + testing_util::ShellQuote(dir.Path("demo"))}) {
    const std::string out = dir.Path("nodev.out"), err = dir.Path("nodev.err");
    const int status = std::system((no_driver + cli + " " + args + " >" + out + " 2>" + err).c_str());
    ASSERT_TRUE(WIFEXITED(status)) << args;
    EXPECT_EQ(WEXITSTATUS(status), 1) << args;
    const std::string e = ReadFile(err);
    EXPECT_EQ(Lines(e).size(), 1u) << e;
    EXPECT_NE(e.find("gpu engine"), std::string::npos) << e;
    EXPECT_NE(e.find(render::GpuBuilt() ? "no Vulkan" : "no Vulkan support"), std::string::npos) << e;
    EXPECT_NE(e.find("--engine cpu"), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace posefilter
