// posefilter/filter_options.h — the particle filter's options (EstimatePose, WeighPoses), grouped
// by the step of the filter they steer. Every field is also a CLI option and a Python keyword:
// posefilter/option_table.h lists each with its name there, help, unit, range and the engines
// that read it (`posefilter options` prints that table; docs/OPTIONS.md is it).
//
// Defaults are the tuned product settings; the thesis's own settings are named in each comment
// ("the thesis"). Units: metres, radians, pixels; weights are eq. 7.4 [ALGORITHM.md] units in [0, 1].
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "posefilter/heuristics.h"
#include "posefilter/render.h"

namespace posefilter {

// The diffusion moves, in the order of DiffusionOptions::move_probabilities: the 13 of thesis
// §7.6 first, then 4 of ours (docs/ALGORITHM.md §8).
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

// The weight of a pose, eq. 7.4 [ALGORITHM.md]: α·I/N_raster + β·I/N_depth + γ·ρ − δ·(edge term) − contact.
struct ScoreOptions {
  // Each ≥ 0, α + β + γ = 1.
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
  // Occlusion-aware precision: rendered pixels hidden behind nearer scene depth (beyond the
  // inlier ramp) are left out of N_raster, so a partly occluded object is not penalised for
  // what it cannot show. false = the thesis's N_raster (every rendered pixel).
  bool occlusion_aware = true;
};

// The scene's support plane (ours): the table the objects stand on.
struct SupportOptions {
  // The pixels of the scene's dominant plane (FindSupportPlane, posefilter/support_plane.h)
  // are taken out of the scored depth: never an inlier, never an occluder, not in N_depth, no
  // particle starts there. A thin or flat object's pose laid into the table, or sunk below it,
  // then explains nothing. false = score against every pixel (the thesis).
  bool plane = true;
  // Contact (only where a plane was found): objects rest on the table, so a pose whose lowest
  // point (of the mesh's convex hull) floats more than contact_tolerance_m above the plane, or
  // sinks more than that below it, loses up to `contact` weight, growing linearly over
  // contact_span_m beyond the tolerance. It breaks the near-ties between a thin or flat object
  // and a pose laid on a neighbour's face. 0 = off (objects stacked on others, no table).
  double contact = 0.15;
  double contact_tolerance_m = 0.015;
  double contact_span_m = 0.03;
  // Stable starts (only where a plane was found): this fraction of the initial particles rest
  // on the plane in one of the mesh's stable poses (posefilter/stable_poses.h, drawn by
  // probability) with a uniform yaw, above the point of the plane below their cell's volume
  // centre; the others start as Listing 7.5 [ALGORITHM.md] says. 0 = off (the thesis).
  double stable_start = 0.5;
};

// How each particle is rendered.
struct RenderOptions {
  bool zbuffer = true;               // exact z-buffer (false: the thesis's culling-only mode)
  double near_m = 0.05;              // triangles closer than this to the camera are skipped, m
  // Level of detail (ours; the thesis downsamples to ≤ 1024 vertices, §7.1): render the mesh
  // simplified to at most this many faces (SimplifyMesh, posefilter/mesh_simplify.h), once per
  // EstimatePose/WeighPoses call. 0 = the full mesh; otherwise ≥ 4. The default leaves meshes
  // of up to 4096 faces as they are and brings a 16k-face YCB-Video mesh to 4096, which finds
  // the same objects 2.3× faster (docs/ALGORITHM.md, "Level of detail").
  int lod_max_faces = 4096;
  // Ours: a level of detail by size in the image. The filter weighs the coarsest of the
  // simplified meshes of faces / m² faces (m = 1..4, at least 256 faces; the ladder of
  // adaptive_resolution and anneal.simplify) with at most D² / lod_face_px faces, D the
  // object's projected diameter in pixels at its most probable cell's depth: an object small
  // in the image is weighed with fewer faces, each covering more pixels. Pixels (of D²) per
  // face; 0 = off (the lod_max_faces mesh at every size). At 16 a 16k-face YCB-Video mesh
  // (4096 at lod_max_faces) keeps 4096 faces from 256 px across, 1024 from 128 px, 455 from
  // 86 px and 256 below: rooms 1.2–1.3× faster, but the scene pass rescues fewer objects on
  // the table (docs/ALGORITHM.md §14), so it is off by default.
  double lod_face_px = 0;
  int max_window_px = 200;           // windows are the cell's box clipped to this, pixels
  // Ours: objects whose projected diameter exceeds 1.25 · max_window_px pixels (a large object
  // close to a long-focal-length camera) are weighed on every s-th pixel of every s-th row in
  // windows of up to s · max_window_px pixels, s in [1, 4] the smallest that fits (the coarse
  // annealing level then uses s · anneal.subsample, and with anneal.simplify a mesh simplified
  // to faces / s²): the window holds the whole object and a weighing costs what a 200 px one
  // does. false = every pixel, windows of at most max_window_px (the thesis).
  bool adaptive_resolution = true;
  // Windows are at least this fraction of the object's projected diameter (at the cell's
  // heuristic depth) wide and high, so a box smaller than the object cannot be "explained"
  // by one flat face of it. 0 = the box as it is (the thesis).
  double min_window_diameters = 1.0;
  // Ours: a particle's window also grows to contain its own projected bounding box (up to
  // max(max_window_px, the cell window) per side), so a pose is never judged on a cut-off
  // rendering; N_depth counts the grown window (summed-area table). false = cell windows only.
  bool grow_window = true;
};

// Coarse-to-fine search (ours).
struct AnnealOptions {
  // The inlier threshold starts at start_m and falls geometrically to score.inlier.thr1_m
  // over the first `fraction` of stop.max_iterations (0 or ≤ thr1 = off, the thesis's fixed
  // threshold).
  double start_m = 0.02;
  double fraction = 0.5;
  // Coarse pixels: in the iterations whose inlier threshold is still above its final value —
  // except a run's last possible iteration, whose weights are the answer's — particles are
  // weighed on every subsample-th pixel of every subsample-th row (SubsampleScene: the depth
  // image and the camera subsampled by that factor; the ratios of eq. 7.4 [ALGORITHM.md] keep their scale).
  // Every weighing after annealing, the polish and WeighPoses use every pixel. 1 = off (the
  // thesis); 1..4.
  int subsample = 3;
  // On that coarse grid, also weigh a simplified mesh: SimplifyMesh to max(256,
  // faces / subsample²) faces, built once per estimate (a mesh meshoptimizer cannot bring to
  // that budget is weighed as it is), so that the per-face work shrinks with the pixels.
  // false = the (LOD) mesh itself on the coarse grid too.
  bool simplify = true;
};

// Niches of the resampling (ours): keep several hypotheses alive until the fine threshold can
// rank them.
struct NicheOptions {
  // At most this fraction of the resampling pool may come from one hypothesis (the cells
  // sharing one decoded box, i.e. one detection). 1 = off (the thesis's elitism).
  double region_cap = 0.34;
  // At most this fraction of the pool may share one hypothesis and one coarse orientation
  // (24 bins: the rotations of a cube). 1 = off.
  double rotation_cap = 0.1;
};

// Diffusion (thesis §7.6): each resampled particle makes one move with Gaussian noise of
// σ = max((1 − w_best)·σ0, min_sigma_fraction·σ0).
struct DiffusionOptions {
  double sigma_t0_m = 0.01;          // translation σ at weight 0, metres
  double sigma_r0_rad = 0.2;         // rotation σ at weight 0, radians
  double min_sigma_fraction = 0.05;  // σ never decays below this fraction of σ0
  // Probability of each Move (normalised internally over the moves that apply: kOnPlane only
  // where a support plane was found).
  std::array<double, kNumMoves> move_probabilities = {0.09, 0.09, 0.09, 0.09, 0.08, 0.08, 0.08, 0.1, 0.02,
                                                      0.02, 0.02, 0.05, 0.05, 0.1,  0.04, 0.05, 0.1};
  double align_band_m = 0.05;        // depth differences used by the align-depth move, metres
};

// When a run ends.
struct StopOptions {
  int max_iterations = 17;           // weighings of the set per run; [1, 100000]
  double confidence = 0.9;           // stop when the best weight reaches this, in (0, 1]
  // Ours: a run also ends, at the final inlier threshold, once its best weight has risen by
  // less than stall_gain over the last stall_iterations iterations (the elite keeps the best
  // particle, so the best weight does not fall there). 0 = off: run until confidence or
  // max_iterations (the thesis).
  int stall_iterations = 3;
  double stall_gain = 0.01;          // weight (eq. 7.4 [ALGORITHM.md] units)
  // Ours: with more than two restarts, the rest are skipped when the first two runs agree: their
  // best poses' origins lie within restart_agree_m (metres, [0, 1]; 0 = off: every restart
  // runs) and their best weights within restart_agree_weight (eq. 7.4 [ALGORITHM.md] units, [0, 1]).
  double restart_agree_m = 0.01;
  double restart_agree_weight = 0.02;
};

// Final polish (ours): the best pose of every run, and each of those turned about the model's
// bounding-box centre by the 23 other rotations of a cube, is refined by point-to-plane ICP
// steps at the final inlier threshold; the best weight seen wins.
struct PolishOptions {
  int steps = 8;                     // ICP steps per polished candidate; 0 = off (the thesis)
  bool turns = true;                 // include the 23 turned copies (false: refine only)
  // Also turn about the bounding box's edges and corners (9 pivots per turn), weigh every
  // copy once, and polish only the best `keep` copies.
  bool pivots = true;
  int keep = 48;
  // With a support plane (and support.stable_start > 0): also stand each seed, at its centre
  // of mass's point of the plane, in each of the mesh's stable poses of at least 1 % (at most
  // 8), turned about the plane's normal in 24 steps of 15°; weighed once with the turned
  // copies, the best `keep` of all go on.
  bool stable = true;
  // Seeds per run: the best particle of each (hypothesis, orientation) niche of the run's
  // final set, best first. With turns, each seed costs 24 × (steps + 1) weighings.
  int seeds = 1;
  // The best this many polished candidates then climb the weight by pattern search
  // (±1 cm / ±0.1 rad along camera axes, halved down to 0.5 mm when nothing improves).
  int climbers = 4;
};

struct FilterOptions {
  // The engine that weighs particles: "cpu" (SIMD kernel), "reference" (float, readable; the
  // same results) or "hw" (bit-accurate model of the thesis's FPGA, posefilter/hw_engine.h).
  std::string engine = "cpu";
  // The cpu engine's instruction set: "auto" (the best this CPU and build run), or "avx512",
  // "avx2", "portable" to force one (same results; for measuring what another machine gets).
  std::string cpu_isa = "auto";
  int num_particles = 510;           // N (thesis design: 510; GRIP: 625)
  int num_elite = 10;                // best particles carried unchanged into the next set
  double resample_pool = 0.25;       // fraction of the sorted set the rest is drawn from, (0, 1]
  // Ours: once the inlier threshold has annealed to its final value, each set has
  // round(fine_particle_fraction · num_particles) particles (340 of 510): the filter then
  // refines modes it has found, and the resampling keeps the best of them. Only with annealing
  // on (anneal.start_m > thr1; without it every set has num_particles, as in the thesis).
  // 1 = every set num_particles; (0, 1]. The fine set has at least num_elite + 1 particles.
  double fine_particle_fraction = 2.0 / 3.0;
  int init_oversample = 1;           // ours: draw this many × N initial particles, keep the best N
  // Ours: where the scene has pose seeds (SceneInput::seeds), this fraction of the initial
  // particles start at a seed (drawn by score); the others start as without seeds. [0, 1].
  double seed_start = 0.3;
  int tracker_bins = 32;             // threshold-tracker entries of the CDF samplers (§7.4)
  int restarts = 4;                  // ours: independent runs, the best weight wins (time × restarts)
  std::uint64_t seed = 1;            // every random stream derives from this
  // Worker threads (scoring, scene normals, heuristic volumes); 0 = all cores, at most 4 per
  // hardware thread. The result does not depend on it.
  int threads = 0;
  // Record every iteration's particle set (poses and weights, EstimateResult::particle_history)
  // for the viewer (posefilter/view.h). The float engines record; the hw engine does not. It
  // changes no pose; false records nothing and costs nothing.
  bool record_particles = false;

  ScoreOptions score;
  SupportOptions support;
  RenderOptions render;
  AnnealOptions anneal;
  NicheOptions niches;
  DiffusionOptions diffusion;
  StopOptions stop;
  PolishOptions polish;
  HeuristicOptions heuristics;       // depth_extension_m is set to the object's radius if 0

  // Checks every option's range and the constraints between options; `why` names the first
  // violated one by its field path (e.g. "anneal.subsample must be in [1, 4] (got 7)").
  bool IsValid(std::string* why) const;
};

}  // namespace posefilter
