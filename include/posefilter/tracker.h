// posefilter/tracker.h — tracking objects through a sequence of depth frames.
//
// Per frame and object (docs/ALGORITHM.md, "Tracking"):
//   1. predict: the last pose, moved by the last frame-to-frame motion (constant velocity) when
//      the object had a pose in the two frames before (tracked, or Reset and then tracked);
//   2. search: first the confirmation (TrackOptions::confirm): the predicted pose alone,
//      refined by the filter's polish (its ICP steps) and weighed in a window around the
//      predicted and the last pose's projections (a one-detection prior of the object); it
//      ends the search when it weighs at least refresh_weight, lost_weight and the object's
//      reference weight less confirm_margin. Otherwise a short particle filter run
//      (TrackOptions::filter: few particles, few iterations, no annealing, small moves) whose
//      initial particles are the predicted and the last pose jittered by (search_t_m,
//      search_r_rad), weighed in the same window; after a failed confirmation it ends once
//      its best particle weighs the reference;
//   3. judge: a best weight below lost_weight means the object is lost; it is then
//      re-initialised by a full estimate (TrackOptions::init) from the frame's stage 1, if
//      the caller gives one, and stays lost otherwise (the next frames search about its last
//      tracked pose again). A weight below refresh_weight also asks the stage 1, and its pose
//      wins where it weighs more. Objects estimated from one stage 1 in the same frame go
//      through the joint scene pass together (scene_pass).
// An object with no pose yet (never started: no Reset and no stage 1 so far) starts from the
// stage 1 the same way.
//
// Units: metres, radians; poses map object → camera (x_cam = T·x_obj). Deterministic: every
// random stream derives from TrackOptions::filter.seed, the frame index and the object.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/filter_options.h"
#include "posefilter/mesh.h"
#include "posefilter/option_rows.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/prepared_model.h"
#include "posefilter/prior.h"

namespace posefilter {

// The filter settings of a tracking step (TrackOptions::filter's default): 64 particles, 4
// elite, 1 run of at most 5 iterations, no annealing, every initial particle at a seed, the
// translate/rotate/align/ICP moves only (no flips, quarter turns or cell jumps), σ0 = 1 cm /
// 0.1 rad, weight α 0.3 + β 0.7 (γ = 0: the tracker's prior is its own prediction, not a
// detector's evidence), a polish of 3 ICP steps without turns, LOD 1024 faces.
FilterOptions TrackingFilterOptions();
// The (re-)initialisations' options: FilterOptions defaults with every restart run
// (stop.restart_agree_m = 0): an initialisation's pose seeds every frame after it, so it does
// not stop early where its first two runs agree.
FilterOptions TrackingInitOptions();

struct TrackOptions {
  // The short filter run of each tracked object and frame (TrackingFilterOptions()).
  // filter.seed seeds every stream of the tracker.
  FilterOptions filter = TrackingFilterOptions();
  // The full estimate that starts or re-initialises an object from a stage 1
  // (TrackingInitOptions()). Its seed is replaced per frame and object (derived from filter.seed).
  FilterOptions init = TrackingInitOptions();
  // A tracking step whose best weight (eq. 7.4 [ALGORITHM.md] with filter's α, β, γ) is below this reports
  // the object lost; so does a (re-)initialisation below it. In [0, 1].
  double lost_weight = 0.45;
  // A tracked object whose best weight is below this (but not below lost_weight) is uncertain:
  // the frame's stage 1 (if given) also estimates it, and its pose replaces the tracked one
  // when it weighs more. It frees a track that started from a wrong stage-1 pose. In [0, 1];
  // 0 = off (the stage 1 runs only for lost or new objects).
  double refresh_weight = 0.6;
  // σ of the initial particles about the predicted and the last pose: translation (metres,
  // ≥ 0, per axis) and rotation (radians, ≥ 0, about a random axis).
  double search_t_m = 0.01;
  double search_r_rad = 0.05;
  // Predict by the last frame-to-frame motion (false: the last pose).
  bool constant_velocity = true;
  // When several objects are estimated from one frame's stage 1, run the joint scene pass
  // (posefilter/scene_pass.h) over them with `init`'s options.
  bool scene_pass = true;
  // The search window: both poses' projected boxes, united and grown by this fraction of
  // their size on each side, (0, 2].
  double window_margin = 0.25;
  // Confirm the prediction before searching: the predicted pose, polished alone (filter's
  // polish: its ICP steps), is the frame's pose when it weighs at least refresh_weight,
  // lost_weight and the object's reference weight less confirm_margin; the particle search runs only
  // otherwise, and then ends as soon as its best particle weighs the reference (the filter's
  // stop.confidence, where that is lower). The reference weight is the weight of the object's
  // last particle search or (re-)initialisation, raised by the confirmations since; an object
  // that has neither (just Reset, or lost) is searched to the end. false = every frame runs the
  // whole particle search.
  bool confirm = true;
  double confirm_margin = 0.02;  // weight (eq. 7.4 [ALGORITHM.md] units), [0, 1]

