// src/filter/polish.cc — the final polish (polish.h; docs/ALGORITHM.md §9 "Final polish"):
// the candidates (seeds turned by the cube's rotations, pivoted about the box's edges and
// corners, re-stood in the mesh's stable poses), their ICP steps, and the compass search on
// the weight. Its fixed tuning constants are named below, with their units.
#include "filter/polish.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "posefilter/pose.h"
#include "posefilter/rng.h"

namespace posefilter::filter {
namespace {

// Pivots: a turn whose box half extents change by less than this (metres, norm of e − |R|·e)
// keeps the box and gets no edge or corner pivots.
constexpr double kPivotMinShiftM = 1e-6;
// Copies per turn with pivots (count): about the centre, and about each of the box's 8 corners.
constexpr int kPivotsPerTurn = 9;
// Stable re-search: at most this many of the mesh's stable poses (count, most probable first) ...
constexpr std::size_t kStableMaxPoses = 8;
// ... each of at least this probability (fraction, 1 %) ...
constexpr double kStableMinProbability = 0.01;
// ... turned about the plane's normal in steps of π / kStableYawStepsPerHalfTurn (count per
// half turn: 12, steps of 15°, 24 per full turn).
constexpr int kStableYawStepsPerHalfTurn = 12;
// Compass search: a climber's first step along each axis (metres, 1 cm) and about each axis
// (radians) ...
constexpr double kClimbStartStepM = 0.01;
constexpr double kClimbStartAngleRad = 0.1;
// ... both multiplied by this (factor) after a round without improvement ...
constexpr double kClimbShrink = 0.5;
// ... until the step is below this (metres, 0.5 mm), or after this many rounds (count).
constexpr double kClimbMinStepM = 0.0005;
constexpr int kClimbRounds = 24;

// The 24 rotations of a cube (signed permutation matrices with determinant +1).
std::vector<Eigen::Matrix3d> CubeRotations() {
  std::vector<Eigen::Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) R(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (R.determinant() > 0) out.push_back(R);
    }
  return out;  // identity first: perms[0] with signs 0
}

}  // namespace

