// posefilter/option_rows.h — an options struct's fields as data: one row per field with its CLI
// name, C++ field path, group, help (with unit), type, range and, where the thesis fixes it, the
// thesis's value. A table of rows drives the struct's range checks and their messages, its CLI
// flags (apps/filter_cli.h), its Python keywords and its section of docs/OPTIONS.md.
//
// The tables: FilterOptionTable (posefilter/option_table.h, with the engines that read each
// option), HeuristicOptionTable (posefilter/heuristics.h), TrackOptionTable
// (posefilter/tracker.h), ScenePassOptionTable (posefilter/scene_pass.h), AutoPriorOptionTable
// (posefilter/auto_prior.h), SynthOptionTable (posefilter/synth.h).
//
// Names: the CLI option is "--" + name (a bool: "--name" / "--no-name"); the Python keyword is
// `python` where a row sets it, else name with '-' → '_'.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

namespace posefilter {

// kDoubles: a std::array<double, count> field (FilterOptions' move probabilities).
enum class OptionType { kBool, kInt, kFloat, kDouble, kString, kUint64, kDoubles };

// How a validation message names an option.
enum class OptionNaming {
  kField,   // C++ field path: "anneal.subsample"
  kCli,     // "--anneal-subsample"
  kPython,  // "anneal_subsample"
};

// lo ≤ v ≤ hi, with lo < v where lo_open and v < hi where hi_open; ±inf = unbounded.
struct OptionRange {
  double lo, hi;
  bool lo_open, hi_open;
};
inline constexpr double kOptionInf = std::numeric_limits<double>::infinity();
constexpr OptionRange ClosedRange(double lo, double hi) { return {lo, hi, false, false}; }
constexpr OptionRange AtLeastRange(double lo) { return {lo, kOptionInf, false, false}; }
inline constexpr OptionRange kPositiveRange = {0, kOptionInf, true, false};        // > 0
inline constexpr OptionRange kFractionRange = {0, 1, false, false};                // [0, 1]
inline constexpr OptionRange kPositiveFractionRange = {0, 1, true, false};         // (0, 1]
inline constexpr OptionRange kAnyRange = {-kOptionInf, kOptionInf, false, false};  // unchecked

struct OptionInfo {
  const char* name;      // CLI name without "--"
  const char* field;     // field path in the options struct, e.g. "anneal.subsample"
  const char* group;     // section of --help and docs/OPTIONS.md
  const char* help;      // one line, with the unit
  OptionType type;
  // Range of a number (kInt, kFloat, kDouble, kUint64; each element of kDoubles). A non-finite
  // value is never in range.
  double lo, hi;
  bool lo_open, hi_open;
  const char* choices;   // kString: the allowed values, '|'-separated; nullptr: any
  unsigned engines;      // FilterOptions rows: EngineBits (posefilter/option_table.h); other sets 0
  // The thesis's value (Ch. 7; as ValueText spells it) where the thesis fixes one; nullptr where
  // the option is a run's own choice or the thesis says nothing of it.
  const char* thesis;
  // With a thesis value: whether a thesis configuration (ThesisFilterOptions, hw-report's
  // "thesis") keeps the caller's value instead of setting the thesis's: the run's scale
  // (particles, iterations, windows) and the thresholds the caller may vary. false: an
  // extension of ours that the thesis configuration switches off.
  bool thesis_kept;
  const char* python;    // the Python keyword where it is not name with '-' → '_'; else nullptr
  int count;             // kDoubles: the array's length; 1 otherwise
  const std::type_info* owner;  // the options struct the field belongs to
  // The field of an options struct of type *owner (typed by `type`: bool, int, float, double,
  // std::string, std::uint64_t, std::array<double, count>).
  void* (*ref)(void* options);

  // The option's name as `naming` spells it.
  std::string Name(OptionNaming naming) const;
  // The range as text: "[1, 4]", "(0, 1]", ">= 0", "> 0", "cpu|reference|hw", or "" (any).
  std::string RangeText() const;
  // The allowed values of a kString option with choices ({"cpu", "reference", "hw"}); empty
  // when any value goes.
  std::vector<std::string> Choices() const;
  // The engines as text: "all" or e.g. "reference, cpu" (FilterOptions rows; defined with the
  // engine registry, src/filter/option_table.cc).
  std::string EnginesText() const;

