// posefilter/filter.h — stage 2: the particle filter that finds an object's 6-DoF pose.
//
// Algorithm (thesis §2.2, §7.4–7.6, App. B; docs/ALGORITHM.md §4–9), per object:
//   1. initialise N particles by importance sampling the prior's cells (normalised CDF,
//      eq. 7.3 [ALGORITHM.md], with a threshold tracker) and placing each in its cell's heuristic volume
//      (x, y at the centre, z uniform, Listing 7.5 [ALGORITHM.md]), angles uniform in ±π;
//   2. weigh each particle: render the mesh in its window and sum soft inliers,
//      w = α·I/N_raster + β·I/N_depth + γ·ρ (eq. 7.4 [ALGORITHM.md]);
//   3. sort online (insertion, like the macro sorting cells of §7.5.4);
//   4. stop when the best weight ≥ confidence or after max_iterations (FilterOptions, filter_options.h);
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
#include "posefilter/filter_options.h"
#include "posefilter/heuristics.h"
#include "posefilter/mesh.h"
#include "posefilter/pose.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"

namespace posefilter {

class PreparedModel;  // a mesh prepared once for the filter (posefilter/prepared_model.h)
class PreparedFrame;  // a depth frame prepared once for the filter (posefilter/prepared_frame.h)

// Counters of one run, the quantities the thesis reports (§7.4, §7.5.3–7.5.4).
struct FilterStats {
  std::int64_t init_cdf_reads = 0, init_cdf_reads_linear = 0;          // with / without tracker
  std::int64_t resample_cdf_reads = 0, resample_cdf_reads_linear = 0;
  std::int64_t faces_total = 0, faces_front = 0;   // summed over all weighings
  std::int64_t fragments = 0;                      // counted fragments (N_raster) summed
  std::int64_t weighings = 0;                      // particle scores computed
  // The rtl engine only: clocks of its weighings in the Verilated accelerator (CYCLES, AP_START
  // to AP_DONE) and the cycle model's clocks for the same part (docs/HARDWARE.md §16), summed
  // over rtl_calls weighings (one per iteration).
  std::int64_t rtl_calls = 0, rtl_cycles = 0, rtl_model_cycles = 0;

