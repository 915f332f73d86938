// posefilter CLI: a thin dispatcher over the RunX subcommands of apps/commands.h.
#include <algorithm>
#include <cstring>
#include <iostream>
#include <string>

#include "commands.h"
#include "posefilter/version.h"
#include "filter/engine_registry.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* help;
};

constexpr Command kCommands[] = {
    {"demo", posefilter::cli::RunDemo,
     "generate a built-in synthetic scene, estimate the pose, print the error vs ground truth"},
    {"estimate", posefilter::cli::RunEstimate,
     "estimate object poses from a depth PNG, a camera JSON, meshes and a prior"},
    {"synth", posefilter::cli::RunSynth,
     "make synthetic scenes with ground truth and a stage-1 prior"},
    {"eval", posefilter::cli::RunEval, "compare a results JSON with a gt.json (ADD, ADD-S, recall)"},
    {"suite", posefilter::cli::RunSuite,
     "accuracy on N synthetic scenes (targets x occlusion levels): ADD-S table and recall"},
    {"gt-detections", posefilter::cli::RunGtDetections,
     "make a stage-1 detections JSON from ground-truth poses (jittered silhouette boxes)"},
    {"run-dataset", posefilter::cli::RunRunDataset,
     "estimate every target of a BOP / YCB-Video dataset into a BOP results CSV (resumable)"},
    {"track", posefilter::cli::RunTrack,
     "track objects through a sequence of depth frames (a dataset scene or a folder of PNGs), per-frame ADD-S"},
    {"bench", posefilter::cli::RunBench,
     "speed of the scoring engines on a fixed synthetic workload (ms per iteration, throughput)"},
    {"hw-report", posefilter::cli::RunHwReport,
     "cycle model of the hw engine (FPGA C simulation) on a synthetic scene, vs the thesis's figures"},
    {"view", posefilter::cli::RunView,
     "write a frame's 3D viewer page (HTML): point cloud, estimated and true poses, support plane, particles"},
    {"options", posefilter::cli::RunOptions,
     "every filter option: default, range, the engines that read it, meaning (--markdown: docs/OPTIONS.md)"},
};

void PrintUsage(std::ostream& os) {
  os << "usage: posefilter <command> [options]   (posefilter <command> --help for options)\n"
        "       posefilter --version   (or: posefilter version; the build's commit and engines too)\n"
        "commands:\n";
  std::size_t width = 0;
  for (const auto& c : kCommands) width = std::max(width, std::strlen(c.name));
  for (const auto& c : kCommands) os << "  " << c.name << std::string(width + 2 - std::strlen(c.name), ' ') << c.help << "\n";
}

// `posefilter --version`: the version, the commit of the build and the scoring engines it has
// (--engine values, one line per row of the engine registry, filter/engine_registry.h). The gpu
// line says whether the build has Vulkan, not whether this machine has a device (the gpu
// engine's own error says that, when asked for).
void PrintVersion(std::ostream& os) {
  os << "posefilter " << posefilter::Version() << " (git " << posefilter::GitRevision() << ")\n";
  os << "engines:\n";
  for (const posefilter::filter::EngineRow& row : posefilter::filter::EngineRegistry()) {
    const std::string name = row.name;
    os << "  " << name << std::string(name.size() < 11 ? 11 - name.size() : 1, ' ')
       << (row.describe ? row.describe() : std::string(row.summary)) << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    PrintUsage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? 2 : 0;
  }
  if (std::strcmp(argv[1], "--version") == 0 || std::strcmp(argv[1], "version") == 0) {
    if (argc > 2) {
      std::cerr << "posefilter: error: " << argv[1] << " takes no arguments (got '" << argv[2] << "')\n";
      return 2;
    }
    PrintVersion(std::cout);
    return 0;
  }
  for (const auto& c : kCommands) {
    if (std::strcmp(argv[1], c.name) == 0) return c.run(argc - 1, argv + 1);
  }
  std::cerr << "posefilter: error: unknown command '" << argv[1] << "'\n";
  PrintUsage(std::cerr);
  return 2;
}
