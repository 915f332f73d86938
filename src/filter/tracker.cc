// src/filter/tracker.cc — Tracker (posefilter/tracker.h): per frame, a short filter run about each
// object's predicted pose, the loss test, and (re-)initialisation from a stage 1.
#include "posefilter/tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <sstream>

#include "core/threads.h"
#include "filter/engine_registry.h"
#include "filter/host_setup.h"
#include "posefilter/error.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/option_table.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/rng.h"
#include "posefilter/scene_pass.h"
#include "posefilter/stage1.h"
#include "posefilter/support_plane.h"

namespace posefilter {
namespace {

using filter::Clock;
using filter::MsSince;

// A stream seed from the tracker's seed, the frame and the object (SplitMix64 finaliser).
std::uint64_t StepSeed(std::uint64_t seed, int frame, std::size_t object, std::uint64_t purpose) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (std::uint64_t(frame) * 1024 + object * 4 + purpose + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The pixel box of the mesh's bounding-box corners at T (object → camera); w = h = 0 when a
// corner lies behind the near plane.
Box CornerBox(const Mesh& mesh, const Eigen::Isometry3d& T, const Camera& cam, double near_m) {
  const Eigen::Vector3d lo = mesh.Min().cast<double>(), hi = mesh.Max().cast<double>();
  double u0 = 1e30, u1 = -1e30, v0 = 1e30, v1 = -1e30;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d p = T * Eigen::Vector3d(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
    if (p.z() < near_m) return Box{};
    const double u = cam.fx * p.x() / p.z() + cam.cx, v = cam.fy * p.y() / p.z() + cam.cy;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  }
  return Box{0.5 * (u0 + u1), 0.5 * (v0 + v1), u1 - u0, v1 - v0};
}

// The search window of a tracking step: the union of boxes a and b (the predicted and the last
// pose's), grown by `margin` of its size per side and clipped to the image, as a detection of
// score 1 (class left to the caller). Returns false when it misses the image.
bool WindowBox(const Box& a, const Box& b, double margin, const Camera& cam, Detection* out) {
  if (a.w <= 0 || b.w <= 0) return false;
  double u0 = std::min(a.cx - 0.5 * a.w, b.cx - 0.5 * b.w), u1 = std::max(a.cx + 0.5 * a.w, b.cx + 0.5 * b.w);
  double v0 = std::min(a.cy - 0.5 * a.h, b.cy - 0.5 * b.h), v1 = std::max(a.cy + 0.5 * a.h, b.cy + 0.5 * b.h);
  const double gu = margin * (u1 - u0), gv = margin * (v1 - v0);
  u0 = std::max(u0 - gu, 0.0), u1 = std::min(u1 + gu, double(cam.width - 1));
  v0 = std::max(v0 - gv, 0.0), v1 = std::min(v1 + gv, double(cam.height - 1));
  if (u1 - u0 < 2 || v1 - v0 < 2) return false;
  out->score = 1.0;
  out->x = u0, out->y = v0, out->w = u1 - u0, out->h = v1 - v0;
  return true;
}

// The cell of the first level whose stride holds pixel (u, v).
int CellAt(const PyramidLayout& L, double u, double v) {
  const int col = std::clamp(int(u / L.StrideX(0)), 0, L.levels[0].cols - 1);
  const int row = std::clamp(int(v / L.StrideY(0)), 0, L.levels[0].rows - 1);
  return L.CellIndex(0, row, col);
}

// T with its translation jittered by N(0, σ_t²) per axis and its rotation turned about the
// object's origin by a rotation vector of N(0, σ_r²) per axis (camera frame).
Eigen::Isometry3d Jitter(const Eigen::Isometry3d& T, double sigma_t, double sigma_r, Rng& rng) {
  Eigen::Isometry3d J = T;
  const Eigen::Vector3d w(rng.Normal() * sigma_r, rng.Normal() * sigma_r, rng.Normal() * sigma_r);
  const Eigen::Vector3d dt(rng.Normal() * sigma_t, rng.Normal() * sigma_t, rng.Normal() * sigma_t);
  if (w.norm() > 0) J.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * T.linear();
  J.translation() += dt;
  return J;
}

bool Finite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

// The part [u0, u0 + w) × [v0, v0 + h) of a frame as a scene of its own: the depth cut out and
// the principal point moved by (−u0, −v0), so camera-frame points project onto the same pixels.
SceneInput CropScene(const DepthImage& depth, const Camera& cam, int u0, int v0, int w, int h) {
  SceneInput s;
  s.depth = DepthImage(w, h);
  for (int v = 0; v < h; ++v)
    std::copy_n(depth.data.begin() + std::ptrdiff_t(v0 + v) * depth.width + u0, w, s.depth.data.begin() + std::ptrdiff_t(v) * w);
  s.camera = cam;
  s.camera.width = w;
  s.camera.height = h;
  s.camera.cx -= u0;
  s.camera.cy -= v0;
  return s;
}

// The one-level, 3 × 3-cell pyramid of a tracking crop: every cell decodes to the search window
// (the one detection), and a seed goes to the cell that holds its projected centre.
PyramidLayout CropLayout(int w, int h) {
  PyramidLayout L;
  L.image_width = w;
  L.image_height = h;
  L.num_classes = 1;
  L.levels = {PyramidLevel{3, 3, 2.0 * w / 3, 2.0 * h / 3}};
  return L;
}

// A stage 1 of the objects names[k] (its prior, seeds[k] the pose seeds of names[k]) as a
// TrackStage1, the seeds by name.
TrackStage1 SeedsByName(Prior prior, std::vector<std::vector<PoseSeed>> seeds, const std::vector<std::string>& names) {
  TrackStage1 s;
  s.prior = std::move(prior);
  for (std::size_t k = 0; k < names.size(); ++k) s.seeds[names[k]] = std::move(seeds[k]);
  return s;
}

}  // namespace

TrackStage1 AutoTrackStage1(const SceneInput& frame, const std::vector<Mesh>& meshes, const std::string& cache_dir,
                            const std::string& what) {
  Stage1Options so;
  so.kind = Stage1Kind::kAuto;
  so.what = what;
  so.cache_dir = cache_dir;
  std::vector<Stage1Object> objects;
  std::vector<std::string> names;
  for (const Mesh& m : meshes) objects.push_back({m.name, &m}), names.push_back(m.name);
  Stage1 s = BuildStage1(frame, objects, so);
  return SeedsByName(std::move(s.prior), std::move(s.seeds), names);
}

TrackStage1 AutoTrackStage1(const SceneInput& frame, const std::vector<std::shared_ptr<const PreparedModel>>& models,
                            const std::string& what) {
  std::vector<const PreparedModel*> ms;
  std::vector<std::string> names;
  for (const auto& m : models) {
    if (!m) throw Error(what + ": no model");
    ms.push_back(m.get()), names.push_back(m->mesh().name);
  }
  AutoStage1 a = AutoPriorForModels(frame.depth, frame.camera, ms, names, what);
  return SeedsByName(std::move(a.prior), std::move(a.seeds), names);
}

FilterOptions TrackingInitOptions() {
  FilterOptions o;
  o.stop.restart_agree_m = 0;
  return o;
}

FilterOptions TrackingFilterOptions() {
  FilterOptions o;
  o.num_particles = 64;
  o.num_elite = 4;
  o.restarts = 1;
  o.fine_particle_fraction = 1.0;
  o.seed_start = 1.0;
  o.support.stable_start = 0;
  o.anneal.start_m = 0;
  o.render.lod_max_faces = 1024;
  o.score.alpha = 0.3;
  o.score.beta = 0.7;
  o.score.gamma = 0;
  o.diffusion.sigma_t0_m = 0.01;
  o.diffusion.sigma_r0_rad = 0.1;
  auto& m = o.diffusion.move_probabilities;
  m.fill(0);
  m[int(Move::kTranslateX)] = m[int(Move::kTranslateY)] = m[int(Move::kTranslateZ)] = 0.1;
  m[int(Move::kTranslateAll)] = 0.1;
  m[int(Move::kRotateRoll)] = m[int(Move::kRotatePitch)] = m[int(Move::kRotateYaw)] = 0.08;
  m[int(Move::kRotateAll)] = 0.1;
  m[int(Move::kAlignDepth)] = 0.1;
  m[int(Move::kIcpStep)] = 0.1;
  m[int(Move::kOnPlane)] = 0.06;
  o.stop.max_iterations = 5;
  o.stop.stall_iterations = 2;
  o.polish.steps = 3;
  o.polish.turns = false;
  o.polish.pivots = false;
  o.polish.stable = false;
  o.polish.climbers = 0;
  return o;
}

const char* TrackStatusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::kTracked: return "tracked";
    case TrackStatus::kInitialised: return "initialised";
    case TrackStatus::kLost: return "lost";
    case TrackStatus::kNotStarted: break;
  }
  return "not-started";
}

