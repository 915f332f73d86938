// posefilter bench — the speed of the scoring engines on one fixed synthetic workload.
//
// Workload (deterministic per --seed): a 640×480 synthetic table-top scene (MakeSynthScene,
// thesis camera, clutter and false detections at their defaults) with a non-convex target at
// 0.6–1.0 m — by default the 2048-triangle torus — and its detection prior. Each engine runs
// the particle filter (EstimatePose) on it with --particles particles for exactly --iterations
// iterations: no early stop (confidence 1, which the weight of eq. 7.4 [ALGORITHM.md] does not reach with a
// prior probability < 1; no stall stop), one run (restarts 1), no final polish, every pixel
// and every particle in every iteration (anneal_subsample 1, fine_particle_fraction 1: the
// 510-particle, full-resolution weighing the engines are compared on), so every timed
// millisecond is an iteration of the filter.
//
// What is timed: EstimateResult::iteration_ms, the wall time of each iteration (weigh all
// unscored particles in parallel, sort, resample, diffuse) — what a user of the engine waits
// for, with the engine-independent steps included (they are < 1 % of an iteration with the
// reference engine). Not timed: building the context (heuristics, scene normals, LOD) and the
// initial draw. Per repeat we take the mean over its iterations; the table shows the median
// (and the minimum) over repeats. Engines run interleaved (repeat 1 of every engine, then
// repeat 2, ...), so a load change on a shared machine hits all of them alike. Before the timed
// repeats each engine makes a one-iteration check run, which also warms the caches: it weighs
// the initial particle set — the same poses for every engine, since the initial draw uses no
// weights — so every correct float engine must count the same fragments (N_raster) there
// (the hw engine draws its own particles with the thesis's LFSRs and is not compared).
// Throughput: particles/s = weighings / timed seconds, fragments/s = fragments / timed seconds,
// both summed over all repeats.
// CPU time: the process's CPU time (all threads) is read at the end of each iteration (the
// progress callback), so iterations 2..N of a run give its CPU ms per iteration (shown when
// --iterations ≥ 2). On a machine shared with other jobs, wall time grows with their load and
// CPU time much less: compare engines on the minimum and on CPU time there; CPU/wall is the
// number of cores the engine kept busy. The load average at the start is printed with it.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/filter.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/synth.h"
#include "render/cpu_kernel.h"
#include "filter/engine_registry.h"
#include "render/gpu_kernel.h"

