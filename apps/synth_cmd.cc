// apps/synth_cmd.cc — `posefilter synth`: writes synthetic scenes with ground truth and a
// stage-1 prior (synth.h), one folder per scene: DIR/scene_000, DIR/scene_001, …
// Scene i uses seed S + i. Prints one line per scene: folder, target, distance, occlusion.
// With --sequence N: one scene whose target moves over N frames (SynthMotion), written as a
// YCB-Video-style dataset folder (WriteSynthSequence) that `track` and `run-dataset` read.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mesh.h"
#include "posefilter/synth.h"

namespace posefilter::cli {

int RunSynth(int argc, char** argv) {
  CLI::App app{"Make synthetic depth scenes with ground truth and a stage-1 prior", "synth"};
  std::string out_dir;
  int count = 1;
  std::uint64_t seed = 1;
  SynthOptions opt;
  std::string mesh_path;
  double unit_scale = 1.0;
  bool no_missing_edges = false;
  app.add_option("--out", out_dir, "output folder (scenes go to OUT/scene_000, ...)")->required();
  app.add_option("--count", count, "number of scenes")->capture_default_str();
  app.add_option("--seed", seed, "seed of the first scene (scene i uses seed + i)")->capture_default_str()->transform(SeedValidator());
  auto* target_opt =
      app.add_option("--target", opt.target, "object kind: box, cylinder, lshape or torus")->capture_default_str();
  auto* mesh_opt = app.add_option("--mesh", mesh_path, "a user mesh (.ply/.obj/.stl) as the target; class = file stem");
  target_opt->excludes(mesh_opt);
  app.add_option("--unit-scale", unit_scale, "--mesh coordinates × this = metres (0.001 for mm)")
      ->capture_default_str();
  app.add_option("--min-distance", opt.min_distance_m, "min camera→target distance, m")->capture_default_str();
  app.add_option("--max-distance", opt.max_distance_m, "max camera→target distance, m")->capture_default_str();
  app.add_option("--occlusion", opt.occlusion, "fraction of the target hidden by an occluder, [0, 0.9]")
      ->capture_default_str();
  app.add_option("--clutter", opt.clutter, "clutter objects on the table, [0, 20]")->capture_default_str();
  app.add_option("--noise", opt.noise_sigma_m, "depth noise σ at 1 m, metres (σ grows with z²)")
      ->capture_default_str();
  app.add_option("--holes", opt.hole_fraction, "fraction of pixels dropped in blobs, [0, 0.5]")->capture_default_str();
  app.add_flag("--no-missing-edges", no_missing_edges, "keep pixels at depth discontinuities");
  app.add_option("--box-jitter", opt.box_jitter_px, "σ of the detection box noise, pixels")->capture_default_str();
  app.add_option("--miss-prob", opt.miss_probability, "probability that the target is not detected")
      ->capture_default_str();
  app.add_option("--false-positives", opt.false_positives, "extra false detections per scene")
      ->capture_default_str();
  app.add_option("--depth-scale", opt.depth_scale, "metres per depth PNG unit")->capture_default_str();
  SynthMotion motion;
  int sequence = 0;
  app.add_option("--sequence", sequence,
                 "write one scene whose target moves over this many frames, as a dataset folder OUT/scenes/synth_0000_<frame>/ "
                 "+ OUT/models/ (for track and run-dataset)");
  app.add_option("--speed", motion.speed_m, "--sequence: the target's slide per frame along the table (m)")->capture_default_str();
  app.add_option("--turn", motion.turn_rad, "--sequence: its turn per frame about the table's normal (rad)")->capture_default_str();
  app.add_option("--jump-frame", motion.jump_frame, "--sequence: from this frame on (1 or later; frames count from 0), the target is also displaced by --jump (-1 = never)")
      ->capture_default_str();
  app.add_option("--jump", motion.jump_m, "--sequence: the jump's length along the slide (m)")->capture_default_str();

  return RunApp(app, argc, argv, [&] {
    if (count < 1 || count > 100000) throw Error("--count must be in [1, 100000]");
    if (seed > UINT64_MAX - std::uint64_t(count - 1))
      throw Error("--seed + --count - 1 is above 2^64 - 1: the last scene's seed would wrap to 0");
    opt.missing_edges = !no_missing_edges;
    std::unique_ptr<Mesh> mesh;
    if (!mesh_path.empty()) {
      // The folders this run writes: OUT itself for --sequence, OUT/scene_NNN otherwise. A --mesh
      // inside one of them could be replaced by the scene's copy of it, so it is refused.
      const std::filesystem::path mesh_dir = std::filesystem::absolute(mesh_path).parent_path();
      bool written = false;
      if (app.count("--sequence")) {
        for (auto d = mesh_dir; !written; d = d.parent_path()) {
          written = SamePath(d.string(), out_dir);
          if (d == d.parent_path()) break;  // the root
        }
      } else {
        char name[32];
        for (int i = 0; i < count && !written; ++i) {
          std::snprintf(name, sizeof name, "scene_%03d", i);
          written = SamePath(mesh_dir.string(), (std::filesystem::path(out_dir) / name).string());
        }
      }
      if (written)
        throw Error("--mesh " + mesh_path + ": lies in a folder this run writes (--out " + out_dir +
                    "), where it could be overwritten; copy it elsewhere or give another --out");
      if (!std::isfinite(unit_scale) || unit_scale <= 0) throw Error("--unit-scale must be finite and > 0");
      mesh = std::make_unique<Mesh>(LoadMesh(mesh_path, unit_scale));
      opt.target_mesh = mesh.get();
    }
    std::string why;
    if (!opt.IsValid(&why)) throw Error("invalid option " + NameSynthOption(why));
    if (app.count("--sequence")) {
      if (app.count("--count")) throw Error("--sequence writes one moving scene; --count does not apply");
      motion.frames = sequence;
      if (!motion.IsValid(&why)) throw Error("invalid --sequence motion: " + why);
      const std::vector<SynthScene> frames = MakeSynthSequence(opt, motion, seed);
      WriteSynthSequence(frames, out_dir);
      std::printf("%s  target %s  %zu frames  distance %.3f m  slide %.3f m/frame  turn %.3f rad/frame%s\n", out_dir.c_str(),
                  frames.front().target.name.c_str(), frames.size(), frames.front().distance_m, motion.speed_m, motion.turn_rad,
                  motion.jump_frame >= 0 ? ("  jump " + std::to_string(motion.jump_m) + " m at frame " + std::to_string(motion.jump_frame)).c_str() : "");
      return;
    }
    if (app.count("--speed") + app.count("--turn") + app.count("--jump-frame") + app.count("--jump"))
      throw Error("--speed, --turn, --jump-frame and --jump describe a --sequence; give --sequence N");
    for (int i = 0; i < count; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "scene_%03d", i);
      const std::string dir = (std::filesystem::path(out_dir) / name).string();
      const SynthScene scene = MakeSynthScene(opt, seed + std::uint64_t(i));
      WriteSynthScene(scene, dir);
      std::printf("%s  target %s  distance %.3f m  occlusion %.2f  detections %zu%s\n", dir.c_str(),
                  scene.target.name.c_str(), scene.distance_m, scene.occlusion_achieved, scene.detections.size(),
                  scene.target_detected ? "" : " (target missed)");
    }
  });
}

}  // namespace posefilter::cli
