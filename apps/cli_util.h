// apps/cli_util.h — shared plumbing of the subcommands: option parsing and error reporting.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace posefilter::cli {

// Parses argv with `app`, then runs `body`. Maps failures to exit codes:
//   CLI11 parse error → CLI11's message, exit 2 (0 for --help);
//   posefilter::Error or std::exception → "posefilter <name>: error: <what>", exit 1.
int RunApp(CLI::App& app, int argc, char** argv, const std::function<void()>& body);

// The median of `v`: the middle value, or the mean of the two middle values for an even count;
// 0 for none. The tables of track, suite and bench print it.
double Median(std::vector<double> v);

// SynthOptions::IsValid's message `why` ("<field> must ...") with the field named by the CLI
// option that sets it too ("--min-distance (min_distance_m): must ..."; NameOptionRow of
// SynthOptionTable); unchanged when no row sets the field. `suite` names its scene options so.
std::string NameSynthOption(const std::string& why);

// Arguments "NAME=PATH" (or, unless require_name, "PATH" with name = the file's stem) of a
// repeatable option, in order, as {name, path}. Throws Error naming `option` for a malformed
// argument or a name given twice.
std::vector<std::pair<std::string, std::string>> ParseNamedPaths(const std::vector<std::string>& args,
                                                                 const std::string& option, bool require_name = false);

}  // namespace posefilter::cli
