// apps/options_cmd.cc — `posefilter options`: every filter option (posefilter/option_table.h)
// with its default, range, engines, thesis value and meaning, then the other option sets'
// tables (tracker, scene pass, auto prior, synthetic scenes); --markdown prints docs/OPTIONS.md.
#include <cstdio>
#include <span>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "posefilter/auto_prior.h"
#include "posefilter/filter_options.h"
#include "posefilter/option_table.h"
#include "posefilter/scene_pass.h"
#include "posefilter/synth.h"
#include "posefilter/tracker.h"

namespace posefilter::cli {
namespace {

// One line per row: flag, default, range, engines (filter rows), thesis value, meaning.
template <class Options>
void PrintOptionRows(std::span<const OptionInfo> rows, const Options& defaults, bool engines, bool first_group) {
  std::string group;
  for (const OptionInfo& f : rows) {
    if (group != f.group) {
      std::printf("%s%s:\n", first_group ? "" : "\n", f.group);
      group = f.group;
      first_group = false;
    }
    const std::string range = f.RangeText();
    const std::string thesis = f.thesis == nullptr ? "-" : std::string(f.thesis) + (f.thesis_kept ? " (kept)" : "");
    std::printf("  --%-28s %-18s %-26s %-15s %-12s %s\n", f.name, f.ValueText(defaults).c_str(),
                range.empty() ? "-" : range.c_str(), engines ? f.EnginesText().c_str() : "-", thesis.c_str(), f.help);
  }
}

}  // namespace

std::string OptionsMarkdown() {
  const SynthOptions synth;
  return OptionTableMarkdown() +
         OptionSetMarkdown("Synthetic scenes",
                           "`posefilter synth` and `posefilter.make_synth_scene` (the keyword is the C++ field); C++: "
                           "`posefilter::SynthOptions` (posefilter/synth.h), whose camera and target mesh (`--mesh`,\n"
                           "`target_mesh=`) are set outside this table. `synth --world ycbv` and `room` read only the "
                           "distances,\n`--box-jitter` and `--false-positives`.",
                           SynthOptionTable(), &synth);
}

int RunOptions(int argc, char** argv) {
  CLI::App app{"Every option: name, default, range, engines that read it, the thesis's value, meaning", "options"};
  bool markdown = false;
  app.add_flag("--markdown", markdown, "print the tables as Markdown (docs/OPTIONS.md)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (markdown) {
    std::fputs(OptionsMarkdown().c_str(), stdout);
    return 0;
  }
  std::printf("%-30s %-18s %-26s %-15s %-12s %s\n\n", "option", "default", "range", "engines", "thesis", "meaning");
  PrintOptionRows(FilterOptionTable(), FilterOptions{}, true, true);
  PrintOptionRows(TrackOptionTable(), TrackOptions{}, false, false);
  PrintOptionRows(ScenePassOptionTable(), ScenePassOptions{}, false, false);
  PrintOptionRows(AutoPriorOptionTable(), AutoPriorOptions{}, false, false);
  PrintOptionRows(SynthOptionTable(), SynthOptions{}, false, false);
  return 0;
}

}  // namespace posefilter::cli