  // The field's value as text ("0.02", "true", "cpu", "0.09,0.09,…"); `o` is of type *owner.
  template <class Options>
  std::string ValueText(const Options& o) const { return ValueTextAt(Field(o)); }
  // Whether the field's value in `a` equals the one in `b`.
  template <class Options>
  bool SameValue(const Options& a, const Options& b) const { return SameValueAt(Field(a), Field(b)); }
  // Sets the field of `o` from text as ValueText spells it ("0", "false", "1,1,0"); false with
  // *why set when the text does not read as the field's type.
  template <class Options>
  bool SetFromText(Options& o, const std::string& text, std::string* why) const {
    return SetFromTextAt(Field(o), text, why);
  }

  template <class T, class Options>
  T& Of(Options& o) const { return *static_cast<T*>(Field(o)); }
  template <class T, class Options>
  const T& Of(const Options& o) const { return *static_cast<const T*>(Field(o)); }

  // The field's address in `o`; throws std::logic_error when Options is not the row's struct.
  template <class Options>
  void* Field(Options& o) const {
    using O = std::remove_const_t<Options>;
    CheckOwner(typeid(O));
    return ref(const_cast<O*>(&o));
  }

  std::string ValueTextAt(const void* field) const;
  bool SameValueAt(const void* a, const void* b) const;
  bool SetFromTextAt(void* field, const std::string& text, std::string* why) const;
  void CheckOwner(const std::type_info& t) const;
};

// The type code of a field type.
template <class T>
constexpr OptionType OptionTypeOf() {
  if constexpr (std::is_same_v<T, bool>) return OptionType::kBool;
  else if constexpr (std::is_same_v<T, int>) return OptionType::kInt;
  else if constexpr (std::is_same_v<T, float>) return OptionType::kFloat;
  else if constexpr (std::is_same_v<T, double>) return OptionType::kDouble;
  else if constexpr (std::is_same_v<T, std::string>) return OptionType::kString;
  else if constexpr (std::is_same_v<T, std::uint64_t>) return OptionType::kUint64;
  else {
    static_assert(std::is_same_v<typename T::value_type, double> && sizeof(T) == sizeof(double) * std::tuple_size_v<T>,
                  "an option field of an unknown type");
    return OptionType::kDoubles;
  }
}
template <class T>
constexpr int OptionCountOf() {
  if constexpr (OptionTypeOf<T>() == OptionType::kDoubles) return int(std::tuple_size_v<T>);
  else return 1;
}

// A row without range, choices, engines, thesis value or Python spelling; set those on the
// result. Build it with POSEFILTER_OPTION_ROW.
OptionInfo MakeOptionRow(const char* name, const char* field, void* (*ref)(void*), OptionType type, int count,
                         const std::type_info* owner, const char* group, OptionRange range, const char* help);

// The field path, its accessor, its type and its struct, from one spelling of the path:
// MakeOptionRow("lost-weight", POSEFILTER_OPTION_FIELD(TrackOptions, lost_weight), group, range, help).
#define POSEFILTER_OPTION_FIELD(Options, path)                                                         \
  #path, [](void* o) -> void* { return &static_cast<Options*>(o)->path; },                           \
      ::posefilter::OptionTypeOf<std::remove_cvref_t<decltype(std::declval<Options&>().path)>>(),     \
      ::posefilter::OptionCountOf<std::remove_cvref_t<decltype(std::declval<Options&>().path)>>(), \
      &typeid(Options)

// The row of `rows` whose field path, name or Python keyword is `key`; nullptr when none.
const OptionInfo* FindOptionRow(std::span<const OptionInfo> rows, const std::string& key);

// Every range and choice list of `rows` on `o` (of the rows' struct); false with *why naming the
// first option out of range as `naming` spells it ("lost_weight must be in [0, 1] (got 2)").
bool ValidateOptionRows(std::span<const OptionInfo> rows, const void* o, OptionNaming naming, std::string* why);
template <class Options>
bool ValidateOptionRows(std::span<const OptionInfo> rows, const Options& o, OptionNaming naming, std::string* why) {
  for (const OptionInfo& f : rows) f.CheckOwner(typeid(Options));
  return ValidateOptionRows(rows, static_cast<const void*>(&o), naming, why);
}

// The shortest text that reads back as v (an integral value without exponent; "inf").
std::string OptionNumberText(double v);
std::string OptionNumberText(float v);

// A table as a Markdown section body: one row per option with CLI name, Python keyword, C++
// field, default (from `defaults`, of the rows' struct), range and meaning.
std::string OptionRowsMarkdown(std::span<const OptionInfo> rows, const void* defaults);
// An option set's section of docs/OPTIONS.md: "## " + title, the paragraph `intro`, then
// OptionRowsMarkdown(rows, defaults).
std::string OptionSetMarkdown(const std::string& title, const std::string& intro, std::span<const OptionInfo> rows,
                              const void* defaults);

}  // namespace posefilter