Tracker::Tracker(std::vector<Mesh> meshes, TrackOptions options) : meshes_(std::move(meshes)), options_(std::move(options)) {
  std::string why;
  if (!options_.IsValid(&why)) throw Error("invalid track option: " + why);
  if (meshes_.empty()) throw Error("tracker: no mesh to track");
  std::set<std::string> names;
  for (const Mesh& m : meshes_) {
    if (std::string w; !m.IsValid(&w)) throw Error("tracker: mesh '" + m.name + "': " + w);
    if (!names.insert(m.name).second) throw Error("tracker: mesh name '" + m.name + "' given twice");
    // Once per sequence: the searches' level of detail (their judgements too); the
    // (re-)initialisations' is prepared by the first one (InitModel).
    models_.push_back(PrepareModel(m, StepOptions(options_.filter.seed)));
    ++stats_.models_prepared;
  }
  init_models_.resize(meshes_.size());
  states_.resize(meshes_.size());
}

const std::shared_ptr<const PreparedModel>& Tracker::InitModel(std::size_t k) {
  if (!init_models_[k]) {
    init_models_[k] = PrepareModel(meshes_[k], options_.init);
    ++stats_.models_prepared;
  }
  return init_models_[k];
}

const Mesh& Tracker::SearchMesh(std::size_t k) const {
  return *models_[k]->Lod(options_.filter.render.lod_max_faces);
}

