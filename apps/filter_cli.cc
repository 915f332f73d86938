#include "filter_cli.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
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
        if (text.size() == 20 && text > "18446744073709551615") return range;
        return "";
      },
      "SEED");
}

void AddFilterOptions(CLI::App& app, FilterOptions* o) {
  for (const OptionInfo& f : FilterOptionTable()) {
    const std::string flag = f.Name(OptionNaming::kCli);
    CLI::Option* added = nullptr;
    switch (f.type) {
      case OptionType::kBool:
        // "--name" sets it, "--no-name" clears it; --help shows the default.
        added = app.add_flag(flag + ",!--no-" + f.name, f.Of<bool>(*o), f.help)->capture_default_str();
        break;
      case OptionType::kInt:
        added = app.add_option(flag, f.Of<int>(*o), f.help)->capture_default_str();
        break;
      case OptionType::kFloat:
        added = app.add_option(flag, f.Of<float>(*o), f.help)->capture_default_str();
        break;
      case OptionType::kDouble:
        added = app.add_option(flag, f.Of<double>(*o), f.help)->capture_default_str();
        break;
      case OptionType::kString: {
        added = app.add_option(flag, f.Of<std::string>(*o), f.help)->capture_default_str();
        if (f.choices != nullptr) {
          std::vector<std::string> choices;
          for (std::string c = f.choices; !c.empty();) {
            const std::size_t bar = c.find('|');
            choices.push_back(c.substr(0, bar));
            c = bar == std::string::npos ? "" : c.substr(bar + 1);
          }
          added->check(CLI::IsMember(choices));
        }
        break;
      }
      case OptionType::kUint64:
        added = app.add_option(flag, f.Of<std::uint64_t>(*o), f.help)->capture_default_str()->check(SeedValidator());
        break;
      case OptionType::kMoveProbabilities: {
        auto* moves = &f.Of<std::array<double, kNumMoves>>(*o);
        added = app.add_option_function<std::vector<double>>(
                       flag,
                       [moves, flag](const std::vector<double>& v) {
                         if (v.size() != moves->size())
                           throw CLI::ValidationError(flag, "takes " + std::to_string(moves->size()) + " numbers, got " +
                                                                std::to_string(v.size()));
                         std::copy(v.begin(), v.end(), moves->begin());
                       },
                       f.help)
                    ->expected(kNumMoves)
                    ->default_str(f.ValueText(FilterOptions{}));
        break;
      }
    }
    added->group(std::string("Filter options: ") + f.group);
  }
}

void CheckFilterOptions(const FilterOptions& opt) {
  std::string why;
  if (!ValidateFilterOptions(opt, OptionNaming::kCli, &why)) throw Error("invalid filter option: " + why);
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
