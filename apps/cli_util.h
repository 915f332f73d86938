// apps/cli_util.h — shared plumbing of the subcommands: option parsing and error reporting.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace posefilter::cli {

// Parses argv with `app`, then runs `body`. Maps failures to exit codes:
//   CLI11 parse error → CLI11's message, exit 2 (0 for --help);
//   posefilter::Error or std::exception → "posefilter <name>: error: <what>", exit 1.
int RunApp(CLI::App& app, int argc, char** argv, const std::function<void()>& body);

// SynthOptions::IsValid's message `why` ("<field> must ...") with the field replaced by the
// CLI option that sets it ("--min-distance (min_distance_m): must ..."); unchanged when no
// option sets the field. Used by the commands that make synthetic scenes (synth, suite).
std::string NameSynthOption(const std::string& why);

}  // namespace posefilter::cli
