// posefilter suite — the accuracy suite: N synthetic scenes (targets and occlusion levels in
// turn, noisy detection prior with false positives), estimated with the given filter options,
// scored with ADD-S against the ground truth. Prints a table and the recall at 10% of the
// diameter; optionally writes it as JSON.
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/metrics.h"
#include "posefilter/synth.h"

namespace posefilter::cli {

int RunSuite(int argc, char** argv) {
  CLI::App app{"Accuracy of the filter on synthetic scenes with ground truth", "suite"};
  int count = 20;
  std::uint64_t first_seed = 1;
  std::vector<std::string> targets = SynthClassNames();
  std::vector<double> occlusions = {0.0, 0.3, 0.5};
  std::string json_path;
  SynthOptions synth;
  FilterOptions opt;
  app.add_option("--count", count, "number of scenes")->capture_default_str();
  app.add_option("--first-seed", first_seed, "scene i uses seed first_seed + i")->capture_default_str();
  app.add_option("--targets", targets, "object kinds, used in turn")->delimiter(',');
  app.add_option("--occlusions", occlusions, "occlusion levels, used in turn")->delimiter(',');
  app.add_option("--box-jitter", synth.box_jitter_px, "detection box noise sigma (px)")->capture_default_str();
  app.add_option("--false-positives", synth.false_positives, "false detections per scene")->capture_default_str();
  app.add_option("--min-distance", synth.min_distance_m, "min camera→target distance, m")->capture_default_str();
  app.add_option("--max-distance", synth.max_distance_m, "max camera→target distance, m")->capture_default_str();
  app.add_option("--json", json_path, "also write the table as JSON");
  AddFilterOptions(app, &opt);

  return RunApp(app, argc, argv, [&] {
    CheckFilterOptions(opt);
    if (count < 1) throw Error("--count must be >= 1");
    if (targets.empty() || occlusions.empty()) throw Error("--targets and --occlusions must not be empty");
    nlohmann::json rows = nlohmann::json::array();
    int found = 0;
    double total_ms = 0;
    std::printf("%5s %-9s %6s %9s %8s %6s %7s %5s %8s\n", "seed", "target", "occl", "ADD-S[mm]", "%diam", "found",
                "weight", "iter", "time[ms]");
    for (int i = 0; i < count; ++i) {
      SynthOptions so = synth;
      so.target = targets[i % targets.size()];
      so.occlusion = occlusions[(i / targets.size()) % occlusions.size()];
      std::string why;
      if (!so.IsValid(&why)) throw Error("invalid scene option " + NameSynthOption(why));
      const std::uint64_t seed = first_seed + i;
      const SynthScene scene = MakeSynthScene(so, seed);
      const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
      FilterOptions o = opt;
      o.seed = opt.seed + i;
      const EstimateResult r =
          EstimatePose(SceneInput{scene.depth, scene.camera}, scene.target, prior, prior.ClassIndex(scene.target.name), o);
      const double diameter = scene.target.Diameter();
      const PoseErrors e = ComputePoseErrors(SamplePoints(scene.target), diameter, r.T_cam_obj, scene.gt[0].T_cam_obj);
      found += e.adds_ok;
      total_ms += r.time_ms;
      std::printf("%5llu %-9s %6.2f %9.1f %8.1f %6s %7.3f %5d %8.0f\n", (unsigned long long)seed, so.target.c_str(),
                  scene.occlusion_achieved, 1000 * e.adds, 100 * e.adds / diameter, e.adds_ok ? "yes" : "NO", r.weight,
                  r.iterations, r.time_ms);
      std::fflush(stdout);
      rows.push_back({{"seed", seed}, {"target", so.target}, {"occlusion", scene.occlusion_achieved},
                      {"adds_m", e.adds}, {"add_m", e.add}, {"diameter_m", diameter}, {"found", e.adds_ok},
                      {"rot_deg", e.rot_deg}, {"trans_m", e.trans_m}, {"weight", r.weight},
                      {"iterations", r.iterations}, {"time_ms", r.time_ms}});
    }
    const double recall = double(found) / count;
    std::printf("recall (ADD-S < 10%% of diameter): %d/%d = %.0f%%, mean time %.0f ms per object\n", found, count,
                100 * recall, total_ms / count);
    if (!json_path.empty()) {
      std::ofstream out(json_path);
      if (!out) throw Error(json_path + ": cannot write");
      out << nlohmann::json{{"scenes", rows}, {"recall_adds", recall}}.dump(1) << "\n";
    }
  });
}

}  // namespace posefilter::cli
