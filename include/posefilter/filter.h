// posefilter/filter.h — stage 2: the particle filter that finds an object's 6-DoF pose.
//
// Algorithm (thesis §2.2, §7.4–7.6, App. B; docs/ALGORITHM.md §4–9), per object:
//   1. initialise N particles by importance sampling the prior's cells (normalised CDF,
//      eq. 7.3, with a threshold tracker) and placing each in its cell's heuristic volume
//      (x, y at the centre, z uniform, Listing 7.5), angles uniform in ±π;
//   2. weigh each particle: render the mesh in its window and sum soft inliers,
//      w = α·I/N_raster + β·I/N_depth + γ·ρ (eq. 7.4);
//   3. sort online (insertion, like the macro sorting cells of §7.5.4);
//   4. stop when the best weight ≥ confidence or after max_iterations;
//   5. resample: keep the elite, importance-sample the rest from the sorted weights' CDF;
//   6. diffuse with one of the moves of `Move`, Gaussian noise with σ = (1 − w_best)·σ0 (§7.6);
//      go to 2.
// docs/ALGORITHM.md lists every formula and each deviation from the thesis.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/heuristics.h"
#include "posefilter/mesh.h"
#include "posefilter/pose.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"

namespace posefilter {

// The diffusion moves, in the order of FilterOptions::move_probabilities: the 13 of thesis §7.6
// first, then 4 of ours (docs/ALGORITHM.md §8).
enum class Move : int {
  kTranslateX, kTranslateY, kTranslateZ, kTranslateAll,
  kRotateRoll, kRotatePitch, kRotateYaw, kRotateAll,
  kFlipRoll, kFlipPitch, kFlipYaw,   // add π to one angle
  kNeighbourCell,                    // move to a neighbouring cell of the same pyramid level
  kOtherLevel,                       // move to the matching cell of another level
  kAlignDepth,                       // ours: shift along the viewing ray by the mean depth
                                     // misalignment measured at the last weighing
  kQuarterTurn,                      // ours: turn ±π/2 about one of the object's own axes
  kIcpStep,                          // ours: one point-to-plane ICP step (from the last weighing)
  kOnPlane,                          // ours: turn about the support plane's normal and slide
                                     // along the plane (only where a support plane was found)
  kCount
};
inline constexpr int kNumMoves = static_cast<int>(Move::kCount);

struct FilterOptions {
  std::string engine = "cpu";  // "cpu" (SIMD kernel, same results) or "reference" (float, readable)
  // The cpu engine's instruction set: "auto" (the best this CPU and build run), or "avx512",
  // "avx2", "portable" to force one (same results; for measuring what another machine gets).
  std::string cpu_isa = "auto";
  int num_particles = 510;           // N (thesis design: 510; GRIP: 625)
  int max_iterations = 17;           // stop a run after this many weighings; [1, 100000]
  double confidence = 0.9;           // stop when the best weight reaches this, in (0, 1]
  // Weight of eq. 7.4: α·I/N_raster + β·I/N_depth + γ·ρ; each ≥ 0, α + β + γ = 1.
  double alpha = 0.2;
  double beta = 0.5;
  double gamma = 0.3;
  // Silhouette edge penalty (ours, z-buffer mode only): the weight loses
  // delta·(edge samples where the scene surface continues across the rendered outline) /
  // (edge samples). A pose whose outline lies inside a continuous surface — a face laid on
  // the table, a silhouette shrunk into the visible part of the object — pays for it.
  double delta = 0.3;
  double edge_band_m = 0.01;         // "no depth step across the outline" band, metres
  InlierParams inlier;               // soft-inlier thresholds / hard switch (final values)
  // Coarse-to-fine search: the inlier threshold starts at anneal_start_m and falls
  // geometrically to inlier.thr1_m over the first anneal_fraction of max_iterations
  // (0 or ≤ thr1 = off, the thesis's fixed threshold).
  double anneal_start_m = 0.02;
  double anneal_fraction = 0.5;
  // Coarse pixels while annealing (ours): in the iterations whose inlier threshold is still
  // above its final value — except a run's last possible iteration, whose weights are the
  // answer's — particles are weighed on every anneal_subsample-th pixel of every
  // anneal_subsample-th row (SubsampleScene: the depth image and the camera subsampled by that
  // factor; the ratios of eq. 7.4 keep their scale). Every weighing after annealing, the
  // polish and WeighPoses use every pixel. 1 = off (the thesis); 1..4. The hw engine, a model
  // of the thesis's full-resolution raster, ignores it.
  int anneal_subsample = 3;
  // On that coarse grid, also weigh a simplified mesh (ours): SimplifyMesh to max(256,
  // faces / anneal_subsample²) faces, built once per estimate (a mesh meshoptimizer cannot
  // bring to that budget is weighed as it is), so that the per-face work shrinks with the
  // pixels. false = the (LOD) mesh itself on the coarse grid too.
  bool anneal_simplify = true;
  bool zbuffer = true;               // exact z-buffer (false: the thesis's culling-only mode)
  // Support plane (ours): the pixels of the scene's dominant plane (the table; FindSupportPlane,
  // posefilter/support_plane.h) are taken out of the scored depth: never an inlier, never an
  // occluder, not in N_depth, no particle starts there. A thin or flat object's pose laid into
  // the table, or sunk below it, then explains nothing. false = score against every pixel
  // (the thesis).
  bool support_plane = true;
  // Contact with the support plane (ours; only where a support plane was found): objects rest
  // on the table, so a pose whose lowest point (of the mesh's convex hull) floats more than
  // contact_tolerance_m above the plane, or sinks more than that below it, loses up to
  // `contact` weight, growing linearly over contact_span_m beyond the tolerance. It breaks
  // the near-ties between a thin or flat object and a pose laid on a neighbour's face. 0 =
  // off (objects stacked on others, or no table in view).
  double contact = 0.15;
  // Stable starts (ours; only where a support plane was found): this fraction of the initial
  // particles rest on the plane in one of the mesh's stable poses (posefilter/stable_poses.h,
  // drawn by probability) with a uniform yaw, above the point of the plane below their cell's
  // volume centre; the others start as Listing 7.5 says. 0 = off (the thesis).
  double stable_start = 0.5;
  double contact_tolerance_m = 0.015;
  double contact_span_m = 0.03;
  // Occlusion-aware precision: rendered pixels hidden behind nearer scene depth (beyond the
  // inlier ramp) are left out of N_raster, so a partly occluded object is not penalised for
  // what it cannot show. false = the thesis's N_raster (every rendered pixel).
  bool occlusion_aware = true;
  int max_window_px = 200;           // windows are the cell's box clipped to this, pixels
  // Ours: objects whose projected diameter exceeds 1.25 · max_window_px pixels (a large object
  // close to a long-focal-length camera) are weighed on every s-th pixel of every s-th row in
  // windows of up to s · max_window_px pixels, s in [1, 4] the smallest that fits (the coarse
  // annealing level then uses s · anneal_subsample, and with anneal_simplify a mesh simplified
  // to faces / s²): the window holds the whole object and a weighing costs what a 200 px one
  // does. false = every pixel, windows of at most max_window_px (the thesis). The hw engine
  // ignores it.
  bool adaptive_resolution = true;
  // Windows are at least this fraction of the object's projected diameter (at the cell's
  // heuristic depth) wide and high, so a box smaller than the object cannot be "explained"
  // by one flat face of it. 0 = the box as it is (thesis).
  double min_window_diameters = 1.0;
  // Ours: a particle's window also grows to contain its own projected bounding box (up to
  // max(max_window_px, the cell window) per side), so a pose is never judged on a cut-off
  // rendering; N_depth counts the grown window (summed-area table). false = cell windows only.
  bool grow_window = true;
  double near_m = 0.05;              // triangles closer than this to the camera are skipped, m
  // Level of detail (ours; the thesis downsamples to ≤ 1024 vertices, §7.1): render the mesh
  // simplified to at most this many faces (SimplifyMesh, posefilter/mesh_simplify.h), once per
  // EstimatePose/WeighPoses call. 0 = the full mesh; otherwise ≥ 4. The default leaves meshes
  // of up to 4096 faces as they are and brings a 16k-face YCB-Video mesh to 4096, which finds
  // the same objects 2.3× faster (docs/ALGORITHM.md, "Level of detail").
  int lod_max_faces = 4096;
  int init_oversample = 1;           // ours: draw this many × N initial particles, keep the best N
  // Ours: once the inlier threshold has annealed to its final value, each set has
  // round(fine_particle_fraction · num_particles) particles (340 of 510): the filter then
  // refines modes it has found, and the resampling keeps the best of them. Only with annealing
  // on (anneal_start_m > thr1; without it every set has num_particles, as in the thesis).
  // 1 = every set num_particles; (0, 1]. The fine set has at least num_elite + 1 particles.
  // The hw engine (510 particles in hardware) ignores it.
  double fine_particle_fraction = 2.0 / 3.0;
  int num_elite = 10;                // best particles carried unchanged into the next set
  double resample_pool = 0.25;       // fraction of the sorted set the rest is drawn from, (0, 1]
  // At most this fraction of the resampling pool may come from one hypothesis (the cells
  // sharing one decoded box, i.e. one detection): keeps true and false detections alive
  // until the fine inlier threshold can tell them apart. 1 = off (the thesis's elitism).
  double region_cap = 0.34;
  // At most this fraction of the pool may share one hypothesis and one coarse orientation
  // (24 bins: the rotations of a cube), so several orientations survive until the fine
  // threshold can rank them. 1 = off.
  double rotation_cap = 0.1;
  int tracker_bins = 32;             // threshold-tracker entries of the CDF samplers (§7.4)
  double sigma_t0_m = 0.01;          // diffusion translation σ at weight 0, metres
  double sigma_r0_rad = 0.2;         // diffusion rotation σ at weight 0, radians
  double min_sigma_fraction = 0.05;  // σ never decays below this fraction of σ0
  // Probability of each Move (normalised internally over the moves that apply: kOnPlane only
  // where a support plane was found).
  std::array<double, kNumMoves> move_probabilities = {0.09, 0.09, 0.09, 0.09, 0.08, 0.08, 0.08, 0.1, 0.02,
                                                      0.02, 0.02, 0.05, 0.05, 0.1,  0.04, 0.05, 0.1};
  double align_band_m = 0.05;        // depth differences used by the align-depth move, metres
  HeuristicOptions heuristics;       // depth_extension_m is set to the object's radius if 0
  int restarts = 4;                  // ours: independent runs, the best weight wins (time × restarts)
  // Ours: a run also ends, at the final inlier threshold, once its best weight has risen by
  // less than stall_gain over the last stall_iterations iterations (the elite keeps the best
  // particle, so the best weight does not fall there). 0 = off: run until confidence or
  // max_iterations (the thesis).
  int stall_iterations = 3;
  double stall_gain = 0.01;          // weight (eq. 7.4 units)
  // Final polish (ours): the best pose of every run, and each of those turned about the
  // model's bounding-box centre by the 23 other rotations of a cube, is refined by this many
  // point-to-plane ICP steps at the final inlier threshold; the best weight seen wins.
  // 0 = off (the thesis: the filter's best particle is the answer).
  int polish_steps = 8;
  bool polish_turns = true;          // include the 23 turned copies (false: refine only)
  // Also turn about the bounding box's edges and corners (9 pivots per turn), weigh every
  // copy once, and polish only the best polish_keep copies.
  bool polish_pivots = true;
  int polish_keep = 48;
  // With a support plane (and stable_start > 0): also stand each seed, at its centre of
  // mass's point of the plane, in each of the mesh's stable poses of at least 1 % (at most 8),
  // turned about the plane's normal in 24 steps of 15°; weighed once with the turned copies,
  // the best polish_keep of all go on.
  bool polish_stable = true;
  // Seeds per run: the best particle of each (hypothesis, orientation) niche of the run's
  // final set, best first. With turns, each seed costs 24 × (polish_steps + 1) weighings.
  int polish_seeds = 1;
  // The best this many polished candidates then climb the weight by pattern search
  // (±1 cm / ±0.1 rad along camera axes, halved down to 0.5 mm when nothing improves).
  int polish_climbers = 4;
  std::uint64_t seed = 1;            // every random stream derives from this
  int threads = 0;                   // worker threads (scoring, scene normals, heuristic volumes); 0 = all cores, at most 4 per hardware thread
  bool IsValid(std::string* why) const;
};

// Counters of one run, the quantities the thesis reports (§7.4, §7.5.3–7.5.4).
struct FilterStats {
  std::int64_t init_cdf_reads = 0, init_cdf_reads_linear = 0;          // with / without tracker
  std::int64_t resample_cdf_reads = 0, resample_cdf_reads_linear = 0;
  std::int64_t faces_total = 0, faces_front = 0;   // summed over all weighings
  std::int64_t fragments = 0;                      // counted fragments (N_raster) summed
  std::int64_t weighings = 0;                      // particle scores computed