  // Checks the ranges above and both filter option sets (names the violated field:
  // "lost_weight must be in [0, 1] (got 2)", "filter.num_particles ...").
  bool IsValid(std::string* why) const;
};

// TrackOptions' own fields (not the filter option sets) as rows (posefilter/option_rows.h):
// CLI flag, Python keyword, range, help. IsValid checks their ranges from these rows.
std::span<const OptionInfo> TrackOptionTable();

enum class TrackStatus {
  kTracked,        // found about its predicted pose
  kInitialised,    // (re-)initialised from this frame's stage 1 (first frame, or after a loss)
  kLost,           // below lost_weight, and no stage 1 brought it back
  kNotStarted,     // no pose yet and no stage 1 given
};
// "tracked", "initialised", "lost", "not-started".
const char* TrackStatusName(TrackStatus status);

// One object in one frame.
struct TrackResult {
  std::string obj;
  TrackStatus status = TrackStatus::kNotStarted;
  // The frame's pose (object → camera): the tracked or initialised pose; for a lost object the
  // best pose of the failed search; identity when not started.
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();
  double weight = 0;      // the best weight of the step that gave T_cam_obj
  int iterations = 0;     // filter iterations spent on the object in this frame
  bool confirmed = false; // tracked by the confirmation of its prediction, without the particle search
  double time_ms = 0;     // wall time spent on the object in this frame (stage 1 not included)
};

// A stage 1 for one frame: a prior whose classes name the tracked objects (those it does not
// name cannot start from it), and pose seeds per object name (optional; as SceneInput::seeds).
struct TrackStage1 {
  Prior prior;
  std::map<std::string, std::vector<PoseSeed>> seeds;
};
// Makes the stage 1 of a frame; the tracker calls it at most once per frame, and only when an
// object needs (re-)initialising, so an expensive stage 1 (--prior auto) costs nothing while
// every object is tracked.
using Stage1Fn = std::function<TrackStage1(const SceneInput& frame)>;

// The no-detector stage 1 of `--prior auto` for `frame` and the tracker's meshes: BuildStage1
// with Stage1Kind::kAuto (posefilter/stage1.h; PPF models cached in cache_dir, "" = no cache)
// as a TrackStage1, the seeds by mesh name. Throws Error naming `what` as BuildStage1 does.
TrackStage1 AutoTrackStage1(const SceneInput& frame, const std::vector<Mesh>& meshes, const std::string& cache_dir,
                            const std::string& what);
// The same on models prepared once with their PPF models (PrepareModel with a PpfPreparation,
// posefilter/prepared_model.h: AutoPriorForModels), the seeds by mesh name: no PPF model is
// loaded or built per frame. The same stage 1, bit for bit.
TrackStage1 AutoTrackStage1(const SceneInput& frame, const std::vector<std::shared_ptr<const PreparedModel>>& models,
                            const std::string& what);

// What a tracker has done so far (Tracker::stats): its preparations, searches and weighings.
struct TrackStats {
  int frames = 0;                      // frames processed
  // PrepareModel calls: one per mesh in the constructor (the searches'), and one per mesh by
  // its first (re-)initialisation (the initialisations').
  int models_prepared = 0;
  // Frame preparations: the scored depth of the searches (support plane out), one per frame.
  int scenes_prepared = 0;
  // The initialisations' prepared frame (PrepareFrame with `init`'s options): one in each
  // frame that calls the stage 1, shared by its initialisations and its scene pass.
  int init_scenes_prepared = 0;
  int searches = 0;                    // tracking steps of objects with a pose
  int confirmed = 0;                   // of those, ended by the confirmation
  int initialisations = 0;             // full estimates from a stage 1
  std::int64_t weighings = 0;          // particle scores of the searches (FilterStats::weighings)
};

class Tracker {
 public:
  // Tracks `meshes` (metres, each named: the names are the object names; distinct). Throws
  // Error on invalid options (naming them), an empty list, an empty mesh or a repeated name.
  explicit Tracker(std::vector<Mesh> meshes, TrackOptions options = {});

