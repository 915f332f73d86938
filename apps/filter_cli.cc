#include "filter_cli.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/option_table.h"

namespace posefilter::cli {

CLI::Validator SeedValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const std::string range = "must be an integer in [0, 18446744073709551615] (got '" + text + "')";
        if (text.empty() || text.size() > 20 || !std::all_of(text.begin(), text.end(), [](unsigned char c) {
              return std::isdigit(c) != 0;
            }))
          return range;
        // Decimal: CLI11 would read a leading 0 as octal ("010" = 8); the zeros go first.
        const std::size_t nz = text.find_first_not_of('0');
        text = nz == std::string::npos ? "0" : text.substr(nz);
        if (text.size() == 20 && text > "18446744073709551615") return range;
        return "";
      },
      "SEED");
}

namespace {

// Registers one flag per row of `rows` on `app`, writing into the fields of *o (defaults: *o's
// values), each in the --help section `section` + the row's group (or `section` alone).
template <class Options>
void AddOptionRowFlags(CLI::App& app, std::span<const OptionInfo> rows, Options* o, const std::string& section,
                       bool with_group) {
  const Options defaults = *o;
  for (const OptionInfo& f : rows) {
    const std::string flag = f.Name(OptionNaming::kCli);
    CLI::Option* added = VisitOption(f, *o, [&](auto& value) {
      using T = std::remove_cvref_t<decltype(value)>;
      if constexpr (std::is_same_v<T, bool>) {
        // "--name" sets it, "--no-name" clears it; --help shows the default.
        return app.add_flag(flag + ",!--no-" + f.name, value, f.help)->default_str(value ? "true" : "false");
      } else if constexpr (std::is_same_v<T, std::array<double, kNumMoves>>) {
        return app
            .add_option_function<std::vector<double>>(
                flag,
                [&value, flag](const std::vector<double>& v) {
                  if (v.size() != value.size())
                    throw CLI::ValidationError(flag, "takes " + std::to_string(value.size()) + " numbers, got " +
                                                         std::to_string(v.size()));
                  std::copy(v.begin(), v.end(), value.begin());
                },
                f.help)
            ->expected(kNumMoves)
            ->default_str(f.ValueText(defaults));
      } else {
        CLI::Option* opt = app.add_option(flag, value, f.help)->capture_default_str();
        if constexpr (std::is_same_v<T, std::uint64_t>) opt->transform(SeedValidator());
        if (const std::vector<std::string> choices = f.Choices(); !choices.empty()) opt->check(CLI::IsMember(choices));
        return opt;
      }
    });
    added->group(with_group ? section + ": " + f.group : section);
  }
}

// Throws Error("<what>: " + IsValid's message, its leading field named by NameOptionRow) unless
// `o` is valid.
template <class Options>
void CheckOptionRows(std::span<const OptionInfo> rows, const Options& o, const std::string& what) {
  std::string why;
  if (!o.IsValid(&why)) throw Error(what + ": " + NameOptionRow(rows, why));
}

}  // namespace

std::string NameOptionRow(std::span<const OptionInfo> rows, const std::string& why) {
  for (const OptionInfo& f : rows) {
    const std::string field = f.field;
    if (why.rfind(field + " ", 0) == 0)
      return f.Name(OptionNaming::kCli) + " (" + field + "): " + why.substr(field.size() + 1);
  }
  return why;
}

void AddFilterOptions(CLI::App& app, FilterOptions* o) {
  AddOptionRowFlags(app, FilterOptionTable(), o, "Filter options", true);
}

void AddTrackOptions(CLI::App& app, TrackOptions* o) {
  AddOptionRowFlags(app, TrackOptionTable(), o, "Tracker options", false);
}

void AddScenePassOptions(CLI::App& app, ScenePassOptions* o) {
  AddOptionRowFlags(app, ScenePassOptionTable(), o, "Scene pass options", false);
}

void AddAutoPriorOptions(CLI::App& app, AutoPriorOptions* o) {
  AddOptionRowFlags(app, AutoPriorOptionTable(), o, "Auto prior options", false);
}

void AddSynthOptions(CLI::App& app, SynthOptions* o) {
  AddOptionRowFlags(app, SynthOptionTable(), o, "Synthetic scene options", false);
}

void CheckTrackOptions(const TrackOptions& o) { CheckOptionRows(TrackOptionTable(), o, "invalid track option"); }

void CheckScenePassOptions(const ScenePassOptions& o) {
  CheckOptionRows(ScenePassOptionTable(), o, "invalid scene pass option");
}

void CheckAutoPriorOptions(const AutoPriorOptions& o) {
  CheckOptionRows(AutoPriorOptionTable(), o, "invalid auto prior option");
}

void CheckSynthOptions(const SynthOptions& o) { CheckOptionRows(SynthOptionTable(), o, "invalid synth option"); }

void CheckFilterOptions(const FilterOptions& opt) {
  ThrowIfInvalid(opt, OptionNaming::kCli);
  for (const std::string& w : IgnoredOptions(opt, OptionNaming::kCli)) std::fprintf(stderr, "warning: %s\n", w.c_str());
}

ProgressFn StderrProgress(const std::string& obj, int max_iterations, bool quiet) {
  if (quiet) return nullptr;
  const bool tty = isatty(fileno(stderr));
  return [obj, max_iterations, tty](int it, double w) {
    // The best weight at the final inlier threshold; none yet while the first run anneals.
    char weight[48];
    if (std::isnan(w))
      std::snprintf(weight, sizeof weight, "annealing");
    else
      std::snprintf(weight, sizeof weight, "best weight %.3f", w);
    if (tty) {
      std::fprintf(stderr, "\r%s: iteration %d/%d, %s   ", obj.c_str(), it + 1, max_iterations, weight);
    } else if ((it + 1) % 10 == 0) {
      std::fprintf(stderr, "%s: iteration %d/%d, %s\n", obj.c_str(), it + 1, max_iterations, weight);
    }
    std::fflush(stderr);
  };
}

}  // namespace posefilter::cli
