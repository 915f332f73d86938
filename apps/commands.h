// apps/commands.h — the CLI's subcommands, each a testable RunX(argc, argv).
//
// argv[0] is the subcommand name ("estimate", ...). Each returns the process exit status:
// 0 on success, 1 on an input error (one line "posefilter <cmd>: error: ..." on stderr),
// 2 on a usage error (unknown or malformed option, printed by CLI11).
#pragma once

#include <string>

namespace posefilter::cli {

int RunEstimate(int argc, char** argv);  // apps/estimate_cmd.cc
int RunDemo(int argc, char** argv);      // apps/demo_cmd.cc
int RunSynth(int argc, char** argv);     // apps/synth_cmd.cc
int RunEval(int argc, char** argv);      // apps/eval_cmd.cc
int RunSuite(int argc, char** argv);     // apps/suite_cmd.cc
int RunGtDetections(int argc, char** argv);  // apps/gt_detections_cmd.cc
int RunRunDataset(int argc, char** argv);    // apps/run_dataset_cmd.cc
int RunTrack(int argc, char** argv);     // apps/track_cmd.cc
int RunBench(int argc, char** argv);     // apps/bench_cmd.cc
int RunHwReport(int argc, char** argv);  // apps/hw_report_cmd.cc
int RunOptions(int argc, char** argv);   // apps/options_cmd.cc
int RunView(int argc, char** argv);      // apps/view_cmd.cc

// docs/OPTIONS.md, as `options --markdown` prints it: OptionTableMarkdown
// (posefilter/option_table.h), then the synthetic scenes' section (SynthOptionTable,
// posefilter/synth.h); apps/options_cmd.cc.
std::string OptionsMarkdown();

// `estimate` (view_command false) or `view` (true): one parser and body, apps/estimate_cmd.cc.
int RunEstimateCommand(int argc, char** argv, bool view_command);

}  // namespace posefilter::cli
