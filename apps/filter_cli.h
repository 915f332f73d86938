// apps/filter_cli.h — the particle-filter options shared by `estimate` and `demo`, and the
// progress/summary printing both use.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "posefilter/filter.h"

namespace posefilter::cli {

// Registers every filter option (--engine, --particles, --iterations, --seed, --threads, …;
// the full list, with help texts, is the body of this function in apps/filter_cli.cc, and
// `posefilter estimate --help` prints it) on `app`, writing into `opt` (defaults =
// FilterOptions defaults).
void AddFilterOptions(CLI::App& app, FilterOptions* opt);
// Checks a --seed value before CLI11 converts it: digits only, at most 2^64 - 1 (so "-1" and
// "1e23" are errors, not 2^64 - 1).
CLI::Validator SeedValidator();
// Validates after parsing; throws Error naming the option ("--alpha ...: ...").
void CheckFilterOptions(const FilterOptions& opt);
// A progress callback printing "<obj>: iteration i/N, best weight w" to stderr (rewritten in
// place on a terminal, every 10 iterations otherwise). Empty when quiet.
ProgressFn StderrProgress(const std::string& obj, int max_iterations, bool quiet);

}  // namespace posefilter::cli
