// apps/synth_cmd.cc — `posefilter synth`: writes synthetic scenes with ground truth and a
// stage-1 prior (synth.h), one folder per scene: DIR/scene_000, DIR/scene_001, …
// Scene i uses seed S + i. Prints one line per scene: folder, target, distance, occlusion.
// With --sequence N: one scene whose target moves over N frames (SynthMotion), written as a
// YCB-Video-style dataset folder (WriteSynthSequence) that `track` and `run-dataset` read.
// With --world ycbv or room: scenes of the YCB-Video meshes on a table (table_world.h) or in a
// room (room_world.h), written by WriteTableScene, as `suite --write-scenes` writes them.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/mesh.h"
#include "posefilter/room_world.h"
#include "posefilter/synth.h"
#include "posefilter/table_world.h"

namespace posefilter::cli {
namespace {

// The parsed command line of `synth`.
struct SynthArgs {
  std::string out_dir;
  int count = 1;
  std::uint64_t seed = 1;
  SynthOptions opt;
  std::string mesh_path;
  double unit_scale = 1.0;
  std::string world = "shapes";
  std::string models_dir;
  TableSceneOptions table;
  RoomSceneOptions room;
  int min_objects = 0, max_objects = 0;
  SynthMotion motion;
  int sequence = 0;
};

// Every option of `synth` on `app`, into a: the command's own, then SynthOptionTable's rows
// (AddSynthOptions), then the motion of --sequence.
void AddSynthArgs(CLI::App& app, SynthArgs& a) {
  if (const char* data = std::getenv("POSEFILTER_DATA"); data != nullptr && *data != '\0')
    a.models_dir = (std::filesystem::path(data) / "ycbv" / "models").string();
  app.add_option("--world", a.world,
                 "shapes: one procedural shape per scene; ycbv: YCB-Video objects on a table; room: YCB-Video objects "
                 "on small raised surfaces and shelf boards in a room (docs/SYNTHETIC.md)")
      ->check(CLI::IsMember({"shapes", "ycbv", "room"}))
      ->capture_default_str();
  app.add_option("--models", a.models_dir,
                 "ycbv, room: folder of the 21 YCB-Video meshes (default: $POSEFILTER_DATA/ycbv/models)")
      ->capture_default_str();
  app.add_option("--min-objects", a.min_objects, "ycbv, room: objects per scene, at least (ycbv 3, room 2)");
  app.add_option("--max-objects", a.max_objects, "ycbv, room: objects per scene, at most (ycbv 6, room 4)");
  app.add_option("--out", a.out_dir, "output folder (scenes go to OUT/scene_000, ...)")->required();
  app.add_option("--count", a.count, "number of scenes")->capture_default_str();
  app.add_option("--seed", a.seed, "seed of the first scene (scene i uses seed + i)")
      ->capture_default_str()
      ->transform(SeedValidator());
  auto* mesh_opt =
      app.add_option("--mesh", a.mesh_path, "a user mesh (.ply/.obj/.stl) as the target; class = file stem");
  app.add_option("--unit-scale", a.unit_scale, "--mesh coordinates × this = metres (0.001 for mm)")
      ->capture_default_str();
  AddSynthOptions(app, &a.opt);
  app.get_option("--target")->excludes(mesh_opt);
  app.add_option(
      "--sequence", a.sequence,
      "write one scene whose target moves over this many frames, as a dataset folder OUT/scenes/synth_0000_<frame>/ "
      "+ OUT/models/ (for track and run-dataset)");
  app.add_option("--speed", a.motion.speed_m, "--sequence: the target's slide per frame along the table (m)")
      ->capture_default_str();
  app.add_option("--turn", a.motion.turn_rad, "--sequence: its turn per frame about the table's normal (rad)")
      ->capture_default_str();
  app.add_option("--jump-frame", a.motion.jump_frame,
                 "--sequence: from this frame on (1 or later; frames count from 0), the target is also displaced by "
                 "--jump (-1 = never)")
      ->capture_default_str();
  app.add_option("--jump", a.motion.jump_m, "--sequence: the jump's length along the slide (m)")->capture_default_str();
}

// --world ycbv or room: the YCB worlds' scenes, with their own objects, sensor and prior. Of
// SynthOptionTable's rows they read the distances and the detections' noise; the other rows,
// the mesh and the motion are refused.
void WriteYcbWorldScenes(const CLI::App& app, SynthArgs& a) {
  const std::vector<std::string> read = {"min-distance", "max-distance", "box-jitter", "false-positives"};
  std::vector<std::string> shapes_only = {"--mesh", "--unit-scale", "--sequence", "--speed",
                                          "--turn", "--jump-frame", "--jump"};
  for (const OptionInfo& f : SynthOptionTable())
    if (std::find(read.begin(), read.end(), f.name) == read.end())
      shapes_only.push_back(f.Name(OptionNaming::kCli) +
                            (f.type == OptionType::kBool ? "/--no-" + std::string(f.name) : ""));
  for (const std::string& o : shapes_only)
    if (app.count(o.substr(0, o.find('/'))))
      throw Error(o + " does not apply to --world " + a.world + " (shapes only)");
  if (a.models_dir.empty())
    throw Error("--world " + a.world + " needs the YCB-Video meshes: give --models DIR, or set POSEFILTER_DATA");
  for (int i = 0; i < a.count; ++i) {  // the scene folders this run writes must not be the meshes'
    char name[32];
    std::snprintf(name, sizeof name, "scene_%03d", i);
    if (SamePath(a.models_dir, (std::filesystem::path(a.out_dir) / name).string()))
      throw Error("--models " + a.models_dir + ": is a folder this run writes (--out " + a.out_dir +
                  "); give another --out");
  }
  std::string why;
  const bool is_room = a.world == "room";
  TableSceneOptions& table = a.table;
  RoomSceneOptions& room = a.room;
  table.box_jitter_px = room.box_jitter_px = a.opt.box_jitter_px;
  table.false_positives = room.false_positives = a.opt.false_positives;
  if (app.count("--min-distance")) table.min_distance_m = room.min_distance_m = a.opt.min_distance_m;
  if (app.count("--max-distance")) table.max_distance_m = room.max_distance_m = a.opt.max_distance_m;
  if (app.count("--min-objects")) table.min_objects = room.min_objects = a.min_objects;
  if (app.count("--max-objects")) table.max_objects = room.max_objects = a.max_objects;
  if (!(is_room ? room.IsValid(&why) : table.IsValid(&why))) {
    const std::pair<const char*, const char*> names[] = {
        {"min_objects", "--min-objects"},     {"max_objects", "--max-objects"},
        {"min_distance_m", "--min-distance"}, {"max_distance_m", "--max-distance"},
        {"box_jitter_px", "--box-jitter"},    {"false_positives", "--false-positives"}};
    for (const auto& [field, option] : names)
      for (std::size_t at; (at = why.find(field)) != std::string::npos;) why.replace(at, std::strlen(field), option);
    throw Error("invalid scene option: " + why);
  }
  const TableWorld ycb = TableWorld::LoadYcbVideo(a.models_dir);
  CheckOutputFolder(a.out_dir, "--out");
  for (int i = 0; i < a.count; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "scene_%03d", i);
    const std::string dir = (std::filesystem::path(a.out_dir) / name).string();
    const std::uint64_t s = a.seed + std::uint64_t(i);
    const TableScene scene = is_room ? MakeRoomScene(ycb, room, s) : ycb.MakeScene(table, s);
    WriteTableScene(scene, dir);
    int targets = 0;
    for (const TableObject& o : scene.objects) targets += o.target;
    std::printf("%s  seed %llu  objects %zu  targets %d  distance %.3f m  elevation %.1f deg  surfaces %zu (%.0f%% of the view)\n",
                dir.c_str(), (unsigned long long)s, scene.objects.size(), targets, scene.distance_m, scene.elevation_deg,
                scene.supports.size(),
                100 * std::accumulate(scene.support_view_fractions.begin(), scene.support_view_fractions.end(), 0.0));
  }
}

// --mesh: refused when it lies in a folder this run writes; loaded (into *mesh) and made the
// target otherwise.
void LoadSynthMesh(const CLI::App& app, SynthArgs& a, std::unique_ptr<Mesh>* mesh) {
  // The folders this run writes: OUT itself for --sequence, OUT/scene_NNN otherwise. A --mesh
  // inside one of them could be replaced by the scene's copy of it, so it is refused.
  const std::filesystem::path mesh_dir = std::filesystem::absolute(a.mesh_path).parent_path();
  bool written = false;
  if (app.count("--sequence")) {
    for (auto d = mesh_dir; !written; d = d.parent_path()) {
      written = SamePath(d.string(), a.out_dir);
      if (d == d.parent_path()) break;  // the root
    }
  } else {
    char name[32];
    for (int i = 0; i < a.count && !written; ++i) {
      std::snprintf(name, sizeof name, "scene_%03d", i);
      written = SamePath(mesh_dir.string(), (std::filesystem::path(a.out_dir) / name).string());
    }
  }
  if (written)
    throw Error("--mesh " + a.mesh_path + ": lies in a folder this run writes (--out " + a.out_dir +
                "), where it could be overwritten; copy it elsewhere or give another --out");
  if (!std::isfinite(a.unit_scale) || a.unit_scale <= 0) throw Error("--unit-scale must be finite and > 0");
  *mesh = std::make_unique<Mesh>(LoadMesh(a.mesh_path, a.unit_scale));
  a.opt.target_mesh = mesh->get();
}

// --sequence N: one scene whose target moves, as a dataset folder.
void WriteSynthSequenceFolder(const CLI::App& app, SynthArgs& a) {
  SynthMotion& motion = a.motion;
  std::string why;
  if (app.count("--count")) throw Error("--sequence writes one moving scene; --count does not apply");
  motion.frames = a.sequence;
  if (!motion.IsValid(&why)) throw Error("invalid --sequence motion: " + why);
  CheckOutputFolder(a.out_dir, "--out");
  const std::vector<SynthScene> frames = MakeSynthSequence(a.opt, motion, a.seed);
  WriteSynthSequence(frames, a.out_dir);
  std::printf(
      "%s  target %s  %zu frames  distance %.3f m  slide %.3f m/frame  turn %.3f rad/frame%s\n", a.out_dir.c_str(),
      frames.front().target.name.c_str(), frames.size(), frames.front().distance_m, motion.speed_m, motion.turn_rad,
      motion.jump_frame >= 0
          ? ("  jump " + std::to_string(motion.jump_m) + " m at frame " + std::to_string(motion.jump_frame)).c_str()
          : "");
}

// The shapes world's scenes, OUT/scene_NNN.
void WriteShapeScenes(const SynthArgs& a) {
  CheckOutputFolder(a.out_dir, "--out");
  for (int i = 0; i < a.count; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "scene_%03d", i);
    const std::string dir = (std::filesystem::path(a.out_dir) / name).string();
    const SynthScene scene = MakeSynthScene(a.opt, a.seed + std::uint64_t(i));
    WriteSynthScene(scene, dir);
    std::printf("%s  target %s  distance %.3f m  occlusion %.2f  detections %zu%s\n", dir.c_str(),
                scene.target.name.c_str(), scene.distance_m, scene.occlusion_achieved, scene.detections.size(),
                scene.target_detected ? "" : " (target missed)");
  }
}

}  // namespace

