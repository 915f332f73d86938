// apps/options_cmd.cc — `posefilter options`: every filter option (posefilter/option_table.h)
// with its default, range, engines and meaning; --markdown prints docs/OPTIONS.md.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "posefilter/filter_options.h"
#include "posefilter/option_table.h"

namespace posefilter::cli {

int RunOptions(int argc, char** argv) {
  CLI::App app{"Every filter option: name, default, range, engines that read it, meaning", "options"};
  bool markdown = false;
  app.add_flag("--markdown", markdown, "print the table as Markdown (docs/OPTIONS.md)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (markdown) {
    std::fputs(OptionTableMarkdown().c_str(), stdout);
    return 0;
  }
  const FilterOptions defaults;
  std::string group;
  for (const OptionInfo& f : FilterOptionTable()) {
    if (group != f.group) {
      group = f.group;
      std::printf("%s%s:\n", group == FilterOptionTable().front().group ? "" : "\n", f.group);
    }
    const std::string range = f.RangeText();
    std::printf("  --%-28s %-18s %-26s %-15s %s\n", f.name, f.ValueText(defaults).c_str(),
                range.empty() ? "-" : range.c_str(), f.EnginesText().c_str(), f.help);
  }
  return 0;
}

}  // namespace posefilter::cli
