// apps/track_cmd.cc — `posefilter track`: track objects through a sequence of depth frames
// (posefilter/tracker.h) and print, per frame and object, the status, weight, time and (where
// the sequence has ground truth) ADD-S.
//
// Sequences: the images of one scene of a dataset (--dataset: a BOP split or a YCB-Video-style
// folder, as `synth --sequence` writes; images in im_id order, objects = the scene's ground
// truth objects unless --objects), or a folder of depth PNGs in name order with one camera
// JSON and the meshes (--frames, --camera, --mesh). Objects start, and restart after a loss,
// from the frame's stage 1 (--prior) or at the first frame's ground truth (--init-gt).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "filter_cli.h"
#include "posefilter/auto_prior.h"
#include "posefilter/bop.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/metrics.h"
#include "posefilter/ppf.h"
#include "posefilter/scene_io.h"
#include "posefilter/stage1.h"
#include "posefilter/tracker.h"

namespace posefilter::cli {
namespace {

namespace fs = std::filesystem;

// One frame of the sequence: where its depth is, how to load it, and its ground truth.
struct Frame {
  std::string name;         // for messages and the CSV ("scene 0 image 3", or the PNG's stem)
  int scene_id = 0, im_id = 0;
  const DatasetImage* image = nullptr;  // dataset frames
  std::string depth_path;               // --frames
  std::map<std::string, Eigen::Isometry3d> gt;  // object name → pose (object → camera)
};

std::string Num(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

// A CSV field as RFC 4180 writes it: quoted, with quotes doubled, where it holds a comma, a
// quote or a line break (an object name from a mesh file's stem may).
std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// The stage 1 of one frame for the tracker: --prior auto (AutoTrackStage1, with the seeds by
// object name), or none or the frame's detections (dets_by_image) through BuildStage1
// (posefilter/stage1.h).
TrackStage1 TrackFrameStage1(const SceneInput& frame, const std::vector<Mesh>& meshes, const std::string& prior_arg,
                             const Frame& f, const std::map<std::pair<int, int>, std::vector<Detection>>& dets_by_image,
                             const std::string& cache_dir) {
  if (prior_arg == "auto") return AutoTrackStage1(frame, meshes, cache_dir, f.name + ": --prior auto");
  Stage1Options so;
  if (prior_arg != "none") {
    so.kind = Stage1Kind::kDetections;
    if (const auto it = dets_by_image.find({f.scene_id, f.im_id}); it != dets_by_image.end()) so.detections = it->second;
  }
  std::vector<Stage1Object> objects;
  for (const Mesh& m : meshes) objects.push_back({m.name, &m});
  TrackStage1 s;
  s.prior = BuildStage1(frame, objects, so).prior;
  return s;
}

// The parsed command line of `track`.
struct TrackArgs {
  std::string dataset_dir, split = "test", frames_dir, camera_path, prior_arg, csv_path, out_dir, objects_arg;
  std::vector<std::string> mesh_args;
  int scene = -1;
  double unit_scale = 1.0, depth_scale = 0;
  bool init_gt = false, quiet = false;
  TrackOptions topt;
  CLI::Option *ds_opt = nullptr, *fr_opt = nullptr, *depth_scale_opt = nullptr;
  bool named_prior = true;  // --prior is empty, none or auto (no file)
};

// Every option of `track` on `app`, into *a.
void AddTrackArgs(CLI::App& app, TrackArgs* a) {
  TrackOptions& topt = a->topt;
  a->ds_opt = app.add_option("--dataset", a->dataset_dir,
                             "dataset folder (BOP: models/ + <split>/; YCB-Video style: scenes/ + models/, as synth "
                             "--sequence writes): the images of one scene in im_id order");
  app.add_option("--split", a->split, "BOP split folder (ignored for a YCB-Video-style folder)")->capture_default_str();
  app.add_option("--scene", a->scene, "the dataset's scene_id to track (default: the first)");
  app.add_option("--objects", a->objects_arg, "comma-separated object names to track (default: the scene's ground-truth objects)");
  a->fr_opt = app.add_option("--frames", a->frames_dir, "folder of 16-bit depth PNGs, tracked in file-name order (with --camera, --mesh)");
  a->ds_opt->excludes(a->fr_opt);
  app.add_option("--camera", a->camera_path, "camera JSON of --frames (fx, fy, cx, cy, width, height, depth_scale)");
  a->depth_scale_opt =
      app.add_option("--depth-scale", a->depth_scale, "metres per PNG unit of --frames (default: the camera JSON's)");
  app.add_option("--mesh", a->mesh_args, "object mesh of --frames, NAME=PATH or PATH (repeatable)");
  app.add_option("--unit-scale", a->unit_scale, "--mesh units to metres (0.001 for millimetre meshes)")->capture_default_str();
  app.add_option("--prior", a->prior_arg,
                 "stage 1 that starts objects and restarts lost ones: 'auto' (no detector: regions and PPF proposals), "
                 "'none' (uniform), or a BOP detections JSON (with --dataset); without it, objects start from --init-gt "
                 "and a lost object stays lost");
  app.add_flag("--init-gt", a->init_gt, "start each object at the first frame's ground-truth pose (the stage 1 then only restarts lost ones)");
  AddTrackOptions(app, &topt);
  app.add_option("--csv", a->csv_path, "write one row per frame and object here");
  app.add_option("--out-dir", a->out_dir, "write one results JSON per frame here (<frame>.json)");
  app.add_flag("--quiet", a->quiet, "print only the summary");
  AddFilterOptions(app, &topt.filter);
  app.callback([a] {
    if (a->ds_opt->count() + a->fr_opt->count() == 0) throw CLI::RequiredError("a sequence: --dataset DIR or --frames DIR");
  });
}

// --out-dir: the per-frame JSONs (<out-dir>/NNNNNN.json) go into a folder of their own: not an
// input folder or one inside it, and not over an input file of that name. Made here.
void CheckTrackOutDir(const std::string& out_dir, const std::vector<NamedPath>& inputs) {
  static const std::regex frame_json(R"(\d{6}\.json)");
  for (const NamedPath& in : inputs) {
    if (in.path.empty()) continue;
    std::error_code ec;
    if (fs::is_directory(in.path, ec) && (SamePath(out_dir, in.path) || InsideFolder(out_dir, in.path)))
      throw Error("--out-dir " + out_dir + ": is inside the input folder " + in.option + " " + in.path +
                  "; its files could be overwritten");
    const fs::path parent = fs::path(in.path).parent_path();
    if (!fs::is_directory(in.path, ec) && SamePath(parent.empty() ? "." : parent.string(), out_dir) &&
        std::regex_match(fs::path(in.path).filename().string(), frame_json))
      throw Error("--out-dir " + out_dir + ": holds the input " + in.option + " " + in.path +
                  ", a name of the per-frame results; it would be overwritten");
  }
  MakeOutputFolder(out_dir, "--out-dir");
}

// Checks the parsed arguments before any work, the output paths included.
void CheckTrackArgs(TrackArgs* a) {
  CheckFilterOptions(a->topt.filter);
  CheckTrackOptions(a->topt);
  const bool use_dataset = !a->dataset_dir.empty();
  const std::string& prior_arg = a->prior_arg;
  if (prior_arg.empty() && !a->init_gt) throw Error("nothing starts the objects: give --prior (auto, none or detections) or --init-gt");
  a->named_prior = prior_arg.empty() || prior_arg == "none" || prior_arg == "auto";
  if (!a->named_prior && !use_dataset) throw Error("--prior " + prior_arg + ": a detections file needs --dataset (use auto or none with --frames)");
  if (!a->named_prior && fs::path(prior_arg).extension() != ".json")
    throw Error("--prior must be auto, none or a BOP detections JSON (*.json), got '" + prior_arg + "'");
  if (use_dataset && (!a->camera_path.empty() || !a->mesh_args.empty()))
    throw Error("--camera and --mesh belong to --frames; a --dataset has its own cameras and models");
  if (!use_dataset && (a->camera_path.empty() || a->mesh_args.empty())) throw Error("--frames needs --camera and --mesh");
  if (a->init_gt && !use_dataset) throw Error("--init-gt needs a --dataset with ground truth");
  if (!(a->unit_scale > 0) || !std::isfinite(a->unit_scale)) throw Error("--unit-scale must be finite and > 0");
  // Every input, files and folders: the outputs may overwrite none of them.
  std::vector<NamedPath> inputs = {{a->camera_path, "--camera"}, {a->dataset_dir, "--dataset"}, {a->frames_dir, "--frames"}};
  if (!a->named_prior) inputs.push_back({prior_arg, "--prior"});
  for (const auto& spec : a->mesh_args) inputs.push_back({spec.substr(spec.find('=') + 1), "--mesh"});
  CheckOutputPaths({{a->csv_path, "--csv"}}, inputs);
  if (!a->out_dir.empty()) CheckTrackOutDir(a->out_dir, inputs);
}

// The sequence: its frames, the meshes and the ground truth.
struct Sequence {
  std::vector<Frame> frames;
  std::vector<Mesh> meshes;
  std::map<std::string, std::vector<Eigen::Vector3f>> points;  // ADD-S points per object
  std::map<std::string, double> diameters;
  Dataset ds;
  CameraFile cam_file;
  double depth_scale = 0;  // --frames
  std::map<std::pair<int, int>, std::vector<Detection>> dets_by_image;
};

// --dataset: the images of one scene, its objects (--objects, else the first frame's ground
// truth) and, with a detections --prior, the detections per image.
void LoadDatasetSequence(TrackArgs& a, Sequence* s) {
  s->ds = OpenDataset(a.dataset_dir, a.split);
  const Dataset& ds = s->ds;
  if (a.scene < 0) a.scene = ds.images.front().scene_id;
  for (const DatasetImage& im : ds.images) {
    if (im.scene_id != a.scene) continue;
    Frame f;
    f.scene_id = im.scene_id;
    f.im_id = im.im_id;
    f.image = &im;
    f.name = "scene " + std::to_string(im.scene_id) + " im " + std::to_string(im.im_id);
    for (const GtInstance& g : im.gt) f.gt[ds.Model(g.obj_id)->name] = g.T_cam_obj;
    s->frames.push_back(std::move(f));
  }
  if (s->frames.empty()) throw Error(a.dataset_dir + ": no images of scene " + std::to_string(a.scene) + " (--scene)");
  std::vector<std::string> names;
  if (!a.objects_arg.empty()) {
    std::stringstream ss(a.objects_arg);
    for (std::string n; std::getline(ss, n, ',');)
      if (!n.empty()) names.push_back(n);
  } else {
    for (const GtInstance& g : s->frames.front().image->gt) names.push_back(ds.Model(g.obj_id)->name);
  }
  if (names.empty()) throw Error(a.dataset_dir + ": the first frame has no ground-truth objects; name them with --objects");
  for (const std::string& n : names) {
    const DatasetModel* m = ds.ModelByName(n);
    if (!m) throw Error("--objects: '" + n + "' is not a model of " + a.dataset_dir);
    if (std::any_of(s->meshes.begin(), s->meshes.end(), [&](const Mesh& x) { return x.name == n; })) continue;
    s->meshes.push_back(LoadDatasetMesh(*m));
    s->points[n] = LoadDatasetPoints(*m);
    s->diameters[n] = m->diameter_m;
  }
  if (!a.named_prior) {
    std::map<std::pair<int, int>, std::vector<BopDetection>> raw;
    for (const BopDetection& d : ReadBopDetections(a.prior_arg)) raw[{d.scene_id, d.im_id}].push_back(d);
    for (auto& [key, list] : raw) s->dets_by_image[key] = ToPriorDetections(list, ds, a.prior_arg);
  }
}

// --frames: the depth PNGs in name order, the camera and the meshes.
void LoadFramesSequence(const TrackArgs& a, Sequence* s) {
  if (!fs::is_directory(a.frames_dir)) throw Error(a.frames_dir + ": not a folder (--frames)");
  std::vector<std::string> pngs;
  for (const auto& e : fs::directory_iterator(a.frames_dir))
    if (e.is_regular_file() && e.path().extension() == ".png") pngs.push_back(e.path().string());
  std::sort(pngs.begin(), pngs.end());
  if (pngs.empty()) throw Error(a.frames_dir + ": holds no .png depth image (--frames)");
  for (std::size_t i = 0; i < pngs.size(); ++i) {
    Frame f;
    f.depth_path = pngs[i];
    f.name = fs::path(pngs[i]).stem().string();
    f.im_id = int(i);
    s->frames.push_back(std::move(f));
  }
  s->cam_file = ReadCameraJson(a.camera_path);
  s->depth_scale = a.depth_scale_opt->count() == 0 ? s->cam_file.depth_scale : a.depth_scale;
  if (!(s->depth_scale > 0) || !std::isfinite(s->depth_scale)) throw Error("--depth-scale must be finite and > 0");
  for (const auto& [name, path] : ParseNamedPaths(a.mesh_args, "--mesh")) {
    s->meshes.push_back(LoadMesh(path, a.unit_scale));
    s->meshes.back().name = name;
  }
}

// Per object: frames, found (of those with ground truth), lost, and the times.
struct TrackTotals {
  int frames = 0, found = 0, with_gt = 0, lost = 0;
  std::vector<double> ms;
};

// One frame's rows: the table (unless quiet), the CSV text, the totals; returns the frame's
// results JSON rows.
std::vector<ObjectResult> ReportTrackFrame(const TrackArgs& a, Sequence& s, std::size_t i, const SceneInput& scene_in,
                                           const std::vector<TrackResult>& results, double frame_ms,
                                           std::map<std::string, TrackTotals>* totals, std::string* csv_text) {
  const Frame& f = s.frames[i];
  std::vector<ObjectResult> json_rows;
  for (const TrackResult& r : results) {
    TrackTotals& t = (*totals)[r.obj];
    ++t.frames;
    t.lost += r.status == TrackStatus::kLost || r.status == TrackStatus::kNotStarted;
    t.ms.push_back(r.time_ms);
    std::string adds = "", found = "";
    const auto g = f.gt.find(r.obj);
    const bool has_pose = r.status != TrackStatus::kNotStarted;
    if (g != f.gt.end() && s.points.count(r.obj)) {
      ++t.with_gt;
      if (has_pose) {
        const PoseErrors e = ComputePoseErrors(s.points[r.obj], s.diameters[r.obj], r.T_cam_obj, g->second);
        adds = Num(e.adds * 1e3, 1);
        found = e.adds_ok && r.status != TrackStatus::kLost ? "yes" : "no";
        t.found += found == "yes";
      } else {
        found = "no";
      }
    }
    if (!a.quiet)
      std::printf("%-5zu %-20s %-22s %-12s %7.3f %8.1f %9s %-5s %8.1f\n", i, f.name.c_str(), r.obj.c_str(),
                  TrackStatusName(r.status), r.weight, r.time_ms, adds.empty() ? "-" : adds.c_str(),
                  found.empty() ? "-" : found.c_str(), frame_ms);
    if (!a.csv_path.empty()) {
      const Eigen::Matrix3d R = r.T_cam_obj.linear();
      const Eigen::Vector3d tr = r.T_cam_obj.translation();
      std::string rs, ts;
      for (int k = 0; k < 9; ++k) rs += (k ? " " : "") + Num(R(k / 3, k % 3), 9);
      for (int k = 0; k < 3; ++k) ts += (k ? " " : "") + Num(tr[k], 6);
      char head[160];
      std::snprintf(head, sizeof head, "%zu,%d,%d,", i, f.scene_id, f.im_id);
      char nums[96];
      std::snprintf(nums, sizeof nums, ",%.6f,%.3f,%.3f,", r.weight, r.time_ms, frame_ms);
      *csv_text += head + CsvField(r.obj) + "," + TrackStatusName(r.status) + nums + rs + "," + ts + "," + adds + "," +
                   found + "\n";
    }
    if (has_pose) {
      ObjectResult o;
      o.obj = r.obj;
      o.pose_base = TransformToPose(scene_in.camera.base_to_camera.inverse() * r.T_cam_obj);
      o.T_cam_obj = r.T_cam_obj;
      o.weight = r.weight;
      o.iterations = r.iterations;
      o.time_ms = r.time_ms;
      json_rows.push_back(o);
    }
  }
  return json_rows;
}

// Tracks the sequence frame by frame (the table, --csv, --out-dir), then prints the summary.
void TrackSequence(const TrackArgs& a, Sequence& s) {
  Tracker tracker(s.meshes, a.topt);
  if (a.init_gt)
    for (const Mesh& m : s.meshes) tracker.Reset(m.name, s.frames.front().gt.at(m.name));
  const std::string cache_dir = DefaultPpfCacheDir();
  // The CSV's rows, written as one file (atomically) when every frame is done: a run that
  // fails leaves an existing --csv as it was.
  std::string csv_text = "frame,scene_id,im_id,obj,status,weight,time_ms,frame_ms,R,t,adds_mm,found\n";
  std::map<std::string, TrackTotals> totals;
  if (!a.quiet)
    std::printf("%-5s %-20s %-22s %-12s %7s %8s %9s %-5s %8s\n", "frame", "image", "object", "status", "weight", "ms",
                "ADD-S mm", "found", "frame ms");
  double stage1_ms = 0;
  std::vector<double> frame_times;  // wall time of each Track call, ms
  int stage1_calls = 0;
  for (std::size_t i = 0; i < s.frames.size(); ++i) {
    const Frame& f = s.frames[i];
    const SceneInput scene_in = f.image ? LoadDatasetScene(*f.image) : SceneInput{LoadDepthPng(f.depth_path, s.depth_scale, s.cam_file.camera.width, s.cam_file.camera.height), s.cam_file.camera};
    ValidateScene(scene_in, f.image ? f.image->depth_path : f.depth_path);
    Stage1Fn stage1 = [&](const SceneInput& fr) {
      const auto t0 = std::chrono::steady_clock::now();
      const TrackStage1 st = TrackFrameStage1(fr, tracker.meshes(), a.prior_arg, f, s.dets_by_image, cache_dir);
      stage1_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      ++stage1_calls;
      return st;
    };
    const auto t_frame = std::chrono::steady_clock::now();
    const std::vector<TrackResult> results = tracker.Track(scene_in, a.prior_arg.empty() ? Stage1Fn() : stage1);
    const double frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_frame).count();
    frame_times.push_back(frame_ms);
    const std::vector<ObjectResult> json_rows = ReportTrackFrame(a, s, i, scene_in, results, frame_ms, &totals, &csv_text);
    if (!a.out_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "%06zu.json", i);
      WriteResultsJson(json_rows, (fs::path(a.out_dir) / name).string());
    }
  }
  if (!a.csv_path.empty()) WriteFileAtomically(a.csv_path, [&](std::ostream& out) { out << csv_text; });

