// posefilter/bop_metrics.h — BOP 2019 pose errors (VSD, MSSD, MSPD), their recalls and the
// average recall AR, and the YCB-Video AUC of ADD / ADD-S (docs/DATASETS.md, "Metrics").
//
// Poses map object → camera (metres); model points are in the object frame (metres).
//   MSSD = min_S max_p ‖T_est·p − T_gt·S·p‖                  (metres)
//   MSPD = min_S max_p ‖π(T_est·p) − π(T_gt·S·p)‖             (pixels, π = the camera's projection)
//   S over SymmetryTransformations(model) (the identity included).
//   VSD (BOP 2019, "step" cost, visibility of the 2019 toolkit): with distance images (range
//   along the pixel's ray) D_I of the test depth, D_e and D_g of the model rendered alone at
//   T_est and T_gt (RenderDepth), the masks
//     V_g = {D_g > 0 ∧ (D_g − D_I ≤ δ ∨ D_I = 0)},
//     V_e = {D_e > 0 ∧ (D_e − D_I ≤ δ ∨ D_I = 0)} ∪ (V_g ∩ {D_e > 0}),
//   e_VSD(τ) = (|{p ∈ V_e ∩ V_g : |D_e − D_g| ≥ τ}| + |V_e ∪ V_g| − |V_e ∩ V_g|) / |V_e ∪ V_g|
//   (1 when the union is empty), τ a fraction of the diameter (distances divided by it).
// Recalls (BOP 2019): per image and object, the top inst_count estimates (by score) are matched
// greedily in score order, each to the unmatched gt instance of the same object with the
// smallest error below the threshold; recall = matched gt instances / gt instances of the
// targets, averaged over the thresholds (VSD: over all τ × threshold pairs); AR = mean of the
// VSD, MSSD and MSPD recalls.
// YCB-Video AUC (PoseCNN, Xiang et al. 2018): per gt instance the error of its estimate (∞ when
// none), the accuracy curve acc(t) = fraction of errors ≤ t for t in [0, max], and its area
// normalised to [0, 1] exactly as PoseCNN's VOCap computes it (right-endpoint steps: the sorted
// finite errors d_1..d_m (≤ max) with acc_k = k/n, area = Σ_k (d_k − d_{k−1})·acc_k +
// (max − d_m)·acc_m, divided by max). With few estimates this is above the exact integral of
// acc(t) by at most d_m/(max·n).
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "posefilter/bop.h"
#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/mesh.h"

namespace posefilter {

// All symmetry transformations of a model, identity first (object frame, metres): the
// discrete ones of models_info, each combined with the continuous ones discretised into
// n = ⌈π / max_sym_disc_step⌉ rotations by 2πk/n, k = 0..n−1 (BOP toolkit's
// get_symmetry_transformations; we keep k = 0, so the plain discrete symmetries stay in the set).
// max_sym_disc_step must be finite and > 0 (BOP: 0.01).
std::vector<Eigen::Isometry3d> SymmetryTransformations(const DatasetModel& model, double max_sym_disc_step = 0.01);

// MSSD (metres) and MSPD (pixels) as above; `syms` non-empty, `pts` non-empty (else Error).
double MssdError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                 const Eigen::Isometry3d& T_gt, const std::vector<Eigen::Isometry3d>& syms);
double MspdError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                 const Eigen::Isometry3d& T_gt, const std::vector<Eigen::Isometry3d>& syms, const Camera& camera);

// Depth image (camera z, metres) → distance image (metres along each pixel's ray), 0 stays 0.
DepthImage DepthToDistance(const DepthImage& depth, const Camera& camera);

// VSD errors, one per τ in `taus` (fractions of `diameter_m`), each in [0, 1]. `test_depth` is
// the image's depth (metres, 0 = missing) of the camera's size; delta_m the visibility
// tolerance δ (BOP: 15 mm). Throws Error on a size mismatch, diameter ≤ 0 or δ < 0.
std::vector<double> VsdErrors(const Mesh& mesh, const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_gt,
                              const DepthImage& test_depth, const Camera& camera, double delta_m,
                              const std::vector<double>& taus, double diameter_m);