void Tracker::Reset(const std::string& obj, const Eigen::Isometry3d& T_cam_obj) {
  for (std::size_t k = 0; k < meshes_.size(); ++k) {
    if (meshes_[k].name != obj) continue;
    if (!Finite(T_cam_obj)) throw Error("tracker: Reset of '" + obj + "': the pose is not finite");
    states_[k] = State{};
    states_[k].has_pose = true;
    states_[k].last = T_cam_obj;
    return;
  }
  throw Error("tracker: Reset of unknown object '" + obj + "'");
}

bool Tracker::MakeWindow(const Camera& cam, const Box& a, const Box& b, std::size_t k, Window* out) const {
  Detection d;
  if (!WindowBox(a, b, options_.window_margin, cam, &d)) return false;
  // The crop: the window grown by kCropMargin of its size + 8 pixels per side (room for particle
  // windows grown to their pose's box and for the scene normals' neighbourhoods), clipped to
  // the image.
  constexpr double kCropMargin = 0.1;
  const double gu = kCropMargin * d.w + 8, gv = kCropMargin * d.h + 8;
  const int u0 = std::max(0, int(std::floor(d.x - gu))), v0 = std::max(0, int(std::floor(d.y - gv)));
  const int u1 = std::min(cam.width, int(std::ceil(d.x + d.w + gu)) + 1);
  const int v1 = std::min(cam.height, int(std::ceil(d.y + d.h + gv)) + 1);
  if (u1 - u0 < 8 || v1 - v0 < 8) return false;
  out->scene = CropScene(scoring_, cam, u0, v0, u1 - u0, v1 - v0);
  d.cls = meshes_[k].name;
  d.x -= u0;
  d.y -= v0;
  DetectionPriorOptions po;
  po.max_box_px = std::max(u1 - u0, v1 - v0);
  out->prior = PriorFromDetections({d}, CropLayout(u1 - u0, v1 - v0), {d.cls}, po);
  out->centre_cell = CellAt(out->prior.layout, d.x + 0.5 * d.w, d.y + 0.5 * d.h);
  return true;
}