  std::printf("\n%-22s %7s %7s %7s %12s %12s\n", "object", "frames", "found", "lost", "median ms", "mean ms");
  for (const Mesh& m : s.meshes) {
    TrackTotals& t = totals[m.name];
    double mean = 0;
    for (double v : t.ms) mean += v / double(t.ms.size());
    const std::string found = t.with_gt ? std::to_string(t.found) + "/" + std::to_string(t.with_gt) : "-";
    std::printf("%-22s %7d %7s %7d %12.1f %12.1f\n", m.name.c_str(), t.frames, found.c_str(), t.lost, Median(t.ms), mean);
  }
  if (!frame_times.empty())
    std::printf("per frame (every object, support plane and stage 1 included): median %.1f ms, max %.1f ms\n",
                Median(frame_times), *std::max_element(frame_times.begin(), frame_times.end()));
  if (stage1_calls)
    std::printf("stage 1 (--prior %s): %d frame(s), %.0f ms in all\n", a.named_prior ? a.prior_arg.c_str() : "detections",
                stage1_calls, stage1_ms);
}

}  // namespace

int RunTrack(int argc, char** argv) {
  CLI::App app{"Track objects through a sequence of depth frames: each object's pose in one frame seeds the next",
               "track"};
  TrackArgs a;
  AddTrackArgs(app, &a);
  return RunApp(app, argc, argv, [&] {
    CheckTrackArgs(&a);
    Sequence s;
    if (!a.dataset_dir.empty())
      LoadDatasetSequence(a, &s);
    else
      LoadFramesSequence(a, &s);
    if (a.init_gt)
      for (const Mesh& m : s.meshes)
        if (!s.frames.front().gt.count(m.name))
          throw Error("--init-gt: the first frame has no ground truth of '" + m.name + "'");
    TrackSequence(a, s);
  });
}

}  // namespace posefilter::cli
