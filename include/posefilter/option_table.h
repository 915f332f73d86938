// posefilter/option_table.h — every FilterOptions field as a row (posefilter/option_rows.h):
// its CLI name, C++ field path, group, help (with unit), type, range, the engines that read it
// and the thesis's value. This one table drives the CLI's options (apps/filter_cli.cc), the
// Python keywords and their help (python/bindings), the range checks of FilterOptions::IsValid
// and their messages, the engine check, the ignored-option warnings, the thesis configuration
// (ThesisFilterOptions: hw-report's "thesis"), the .pyi stub's Estimator signature and
// docs/OPTIONS.md (`posefilter options --markdown`, with the other option sets' tables).
//
// Names: the CLI option is "--" + name (a bool: "--name" / "--no-name"); the Python keyword is
// name with '-' → '_'. Adding an option = a field in filter_options.h + a row in
// src/filter/option_table.cc (+ its use) + a probe in tests/filter/option_engines_test.cc: the
// tests fail while a field has no row (tests/filter/option_rows_test.cc, counted from the
// structs) or a row's engines differ from those whose results the option changes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "posefilter/filter_options.h"
#include "posefilter/option_rows.h"

namespace posefilter {

// The engines an option is read by (bit set): a bit per engine with options of its own. The
// engine registry (src/filter/engine_registry.h) gives each engine name its bit; an engine may
// read another's options and share its bit (rtl: the hw engine's).
enum EngineBits : unsigned {
  kEngineReference = 1u << 0,
  kEngineCpu = 1u << 1,
  kEngineHw = 1u << 2,
  kEngineGpu = 1u << 3,
  kAllEngines = kEngineReference | kEngineCpu | kEngineHw | kEngineGpu,
};

// The bit of an engine name (a row of the engine registry: "reference", "cpu", "hw", "gpu", and
// "rtl" with the hw engine's bit); 0 for any other name.
unsigned EngineBit(const std::string& engine);

// Calls fn(field) with the field of `o` that `f` describes, as its C++ type (bool&, int&, …;
// const with a const `o`), and returns what fn returns (the same type for every field type).
template <class Options, class Fn>
decltype(auto) VisitOption(const OptionInfo& f, Options& o, Fn&& fn) {
  switch (f.type) {
    case OptionType::kBool: return fn(f.Of<bool>(o));
    case OptionType::kInt: return fn(f.Of<int>(o));
    case OptionType::kFloat: return fn(f.Of<float>(o));
    case OptionType::kDouble: return fn(f.Of<double>(o));
    case OptionType::kString: return fn(f.Of<std::string>(o));
    case OptionType::kUint64: return fn(f.Of<std::uint64_t>(o));
    case OptionType::kDoubles: break;
  }
  return fn(f.Of<std::array<double, kNumMoves>>(o));
}

// Every option, in the order of filter_options.h's groups.
std::span<const OptionInfo> FilterOptionTable();
// The row of a field path ("anneal.subsample") or name ("anneal-subsample", or the Python
// spelling "anneal_subsample"); nullptr when there is none.
const OptionInfo* FindOption(const std::string& field_or_name);

// FilterOptions::IsValid with the messages naming options as `naming` spells them: every
// range of the table, then the constraints between options (α + β + γ = 1,
// num_elite < num_particles, the cpu ISA this machine runs, lod 0 or ≥ 4, move probabilities,
// the heuristics' percentiles, the thread cap).
bool ValidateFilterOptions(const FilterOptions& o, OptionNaming naming, std::string* why);

// Throws Error("invalid filter option: " + the message of ValidateFilterOptions) unless `o`
// is valid. Every entry point calls it once, before any work: EstimatePose, WeighPoses and
// ProfileHw (kField), the CLI (kCli) and Python (kPython).
void ThrowIfInvalid(const FilterOptions& o, OptionNaming naming);

// The options set away from their defaults that `o.engine` does not read, each as
// "<name> is ignored by the <engine> engine" in `naming`'s spelling. Empty when every set
// option is read (or the engine is unknown: IsValid reports that).
std::vector<std::string> IgnoredOptions(const FilterOptions& o, OptionNaming naming);

// The thesis's configuration of the filter (Ch. 7) at the scale of `scale`: `scale` with every
// row's thesis value set where the row has one and does not keep the caller's (thesis_kept):
// no z-buffer, the thesis's 13 moves, no annealing, niches, support plane or polish; the
// particles, iterations, windows, thresholds and seed stay those of `scale`.
FilterOptions ThesisFilterOptions(const FilterOptions& scale);

// docs/OPTIONS.md but its last section: the filter options, one section per group, one row per
// option with CLI name, Python keyword, C++ field, default, range, engines, thesis value and
// help; then the other option sets' tables (the tracker's, the scene pass's, the auto prior's).
// The synthetic scenes' table is in the synth layer, which is not below the filter:
// `posefilter options --markdown` (OptionsMarkdown, apps/commands.h) adds its section.
std::string OptionTableMarkdown();

}  // namespace posefilter
