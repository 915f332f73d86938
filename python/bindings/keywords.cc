// python/bindings/keywords.cc — the keyword options of Estimator (the rows of the option table,
// posefilter/option_table.h), of the tracker, the scene pass, the auto prior and make_synth_scene
// (the rows of their tables, posefilter/option_rows.h; make_synth_scene's camera besides).
#include "bindings.h"

namespace posefilter::python {

namespace {

// The keyword of one row of an options table: its Python spelling, a setter and a getter of the
// row's field (of type T).
template <class Options, class T>
Keyword<Options> RowKeyword(const OptionInfo& f) {
  const OptionInfo* row = &f;
  return {f.Name(OptionNaming::kPython), [row](Options& o, py::handle h) { row->Of<T>(o) = h.cast<T>(); },
          [row](const Options& o) { return py::cast(row->Of<T>(o)); }};
}

// One keyword per row of `rows`, in their order.
template <class Options>
std::vector<Keyword<Options>> RowKeywords(std::span<const OptionInfo> rows) {
  std::vector<Keyword<Options>> out;
  Options typed;  // only the fields' types are read
  for (const OptionInfo& f : rows)
    VisitOption(f, typed, [&](auto& v) { out.push_back(RowKeyword<Options, std::remove_cvref_t<decltype(v)>>(f)); });
  return out;
}

}  // namespace

// One keyword per row of the option table (posefilter/option_table.h), in its order.
const std::vector<Keyword<FilterOptions>>& FilterKeywords() {
  static const std::vector<Keyword<FilterOptions>> k = RowKeywords<FilterOptions>(FilterOptionTable());
  return k;
}

const std::vector<Keyword<TrackOptions>>& TrackKeywords() {
  static const std::vector<Keyword<TrackOptions>> k = RowKeywords<TrackOptions>(TrackOptionTable());
  return k;
}

const std::vector<Keyword<ScenePassOptions>>& ScenePassKeywords() {
  static const std::vector<Keyword<ScenePassOptions>> k = RowKeywords<ScenePassOptions>(ScenePassOptionTable());
  return k;
}

const std::vector<Keyword<AutoPriorOptions>>& AutoPriorKeywords() {
  static const std::vector<Keyword<AutoPriorOptions>> k = RowKeywords<AutoPriorOptions>(AutoPriorOptionTable());
  return k;
}

std::string PythonTypeName(OptionType t) {
  switch (t) {
    case OptionType::kBool: return "bool";
    case OptionType::kInt:
    case OptionType::kUint64: return "int";
    case OptionType::kFloat:
    case OptionType::kDouble: return "float";
    case OptionType::kString: return "str";
    case OptionType::kDoubles: return "Sequence[float]";
  }
  return "object";
}

std::string KeywordDocHead(const OptionInfo& f, const std::string& default_text) {
  const std::string range = f.RangeText();
  return "  " + f.Name(OptionNaming::kPython) + ": " + PythonTypeName(f.type) + " = " + default_text +
         (range.empty() ? "" : ", " + range);
}

const std::string& EstimatorDoc() {
  static const std::string doc = [] {
    std::string d =
        "The particle filter with fixed options: Estimator(**options), each keyword one of the CLI's filter "
        "options with '-' as '_' (`posefilter options`, docs/OPTIONS.md). Units: metres, radians, pixels.\n\n"
        "Keywords (type = default, range; engines that read it: meaning):\n";
    const FilterOptions defaults;
    std::string group;
    for (const OptionInfo& f : FilterOptionTable()) {
      if (group != f.group) d += "\n" + (group = f.group) + ":\n";
      d += KeywordDocHead(f, f.ValueText(defaults)) + "; " + f.EnginesText() + ": " + f.help + "\n";
    }
    return d;
  }();
  return doc;
}

const std::vector<Keyword<SynthOptions>>& SynthKeywords() {
  static const std::vector<Keyword<SynthOptions>> k = [] {
    // The camera, then one keyword per row; target_mesh (a pointer) is make_synth_scene's own.
    std::vector<Keyword<SynthOptions>> out = {Field("camera", &SynthOptions::camera)};
    for (Keyword<SynthOptions>& row : RowKeywords<SynthOptions>(SynthOptionTable())) out.push_back(std::move(row));
    return out;
  }();
  return k;
}

FilterOptions CheckedFilterOptions(const FilterOptions& o) {
  ThrowIfInvalid(o, OptionNaming::kPython);
  WarnAll(IgnoredOptions(o, OptionNaming::kPython));
  return o;
}

}  // namespace posefilter::python