FilterOptions Tracker::StepOptions(std::uint64_t seed) const {
  FilterOptions o = options_.filter;
  o.seed = seed;
  o.support.plane = false;  // the frame's plane pixels are already out of scoring_
  o.threads = 1;            // Track runs the objects' searches in parallel
  return o;
}

FilterOptions Tracker::ConfirmOptions(std::uint64_t seed) const {
  FilterOptions o = StepOptions(seed);
  // Two particles at the one seed (the fewest a set holds), weighed once, then the polish of
  // the better: the search's final step alone.
  o.num_particles = 2;
  o.num_elite = 1;
  o.init_oversample = 1;
  o.restarts = 1;
  o.seed_start = 1.0;
  o.stop.max_iterations = 1;
  o.polish.seeds = 1;
  return o;
}

TrackResult Tracker::Search(const Camera& cam, std::size_t k, SearchCounts* counts) {
  const auto t0 = Clock::now();
  const State& s = states_[k];
  const Mesh& mesh = SearchMesh(k);
  const FilterOptions& fo = options_.filter;
  TrackResult r;
  r.obj = mesh.name;
  r.status = TrackStatus::kLost;
  r.T_cam_obj = s.last;
  counts->searched = true;
  const Eigen::Isometry3d predicted = options_.constant_velocity && s.has_velocity ? s.velocity * s.last : s.last;
  Window win;
  if (!MakeWindow(cam, CornerBox(mesh, predicted, cam, fo.render.near_m), CornerBox(mesh, s.last, cam, fo.render.near_m), k,
                  &win)) {
    r.time_ms = MsSince(t0);
    return r;  // out of view: lost
  }
  // The confirmation: the prediction polished alone, in the search's window and weighing.
  if (options_.confirm && s.has_reference) {
    win.scene.seeds = {{predicted, 1.0}};
    try {
      const EstimateResult e =
          EstimatePose(win.scene, *models_[k], win.prior, 0, ConfirmOptions(StepSeed(fo.seed, frame_, k, 4)));
      counts->weighings += e.stats.weighings;
      const double floor = std::max({options_.refresh_weight, options_.lost_weight, s.reference - options_.confirm_margin});
      if (e.weight >= floor) {
        r.T_cam_obj = e.T_cam_obj;
        r.weight = e.weight;
        r.iterations = e.iterations;
        r.status = TrackStatus::kTracked;
        r.confirmed = true;
        counts->confirmed = true;
        r.time_ms = MsSince(t0);
        return r;
      }
    } catch (const Error&) {
      // No window cell with valid depth: the particle search below reports it lost.
    }
    win.scene.seeds.clear();
  }
  Rng rng(StepSeed(fo.seed, frame_, k, 0));
  const int n = fo.num_particles;
  win.scene.seeds.reserve(std::size_t(n));
  for (int i = 0; i < n; ++i) {
    const Eigen::Isometry3d& base = i % 2 == 0 ? predicted : s.last;
    win.scene.seeds.push_back({i < 2 ? base : Jitter(base, options_.search_t_m, options_.search_r_rad, rng), 1.0});
  }
  FilterOptions so = StepOptions(StepSeed(fo.seed, frame_, k, 1));
  // After a failed confirmation the search ends as soon as its best particle weighs the
  // reference: the object is found again as well as its last search found it.
  if (options_.confirm && s.has_reference) so.stop.confidence = std::min(so.stop.confidence, s.reference);
  try {
    const EstimateResult e = EstimatePose(win.scene, *models_[k], win.prior, 0, so);
    counts->weighings += e.stats.weighings;
    r.T_cam_obj = e.T_cam_obj;
    r.weight = e.weight;
    r.iterations = e.iterations;
    r.status = e.weight >= options_.lost_weight ? TrackStatus::kTracked : TrackStatus::kLost;
  } catch (const Error&) {
    // No window cell with valid depth (the object's region is empty in this frame): lost.
  }
  r.time_ms = MsSince(t0);
  return r;
}