  FilterStats& operator+=(const FilterStats& o) {
    init_cdf_reads += o.init_cdf_reads;
    init_cdf_reads_linear += o.init_cdf_reads_linear;
    resample_cdf_reads += o.resample_cdf_reads;
    resample_cdf_reads_linear += o.resample_cdf_reads_linear;
    faces_total += o.faces_total;
    faces_front += o.faces_front;
    fragments += o.fragments;
    weighings += o.weighings;
    rtl_calls += o.rtl_calls;
    rtl_cycles += o.rtl_cycles;
    rtl_model_cycles += o.rtl_model_cycles;
    return *this;
  }
};

// One iteration's particle set, recorded when FilterOptions::record_particles is on: every
// particle as weighed in that iteration, best first. Weights of annealing iterations are
// measured at that iteration's looser inlier threshold (and on the coarse pixel grid).
struct ParticleSet {
  int run = 0;                     // restart, from 0
  int iteration = 0;               // iteration within the run, from 0
  std::vector<Pose6> poses;        // object → base
  std::vector<double> weights;     // eq. 7.4 [ALGORITHM.md], same order as poses (descending)
};

struct EstimateResult {
  std::string obj;
  Pose6 pose_base;                                              // object → base
  Eigen::Isometry3d T_cam_obj = Eigen::Isometry3d::Identity();  // object → camera
  double weight = 0;            // best weight, eq. 7.4 [ALGORITHM.md]
  int cell = -1;                // prior cell of the best particle
  int iterations = 0;           // weighings of the whole set (summed over restarts)
  bool converged = false;       // weight reached the confidence threshold
  double time_ms = 0;           // wall time
  std::vector<double> best_weight_history;   // best weight after each iteration
  std::vector<double> iteration_ms;          // wall time of each iteration
  // With FilterOptions::record_particles (float engines): the particle set of every
  // iteration of every run, in order (run 0's iterations first); empty otherwise.
  std::vector<ParticleSet> particle_history;
  FilterStats stats;
};

// Called after each iteration with (iteration index from 0, counted over all restarts; the best
// weight any run has reached at the final inlier threshold). The weight never falls; it is NaN
// while the first run is still annealing (its weights are measured at a looser threshold and do
// not compare with the final ones). The final polish may raise the result's weight above it.
using ProgressFn = std::function<void(int, double)>;

// The scene a filter runs on: depth (camera z, metres, 0 = missing) and the camera, and
// optionally the instance mask and pose seeds of the object looked for.
struct SceneInput {
  DepthImage depth;
  Camera camera;
  // Empty, or width × height bytes (row-major): non-zero where a segmentation front end
  // (Mask R-CNN, SAM, a label image) sees the object. With a mask, only mask pixels can be
  // inliers and count in N_depth, and particles start from the mask's depth; pixels outside
  // it never count against a pose that something else hides (docs/ALGORITHM.md, "Mask priors").
  std::vector<std::uint8_t> mask = {};
  // Empty, or pose hypotheses of the object: the float engines start FilterOptions::seed_start
  // of the initial particles at them (drawn by score, each in the prior cell of the class's
  // highest probability whose anchor holds its projected centre; a seed no such cell holds is
  // not used). The hw engine does not read them.
  std::vector<PoseSeed> seeds = {};
};

// What one object adds to a frame prepared once for several (PreparedFrame): SceneInput's mask
// and seeds, with the same meaning and checks.
struct ObjectInput {
  std::vector<std::uint8_t> mask = {};
  std::vector<PoseSeed> seeds = {};
};

// Checks that depth and camera agree in size, the depth holds at least one valid pixel and
// no NaN/inf/negative value, a mask (if any) has the image's size and at least one pixel,
// and every seed is finite with a score > 0; throws Error naming `what` otherwise.
void ValidateScene(const SceneInput& scene, const std::string& what);

// The scene on a coarser pixel grid (FilterOptions::anneal.subsample): pixel (i, j) of the
// result is pixel (factor·i, factor·j) of `scene` (no averaging: every depth is a reading of
// the sensor), ceil(width / factor) × ceil(height / factor) pixels, fx, fy, cx, cy divided
// by factor, the same base_to_camera — so a camera-frame point projects to 1/factor of its
// full-resolution pixel coordinates. Throws Error when factor < 1.
SceneInput SubsampleScene(const SceneInput& scene, int factor);

// Runs the filter for one object. `cls` indexes prior.classes. Throws Error on invalid
// options, a class index out of range, a prior of the wrong image size, or when no prior
// cell has both probability mass and valid depth. The mesh is prepared for this one estimate
// (PrepareModel, posefilter/prepared_model.h).
EstimateResult EstimatePose(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress = nullptr);
// The same on a mesh prepared once (PrepareModel): the same result, bit for bit, without the
// mesh's preparation when the model holds what `options` read (PreparedModel::Covers; else
// the missing part is prepared for this estimate). Any number of estimates may share `model`,
// from any threads.
EstimateResult EstimatePose(const SceneInput& scene, const PreparedModel& model, const Prior& prior, int cls,
                            const FilterOptions& options, const ProgressFn& progress = nullptr);
// The same on a frame prepared once (PrepareFrame, posefilter/prepared_frame.h) with the
// object's mask and seeds: the result of EstimatePose on SceneInput{frame's depth and camera,
// object.mask, object.seeds}, bit for bit, without preparing the frame again (its support
// surfaces) when the frame was prepared with options.support.plane. Throws Error as above, and
// on a mask or seed that SceneInput's checks (ValidateScene) reject.
EstimateResult EstimatePose(const PreparedFrame& frame, const ObjectInput& object, const PreparedModel& model,
                            const Prior& prior, int cls, const FilterOptions& options,
                            const ProgressFn& progress = nullptr);
EstimateResult EstimatePose(const PreparedFrame& frame, const ObjectInput& object, const Mesh& mesh, const Prior& prior,
                            int cls, const FilterOptions& options, const ProgressFn& progress = nullptr);

// Weighs given hypotheses (pose object → base, prior cell whose window is used) exactly as
// the filter would with `options` (final inlier thresholds): eq. 7.4 [ALGORITHM.md] per hypothesis.
std::vector<double> WeighPoses(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                               const FilterOptions& options, const std::vector<std::pair<Pose6, int>>& hypotheses);
std::vector<double> WeighPoses(const SceneInput& scene, const PreparedModel& model, const Prior& prior, int cls,
                               const FilterOptions& options, const std::vector<std::pair<Pose6, int>>& hypotheses);
// The same on a prepared frame with the object's mask and seeds (as EstimatePose above).
std::vector<double> WeighPoses(const PreparedFrame& frame, const ObjectInput& object, const PreparedModel& model,
                               const Prior& prior, int cls, const FilterOptions& options,
                               const std::vector<std::pair<Pose6, int>>& hypotheses);
std::vector<double> WeighPoses(const PreparedFrame& frame, const ObjectInput& object, const Mesh& mesh,
                               const Prior& prior, int cls, const FilterOptions& options,
                               const std::vector<std::pair<Pose6, int>>& hypotheses);

}  // namespace posefilter
