// posefilter view — the 3D viewer page of a frame (posefilter/view.h, docs/VIEWER.md): one
// self-contained HTML file with the point cloud, the meshes in their estimated and true poses,
// the support plane and the particle sets of every iteration.
//
// It takes the inputs of `estimate` and estimates the objects with the particle sets recorded
// (FilterOptions::record_particles); --out names the page and --json the results JSON. With
// --results it shows an estimate's results JSON on the frame without estimating (no
// particles then). The command is `estimate`'s parser and body in its view form
// (RunEstimateCommand, apps/estimate_cmd.cc).
#include "commands.h"
#include "view_cli.h"

namespace posefilter::cli {

int RunView(int argc, char** argv) { return RunEstimateCommand(argc, argv, /*view_command=*/true); }

}  // namespace posefilter::cli
