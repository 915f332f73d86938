#include "filter_cli.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

#include "posefilter/error.h"

namespace posefilter::cli {

namespace {

// The value options of AddFilterOptions and the FilterOptions fields they set, each field spelt
// as FilterOptions::IsValid names it in its messages (inlier.thr1_m is "inlier threshold").
struct FieldOption {
  std::string_view field;
  std::string_view option;
};
constexpr FieldOption kFieldOptions[] = {
    {"engine", "--engine"},         {"num_particles", "--particles"},     {"max_iterations", "--iterations"},
    {"confidence", "--confidence"}, {"alpha", "--alpha"},                 {"beta", "--beta"},
    {"gamma", "--gamma"},           {"inlier threshold", "--inlier-thr"}, {"max_window_px", "--window"},
    {"num_elite", "--elite"},       {"resample_pool", "--pool"},          {"sigma_t0_m", "--sigma-t"},
    {"sigma_r0_rad", "--sigma-r"},  {"seed", "--seed"},                   {"threads", "--threads"},
    {"delta", "--delta"},           {"contact", "--contact"}, {"stable_start", "--stable-start"},           {"restarts", "--restarts"},           {"anneal_start_m", "--anneal"},
    {"anneal_subsample", "--anneal-subsample"}, {"anneal_fraction", "--anneal-fraction"},
    {"fine_particle_fraction", "--fine-fraction"},
    {"lod_max_faces", "--lod"},     {"polish_steps", "--polish-steps"},   {"polish_seeds", "--polish-seeds"},
    {"polish_climbers", "--polish-climbers"}, {"cpu_isa", "--cpu-isa"},
    {"stall_iterations", "--stall-iterations"}, {"stall_gain", "--stall-gain"}};

// The option that sets `field`; evaluated while compiling, so an unknown field does not compile.
consteval const char* OptionOf(std::string_view field) {
  for (const FieldOption& f : kFieldOptions)
    if (f.field == field) return f.option.data();
  throw "no CLI option sets this FilterOptions field";
}

bool IsNameChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; }

// `why` of FilterOptions::IsValid with every field that has an option replaced by the option
// ("num_elite must be in [0, num_particles)" → "--elite must be in [0, --particles)"). A field
// counts where it starts a phrase: a whole word at the message start or after punctuation (so
// the "inlier threshold" of "hard inlier threshold", which has no option, stays).
std::string NameOptions(const std::string& why) {
  std::string out;
  for (std::size_t i = 0; i < why.size();) {
    const std::size_t prev = i == 0 ? std::string::npos : why.find_last_not_of(' ', i - 1);
    const FieldOption* match = nullptr;
    if (prev == std::string::npos || !IsNameChar(why[prev])) {
      for (const FieldOption& f : kFieldOptions) {
        const std::size_t end = i + f.field.size();
        if (why.compare(i, f.field.size(), f.field) == 0 && (end == why.size() || !IsNameChar(why[end]))) {
          match = &f;
          break;
        }
      }
    }
    if (match != nullptr) {
      out += match->option;
      i += match->field.size();
    } else {
      out += why[i++];
    }
  }
  return out;
}

}  // namespace

CLI::Validator SeedValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const std::string range = "must be an integer in [0, 18446744073709551615] (got '" + text + "')";
        if (text.empty() || text.size() > 20 || !std::all_of(text.begin(), text.end(), [](unsigned char c) {
              return std::isdigit(c) != 0;
            }))
          return range;
        if (text.size() == 20 && text > "18446744073709551615") return range;
        return "";
      },
      "SEED");
}

