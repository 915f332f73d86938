// posefilter/option_table.h — every FilterOptions field as data: its CLI name, C++ field path,
// group, help (with unit), type, range and the engines that read it. This one table drives the
// CLI's options (apps/filter_cli.cc), the Python keywords and their help (python/bindings),
// the range checks of FilterOptions::IsValid and their messages, the engine check, the .pyi
// stub's Estimator signature and docs/OPTIONS.md (`posefilter options --markdown`).
//
// Names: the CLI option is "--" + name (a bool: "--name" / "--no-name"); the Python keyword is
// name with '-' → '_'. Adding an option = a field in filter_options.h + a row in
// src/filter/option_table.cc (+ its use).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "posefilter/filter_options.h"

namespace posefilter {

enum class OptionType { kBool, kInt, kFloat, kDouble, kString, kUint64, kMoveProbabilities };

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

// How a validation message names an option.
enum class OptionNaming {
  kField,   // C++ field path: "anneal.subsample"
  kCli,     // "--anneal-subsample"
  kPython,  // "anneal_subsample"
};

struct OptionInfo {
  const char* name;      // CLI name without "--"; Python keyword = name with '-' → '_'
  const char* field;     // field path in FilterOptions, e.g. "anneal.subsample"
  const char* group;     // section of --help and docs/OPTIONS.md
  const char* help;      // one line, with the unit
  OptionType type;
  // Range of a number (kInt, kFloat, kDouble, kUint64; each element of kMoveProbabilities):
  // lo ≤ v ≤ hi, with lo < v where lo_open and v < hi where hi_open; ±inf = unbounded. A
  // non-finite value is never in range.
  double lo, hi;
  bool lo_open, hi_open;
  const char* choices;   // kString: the allowed values, '|'-separated; nullptr: any
  unsigned engines;      // EngineBits of the engines that read it
  // The field of `o` (typed by `type`: bool, int, float, double, std::string, std::uint64_t,
  // std::array<double, kNumMoves>).
  void* (*ref)(FilterOptions& o);

  // The option's name as `naming` spells it.
  std::string Name(OptionNaming naming) const;
  // The field's value and default as text ("0.02", "true", "cpu", "0.09,0.09,…").
  std::string ValueText(const FilterOptions& o) const;
  // Whether the field's value in `a` equals the one in `b`.
  bool SameValue(const FilterOptions& a, const FilterOptions& b) const;
  // The range as text: "[1, 4]", "(0, 1]", ">= 0", "> 0", "cpu|reference|hw", or "" (any).
  std::string RangeText() const;
  // The engines as text: "all" or e.g. "reference, cpu".
  std::string EnginesText() const;
  // The allowed values of a kString option with choices ({"cpu", "reference", "hw"}); empty
  // when any value goes.
  std::vector<std::string> Choices() const;

  template <class T>
  T& Of(FilterOptions& o) const { return *static_cast<T*>(ref(o)); }
  template <class T>
  const T& Of(const FilterOptions& o) const { return *static_cast<const T*>(ref(const_cast<FilterOptions&>(o))); }
};

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
    case OptionType::kMoveProbabilities: break;
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

// The table as a Markdown document (docs/OPTIONS.md): one section per group, one row per
// option with CLI name, Python keyword, default, range, engines and help.
std::string OptionTableMarkdown();

}  // namespace posefilter