TrackResult Tracker::Initialise(const PreparedFrame& frame, std::size_t k, const TrackStage1& stage1,
                                EstimateResult* est, int* cls) {
  const auto t0 = Clock::now();
  const Mesh& mesh = meshes_[k];
  TrackResult r;
  r.obj = mesh.name;
  r.status = states_[k].has_pose ? TrackStatus::kLost : TrackStatus::kNotStarted;
  r.T_cam_obj = states_[k].last;
  const auto& classes = stage1.prior.classes;
  const auto it = std::find(classes.begin(), classes.end(), mesh.name);
  if (it == classes.end()) return r;
  *cls = int(it - classes.begin());
  ObjectInput object;
  if (const auto s = stage1.seeds.find(mesh.name); s != stage1.seeds.end()) object.seeds = s->second;
  FilterOptions o = options_.init;
  o.seed = StepSeed(options_.filter.seed, frame_, k, 2);
  try {
    *est = EstimatePose(frame, object, *InitModel(k), stage1.prior, *cls, o);
    r = Judge(frame.frame().camera, k, *est);
  } catch (const Error&) {
    // The stage 1 holds no usable cell for the object in this frame.
  }
  r.time_ms = MsSince(t0);
  return r;
}

TrackResult Tracker::Judge(const Camera& cam, std::size_t k, const EstimateResult& e) const {
  TrackResult r;
  r.obj = meshes_[k].name;
  r.status = TrackStatus::kLost;
  r.T_cam_obj = e.T_cam_obj;
  r.iterations = e.iterations;
  // Weighed as a search would weigh it (the tracker's α, β, γ, in the window about the pose),
  // so that one threshold serves both.
  const Box b = CornerBox(SearchMesh(k), e.T_cam_obj, cam, options_.filter.render.near_m);
  Window win;
  if (MakeWindow(cam, b, b, k, &win)) {
    const Pose6 pose = TransformToPose(win.scene.camera.base_to_camera.inverse() * e.T_cam_obj);
    r.weight =
        WeighPoses(win.scene, *models_[k], win.prior, 0, StepOptions(options_.filter.seed), {{pose, win.centre_cell}})[0];
    r.status = r.weight >= options_.lost_weight ? TrackStatus::kInitialised : TrackStatus::kLost;
  }
  return r;
}

void Tracker::Accept(std::size_t k, const TrackResult& r) {
  State& s = states_[k];
  if (r.status == TrackStatus::kTracked) {
    if (s.has_pose && !s.lost) {
      s.velocity = r.T_cam_obj * s.last.inverse();
      s.has_velocity = true;
    }
    s.last = r.T_cam_obj;
    s.lost = false;
    // A particle search sets the reference; a confirmation may only raise it.
    s.reference = r.confirmed && s.has_reference ? std::max(s.reference, r.weight) : r.weight;
    s.has_reference = true;
  } else if (r.status == TrackStatus::kInitialised) {
    s.last = r.T_cam_obj;
    s.has_pose = true;
    s.lost = false;
    s.has_velocity = false;
    s.reference = r.weight;
    s.has_reference = true;
  } else if (r.status == TrackStatus::kLost) {
    s.lost = true;
    s.has_velocity = false;
    s.has_reference = false;
  }
}