void AddFilterOptions(CLI::App& app, FilterOptions* o) {
  // A value option whose --help shows its default.
  auto add = [&app](const char* name, auto& value, const char* help) {
    return app.add_option(name, value, help)->capture_default_str();
  };
  add(OptionOf("engine"), o->engine, "scoring engine")->check(CLI::IsMember({"cpu", "reference", "hw"}));
  add(OptionOf("cpu_isa"), o->cpu_isa,
      "cpu engine's instruction set: auto (the best this CPU runs), avx512, avx2 or portable (same results)");
  add(OptionOf("num_particles"), o->num_particles, "number of particles N");
  add(OptionOf("max_iterations"), o->max_iterations, "maximum iterations");
  add(OptionOf("confidence"), o->confidence, "stop when the best weight reaches this");
  add(OptionOf("alpha"), o->alpha, "weight of I/N_raster (eq. 7.4)");
  add(OptionOf("beta"), o->beta, "weight of I/N_depth (eq. 7.4)");
  add(OptionOf("gamma"), o->gamma, "weight of the stage-1 probability (eq. 7.4)");
  add(OptionOf("inlier threshold"), o->inlier.thr1_m, "soft inlier: chi = 1 up to this, 0 from twice it (m)");
  app.add_flag("--hard-inlier", o->inlier.hard, "hard inlier (chi = 1 iff d <= 5 mm) instead of the soft ramp");
  app.add_flag("!--no-zbuffer", o->zbuffer, "thesis mode: back-face culling only, no z-buffer");
  app.add_flag("!--no-support-plane", o->support_plane,
               "score against every pixel, the table's too (default: the dominant plane's pixels are left out)");
  app.add_flag("!--no-occlusion-aware", o->occlusion_aware,
               "count occluded rendered pixels in N_raster, as the thesis does");
  add(OptionOf("max_window_px"), o->max_window_px, "maximum window side (pixels)");
  app.add_flag("!--no-adaptive-resolution", o->adaptive_resolution,
               "weigh large objects on every pixel in windows of at most --window pixels (default: every s-th pixel, "
               "s the smallest stride that fits the object in a window)");
  app.add_flag("!--no-anneal-simplify", o->anneal_simplify,
               "weigh the full mesh on the coarse annealing grid too (not one simplified to faces / N^2)");
  add(OptionOf("fine_particle_fraction"), o->fine_particle_fraction,
      "after annealing, each set has this fraction of --particles (1 = all of them)");
  add(OptionOf("num_elite"), o->num_elite, "best particles kept unchanged each iteration");
  add(OptionOf("resample_pool"), o->resample_pool, "fraction of the sorted set resampled from");
  add(OptionOf("sigma_t0_m"), o->sigma_t0_m, "initial diffusion translation sigma (m)");
  add(OptionOf("sigma_r0_rad"), o->sigma_r0_rad, "initial diffusion rotation sigma (rad)");
  add(OptionOf("delta"), o->delta, "silhouette edge penalty weight (0 = off)");
  add(OptionOf("stable_start"), o->stable_start,
      "fraction of the initial particles resting on the support plane in a stable pose of the mesh (0 = off)");
  add(OptionOf("contact"), o->contact,
      "contact prior: weight lost by a pose floating above or sunk into the support plane (0 = off)");
  add(OptionOf("anneal_start_m"), o->anneal_start_m, "coarse-to-fine: initial inlier threshold (m, 0 = off)");
  add(OptionOf("anneal_fraction"), o->anneal_fraction,
      "coarse-to-fine: fraction of --iterations over which the threshold falls to --inlier-thr");
  add(OptionOf("anneal_subsample"), o->anneal_subsample,
      "coarse-to-fine: weigh on every Nth pixel of every Nth row while the threshold anneals (1 = every pixel)");
  add(OptionOf("restarts"), o->restarts, "independent runs, the best weight wins");
  add(OptionOf("stall_iterations"), o->stall_iterations,
      "a run ends when its best weight rose by less than --stall-gain over this many iterations at the final threshold (0 = off)");
  add(OptionOf("stall_gain"), o->stall_gain, "see --stall-iterations");
  add(OptionOf("lod_max_faces"), o->lod_max_faces, "level of detail: render the mesh simplified to at most this many faces (0 = full mesh)");
  add(OptionOf("polish_steps"), o->polish_steps, "final polish: ICP steps per polished candidate (0 = off)");
  app.add_flag("!--no-polish-turns", o->polish_turns, "final polish: do not try the 23 cube turns of each seed");
  app.add_flag("!--no-polish-pivots", o->polish_pivots, "final polish: turn about the box centre only (no edge/corner pivots)");
  app.add_flag("!--no-polish-stable", o->polish_stable,
               "final polish: do not try the mesh's stable poses on the support plane at each seed");
  add(OptionOf("polish_seeds"), o->polish_seeds, "final polish: niche leaders per run used as seeds");
  add(OptionOf("polish_climbers"), o->polish_climbers, "final polish: candidates refined by pattern search");
  app.add_flag("!--no-grow-window", o->grow_window, "weigh each particle in its cell's window only (thesis)");
  add(OptionOf("seed"), o->seed, "random seed (same seed, same poses), an integer in [0, 2^64 - 1]")
      ->check(SeedValidator());
  add(OptionOf("threads"), o->threads, "worker threads: scoring, scene normals, heuristic volumes (0 = all cores)");
}

void CheckFilterOptions(const FilterOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("invalid filter option: " + NameOptions(why));
}

ProgressFn StderrProgress(const std::string& obj, int max_iterations, bool quiet) {
  if (quiet) return nullptr;
  const bool tty = isatty(fileno(stderr));
  return [obj, max_iterations, tty](int it, double w) {
    if (tty) {
      std::fprintf(stderr, "\r%s: iteration %d/%d, best weight %.3f   ", obj.c_str(), it + 1, max_iterations, w);
    } else if ((it + 1) % 10 == 0) {
      std::fprintf(stderr, "%s: iteration %d/%d, best weight %.3f\n", obj.c_str(), it + 1, max_iterations, w);
    }
    std::fflush(stderr);
  };
}

}  // namespace posefilter::cli