  // Starts (or restarts) `obj` at a known pose (object → camera) for the next frame. Throws
  // Error for an unknown object or a non-finite pose.
  void Reset(const std::string& obj, const Eigen::Isometry3d& T_cam_obj);

  // Processes the next frame (depth and camera; mask and seeds are ignored): one result per
  // mesh, in the meshes' order. `stage1` (may be empty) is called at most once, when an
  // object has no pose yet or is lost. Throws Error when the frame is invalid (ValidateScene)
  // or differs in size from the first frame.
  std::vector<TrackResult> Track(const SceneInput& frame, const Stage1Fn& stage1 = nullptr);

  int frames() const { return frame_; }  // frames processed so far
  const std::vector<Mesh>& meshes() const { return meshes_; }
  // The meshes prepared once for the sequence, in the meshes' order: for the searches
  // (PrepareModel with the tracking step's options, in the constructor; the judgements of
  // initialised poses use them too) and for the (re-)initialisations (with `init`'s options,
  // by an object's first initialisation; null until then; its scene passes use them too).
  const std::vector<std::shared_ptr<const PreparedModel>>& models() const { return models_; }
  const std::vector<std::shared_ptr<const PreparedModel>>& init_models() const { return init_models_; }
  const TrackOptions& options() const { return options_; }
  const TrackStats& stats() const { return stats_; }

 private:
  struct State {
    bool has_pose = false;       // `last` holds a tracked or initialised pose
    bool lost = false;           // the last frame lost it
    bool has_velocity = false;   // `velocity` holds the last frame-to-frame motion
    Eigen::Isometry3d last = Eigen::Isometry3d::Identity();      // object → camera
    Eigen::Isometry3d velocity = Eigen::Isometry3d::Identity();  // camera frame, last[t] · last[t−1]⁻¹
    bool has_reference = false;  // `reference` holds the confirmation's reference weight
    double reference = 0;
  };
  // What one object's search did (summed into stats_ after the parallel searches).
  struct SearchCounts {
    bool searched = false, confirmed = false;
    std::int64_t weighings = 0;
  };
  // A search window: the frame's scoring depth cropped around it, its one-detection prior, and
  // the cell whose window is the search window's.
  struct Window {
    SceneInput scene;
    Prior prior;
    int centre_cell = 0;
  };
  bool MakeWindow(const Camera& cam, const Box& a, const Box& b, std::size_t k, Window* out) const;
  FilterOptions StepOptions(std::uint64_t seed) const;
  // The confirmation's options: StepOptions with two particles at the one seed, one weighing,
  // and the polish.
  FilterOptions ConfirmOptions(std::uint64_t seed) const;
  TrackResult Search(const Camera& cam, std::size_t k, SearchCounts* counts);
  // The full estimate of object k from the stage 1 (*est, *cls: its result and class, when it
  // ran), judged by Judge.
  TrackResult Initialise(const PreparedFrame& frame, std::size_t k, const TrackStage1& stage1, EstimateResult* est,
                         int* cls);
  // An estimate of object k weighed as a search would weigh it, and its status by lost_weight.
  TrackResult Judge(const Camera& cam, std::size_t k, const EstimateResult& e) const;
  void Accept(std::size_t k, const TrackResult& r);

  // The mesh weighed by the searches (its level of detail at filter.render.lod_max_faces).
  const Mesh& SearchMesh(std::size_t k) const;
  // Object k's model for the (re-)initialisations, prepared by the first call (the serial part
  // of Track calls it).
  const std::shared_ptr<const PreparedModel>& InitModel(std::size_t k);

  std::vector<Mesh> meshes_;      // as given
  std::vector<std::shared_ptr<const PreparedModel>> models_;       // per mesh: the searches'
  std::vector<std::shared_ptr<const PreparedModel>> init_models_;  // per mesh: the initialisations' (InitModel)
  TrackOptions options_;
  std::vector<State> states_;
  TrackStats stats_;
  DepthImage scoring_;            // this frame's depth without its support plane's pixels
  int frame_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace posefilter
