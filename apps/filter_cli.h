// apps/filter_cli.h — the option sets' CLI flags, from their tables (posefilter/option_rows.h):
// the filter's (every command that estimates), the tracker's, the scene pass's, the auto
// prior's and the synthetic scenes'; their checks; and the progress printing of the commands
// that estimate.
#pragma once

#include <CLI/CLI.hpp>
#include <span>
#include <string>

#include "posefilter/auto_prior.h"
#include "posefilter/filter.h"
#include "posefilter/scene_pass.h"
#include "posefilter/synth.h"
#include "posefilter/tracker.h"

namespace posefilter::cli {

// Registers every filter option of posefilter/option_table.h (--engine, --particles,
// --iterations, --seed, --threads, …; `posefilter options` lists them) on `app`, writing into
// `opt` (defaults = FilterOptions defaults), in one --help section per group.
void AddFilterOptions(CLI::App& app, FilterOptions* opt);
// Register the rows of TrackOptionTable (--lost-weight, --refresh-weight, --search-t,
// --search-r, --velocity/--no-velocity, --scene-pass/--no-scene-pass, --window-margin,
// --confirm/--no-confirm, --confirm-margin), of ScenePassOptionTable (--scene-pass-band,
// --scene-pass-conflict-drop), of AutoPriorOptionTable (--auto-min-height, …) and of
// SynthOptionTable (--target, --min-distance, --noise, --missing-edges/--no-missing-edges, …)
// on `app`, writing into `opt` (defaults: its values), each set in one --help section.
void AddTrackOptions(CLI::App& app, TrackOptions* opt);
void AddScenePassOptions(CLI::App& app, ScenePassOptions* opt);
void AddAutoPriorOptions(CLI::App& app, AutoPriorOptions* opt);
void AddSynthOptions(CLI::App& app, SynthOptions* opt);
// Validate after parsing (IsValid): throw Error naming the flag and the field ("invalid track
// option: --lost-weight (lost_weight): must be in [0, 1] (got 2)"), or with IsValid's message
// for a constraint between fields.
void CheckTrackOptions(const TrackOptions& opt);
void CheckScenePassOptions(const ScenePassOptions& opt);
void CheckAutoPriorOptions(const AutoPriorOptions& opt);
void CheckSynthOptions(const SynthOptions& opt);
// An IsValid message `why` of the set whose rows are `rows`, with a leading field of a row named
// by its flag too ("lost_weight must be in [0, 1] (got 2)" → "--lost-weight (lost_weight): must
// be in [0, 1] (got 2)"); `why` as it is when no row's field leads it.
std::string NameOptionRow(std::span<const OptionInfo> rows, const std::string& why);
// Checks a --seed value before CLI11 converts it (a transform: add it with ->transform):
// decimal digits only, at most 2^64 - 1 (so "-1" and "1e23" are errors, not 2^64 - 1), leading
// zeros dropped (so "010" is 10, not CLI11's octal 8).
CLI::Validator SeedValidator();
// Validates after parsing; throws Error naming the option ("--alpha must be in [0, 1] (got 2)").
// Then prints one warning to stderr per option set away from its default that the chosen
// engine does not read.
void CheckFilterOptions(const FilterOptions& opt);
// A progress callback printing "<obj>: iteration i/N, best weight w" to stderr, w the best
// weight at the final inlier threshold ("annealing" before there is one; ProgressFn); rewritten
// in place on a terminal, every 10 iterations otherwise. Empty when quiet.
ProgressFn StderrProgress(const std::string& obj, int max_iterations, bool quiet);

}  // namespace posefilter::cli
