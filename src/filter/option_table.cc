// src/filter/option_table.cc — the table of every FilterOptions field (posefilter/option_table.h)
// and what is derived from it: the engines text, the checks between options, ignored-option
// warnings, the thesis configuration, docs/OPTIONS.md.
#include "posefilter/option_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/option_check.h"
#include "core/threads.h"
#include "filter/engine_registry.h"
#include "posefilter/auto_prior.h"
#include "posefilter/error.h"
#include "posefilter/heuristics.h"
#include "posefilter/hw_engine.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/scene_pass.h"
#include "posefilter/tracker.h"
#include "render/cpu_kernel.h"

namespace posefilter {

namespace {

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

constexpr OptionRange Closed(double lo, double hi) { return ClosedRange(lo, hi); }
constexpr OptionRange AtLeast(double lo) { return AtLeastRange(lo); }
constexpr OptionRange kPositive = kPositiveRange;
constexpr OptionRange kFraction = kFractionRange;                  // [0, 1]
constexpr OptionRange kPositiveFraction = kPositiveFractionRange;  // (0, 1]
constexpr OptionRange kAny = kAnyRange;

#define POSEFILTER_FIELD(path) POSEFILTER_OPTION_FIELD(FilterOptions, path)

OptionInfo Row(const char* name, const char* field, void* (*ref)(void*), OptionType type, int count,
               const std::type_info* owner, const char* group, OptionRange range, unsigned engines, const char* help,
               const char* choices = nullptr) {
  OptionInfo row = MakeOptionRow(name, field, ref, type, count, owner, group, range, help);
  row.engines = engines;
  row.choices = choices;
  return row;
}

// A row with the thesis's value, which a thesis configuration sets (an extension of ours the
// thesis does not have, switched off).
OptionInfo Thesis(const char* value, OptionInfo row) {
  row.thesis = value;
  return row;
}
// A row with the thesis's value, which a thesis configuration keeps from the caller's options
// (the run's scale, a threshold the caller varies).
OptionInfo ThesisKept(const char* value, OptionInfo row) {
  row.thesis = value;
  row.thesis_kept = true;
  return row;
}

// A heuristic-volume row: range and help from HeuristicOptionTable (posefilter/heuristics.h),
// the one place they are written.
OptionInfo HeuristicRow(const char* name, const char* field, void* (*ref)(void*), OptionType type, int count,
                        const std::type_info* owner, const char* heuristic_field, const char* help = nullptr) {
  const OptionInfo* h = FindOptionRow(HeuristicOptionTable(), heuristic_field);
  if (h == nullptr || h->type != type) throw std::logic_error(std::string("no heuristic option row ") + heuristic_field);
  OptionInfo row = Row(name, field, ref, type, count, owner, "Heuristic volumes",
                       OptionRange{h->lo, h->hi, h->lo_open, h->hi_open}, kAllEngines, help ? help : h->help);
  row.thesis = h->thesis;
  row.thesis_kept = h->thesis_kept;
  return row;
}

const std::vector<OptionInfo>& Table() {
  static const unsigned kFloatEngines = FloatEngineBits();
  static const std::vector<OptionInfo> t = {
      // ---- engine and run
      Row("engine", POSEFILTER_FIELD(engine), "Engine", kAny, kAllEngines, "engine that weighs the particles",
          EngineChoiceText()),
      Row("cpu-isa", POSEFILTER_FIELD(cpu_isa), "Engine", kAny, kAllEngines,
          "cpu kernel's instruction set (the cpu engine; the gpu engine's ICP weighings; every engine's final "
          "polish): auto (the best this CPU runs), avx512, avx2 or portable (same weights; a polished pose may "
          "differ in rounding)",
          "auto|avx512|avx2|portable"),
      Row("threads", POSEFILTER_FIELD(threads), "Engine", AtLeast(0), kAllEngines,
          "worker threads: scoring, scene normals, heuristic volumes (0 = all cores, at most 4 per hardware thread)"),
      Row("seed", POSEFILTER_FIELD(seed), "Engine", kAny, kAllEngines,
          "random seed (same seed, same poses), an integer in [0, 2^64 - 1]"),
      ThesisKept("1", Row("restarts", POSEFILTER_FIELD(restarts), "Engine", Closed(1, 100), kAllEngines,
                          "independent runs, the best weight wins (time x restarts)")),
      Row("record-particles", POSEFILTER_FIELD(record_particles), "Engine", kAny, kFloatEngines,
          "record each iteration's particle set (poses, weights) for the viewer; changes no pose"),
      // ---- particles and resampling
      ThesisKept("510", Row("particles", POSEFILTER_FIELD(num_particles), "Particles", Closed(2, 1'000'000),
                            kAllEngines, "number of particles N (the hw engine: at most 510)")),
      Row("elite", POSEFILTER_FIELD(num_elite), "Particles", Closed(0, 1'000'000), kAllEngines,
          "best particles carried unchanged into the next set (< --particles)"),
      Row("pool", POSEFILTER_FIELD(resample_pool), "Particles", kPositiveFraction, kAllEngines,
          "fraction of the sorted set the rest is resampled from"),
      Thesis("1", Row("fine-fraction", POSEFILTER_FIELD(fine_particle_fraction), "Particles", kPositiveFraction,
                      kFloatEngines, "after annealing, each set has this fraction of --particles (1 = all of them)")),
      Thesis("1", Row("init-oversample", POSEFILTER_FIELD(init_oversample), "Particles", Closed(1, 64), kFloatEngines,
                      "draw this many x N initial particles, weigh them all and keep the best N")),
      Thesis(
          "0",
          Row("seed-start", POSEFILTER_FIELD(seed_start), "Particles", kFraction, kFloatEngines,
              "fraction of the initial particles started at the scene's pose seeds (the --prior auto proposals) where "
              "it has any")),
      ThesisKept("32", Row("tracker-bins", POSEFILTER_FIELD(tracker_bins), "Particles", Closed(1, 4096), kFloatEngines,
                           "threshold-tracker entries of the CDF samplers (thesis 7.4; the hw engine has 32)")),
      // ---- weight, eq. 7.4 [ALGORITHM.md]
      Row("alpha", POSEFILTER_FIELD(score.alpha), "Weight", kFraction, kAllEngines,
          "weight of I/N_raster (eq. 7.4); alpha + beta + gamma = 1"),
      Row("beta", POSEFILTER_FIELD(score.beta), "Weight", kFraction, kAllEngines, "weight of I/N_depth (eq. 7.4)"),
      Row("gamma", POSEFILTER_FIELD(score.gamma), "Weight", kFraction, kAllEngines,
          "weight of the stage-1 probability (eq. 7.4)"),
      Thesis(
          "0",
          Row("delta", POSEFILTER_FIELD(score.delta), "Weight", kFraction, kAllEngines,
              "silhouette edge penalty: weight lost where the scene surface continues across the outline (0 = off)")),
      Row("edge-band", POSEFILTER_FIELD(score.edge_band_m), "Weight", kPositive, kAllEngines,
          "edge penalty: depth step across the outline below which the surface continues (m)"),
      ThesisKept("0.00390625", Row("inlier-thr", POSEFILTER_FIELD(score.inlier.thr1_m), "Weight", kPositive,
                                   kAllEngines, "soft inlier: chi = 1 up to this, 0 from twice it (m)")),
      ThesisKept("false", Row("hard-inlier", POSEFILTER_FIELD(score.inlier.hard), "Weight", kAny, kAllEngines,
                              "hard inlier (chi = 1 iff d <= --hard-inlier-thr) instead of the soft ramp")),
      ThesisKept("0.005", Row("hard-inlier-thr", POSEFILTER_FIELD(score.inlier.hard_thr_m), "Weight", kPositive,
                              kAllEngines, "hard inlier threshold (m)")),
      Thesis("false", Row("occlusion-aware", POSEFILTER_FIELD(score.occlusion_aware), "Weight", kAny, kAllEngines,
                          "leave rendered pixels hidden behind nearer scene depth out of N_raster (off: the thesis)")),
      // ---- support plane
      Thesis("false", Row("support-plane", POSEFILTER_FIELD(support.plane), "Support plane", kAny, kAllEngines,
                          "leave the dominant plane's (the table's) pixels out of the scored depth (off: every pixel, "
                          "the thesis)")),
      Thesis("0", Row("contact", POSEFILTER_FIELD(support.contact), "Support plane", kFraction, kAllEngines,
                      "contact prior: weight lost by a pose floating above or sunk into the support plane (0 = off)")),
      Row("contact-tolerance", POSEFILTER_FIELD(support.contact_tolerance_m), "Support plane", AtLeast(0), kAllEngines,
          "contact prior: gap or overlap with the plane that costs nothing (m)"),
      Row("contact-span", POSEFILTER_FIELD(support.contact_span_m), "Support plane", kPositive, kAllEngines,
          "contact prior: distance beyond the tolerance over which the full --contact is lost (m)"),
      Thesis("0",
             Row("stable-start", POSEFILTER_FIELD(support.stable_start), "Support plane", kFraction, kAllEngines,
                 "fraction of the initial particles resting on the plane in a stable pose of the mesh (0 = off; the hw "
                 "engine uses it for the polish only)")),
      // ---- rendering and windows
      Thesis("false", Row("zbuffer", POSEFILTER_FIELD(render.zbuffer), "Rendering", kAny, kAllEngines,
                          "exact z-buffer (off: the thesis's back-face culling only)")),
      Row("near", POSEFILTER_FIELD(render.near_m), "Rendering", kPositive, kAllEngines,
          "triangles closer than this to the camera are skipped (m; the hw engine: >= 1/64)"),
      Row("lod", POSEFILTER_FIELD(render.lod_max_faces), "Rendering", AtLeast(0), kAllEngines,
          "level of detail: render the mesh simplified to at most this many faces (0 = the full mesh, else >= 4)"),
      Row("lod-face-px", POSEFILTER_FIELD(render.lod_face_px), "Rendering", AtLeast(0), kAllEngines,
          "level of detail by size in the image: at most (projected diameter in px)^2 / this many faces (the mesh "
          "simplified to faces/m^2, m <= 4; 0 = off; the hw engine uses it for the polish only)"),
      ThesisKept("200", Row("window", POSEFILTER_FIELD(render.max_window_px), "Rendering", AtLeast(8), kAllEngines,
                            "maximum window side (pixels; the hw engine: at most 200)")),
      Thesis(
          "false",
          Row("adaptive-resolution", POSEFILTER_FIELD(render.adaptive_resolution), "Rendering", kAny, kAllEngines,
              "weigh objects too large for a window on every s-th pixel, s the smallest stride that fits (off: every "
              "pixel, the thesis; the hw engine uses it for the polish only)")),
      ThesisKept(
          "0", Row("min-window-diameters", POSEFILTER_FIELD(render.min_window_diameters), "Rendering", Closed(0, 4),
                   kAllEngines, "windows are at least this fraction of the object's projected diameter (0 = the box)")),
      Thesis("false", Row("grow-window", POSEFILTER_FIELD(render.grow_window), "Rendering", kAny, kAllEngines,
                          "grow each particle's window to its own projected box (off: the cell's window, the thesis)")),
      // ---- coarse-to-fine
      Thesis("0", Row("anneal", POSEFILTER_FIELD(anneal.start_m), "Annealing", AtLeast(0), kAllEngines,
                      "coarse-to-fine: initial inlier threshold (m; 0 = off)")),
      Row("anneal-fraction", POSEFILTER_FIELD(anneal.fraction), "Annealing", kFraction, kAllEngines,
          "coarse-to-fine: fraction of --iterations over which the threshold falls to --inlier-thr"),
      Thesis("1", Row("anneal-subsample", POSEFILTER_FIELD(anneal.subsample), "Annealing", Closed(1, 4), kFloatEngines,
                      "coarse-to-fine: weigh on every Nth pixel of every Nth row while the threshold anneals (1 = "
                      "every pixel)")),
      Thesis("false", Row("anneal-simplify", POSEFILTER_FIELD(anneal.simplify), "Annealing", kAny, kAllEngines,
                          "on a coarse pixel grid, weigh a mesh simplified to faces / N^2 (off: the full mesh; the "
                          "hw engine: in its final polish only)")),
      // ---- niches
      Thesis("1", Row("region-cap", POSEFILTER_FIELD(niches.region_cap), "Niches", kPositiveFraction, kAllEngines,
                      "at most this fraction of the resampling pool from one detection (1 = off)")),
      Thesis("1", Row("rotation-cap", POSEFILTER_FIELD(niches.rotation_cap), "Niches", kPositiveFraction, kAllEngines,
                      "at most this fraction of the pool from one detection and coarse orientation (1 = off)")),
      // ---- diffusion
      Row("sigma-t", POSEFILTER_FIELD(diffusion.sigma_t0_m), "Diffusion", AtLeast(0), kAllEngines,
          "diffusion translation sigma at weight 0 (m)"),
      Row("sigma-r", POSEFILTER_FIELD(diffusion.sigma_r0_rad), "Diffusion", AtLeast(0), kAllEngines,
          "diffusion rotation sigma at weight 0 (rad)"),
      Thesis("0", Row("min-sigma-fraction", POSEFILTER_FIELD(diffusion.min_sigma_fraction), "Diffusion", kFraction,
                      kAllEngines, "sigma never decays below this fraction of sigma at weight 0")),
      Thesis("1,1,1,1,1,1,1,1,1,1,1,1,1,0,0,0,0",
             Row("move-probabilities", POSEFILTER_FIELD(diffusion.move_probabilities), "Diffusion", AtLeast(0),
                 kAllEngines,
                 "probability of each of the 17 moves (docs/ALGORITHM.md), normalised over the moves that apply")),
      Row("align-band", POSEFILTER_FIELD(diffusion.align_band_m), "Diffusion", kPositive, kAllEngines,
          "depth differences used by the align-depth move (m)"),
      // ---- stopping
      ThesisKept("50", Row("iterations", POSEFILTER_FIELD(stop.max_iterations), "Stopping", Closed(1, 100'000),
                           kAllEngines, "maximum iterations per run")),
      Row("confidence", POSEFILTER_FIELD(stop.confidence), "Stopping", kPositiveFraction, kAllEngines,
          "a run stops when its best weight reaches this"),
      Thesis(
          "0",
          Row("stall-iterations", POSEFILTER_FIELD(stop.stall_iterations), "Stopping", Closed(0, 1000), kAllEngines,
              "a run ends when its best weight rose by less than --stall-gain over this many iterations at the final "
              "threshold (0 = off)")),
      Row("stall-gain", POSEFILTER_FIELD(stop.stall_gain), "Stopping", kFraction, kAllEngines,
          "see --stall-iterations (weight)"),
      Thesis("0", Row("restart-agree-m", POSEFILTER_FIELD(stop.restart_agree_m), "Stopping", Closed(0, 1), kAllEngines,
                      "with more than 2 --restarts, skip the rest when the first two runs' best poses lie within this "
                      "of each other (m; 0 = off: every restart runs)")),
      Row("restart-agree-weight", POSEFILTER_FIELD(stop.restart_agree_weight), "Stopping", kFraction, kAllEngines,
          "see --restart-agree-m: and their best weights lie within this (weight)"),
      // ---- polish
      Thesis("0", Row("polish-steps", POSEFILTER_FIELD(polish.steps), "Polish", Closed(0, 100), kAllEngines,
                      "final polish: ICP steps per polished candidate (0 = off)")),
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
      // ---- heuristic volumes (ranges and help: HeuristicOptionTable)
      HeuristicRow("heuristics-percentile-lo", POSEFILTER_FIELD(heuristics.percentile_lo), "percentile_lo"),
      HeuristicRow("heuristics-percentile-hi", POSEFILTER_FIELD(heuristics.percentile_hi), "percentile_hi"),
      HeuristicRow("heuristics-depth-extension", POSEFILTER_FIELD(heuristics.depth_extension_m), "depth_extension_m",
                   "points also moved this far along their ray (m; 0 = the object's radius)"),
      HeuristicRow("heuristics-max-samples", POSEFILTER_FIELD(heuristics.max_samples), "max_samples"),
      HeuristicRow("heuristics-max-depth", POSEFILTER_FIELD(heuristics.max_depth_m), "max_depth_m"),
      HeuristicRow("heuristics-min-valid-pixels", POSEFILTER_FIELD(heuristics.min_valid_pixels), "min_valid_pixels"),
  };
  return t;
}

#undef POSEFILTER_FIELD

}  // namespace

unsigned EngineBit(const std::string& engine) {
  const filter::EngineRow* row = filter::FindEngine(engine);
  return row != nullptr ? row->bit : 0;
}

std::span<const OptionInfo> FilterOptionTable() { return Table(); }

const OptionInfo* FindOption(const std::string& key) { return FindOptionRow(Table(), key); }

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

FilterOptions ThesisFilterOptions(const FilterOptions& scale) {
  FilterOptions o = scale;
  for (const OptionInfo& f : Table()) {
    std::string why;
    if (f.thesis != nullptr && !f.thesis_kept && !f.SetFromText(o, f.thesis, &why))
      throw std::logic_error("option table: the thesis value of " + why);
  }
  return o;
}

namespace {

// The thesis column: the value, "(kept)" where a thesis configuration keeps the caller's.
std::string ThesisText(const OptionInfo& f) {
  if (f.thesis == nullptr) return "";
  return std::string(f.thesis) + (f.thesis_kept ? " (kept)" : "");
}

}  // namespace

std::string OptionTableMarkdown() {
  const FilterOptions defaults;
  std::string md =
      "# Options\n\n"
      "Every option of the particle filter, as `posefilter estimate`, `demo`, `suite`, `run-dataset` and\n"
      "`hw-report` take it (`--name`; a switch also as `--no-name`) and as `posefilter.Estimator` takes it (the keyword is\n"
      "the name with `-` as `_`). C++ sets the field of `posefilter::FilterOptions` (posefilter/filter_options.h).\n"
      "Ranges are checked before any work, and an error names the option. Engines: the engines that read the\n"
      "option; setting one away from its default for another engine prints a warning. Thesis: the thesis's value\n"
      "(Ch. 7) where it fixes one; `hw-report`'s thesis configuration sets it, except where marked (kept): there it\n"
      "keeps the value given (the run's scale, thresholds).\n\n"
      "Then the options of the tracker, the scene pass, the auto prior and the synthetic scenes, from tables of the\n"
      "same kind.\n\n"
      "This file is the output of `posefilter options --markdown`; a test keeps them equal.\n";
  const char* group = "";
  for (const OptionInfo& f : Table()) {
    if (std::string(group) != f.group) {
      group = f.group;
      md += std::string("\n## ") + group +
            "\n\n| option | Python | C++ field | default | range | engines | thesis | meaning |\n"
            "|---|---|---|---|---|---|---|---|\n";
    }
    std::string range = f.RangeText();
    std::replace(range.begin(), range.end(), '|', '/');
    md += "| `--" + std::string(f.name) + "` | `" + f.Name(OptionNaming::kPython) + "` | `" + f.field + "` | " +
          f.ValueText(defaults) + " | " + range + " | " + f.EnginesText() + " | " + ThesisText(f) + " | " + f.help +
          " |\n";
  }
  const TrackOptions track;
  md += OptionSetMarkdown("Tracker",
                          "`posefilter track` and `posefilter.Tracker` (C++: `posefilter::TrackOptions`, "
                          "posefilter/tracker.h); the tracking step's filter options are the filter options above.",
                          TrackOptionTable(), &track);
  const ScenePassOptions pass;
  md += OptionSetMarkdown("Scene pass",
                          "The joint pass over several objects' estimates (C++: `posefilter::ScenePassOptions`, "
                          "posefilter/scene_pass.h).",
                          ScenePassOptionTable(), &pass);
  const AutoPriorOptions autop;
  md += OptionSetMarkdown("Auto prior",
                          "`--prior auto`: regions above the support and PPF pose proposals (C++: "
                          "`posefilter::AutoPriorOptions`, posefilter/auto_prior.h).",
                          AutoPriorOptionTable(), &autop);
  return md;
}

bool ValidateFilterOptions(const FilterOptions& o, OptionNaming naming, std::string* why) {
  if (!ValidateOptionRows(Table(), o, naming, why)) return false;
  auto name = [naming](const char* field) { return FindOption(field)->Name(naming); };
  if (o.cpu_isa != "auto") {
    render::CpuTarget t;
    render::ParseCpuTarget(o.cpu_isa, &t);  // a listed choice: parses
    if (!render::CpuTargetSupported(t)) {
      std::string supported;
      for (render::CpuTarget c : render::SupportedCpuTargets())
        supported += std::string(supported.empty() ? "" : ", ") + render::CpuTargetName(c);
      return Fail(why, name("cpu_isa") + " '" + o.cpu_isa +
                           "' is not supported by this CPU or build (supported: " + supported + ")");
    }
  }
  if (std::fabs(o.score.alpha + o.score.beta + o.score.gamma - 1) > 1e-6)
    return Fail(why, name("score.alpha") + " + " + name("score.beta") + " + " + name("score.gamma") + " must equal 1");
  if (o.num_elite >= o.num_particles)
    return Fail(why, name("num_elite") + " must be < " + name("num_particles") + " (got " +
                         std::to_string(o.num_elite) + " >= " + std::to_string(o.num_particles) + ")");
  if (o.render.lod_max_faces != 0 && o.render.lod_max_faces < kMinSimplifyFaces)
    return Fail(why, name("render.lod_max_faces") + " must be 0 (the full mesh) or >= " +
                         std::to_string(kMinSimplifyFaces) + " (got " + std::to_string(o.render.lod_max_faces) + ")");
  double total = 0;
  for (double p : o.diffusion.move_probabilities) total += p;
  if (!(total > 0)) return Fail(why, name("diffusion.move_probabilities") + ": at least one must be > 0");
  if (o.threads > MaxWorkerThreads())
    return Fail(why, name("threads") + " must be in [0, " + std::to_string(MaxWorkerThreads()) +
                         "] (0 = all cores; at most 4 per hardware thread; got " + std::to_string(o.threads) + ")");
  if (EngineBit(o.engine) == kEngineHw) {  // the hardware's limits (posefilter/hw_engine.h): hw and rtl
    if (o.num_particles > kHwMaxParticles)
      return Fail(why, name("num_particles") + " must be <= " + std::to_string(kHwMaxParticles) +
                           " with the hw engine (got " + std::to_string(o.num_particles) + ")");
    if (o.render.max_window_px > kHwMaxWindowPx)
      return Fail(why, name("render.max_window_px") + " must be <= " + std::to_string(kHwMaxWindowPx) +
                           " with the hw engine (got " + std::to_string(o.render.max_window_px) + ")");
    if (o.render.near_m < kHwMinNearM)
      return Fail(why, name("render.near_m") + " must be >= 1/64 m with the hw engine (got " +
                           OptionNumberText(o.render.near_m) + ")");
  }
  if (o.heuristics.percentile_lo > o.heuristics.percentile_hi)
    return Fail(why, name("heuristics.percentile_lo") + " must be <= " + name("heuristics.percentile_hi"));
  return true;
}

void ThrowIfInvalid(const FilterOptions& o, OptionNaming naming) {
  std::string why;
  if (!ValidateFilterOptions(o, naming, &why)) throw Error("invalid filter option: " + why);
}

bool FilterOptions::IsValid(std::string* why) const { return ValidateFilterOptions(*this, OptionNaming::kField, why); }

}  // namespace posefilter