std::vector<TrackResult> Tracker::Track(const SceneInput& frame, const Stage1Fn& stage1) {
  const std::string what = "frame " + std::to_string(frame_);
  ValidateScene(frame, what);
  if (frame_ == 0) {
    width_ = frame.camera.width;
    height_ = frame.camera.height;
  } else if (frame.camera.width != width_ || frame.camera.height != height_) {
    throw Error(what + ": " + std::to_string(frame.camera.width) + "x" + std::to_string(frame.camera.height) +
                " pixels, but the sequence started at " + std::to_string(width_) + "x" + std::to_string(height_));
  }
  // The scored depth of every search: the frame without its support plane's pixels.
  scoring_ = frame.depth;
  if (options_.filter.support.plane) {
    const std::vector<std::uint8_t> on = SupportPlanePixels(frame.depth, frame.camera, FindSupportPlane(frame.depth, frame.camera));
    for (std::size_t i = 0; i < on.size(); ++i)
      if (on[i]) scoring_.data[i] = 0;
  }
  ++stats_.scenes_prepared;
  std::vector<TrackResult> out(meshes_.size());
  // The searches run in parallel over the objects, each on one thread (a search is a few
  // hundred small weighings: threads inside it would mostly wait on each other). Each has its
  // own random stream, so the result does not depend on the thread count.
  const int n = int(meshes_.size());
  const int workers = std::min(WorkerThreads(options_.filter.threads), n);
  std::vector<std::string> errors(meshes_.size());
  std::vector<SearchCounts> counts(meshes_.size());
  ParallelFor(workers, n, 1, [&](int, int k) {
    out[std::size_t(k)].obj = meshes_[std::size_t(k)].name;
    if (!states_[std::size_t(k)].has_pose) return;
    try {
      out[std::size_t(k)] = Search(frame.camera, std::size_t(k), &counts[std::size_t(k)]);
    } catch (const std::exception& e) {
      errors[std::size_t(k)] = e.what();
    }
  });
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(what + ": " + e);
  for (const SearchCounts& c : counts) {
    stats_.searches += c.searched;
    stats_.confirmed += c.confirmed;
    stats_.weighings += c.weighings;
  }
  std::vector<std::size_t> need;
  for (std::size_t k = 0; k < meshes_.size(); ++k)
    if (!states_[k].has_pose || out[k].status == TrackStatus::kLost || out[k].weight < options_.refresh_weight)
      need.push_back(k);
  if (!need.empty() && stage1) {
    const TrackStage1 s1 = stage1(frame);
    // The frame prepared once (its support surfaces) for every initialisation and the scene
    // pass; its time is shared by the objects initialised.
    const auto t_prep = Clock::now();
    const std::shared_ptr<const PreparedFrame> prepared = PrepareFrame(SceneInput{frame.depth, frame.camera}, options_.init, what);
    const double prep_share = MsSince(t_prep) / double(need.size());
    ++stats_.init_scenes_prepared;
    std::vector<TrackResult> inits(meshes_.size());
    std::vector<SceneObject> joint;  // the objects estimated from the stage 1 in this frame
    std::vector<std::size_t> joint_k;
    for (std::size_t k : need) {
      EstimateResult est;
      int cls = -1;
      inits[k] = Initialise(*prepared, k, s1, &est, &cls);
      inits[k].time_ms += prep_share;
      stats_.initialisations += est.iterations > 0;
      if (est.iterations > 0) joint.push_back({&meshes_[k], cls, est, init_models_[k]}), joint_k.push_back(k);
    }
    // Several objects from one stage 1: the joint scene pass (§17), so that two of them do not
    // settle on one object's pixels.
    if (options_.scene_pass && joint.size() > 1) {
      const auto t0 = Clock::now();
      FilterOptions o = options_.init;
      o.seed = StepSeed(options_.filter.seed, frame_, 0, 3);
      const std::vector<ScenePassResult> passed = RunScenePass(*prepared, s1.prior, joint, o);
      const double share = MsSince(t0) / double(joint.size());
      for (std::size_t j = 0; j < passed.size(); ++j) {
        TrackResult& init = inits[joint_k[j]];
        if (passed[j].replaced) {
          const TrackResult again = Judge(frame.camera, joint_k[j], passed[j].estimate);
          if (again.weight > init.weight) {
            const double time_ms = init.time_ms;
            init = again;
            init.time_ms = time_ms;
          }
        }
        init.time_ms += share;
      }
    }
    for (std::size_t k : need) {
      const TrackResult& init = inits[k];
      const double spent = out[k].time_ms;
      // A lost (or new) object takes the stage 1's pose when that is found, or at least better;
      // a tracked one only when the stage 1's is found and weighs more.
      const bool tracked = out[k].status == TrackStatus::kTracked;
      const bool better = init.weight > out[k].weight;
      if (tracked ? init.status == TrackStatus::kInitialised && better
                  : init.status == TrackStatus::kInitialised || !states_[k].has_pose || better) {
        const int iterations = out[k].iterations;
        out[k] = init;
        out[k].iterations += iterations;
      }
      out[k].time_ms = spent + init.time_ms;
    }
  }
  for (std::size_t k = 0; k < meshes_.size(); ++k) Accept(k, out[k]);
  ++frame_;
  ++stats_.frames;
  return out;
}

}  // namespace posefilter