int RunSynth(int argc, char** argv) {
  CLI::App app{"Make synthetic depth scenes with ground truth and a stage-1 prior", "synth"};
  SynthArgs a;
  AddSynthArgs(app, a);
  return RunApp(app, argc, argv, [&] {
    if (a.count < 1 || a.count > 100000) throw Error("--count must be in [1, 100000]");
    if (a.seed > UINT64_MAX - std::uint64_t(a.count - 1))
      throw Error("--seed + --count - 1 is above 2^64 - 1: the last scene's seed would wrap to 0");
    if (a.world != "shapes") {
      // The YCB worlds: their own objects, sensor and prior; the shapes' options do not apply.
      WriteYcbWorldScenes(app, a);
      return;
    }
    if (app.count("--models") + app.count("--min-objects") + app.count("--max-objects"))
      throw Error("--models, --min-objects and --max-objects describe --world ycbv or room scenes");
    std::unique_ptr<Mesh> mesh;
    if (!a.mesh_path.empty()) LoadSynthMesh(app, a, &mesh);
    CheckSynthOptions(a.opt);
    if (app.count("--sequence")) {
      WriteSynthSequenceFolder(app, a);
      return;
    }
    if (app.count("--speed") + app.count("--turn") + app.count("--jump-frame") + app.count("--jump"))
      throw Error("--speed, --turn, --jump-frame and --jump describe a --sequence; give --sequence N");
    WriteShapeScenes(a);
  });
}

}  // namespace posefilter::cli