  FilterStats& operator+=(const FilterStats& o) {
    init_cdf_reads += o.init_cdf_reads;
    init_cdf_reads_linear += o.init_cdf_reads_linear;
    resample_cdf_reads += o.resample_cdf_reads;
    resample_cdf_reads_linear += o.resample_cdf_reads_linear;
    faces_total += o.faces_total;
    faces_front += o.faces_front;
    fragments += o.fragments;
    weighings += o.weighings;
    return *this;
  }
};

struct EstimateResult {
  std::string obj;
  Pose6 pose_base;                                              // object → base
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera
  double weight = 0;            // best weight, eq. 7.4
  int cell = -1;                // prior cell of the best particle
  int iterations = 0;           // weighings of the whole set (summed over restarts)
  bool converged = false;       // weight reached the confidence threshold
  double time_ms = 0;           // wall time
  std::vector<double> best_weight_history;   // best weight after each iteration
  std::vector<double> iteration_ms;          // wall time of each iteration
  FilterStats stats;
};

// Called after each iteration with (iteration index from 0, best weight so far).
using ProgressFn = std::function<void(int, double)>;

// The scene a filter runs on: depth (camera z, metres, 0 = missing) and the camera, and
// optionally the instance mask of the object looked for.
struct SceneInput {
  DepthImage depth;
  Camera camera;
  // Empty, or width × height bytes (row-major): non-zero where a segmentation front end
  // (Mask R-CNN, SAM, a label image) sees the object. With a mask, only mask pixels can be
  // inliers and count in N_depth, and particles start from the mask's depth; pixels outside
  // it never count against a pose that something else hides (docs/ALGORITHM.md, "Mask priors").
  std::vector<std::uint8_t> mask = {};
};

// Checks that depth and camera agree in size, the depth holds at least one valid pixel and
// no NaN/inf/negative value, and a mask (if any) has the image's size and at least one
// pixel; throws Error naming `what` otherwise.
void ValidateScene(const SceneInput& scene, const std::string& what);

// The scene on a coarser pixel grid (FilterOptions::anneal_subsample): pixel (i, j) of the
// result is pixel (factor·i, factor·j) of `scene` (no averaging: every depth is a reading of
// the sensor), ceil(width / factor) × ceil(height / factor) pixels, fx, fy, cx, cy divided
// by factor, the same base_to_camera — so a camera-frame point projects to 1/factor of its
// full-resolution pixel coordinates. Throws Error when factor < 1.
SceneInput SubsampleScene(const SceneInput& scene, int factor);

// Runs the filter for one object. `cls` indexes prior.classes. Throws Error on invalid
// options, a class index out of range, a prior of the wrong image size, or when no prior
// cell has both probability mass and valid depth.
EstimateResult EstimatePose(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress = nullptr);

// Weighs given hypotheses (pose object → base, prior cell whose window is used) exactly as
// the filter would with `options` (final inlier thresholds): eq. 7.4 per hypothesis.
std::vector<double> WeighPoses(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                               const FilterOptions& options, const std::vector<std::pair<Pose6, int>>& hypotheses);

}  // namespace posefilter