namespace posefilter::cli {

namespace {

// The engines the bench knows of: every row of the engine registry (filter/engine_registry.h),
// in its order; the available ones are those FilterOptions::IsValid accepts and the row says
// this build and machine can run. A row not listed by default (rtl: it simulates every clock)
// runs only when asked for.
std::vector<std::string> KnownEngines() {
  std::vector<std::string> names;
  for (const filter::EngineRow& row : filter::EngineRegistry()) names.push_back(row.name);
  return names;
}

// An engine name of the bench: a FilterOptions engine, or "cpu/<isa>" — the cpu engine with
// its instruction set forced (FilterOptions::cpu_isa: avx512, avx2, portable).
// Any other name is taken whole as the engine (so "reference/avx2" is an invalid engine).
void ApplyEngine(const std::string& name, FilterOptions* o) {
  const std::string cpu = "cpu/";
  const bool forced = name.compare(0, cpu.size(), cpu) == 0;
  o->engine = forced ? "cpu" : name;
  o->cpu_isa = forced ? name.substr(cpu.size()) : "auto";
}

// The registry's row of a bench engine name (cpu/<isa>: the cpu engine's); null for none.
const filter::EngineRow* EngineRowOf(const std::string& engine) {
  FilterOptions o;
  ApplyEngine(engine, &o);
  return filter::FindEngine(o.engine);
}

// `why` (may be null): the option's error, or the row's reason (no Vulkan device, built without
// Verilator, ...).
bool EngineAvailable(const std::string& engine, std::string* why = nullptr) {
  FilterOptions o;
  ApplyEngine(engine, &o);
  if (!o.IsValid(why)) return false;
  return EngineRowOf(engine)->available(why);
}

// The gpu engine's device ("" when there is none).
std::string GpuDevice() {
  return render::GpuAvailable(nullptr) ? render::GpuDeviceName() : std::string();
}

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

// Per engine: what the repeats measured.
struct EngineRun {
  std::string engine;
  std::vector<double> ms_per_iteration;  // one per repeat: mean over its iterations
  std::vector<double> cpu_ms_per_iteration;  // one per repeat: CPU ms of iterations 2..N / (N − 1)
  double timed_ms = 0;                   // Σ iteration_ms over all repeats
  FilterStats stats;                     // summed over all repeats
  std::vector<std::int64_t> fragments_per_repeat;
  std::int64_t check_fragments = 0;      // the one-iteration check run
  double check_weight = 0;
  double best_weight = 0;                // of the last repeat
};

// CPU time of the whole process (all threads), milliseconds.
double ProcessCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

// The 1-minute load average ("" where /proc/loadavg is missing).
std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string first;
  in >> first;
  return first;
}

// The parsed command line of `bench`, and the engine lists its help and checks name.
struct BenchArgs {
  std::vector<std::string> engines;
  int particles = 510;
  int iterations = 10;
  int repeats = 5;
  int threads = 0;
  std::string zbuffer = "on";
  int lod = 0;
  std::uint64_t seed = 1;
  std::string target = "torus";
  std::string json_path;
  bool quiet = false;
  std::vector<std::string> available, cpu_isas;
  // The default list: the available rows listed by default (EngineRow::listed_by_default; the
  // gpu engine only on a GPU: on a CPU Vulkan driver, lavapipe, it is correct but hundreds of
  // times slower than the cpu engine).
  std::vector<std::string> defaults;
};

// The workload's facts the table and the JSON name.
struct BenchWorkload {
  std::string target;
  std::size_t mesh_faces = 0, rendered_faces = 0;
  double distance_m = 0;
  int width = 0, height = 0;
  unsigned hw_threads = 1;
  std::string load_average, cpu_isa, gpu_device;
};

// Every option of `bench` on `app`, into *a.
void AddBenchOptions(CLI::App& app, BenchArgs& a) {
  auto &engines = a.engines, &available = a.available, &cpu_isas = a.cpu_isas, &defaults = a.defaults;
  auto &particles = a.particles, &iterations = a.iterations, &repeats = a.repeats, &threads = a.threads, &lod = a.lod;
  auto &zbuffer = a.zbuffer, &target = a.target, &json_path = a.json_path;
  auto& seed = a.seed;
  auto& quiet = a.quiet;
  for (const auto& e : KnownEngines())
    if (EngineAvailable(e)) {
      available.push_back(e);
      if (EngineRowOf(e)->listed_by_default()) defaults.push_back(e);
    }
  for (const char* isa : {"portable", "avx2", "avx512"})
    if (EngineAvailable(std::string("cpu/") + isa)) cpu_isas.push_back(isa);
  app.add_option("--engines", engines,
                 "engines to compare, comma-separated (default: " + Join(defaults) + "; available: " +
                     Join(available) + "); cpu/avx512, cpu/avx2, cpu/portable force the cpu engine's instruction set")
      ->delimiter(',');
  app.add_option("--particles", particles, "particles N, 128..8192")->capture_default_str();
  app.add_option("--iterations", iterations, "iterations per run (no early stop), 1..1000")->capture_default_str();
  app.add_option("--repeats", repeats, "timed runs per engine; the median is reported, 1..100")->capture_default_str();
  app.add_option("--threads", threads, "worker threads: scoring, scene normals, heuristic volumes (0 = all cores)")->capture_default_str();
  app.add_option("--zbuffer", zbuffer, "on: exact z-buffer; off: the thesis's culling-only mode")->capture_default_str();
  app.add_option("--lod", lod, "render the mesh simplified to at most this many faces (0 = full mesh)")->capture_default_str();
  app.add_option("--seed", seed, "seed of the scene and of the filter")->capture_default_str()->transform(SeedValidator());
  app.add_option("--target", target, "object kind of the scene (box, cylinder, lshape, torus)")->capture_default_str();
  app.add_option("--json", json_path, "also write the results as JSON to this file");
  app.add_flag("--quiet", quiet, "no progress on stderr");
}

// Checks the parsed arguments (before the measurement) and returns the filter options of the
// workload.
FilterOptions CheckBenchArgs(BenchArgs& a) {
  auto &engines = a.engines, &defaults = a.defaults;
  const auto &available = a.available, &cpu_isas = a.cpu_isas;
  const auto &particles = a.particles, &iterations = a.iterations, &repeats = a.repeats, &threads = a.threads, &lod = a.lod;
  const auto &zbuffer = a.zbuffer, &target = a.target, &json_path = a.json_path;
  const auto& seed = a.seed;
  if (engines.empty()) engines = defaults;
  if (engines.empty()) throw Error("--engines: no engine is available");
  for (std::size_t i = 0; i < engines.size(); ++i) {
    std::string why;
    if (!EngineAvailable(engines[i], &why))
      throw Error("--engines: engine '" + engines[i] + "' is not available (available: " + Join(available) +
                  "; cpu/ with one of: " + Join(cpu_isas) + ")" +
                  (EngineRowOf(engines[i]) != nullptr && !EngineRowOf(engines[i])->available(nullptr) ? ": " + why : ""));
    if (std::find(engines.begin(), engines.begin() + i, engines[i]) != engines.begin() + i)
      throw Error("--engines: engine '" + engines[i] + "' is listed twice");
  }
  if (particles < 128 || particles > 8192)
    throw Error("--particles must be in [128, 8192] (got " + std::to_string(particles) + ")");
  if (iterations < 1 || iterations > 1000)
    throw Error("--iterations must be in [1, 1000] (got " + std::to_string(iterations) + ")");
  if (repeats < 1 || repeats > 100) throw Error("--repeats must be in [1, 100] (got " + std::to_string(repeats) + ")");
  if (zbuffer != "on" && zbuffer != "off") throw Error("--zbuffer must be 'on' or 'off' (got '" + zbuffer + "')");
  FilterOptions opt;
  opt.num_particles = particles;
  opt.stop.max_iterations = iterations;
  opt.stop.confidence = 1.0;
  opt.restarts = 1;
  opt.stop.stall_iterations = 0;
  opt.polish.steps = 0;
  opt.anneal.subsample = 1;         // every iteration weighs every pixel ...
  opt.fine_particle_fraction = 1;   // ... of --particles particles: the kernel's full-resolution cost
  opt.threads = threads;
  opt.render.zbuffer = zbuffer == "on";
  opt.render.lod_max_faces = lod;
  opt.render.lod_face_px = 0;       // the --lod mesh at every size in the image
  opt.seed = seed;
  CheckFilterOptions(opt);  // names --threads, --lod, ... as the filter commands do
  SynthOptions synth;
  synth.target = target;
  std::string why;
  if (!synth.IsValid(&why)) throw Error("--target: " + why);
  CheckOutputPaths({{json_path, "--json"}}, {});  // fail before the measurement, not after it
  return opt;
}

// The table of the runs (and --json); an Error when the float engines' check runs disagree.
void ReportBench(const BenchArgs& a, const FilterOptions& opt, const BenchWorkload& wl, const std::vector<EngineRun>& runs) {
  const auto& engines = a.engines;
  const auto &particles = a.particles, &iterations = a.iterations, &repeats = a.repeats, &threads = a.threads, &lod = a.lod;
  const auto& json_path = a.json_path;
  const auto& seed = a.seed;
  const double base_ms = Median(runs[0].ms_per_iteration);
  bool agree = true;
  // The float engines draw the same particles and must count the same fragments exactly.
  // The hw engine draws its own (the thesis's LFSRs, fixed-point samples), so its check run
  // weighs other poses: it is left out of the comparison (its agreement with the float
  // weighing of the same pose is tested in tests/hw).
  const EngineRun* first_float = nullptr;
  for (const auto& r : runs) {
    if (!EngineRowOf(r.engine)->float_filter) continue;
    if (first_float == nullptr) first_float = &r;
    agree = agree && r.check_fragments == first_float->check_fragments;
  }
  std::printf("%-12s %12s %12s %12s %12s %13s %10s %12s %9s\n", "engine", "ms/iter(med)", "ms/iter(min)",
              "cpu-ms/iter", "particles/s", "Mfragments/s", "faces/wgh", "rendered/wgh", "speedup");
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : runs) {
    const double med = Median(r.ms_per_iteration);
    const double mn = *std::min_element(r.ms_per_iteration.begin(), r.ms_per_iteration.end());
    const double secs = r.timed_ms / 1000;
    const double w = double(std::max<std::int64_t>(1, r.stats.weighings));
    const double pps = secs > 0 ? double(r.stats.weighings) / secs : 0;
    const double fps = secs > 0 ? double(r.stats.fragments) / secs : 0;
    const double speedup = med > 0 ? base_ms / med : 0;
    const bool deterministic = std::all_of(r.fragments_per_repeat.begin(), r.fragments_per_repeat.end(),
                                           [&](std::int64_t f) { return f == r.fragments_per_repeat[0]; });
    const double cpu_med = r.cpu_ms_per_iteration.empty() ? 0.0 : Median(r.cpu_ms_per_iteration);
    char cpu_text[32] = "-";
    if (!r.cpu_ms_per_iteration.empty()) std::snprintf(cpu_text, sizeof cpu_text, "%.2f", cpu_med);
    std::printf("%-12s %12.2f %12.2f %12s %12.0f %13.2f %10.0f %12.1f %8.2fx\n", r.engine.c_str(), med, mn, cpu_text,
                pps, fps / 1e6, double(r.stats.faces_total) / w, double(r.stats.faces_front) / w, speedup);
    rows.push_back({{"engine", r.engine},
                    {"ms_per_iteration_median", med},
                    {"ms_per_iteration_min", mn},
                    {"ms_per_iteration_repeats", r.ms_per_iteration},
                    {"cpu_ms_per_iteration_median", r.cpu_ms_per_iteration.empty() ? nlohmann::json() : nlohmann::json(cpu_med)},
                    {"cpu_ms_per_iteration_repeats", r.cpu_ms_per_iteration},
                    {"particles_per_s", pps},
                    {"fragments_per_s", fps},
                    {"weighings", r.stats.weighings},
                    {"fragments", r.stats.fragments},
                    {"faces_per_weighing", double(r.stats.faces_total) / w},
                    {"rendered_faces_per_weighing", double(r.stats.faces_front) / w},
                    {"speedup_vs_baseline", speedup},
                    {"deterministic", deterministic},
                    {"best_weight", r.best_weight},
                    {"check_fragments", r.check_fragments},
                    {"check_weight", r.check_weight}});
  }
  std::printf("speedup = median ms/iteration of %s / that of the engine, same run. check run (initial set, same "
              "poses for all float engines; hw draws its own): fragments %s\n",
              engines[0].c_str(), agree ? "agree" : "DIFFER");
  if (!json_path.empty()) {
    const nlohmann::json doc = {
        {"workload",
         {{"target", wl.target},
          {"mesh_faces", wl.mesh_faces},
          {"rendered_faces", wl.rendered_faces},
          {"lod_max_faces", lod},
          {"distance_m", wl.distance_m},
          {"image_width", wl.width},
          {"image_height", wl.height},
          {"particles", particles},
          {"iterations", iterations},
          {"repeats", repeats},
          {"threads", threads},
          {"hardware_threads", wl.hw_threads},
          {"cpu_isa", wl.cpu_isa},
          {"gpu_device", wl.gpu_device},
          {"load_average", wl.load_average},
          {"zbuffer", opt.render.zbuffer},
          {"seed", seed},
          {"anneal_subsample", opt.anneal.subsample},
          {"fine_particle_fraction", opt.fine_particle_fraction},
          {"timing", "median over repeats of the mean EstimateResult::iteration_ms (no early stop, 1 restart, "
                     "no polish, every pixel and particle in each iteration); engines interleaved"}}},
        {"baseline", engines[0]},
        {"engines", rows},
        {"engines_agree", agree}};
    WriteFileAtomically(json_path, [&](std::ostream& out) { out << doc.dump(1) << "\n"; });
  }
  if (!agree) throw Error("engines disagree on the fragments of the check run (see the table)");
}

