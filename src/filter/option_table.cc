// src/filter/option_table.cc — the table of every FilterOptions field (posefilter/option_table.h)
// and what is derived from it: names, value text, ranges, ignored-option checks, Markdown.
#include "posefilter/option_table.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include "core/threads.h"
#include "filter/engine_registry.h"
#include "posefilter/error.h"
#include "posefilter/hw_engine.h"
#include "posefilter/mesh_simplify.h"
#include "render/cpu_kernel.h"

namespace posefilter {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The engines that run the float filter (engine_registry.h), not modelled by the hw engine.
unsigned FloatEngineBits() {
  unsigned bits = 0;
  for (const filter::EngineRow& row : filter::EngineRegistry())
    if (row.float_filter) bits |= row.bit;
  return bits;
}

// The engine option's choices: every engine of the registry, the default first.
const char* EngineChoiceText() {
  static const std::string choices = filter::EngineChoices("|");
  return choices.c_str();
}

struct Range {
  double lo, hi;
  bool lo_open, hi_open;
};
constexpr Range Closed(double lo, double hi) { return {lo, hi, false, false}; }
constexpr Range AtLeast(double lo) { return {lo, kInf, false, false}; }
constexpr Range kPositive = {0, kInf, true, false};
constexpr Range kFraction = Closed(0, 1);                 // [0, 1]
constexpr Range kPositiveFraction = {0, 1, true, false};  // (0, 1]
constexpr Range kAny = {-kInf, kInf, false, false};

template <class T>
constexpr OptionType TypeCode() {
  if constexpr (std::is_same_v<T, bool>) return OptionType::kBool;
  else if constexpr (std::is_same_v<T, int>) return OptionType::kInt;
  else if constexpr (std::is_same_v<T, float>) return OptionType::kFloat;
  else if constexpr (std::is_same_v<T, double>) return OptionType::kDouble;
  else if constexpr (std::is_same_v<T, std::string>) return OptionType::kString;
  else if constexpr (std::is_same_v<T, std::uint64_t>) return OptionType::kUint64;
  else {
    static_assert(std::is_same_v<T, std::array<double, kNumMoves>>, "a FilterOptions field of an unknown type");
    return OptionType::kMoveProbabilities;
  }
}

// The field path, its accessor and its type, from one spelling of the path.
#define POSEFILTER_FIELD(path)                                 \
  #path, [](FilterOptions& o) -> void* { return &o.path; }, \
      TypeCode<std::remove_cvref_t<decltype(std::declval<FilterOptions&>().path)>>()

OptionInfo Row(const char* name, const char* field, void* (*ref)(FilterOptions&), OptionType type, const char* group,
               Range range, unsigned engines, const char* help, const char* choices = nullptr) {
  return OptionInfo{name, field, group, help, type, range.lo, range.hi, range.lo_open, range.hi_open, choices, engines, ref};
}

const std::vector<OptionInfo>& Table() {
  static const unsigned kFloatEngines = FloatEngineBits();
  static const std::vector<OptionInfo> t = {
      // ---- engine and run
      Row("engine", POSEFILTER_FIELD(engine), "Engine", kAny, kAllEngines, "engine that weighs the particles",
          EngineChoiceText()),
      Row("cpu-isa", POSEFILTER_FIELD(cpu_isa), "Engine", kAny, kEngineCpu | kEngineGpu,
          "cpu kernel's instruction set (the cpu engine; the gpu engine's ICP weighings): auto (the best this CPU "
          "runs), avx512, avx2 or portable (same results)",
          "auto|avx512|avx2|portable"),
      Row("threads", POSEFILTER_FIELD(threads), "Engine", AtLeast(0), kAllEngines,
          "worker threads: scoring, scene normals, heuristic volumes (0 = all cores, at most 4 per hardware thread)"),
      Row("seed", POSEFILTER_FIELD(seed), "Engine", kAny, kAllEngines,
          "random seed (same seed, same poses), an integer in [0, 2^64 - 1]"),
      Row("restarts", POSEFILTER_FIELD(restarts), "Engine", Closed(1, 100), kAllEngines,
          "independent runs, the best weight wins (time x restarts)"),
      Row("record-particles", POSEFILTER_FIELD(record_particles), "Engine", kAny, kFloatEngines,
          "record each iteration's particle set (poses, weights) for the viewer; changes no pose"),
      // ---- particles and resampling
      Row("particles", POSEFILTER_FIELD(num_particles), "Particles", Closed(2, 1'000'000), kAllEngines,
          "number of particles N (the hw engine: at most 510)"),
      Row("elite", POSEFILTER_FIELD(num_elite), "Particles", Closed(0, 1'000'000), kAllEngines,
          "best particles carried unchanged into the next set (< --particles)"),
      Row("pool", POSEFILTER_FIELD(resample_pool), "Particles", kPositiveFraction, kAllEngines,
          "fraction of the sorted set the rest is resampled from"),
      Row("fine-fraction", POSEFILTER_FIELD(fine_particle_fraction), "Particles", kPositiveFraction, kFloatEngines,
          "after annealing, each set has this fraction of --particles (1 = all of them)"),
      Row("init-oversample", POSEFILTER_FIELD(init_oversample), "Particles", Closed(1, 64), kFloatEngines,
          "draw this many x N initial particles, weigh them all and keep the best N"),
      Row("seed-start", POSEFILTER_FIELD(seed_start), "Particles", kFraction, kFloatEngines,
          "fraction of the initial particles started at the scene's pose seeds (the --prior auto proposals) where "
          "it has any"),
      Row("tracker-bins", POSEFILTER_FIELD(tracker_bins), "Particles", Closed(1, 4096), kFloatEngines,
          "threshold-tracker entries of the CDF samplers (thesis 7.4; the hw engine has 32)"),
      // ---- weight, eq. 7.4 [ALGORITHM.md]
      Row("alpha", POSEFILTER_FIELD(score.alpha), "Weight", kFraction, kAllEngines,
          "weight of I/N_raster (eq. 7.4); alpha + beta + gamma = 1"),
      Row("beta", POSEFILTER_FIELD(score.beta), "Weight", kFraction, kAllEngines, "weight of I/N_depth (eq. 7.4)"),
      Row("gamma", POSEFILTER_FIELD(score.gamma), "Weight", kFraction, kAllEngines,
          "weight of the stage-1 probability (eq. 7.4)"),
      Row("delta", POSEFILTER_FIELD(score.delta), "Weight", kFraction, kAllEngines,
          "silhouette edge penalty: weight lost where the scene surface continues across the outline (0 = off)"),
      Row("edge-band", POSEFILTER_FIELD(score.edge_band_m), "Weight", kPositive, kAllEngines,
          "edge penalty: depth step across the outline below which the surface continues (m)"),
      Row("inlier-thr", POSEFILTER_FIELD(score.inlier.thr1_m), "Weight", kPositive, kAllEngines,
          "soft inlier: chi = 1 up to this, 0 from twice it (m)"),
      Row("hard-inlier", POSEFILTER_FIELD(score.inlier.hard), "Weight", kAny, kAllEngines,
          "hard inlier (chi = 1 iff d <= --hard-inlier-thr) instead of the soft ramp"),
      Row("hard-inlier-thr", POSEFILTER_FIELD(score.inlier.hard_thr_m), "Weight", kPositive, kAllEngines,
          "hard inlier threshold (m)"),
      Row("occlusion-aware", POSEFILTER_FIELD(score.occlusion_aware), "Weight", kAny, kAllEngines,
          "leave rendered pixels hidden behind nearer scene depth out of N_raster (off: the thesis)"),
      // ---- support plane
      Row("support-plane", POSEFILTER_FIELD(support.plane), "Support plane", kAny, kAllEngines,
          "leave the dominant plane's (the table's) pixels out of the scored depth (off: every pixel, the thesis)"),
      Row("contact", POSEFILTER_FIELD(support.contact), "Support plane", kFraction, kAllEngines,
          "contact prior: weight lost by a pose floating above or sunk into the support plane (0 = off)"),
      Row("contact-tolerance", POSEFILTER_FIELD(support.contact_tolerance_m), "Support plane", AtLeast(0), kAllEngines,
          "contact prior: gap or overlap with the plane that costs nothing (m)"),
      Row("contact-span", POSEFILTER_FIELD(support.contact_span_m), "Support plane", kPositive, kAllEngines,
          "contact prior: distance beyond the tolerance over which the full --contact is lost (m)"),
      Row("stable-start", POSEFILTER_FIELD(support.stable_start), "Support plane", kFraction, kAllEngines,
          "fraction of the initial particles resting on the plane in a stable pose of the mesh (0 = off; the hw "
          "engine uses it for the polish only)"),
      // ---- rendering and windows
      Row("zbuffer", POSEFILTER_FIELD(render.zbuffer), "Rendering", kAny, kAllEngines,
          "exact z-buffer (off: the thesis's back-face culling only)"),
      Row("near", POSEFILTER_FIELD(render.near_m), "Rendering", kPositive, kAllEngines,
          "triangles closer than this to the camera are skipped (m; the hw engine: >= 1/64)"),
      Row("lod", POSEFILTER_FIELD(render.lod_max_faces), "Rendering", AtLeast(0), kAllEngines,
          "level of detail: render the mesh simplified to at most this many faces (0 = the full mesh, else >= 4)"),
      Row("window", POSEFILTER_FIELD(render.max_window_px), "Rendering", AtLeast(8), kAllEngines,
          "maximum window side (pixels; the hw engine: at most 200)"),
      Row("adaptive-resolution", POSEFILTER_FIELD(render.adaptive_resolution), "Rendering", kAny, kAllEngines,
          "weigh objects too large for a window on every s-th pixel, s the smallest stride that fits (off: every "
          "pixel, the thesis; the hw engine uses it for the polish only)"),
      Row("min-window-diameters", POSEFILTER_FIELD(render.min_window_diameters), "Rendering", Closed(0, 4),
          kAllEngines, "windows are at least this fraction of the object's projected diameter (0 = the box)"),
      Row("grow-window", POSEFILTER_FIELD(render.grow_window), "Rendering", kAny, kAllEngines,
          "grow each particle's window to its own projected box (off: the cell's window, the thesis)"),
      // ---- coarse-to-fine
      Row("anneal", POSEFILTER_FIELD(anneal.start_m), "Annealing", AtLeast(0), kAllEngines,
          "coarse-to-fine: initial inlier threshold (m; 0 = off)"),
      Row("anneal-fraction", POSEFILTER_FIELD(anneal.fraction), "Annealing", kFraction, kAllEngines,
          "coarse-to-fine: fraction of --iterations over which the threshold falls to --inlier-thr"),
      Row("anneal-subsample", POSEFILTER_FIELD(anneal.subsample), "Annealing", Closed(1, 4), kFloatEngines,
          "coarse-to-fine: weigh on every Nth pixel of every Nth row while the threshold anneals (1 = every pixel)"),
      Row("anneal-simplify", POSEFILTER_FIELD(anneal.simplify), "Annealing", kAny, kFloatEngines,
          "on the coarse annealing grid, weigh a mesh simplified to faces / N^2 (off: the full mesh)"),
      // ---- niches
      Row("region-cap", POSEFILTER_FIELD(niches.region_cap), "Niches", kPositiveFraction, kAllEngines,
          "at most this fraction of the resampling pool from one detection (1 = off)"),
      Row("rotation-cap", POSEFILTER_FIELD(niches.rotation_cap), "Niches", kPositiveFraction, kAllEngines,
          "at most this fraction of the pool from one detection and coarse orientation (1 = off)"),
      // ---- diffusion
      Row("sigma-t", POSEFILTER_FIELD(diffusion.sigma_t0_m), "Diffusion", AtLeast(0), kAllEngines,
          "diffusion translation sigma at weight 0 (m)"),
      Row("sigma-r", POSEFILTER_FIELD(diffusion.sigma_r0_rad), "Diffusion", AtLeast(0), kAllEngines,
          "diffusion rotation sigma at weight 0 (rad)"),
      Row("min-sigma-fraction", POSEFILTER_FIELD(diffusion.min_sigma_fraction), "Diffusion", kFraction, kAllEngines,
          "sigma never decays below this fraction of sigma at weight 0"),
      Row("move-probabilities", POSEFILTER_FIELD(diffusion.move_probabilities), "Diffusion", AtLeast(0), kAllEngines,
          "probability of each of the 17 moves (docs/ALGORITHM.md), normalised over the moves that apply"),
      Row("align-band", POSEFILTER_FIELD(diffusion.align_band_m), "Diffusion", kPositive, kAllEngines,
          "depth differences used by the align-depth move (m)"),
      // ---- stopping
      Row("iterations", POSEFILTER_FIELD(stop.max_iterations), "Stopping", Closed(1, 100'000), kAllEngines,
          "maximum iterations per run"),
      Row("confidence", POSEFILTER_FIELD(stop.confidence), "Stopping", kPositiveFraction, kAllEngines,
          "a run stops when its best weight reaches this"),
      Row("stall-iterations", POSEFILTER_FIELD(stop.stall_iterations), "Stopping", Closed(0, 1000), kAllEngines,
          "a run ends when its best weight rose by less than --stall-gain over this many iterations at the final "
          "threshold (0 = off)"),
      Row("stall-gain", POSEFILTER_FIELD(stop.stall_gain), "Stopping", kFraction, kAllEngines,
          "see --stall-iterations (weight)"),
      // ---- polish
      Row("polish-steps", POSEFILTER_FIELD(polish.steps), "Polish", Closed(0, 100), kAllEngines,
          "final polish: ICP steps per polished candidate (0 = off)"),
      Row("polish-turns", POSEFILTER_FIELD(polish.turns), "Polish", kAny, kAllEngines,
          "final polish: also try the 23 cube turns of each seed"),
      Row("polish-pivots", POSEFILTER_FIELD(polish.pivots), "Polish", kAny, kAllEngines,
          "final polish: also turn about the box's edges and corners (off: about its centre only)"),
      Row("polish-keep", POSEFILTER_FIELD(polish.keep), "Polish", Closed(1, 100'000), kAllEngines,
          "final polish: turned copies refined after one weighing of all"),
      Row("polish-stable", POSEFILTER_FIELD(polish.stable), "Polish", kAny, kAllEngines,
          "final polish: also try the mesh's stable poses on the support plane at each seed"),
      Row("polish-seeds", POSEFILTER_FIELD(polish.seeds), "Polish", Closed(1, 1000), kAllEngines,
          "final polish: niche leaders per run used as seeds"),
      Row("polish-climbers", POSEFILTER_FIELD(polish.climbers), "Polish", Closed(0, 1000), kAllEngines,
          "final polish: candidates refined by pattern search"),
      // ---- heuristic volumes
      Row("heuristics-percentile-lo", POSEFILTER_FIELD(heuristics.percentile_lo), "Heuristic volumes", kFraction,
          kAllEngines, "volume bounds: lower quantile of the cell's points, per axis"),
      Row("heuristics-percentile-hi", POSEFILTER_FIELD(heuristics.percentile_hi), "Heuristic volumes", kFraction,
          kAllEngines, "volume bounds: upper quantile (>= the lower)"),
      Row("heuristics-depth-extension", POSEFILTER_FIELD(heuristics.depth_extension_m), "Heuristic volumes",
          AtLeast(0), kAllEngines, "points also moved this far along their ray (m; 0 = the object's radius)"),
      Row("heuristics-max-samples", POSEFILTER_FIELD(heuristics.max_samples), "Heuristic volumes", AtLeast(1),
          kAllEngines, "depth pixels sampled per box"),
      Row("heuristics-max-depth", POSEFILTER_FIELD(heuristics.max_depth_m), "Heuristic volumes", kPositive,
          kAllEngines, "depth beyond this is ignored (m)"),
      Row("heuristics-min-valid-pixels", POSEFILTER_FIELD(heuristics.min_valid_pixels), "Heuristic volumes",
          AtLeast(1), kAllEngines, "a box with fewer valid sampled pixels has no volume"),
  };
  return t;
}

#undef POSEFILTER_FIELD

// The shortest text that reads back as `v` (an integral value without exponent).
template <class T>
std::string NumberText(T v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::isfinite(v) && v == std::trunc(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

bool InRange(double v, const OptionInfo& f) {
  if (!std::isfinite(v)) return false;
  if (f.lo_open ? !(v > f.lo) : !(v >= f.lo)) return false;
  if (f.hi_open ? !(v < f.hi) : !(v <= f.hi)) return false;
  return true;
}

}  // namespace

unsigned EngineBit(const std::string& engine) {
  const filter::EngineRow* row = filter::FindEngine(engine);
  return row != nullptr ? row->bit : 0;
}

std::span<const OptionInfo> FilterOptionTable() { return Table(); }

const OptionInfo* FindOption(const std::string& key) {
  for (const OptionInfo& f : Table()) {
    if (key == f.field || key == f.name || key == f.Name(OptionNaming::kPython)) return &f;
  }
  return nullptr;
}

std::string OptionInfo::Name(OptionNaming naming) const {
  switch (naming) {
    case OptionNaming::kField:
      return field;
    case OptionNaming::kCli:
      return std::string("--") + name;
    case OptionNaming::kPython: {
      std::string s = name;
      for (char& c : s)
        if (c == '-') c = '_';
      return s;
    }
  }
  return name;
}

std::string OptionInfo::ValueText(const FilterOptions& o) const {
  return VisitOption(*this, o, [](const auto& v) -> std::string {
    using T = std::remove_cvref_t<decltype(v)>;
    if constexpr (std::is_same_v<T, bool>) {
      return v ? "true" : "false";
    } else if constexpr (std::is_same_v<T, std::string>) {
      return v;
    } else if constexpr (std::is_integral_v<T>) {
      return std::to_string(v);
    } else if constexpr (std::is_floating_point_v<T>) {
      return NumberText(v);
    } else {  // the move probabilities
      std::string s;
      for (double p : v) {
        if (!s.empty()) s += ',';
        s += NumberText(p);
      }
      return s;
    }
  });
}

bool OptionInfo::SameValue(const FilterOptions& a, const FilterOptions& b) const {
  return VisitOption(*this, a, [&](const auto& va) {
    return va == Of<std::remove_cvref_t<decltype(va)>>(b);
  });
}

std::string OptionInfo::RangeText() const {
  if (choices != nullptr) return choices;
  if (type == OptionType::kBool || type == OptionType::kString) return "";
  if (type == OptionType::kUint64) return "[0, 2^64 - 1]";
  const bool lo_bounded = std::isfinite(lo), hi_bounded = std::isfinite(hi);
  if (lo_bounded && hi_bounded)
    return std::string(lo_open ? "(" : "[") + NumberText(lo) + ", " + NumberText(hi) + (hi_open ? ")" : "]");
  if (lo_bounded) return std::string(lo_open ? "> " : ">= ") + NumberText(lo);
  if (hi_bounded) return std::string(hi_open ? "< " : "<= ") + NumberText(hi);
  return "";
}

std::string OptionInfo::EnginesText() const {
  if (engines == kAllEngines) return "all";
  // Each bit under the name of its first row (rtl reads the hw engine's options: "hw").
  std::string s;
  unsigned listed = 0;
  for (const filter::EngineRow& row : filter::EngineRegistry()) {
    if ((engines & row.bit) == 0 || (listed & row.bit) != 0) continue;
    listed |= row.bit;
    s += (s.empty() ? "" : ", ") + std::string(row.name);
  }
  return s;
}

std::vector<std::string> OptionInfo::Choices() const {
  std::vector<std::string> out;
  if (choices == nullptr) return out;
  for (std::string c = choices;;) {
    const std::size_t bar = c.find('|');
    out.push_back(c.substr(0, bar));
    if (bar == std::string::npos) return out;
    c = c.substr(bar + 1);
  }
}

std::vector<std::string> IgnoredOptions(const FilterOptions& o, OptionNaming naming) {
  std::vector<std::string> out;
  const unsigned bit = EngineBit(o.engine);
  if (bit == 0) return out;
  const FilterOptions defaults;
  for (const OptionInfo& f : Table())
    if (!(f.engines & bit) && !f.SameValue(o, defaults))
      out.push_back(f.Name(naming) + " is ignored by the " + o.engine + " engine");
  return out;
}

std::string OptionTableMarkdown() {
  const FilterOptions defaults;
  std::string md =
      "# Filter options\n\n"
      "Every option of the particle filter, as `posefilter estimate`, `demo`, `suite`, `run-dataset` and\n"
      "`hw-report` take it (`--name`; a switch also as `--no-name`) and as `posefilter.Estimator` takes it (the keyword is\n"
      "the name with `-` as `_`). C++ sets the field of `posefilter::FilterOptions` (posefilter/filter_options.h).\n"
      "Ranges are checked before any work, and an error names the option. Engines: the engines that read the\n"
      "option; setting one away from its default for another engine prints a warning.\n\n"
      "This file is the output of `posefilter options --markdown`; a test keeps them equal.\n";
  const char* group = "";
  for (const OptionInfo& f : Table()) {
    if (std::string(group) != f.group) {
      group = f.group;
      md += std::string("\n## ") + group + "\n\n| option | Python | C++ field | default | range | engines | meaning |\n"
            "|---|---|---|---|---|---|---|\n";
    }
    std::string range = f.RangeText();
    for (char& c : range)
      if (c == '|') c = '/';
    md += "| `--" + std::string(f.name) + "` | `" + f.Name(OptionNaming::kPython) + "` | `" + f.field + "` | " +
          f.ValueText(defaults) + " | " + range + " | " + f.EnginesText() + " | " + f.help + " |\n";
  }
  return md;
}

namespace {

// Every range and choice list of the table.
bool ValidateRanges(const FilterOptions& o, OptionNaming naming, std::string* why) {
  auto fail = [&](const OptionInfo& f, const std::string& value) {
    if (why) {
      const std::string range = f.RangeText();
      const bool interval = !range.empty() && (range[0] == '[' || range[0] == '(');
      *why = f.Name(naming) + " must be " + (f.choices ? "one of " : interval ? "in " : "") + range + " (got " + value +
             ")";
    }
    return false;
  };
  for (const OptionInfo& f : Table()) {
    const bool ok = VisitOption(f, o, [&](const auto& v) {
      using T = std::remove_cvref_t<decltype(v)>;
      if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::uint64_t>) {
        return true;  // every value is in range
      } else if constexpr (std::is_same_v<T, std::string>) {
        const std::vector<std::string> choices = f.Choices();
        if (choices.empty() || std::find(choices.begin(), choices.end(), v) != choices.end()) return true;
        return fail(f, "'" + v + "'");
      } else if constexpr (std::is_arithmetic_v<T>) {
        return InRange(v, f) || fail(f, f.ValueText(o));
      } else {  // the move probabilities: each in range
        for (double p : v)
          if (!InRange(p, f)) {
            if (why) *why = f.Name(naming) + " must each be finite and >= 0 (got " + NumberText(p) + ")";
            return false;
          }
        return true;
      }
    });
    if (!ok) return false;
  }
  return true;
}

}  // namespace

bool ValidateFilterOptions(const FilterOptions& o, OptionNaming naming, std::string* why) {
  if (!ValidateRanges(o, naming, why)) return false;
  auto name = [naming](const char* field) { return FindOption(field)->Name(naming); };
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (o.cpu_isa != "auto") {
    render::CpuTarget t;
    render::ParseCpuTarget(o.cpu_isa, &t);  // a listed choice: parses
    if (!render::CpuTargetSupported(t)) {
      std::string supported;
      for (render::CpuTarget c : render::SupportedCpuTargets())
        supported += std::string(supported.empty() ? "" : ", ") + render::CpuTargetName(c);
      return fail(name("cpu_isa") + " '" + o.cpu_isa + "' is not supported by this CPU or build (supported: " +
                  supported + ")");
    }
  }
  if (std::fabs(o.score.alpha + o.score.beta + o.score.gamma - 1) > 1e-6)
    return fail(name("score.alpha") + " + " + name("score.beta") + " + " + name("score.gamma") + " must equal 1");
  if (o.num_elite >= o.num_particles)
    return fail(name("num_elite") + " must be < " + name("num_particles") + " (got " + std::to_string(o.num_elite) +
                " >= " + std::to_string(o.num_particles) + ")");
  if (o.render.lod_max_faces != 0 && o.render.lod_max_faces < kMinSimplifyFaces)
    return fail(name("render.lod_max_faces") + " must be 0 (the full mesh) or >= " + std::to_string(kMinSimplifyFaces) +
                " (got " + std::to_string(o.render.lod_max_faces) + ")");
  double total = 0;
  for (double p : o.diffusion.move_probabilities) total += p;
  if (!(total > 0)) return fail(name("diffusion.move_probabilities") + ": at least one must be > 0");
  if (o.threads > MaxWorkerThreads())
    return fail(name("threads") + " must be in [0, " + std::to_string(MaxWorkerThreads()) +
                "] (0 = all cores; at most 4 per hardware thread; got " + std::to_string(o.threads) + ")");
  if (EngineBit(o.engine) == kEngineHw) {  // the hardware's limits (posefilter/hw_engine.h): hw and rtl
    if (o.num_particles > kHwMaxParticles)
      return fail(name("num_particles") + " must be <= " + std::to_string(kHwMaxParticles) + " with the hw engine (got " +
                  std::to_string(o.num_particles) + ")");
    if (o.render.max_window_px > kHwMaxWindowPx)
      return fail(name("render.max_window_px") + " must be <= " + std::to_string(kHwMaxWindowPx) +
                  " with the hw engine (got " + std::to_string(o.render.max_window_px) + ")");
    if (o.render.near_m < kHwMinNearM)
      return fail(name("render.near_m") + " must be >= 1/64 m with the hw engine (got " + NumberText(o.render.near_m) +
                  ")");
  }
  if (o.heuristics.percentile_lo > o.heuristics.percentile_hi)
    return fail(name("heuristics.percentile_lo") + " must be <= " + name("heuristics.percentile_hi"));
  return true;
}

void ThrowIfInvalid(const FilterOptions& o, OptionNaming naming) {
  std::string why;
  if (!ValidateFilterOptions(o, naming, &why)) throw Error("invalid filter option: " + why);
}

bool FilterOptions::IsValid(std::string* why) const { return ValidateFilterOptions(*this, OptionNaming::kField, why); }

}  // namespace posefilter