Particle Polish(const Context& ctx, Scratch& scratch, const std::vector<Particle>& seeds, FilterStats* stats) {
  const FilterOptions& o = ctx.opt;
  const RunState run = FinalRunState(ctx);  // final thresholds, the fine level, the level-of-detail mesh
  const Eigen::Vector3d centre = ctx.model->box_centre;
  const Eigen::Matrix3d& A = ctx.model->box_axes;
  std::vector<Eigen::Matrix3d> turns = CubeRotations();
  if (!o.polish.turns) turns.resize(1);
  // Pivots: a turn about the centre, and (polish_pivots) the same turn followed by the shift
  // that puts a corner of the turned box where that corner of the seed's box was — a turn
  // about an edge or corner, as when an object tips over onto another face. Half extents e
  // and, turned, e' = |R|·e; corner σ ∈ {±1}³ moves the centre by σ∘(e − e') (box frame).
  // Turns that keep the box (e' = e) need no shift. The turns R are the cube's in the box's
  // frame: A·R·Aᵀ in the object frame.
  const Eigen::Vector3d half = ctx.model->box_half;
  std::vector<Particle> cands;
  for (const Particle& s : seeds)
    for (const Eigen::Matrix3d& R : turns) {
      const Eigen::Vector3d diff = half - R.cwiseAbs() * half;
      const int pivots = o.polish.pivots && diff.norm() > kPivotMinShiftM ? kPivotsPerTurn : 1;
      const Eigen::Matrix3d R_obj = A * R * A.transpose();
      for (int k = 0; k < pivots; ++k) {
        Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
        turn.linear() = R_obj;
        turn.translation() = centre - R_obj * centre;
        if (k > 0) {
          const Eigen::Vector3d sigma((k - 1) & 1 ? 1.0 : -1.0, (k - 1) & 2 ? 1.0 : -1.0, (k - 1) & 4 ? 1.0 : -1.0);
          turn.translation() += A * sigma.cwiseProduct(diff);
        }
        Particle p = s;
        p.pose = TransformToPose(PoseToTransform(s.pose) * turn);
        p.scored = false;
        cands.push_back(p);
      }
    }
  // Stable re-search (polish_stable, with a support plane): each seed's centre of mass
  // dropped onto the plane, and the object standing there in each of its stable poses of at
  // least 1 % probability (at most 8), turned about the plane's normal in 24 steps of 15°: an
  // answer in the wrong stable pose, or the right one turned or flipped, gets the right one.
  if (o.polish.stable && !ctx.stable.empty()) {
    const Eigen::Isometry3d& C = ctx.scene().camera.base_to_camera;
    for (const Particle& s : seeds) {
      const Eigen::Vector3d com = C * PoseToTransform(s.pose) * ctx.model->com_obj;
      const SupportPlane* below = PlaneBelow(ctx, com);  // the seed's own support; none: not re-searched
      if (!below) continue;
      const Eigen::Vector3d n = below->normal, ex = n.unitOrthogonal();
      Eigen::Isometry3d T_cam_table = Eigen::Isometry3d::Identity();
      T_cam_table.linear() << ex, n.cross(ex), n;
      T_cam_table.translation() = com - below->Height(com) * n;
      for (std::size_t k = 0; k < std::min<std::size_t>(ctx.stable.size(), kStableMaxPoses); ++k) {
        if (ctx.stable[k].probability < kStableMinProbability) break;  // most probable first
        for (int j = 0; j < 2 * kStableYawStepsPerHalfTurn; ++j) {
          const Eigen::Isometry3d T =
              T_cam_table * Eigen::AngleAxisd(j * M_PI / kStableYawStepsPerHalfTurn, Eigen::Vector3d::UnitZ()) *
              ctx.stable[k].T_table_obj;
          Particle p = s;
          p.pose = TransformToPose(C.inverse() * T);
          p.scored = false;
          cands.push_back(p);
        }
      }
    }
  }
  // With pivots, weigh every copy once and polish only the best polish_keep of them.
  if ((o.polish.pivots || o.polish.stable) && int(cands.size()) > o.polish.keep) {
    WeighAll(ctx, run, scratch, cands, stats, /*icp=*/true);
    std::partial_sort(cands.begin(), cands.begin() + o.polish.keep, cands.end(),
                      [](const Particle& a, const Particle& b) { return a.weight > b.weight; });
    cands.resize(o.polish.keep);
  }
  const DiffusionContext diffusion(ctx.scene().camera, ctx.prior->layout, ctx.volumes, o, &ctx.plane(), centre,
                                   &ctx.surfaces());
  Rng unused(0);  // the ICP move draws no random numbers
  std::vector<Particle> path_best(cands.size());  // best weighed state of each candidate
  for (auto& p : path_best) p.weight = -1;
  for (int step = 0; step <= o.polish.steps; ++step) {
    WeighAll(ctx, run, scratch, cands, stats, /*icp=*/true);
    for (std::size_t i = 0; i < cands.size(); ++i)
      if (cands[i].weight > path_best[i].weight) path_best[i] = cands[i];
    if (step == o.polish.steps) break;
    for (Particle& p : cands) ApplyMove(diffusion, Move::kIcpStep, &p, p.weight, unused);
  }
  std::sort(path_best.begin(), path_best.end(), [](const Particle& a, const Particle& b) { return a.weight > b.weight; });

  // Pattern search (compass search) on the weight itself from the best candidates: each
  // round tries ±step along three axes and ±angle about them through the model centre, moves
  // to the best improvement, and halves step and angle when none improves; the ICP steps
  // align surfaces, this also aligns the outline (N_depth, edges). The axes are the support
  // plane's (two in the plane, its normal) where one was found — an object resting on the
  // table then slides and turns on it, the moves that align the outline of a thin or flat
  // object, which point-to-plane ICP on its top face cannot — else the camera's.
  const Eigen::Isometry3d& C = ctx.scene().camera.base_to_camera;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns, camera frame
  if (ctx.plane().found) {
    const Eigen::Vector3d n = ctx.plane().normal, e1 = n.unitOrthogonal();
    axes << e1, n.cross(e1), n;
  }
  struct Climber {
    Particle p;
    double step_m = kClimbStartStepM, angle_rad = kClimbStartAngleRad;
  };
  std::vector<Climber> climbers;
  for (int i = 0; i < std::min(int(path_best.size()), o.polish.climbers); ++i) climbers.push_back({path_best[i]});
  for (int round = 0; round < kClimbRounds; ++round) {
    std::vector<Particle> trials;
    std::vector<int> owner;
    for (int c = 0; c < int(climbers.size()); ++c) {
      const Climber& cl = climbers[c];
      if (cl.step_m < kClimbMinStepM) continue;
      const Eigen::Isometry3d T_cam = C * PoseToTransform(cl.p.pose);
      const Eigen::Vector3d pc = T_cam * centre;
      for (int dof = 0; dof < 6; ++dof)
        for (double sign : {-1.0, 1.0}) {
          Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
          if (dof < 3) {
            D.translation() = sign * cl.step_m * axes.col(dof);
          } else {
            D.linear() = Eigen::AngleAxisd(sign * cl.angle_rad, axes.col(dof - 3)).toRotationMatrix();
            D.translation() = pc - D.linear() * pc;
          }
          Particle t = cl.p;
          t.pose = TransformToPose(C.inverse() * D * T_cam);
          t.scored = false;
          trials.push_back(t);
          owner.push_back(c);
        }
    }
    if (trials.empty()) break;
    WeighAll(ctx, run, scratch, trials, stats);
    std::vector<int> best_trial(climbers.size(), -1);
    for (int i = 0; i < int(trials.size()); ++i) {
      const int c = owner[i];
      const double ref = best_trial[c] < 0 ? climbers[c].p.weight : trials[best_trial[c]].weight;
      if (trials[i].weight > ref) best_trial[c] = i;
    }
    for (int c = 0; c < int(climbers.size()); ++c) {
      Climber& cl = climbers[c];
      if (cl.step_m < kClimbMinStepM) continue;
      if (best_trial[c] >= 0) {
        cl.p = trials[best_trial[c]];
      } else {
        cl.step_m *= kClimbShrink;
        cl.angle_rad *= kClimbShrink;
      }
    }
  }
  Particle best = path_best.front();
  for (const Climber& cl : climbers)
    if (cl.p.weight > best.weight) best = cl.p;
  return best;
}

}  // namespace posefilter::filter