// Builds the workload, prints its line, and times every engine (a check run each, then the
// repeats, engines interleaved); then the report.
void MeasureBench(const BenchArgs& a, const FilterOptions& opt) {
  const auto& engines = a.engines;
  const auto &particles = a.particles, &iterations = a.iterations, &repeats = a.repeats, &threads = a.threads, &lod = a.lod;
  const auto& zbuffer = a.zbuffer;
  const auto& seed = a.seed;
  const auto& quiet = a.quiet;
  SynthOptions synth;
  synth.target = a.target;
  const SynthScene scene = MakeSynthScene(synth, seed);
  const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
  const SceneInput input{scene.depth, scene.camera};
  const int cls = prior.ClassIndex(scene.target.name);
  Mesh lod_storage;
  const Mesh& rendered = MeshAtLod(scene.target, lod, &lod_storage);
  const unsigned hw_threads = std::max(1u, std::thread::hardware_concurrency());
  const std::string load_average = LoadAverage().empty() ? "n/a" : LoadAverage();
  // The variant the `cpu` engine runs here: tables of different machines say which they measured.
  const std::string cpu_isa = render::CpuTargetName(render::BestCpuTarget());
  const bool uses_gpu = std::find(engines.begin(), engines.end(), "gpu") != engines.end();
  const std::string gpu_device = uses_gpu ? GpuDevice() : "";
  std::printf("workload: %s, %zu faces (rendered: %zu%s), at %.2f m in a %dx%d scene (seed %llu); %d particles, "
              "%d iterations x %d repeats, every pixel and particle in each; threads %d%s; z-buffer %s; "
              "cpu engine: %s;%s load average %s\n",
              scene.target.name.c_str(), scene.target.faces.size(), rendered.faces.size(),
              lod > 0 ? (" with --lod " + std::to_string(lod)).c_str() : "", scene.distance_m, scene.camera.width,
              scene.camera.height, (unsigned long long)seed, particles, iterations, repeats, threads,
              threads == 0 ? (" (all " + std::to_string(hw_threads) + " cores)").c_str() : "", zbuffer.c_str(),
              cpu_isa.c_str(), uses_gpu ? (" gpu engine: " + gpu_device + ";").c_str() : "", load_average.c_str());
  std::fflush(stdout);

  std::vector<EngineRun> runs(engines.size());
  std::vector<double> cpu_stamps;  // process CPU ms at the end of each iteration of the last run
  auto run_once = [&](const std::string& engine, int its) {
    FilterOptions o = opt;
    ApplyEngine(engine, &o);
    o.stop.max_iterations = its;
    cpu_stamps.clear();
    const EstimateResult r =
        EstimatePose(input, scene.target, prior, cls, o, [&](int, double) { cpu_stamps.push_back(ProcessCpuMs()); });
    if (r.iterations != its || int(r.iteration_ms.size()) != its)
      throw Error("engine '" + engine + "' stopped after " + std::to_string(r.iterations) + " of " +
                  std::to_string(its) + " iterations");
    return r;
  };
  for (std::size_t e = 0; e < engines.size(); ++e) {  // check runs (and warm-up)
    runs[e].engine = engines[e];
    const EstimateResult r = run_once(engines[e], 1);
    runs[e].check_fragments = r.stats.fragments;
    runs[e].check_weight = r.weight;
  }
  for (int rep = 0; rep < repeats; ++rep) {
    for (std::size_t e = 0; e < engines.size(); ++e) {
      const EstimateResult r = run_once(engines[e], iterations);
      const double ms = std::accumulate(r.iteration_ms.begin(), r.iteration_ms.end(), 0.0);
      runs[e].ms_per_iteration.push_back(ms / iterations);
      if (iterations >= 2 && int(cpu_stamps.size()) == iterations)
        runs[e].cpu_ms_per_iteration.push_back((cpu_stamps.back() - cpu_stamps.front()) / (iterations - 1));
      runs[e].timed_ms += ms;
      runs[e].stats += r.stats;
      runs[e].fragments_per_repeat.push_back(r.stats.fragments);
      runs[e].best_weight = r.weight;
      if (!quiet)
        std::fprintf(stderr, "repeat %d/%d %-12s %9.2f ms/iteration\n", rep + 1, repeats, engines[e].c_str(),
                     ms / iterations);
    }
  }
  BenchWorkload wl{scene.target.name, scene.target.faces.size(), rendered.faces.size(), scene.distance_m,
                   scene.camera.width, scene.camera.height, hw_threads, load_average, cpu_isa, gpu_device};
  ReportBench(a, opt, wl, runs);
}

}  // namespace

int RunBench(int argc, char** argv) {
  CLI::App app{"Speed of the scoring engines on a fixed synthetic workload (ms per iteration, throughput)", "bench"};
  BenchArgs a;
  AddBenchOptions(app, a);
  return RunApp(app, argc, argv, [&] {
    const FilterOptions opt = CheckBenchArgs(a);
    MeasureBench(a, opt);
  });
}

}  // namespace posefilter::cli
