// apps/filter_cli.h — the particle-filter options shared by `estimate` and `demo`, and the
// progress/summary printing both use.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "posefilter/filter.h"

namespace posefilter::cli {

// Registers every filter option of posefilter/option_table.h (--engine, --particles,
// --iterations, --seed, --threads, …; `posefilter options` lists them) on `app`, writing into
// `opt` (defaults = FilterOptions defaults), in one --help section per group.
void AddFilterOptions(CLI::App& app, FilterOptions* opt);
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