// YCB-Video AUC (see above) of per-instance errors (metres; ∞ or > max_m = not accepted).
// Returns 0 for no errors; max_m must be > 0.
double YcbvAuc(const std::vector<double>& errors_m, double max_m = 0.1);

// {start, start + step, …} with k = 1..count: start·k (0.05…0.5 for (0.05, 10)).
std::vector<double> Multiples(double start, int count);

struct BopEvalOptions {
  double vsd_delta_m = 0.015;                       // δ, metres (BOP 2019: 15 mm)
  std::vector<double> vsd_taus = Multiples(0.05, 10);        // τ, fractions of the diameter
  std::vector<double> vsd_thresholds = Multiples(0.05, 10);  // e_VSD < th is correct
  std::vector<double> mssd_thresholds = Multiples(0.05, 10);  // fractions of the diameter
  // MSPD thresholds in pixels at a 640-pixel-wide image; scaled by width/640 (BOP 2019: r = w/640).
  std::vector<double> mspd_thresholds_px = Multiples(5, 10);
  double add_threshold = 0.1;          // ADD / ADD-S accepted below this fraction of the diameter
  double auc_max_m = 0.1;              // YCB-Video AUC: errors capped at this, metres
  double max_sym_disc_step = 0.01;     // continuous symmetry discretisation (BOP: 0.01)
  int max_points = 2000;               // model points from a mesh (SamplePoints); a points file is used whole
  bool compute_vsd = true;             // false: skip the renderings (VSD recall and AR reported as NaN)
  // Every list non-empty with finite values > 0 (VSD thresholds ≤ 1), δ ≥ 0, thresholds > 0,
  // max_points ≥ 1. Names the violated field.
  bool IsValid(std::string* why) const;
};

// Errors of one gt instance of a target (∞ = no estimate assigned to it; assignment per metric:
// estimates in score order each take the unmatched instance with the smallest error).
struct BopTargetEval {
  int scene_id = 0, im_id = 0, obj_id = 0;
  int gt_index = 0;                 // index in the image's scene_gt list
  bool estimated = false;           // some estimate of its object exists in the image
  double add_m = std::numeric_limits<double>::infinity();
  double adds_m = std::numeric_limits<double>::infinity();
  double mssd_m = std::numeric_limits<double>::infinity();
  double mspd_px = std::numeric_limits<double>::infinity();
  std::vector<double> vsd;          // per τ (empty without an estimate or with compute_vsd off)
};

struct BopScores {
  int obj_id = 0;                   // 0 for the overall row
  std::string name;                 // model name, "all" for the overall row
  double diameter_m = 0;            // 0 for the overall row
  int n_instances = 0;              // gt instances of the targets
  int n_estimated = 0;              // of those with an assigned estimate
  double add_recall = 0, adds_recall = 0;   // at add_threshold·diameter
  double auc_add = 0, auc_adds = 0;         // YCB-Video AUC
  double vsd_recall = 0, mssd_recall = 0, mspd_recall = 0;
  double ar = 0;                    // mean of the three BOP recalls
};

struct BopEvalReport {
  std::vector<BopTargetEval> instances;   // target order, then gt order
  std::vector<BopScores> objects;         // per object with targets, ascending obj_id
  BopScores overall;                      // pooled over all instances
  int n_results = 0;                      // rows read
  int n_results_used = 0;                 // rows that are among the top inst_count of a target
  double mean_time_s = -1;                // BOP average time per image (−1 if any time < 0)
};

// Progress: (images done, images with targets).
using EvalProgressFn = std::function<void(int, int)>;

// Evaluates `results` on the dataset's targets. Needs gt for every target image (Error naming
// the image otherwise); results of an obj_id without a model → Error naming the obj_id; results
// for non-target images or objects are ignored. Loads the depth of each target image when VSD
// is on.
BopEvalReport EvaluateBop(const Dataset& dataset, const std::vector<BopResult>& results,
                          const BopEvalOptions& options = {}, const EvalProgressFn& progress = nullptr);

}  // namespace posefilter
