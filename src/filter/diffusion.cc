#include "filter/diffusion.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace posefilter::filter {

DiffusionContext::DiffusionContext(const Camera& c, const PyramidLayout& l, const prior::VolumeCache& v,
                                   const FilterOptions& o, const SupportPlane* support, const Eigen::Vector3d& pivot_obj,
                                   const SupportSurfaces* all)
    : camera(c), layout(l), volumes(v), opt(o), plane(support && support->found ? support : nullptr),
      surfaces(all && all->supports > 0 ? all : nullptr), pivot(pivot_obj),
      move_cdf(kNumMoves) {
  auto probability = [&](int m) { return m == int(Move::kOnPlane) && !plane ? 0.0 : o.diffusion.move_probabilities[m]; };
  double total = 0, acc = 0;
  for (int m = 0; m < kNumMoves; ++m) total += probability(m);
  if (!(total > 0)) {  // only kOnPlane was asked for and there is no plane: it is drawn, and changes nothing
    std::fill(move_cdf.begin(), move_cdf.end(), 0.0);
    move_cdf.back() = 1.0;
    return;
  }
  for (int m = 0; m < kNumMoves; ++m) move_cdf[m] = (acc += probability(m)) / total;
}

Move DiffusionContext::PickMove(double u) const {
  int m = 0;
  while (m + 1 < kNumMoves && move_cdf[m] <= u) ++m;
  return static_cast<Move>(m);
}

int MoveCell(const DiffusionContext& ctx, int cell, Move move, Rng& rng) {
  const PyramidLayout& L = ctx.layout;
  int level, row, col;
  L.CellRowCol(cell, &level, &row, &col);
  int target = -1;
  if (move == Move::kNeighbourCell) {
    static constexpr int kDr[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
    static constexpr int kDc[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
    const int k = int(rng.UniformInt(8));  // one of the 8 neighbours
    const int r = row + kDr[k], c = col + kDc[k];
    const PyramidLevel& lv = L.levels[level];
    if (r >= 0 && r < lv.rows && c >= 0 && c < lv.cols) target = L.CellIndex(level, r, c);
  } else if (move == Move::kOtherLevel) {
    const int nl = int(L.levels.size());
    if (nl < 2) return -1;
    int other = int(rng.UniformInt(nl - 1));
    if (other >= level) ++other;
    const PyramidLevel& from = L.levels[level];
    const PyramidLevel& to = L.levels[other];
    // The cell of the other level that contains this cell's centre.
    const int r = std::min(to.rows - 1, int((row + 0.5) * to.rows / from.rows));
    const int c = std::min(to.cols - 1, int((col + 0.5) * to.cols / from.cols));
    target = L.CellIndex(other, r, c);
  }
  if (target < 0 || !ctx.volumes.Valid(target)) return -1;
  return target;
}

bool SolveIcpStep(const ScoreKernelResult& r, std::array<double, 6>* step) {
  if (r.icp_count < 30) return false;
  Eigen::Matrix<double, 6, 6> A;
  int e = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) A(i, j) = A(j, i) = r.icp_A[e++];
  Eigen::Matrix<double, 6, 1> b;
  for (int i = 0; i < 6; ++i) b(i) = r.icp_b[i];
  // Levenberg damping relative to the diagonal keeps unobservable directions still.
  A.diagonal() *= 1.0 + 1e-3;
  A.diagonal().array() += 1e-9 * A.diagonal().maxCoeff();
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(A);
  if (ldlt.info() != Eigen::Success) return false;
  Eigen::Matrix<double, 6, 1> x = ldlt.solve(b);
  if (!x.allFinite()) return false;
  const double w = x.head<3>().norm(), t = x.tail<3>().norm();
  if (w > 0.3) x.head<3>() *= 0.3 / w;
  if (t > 0.05) x.tail<3>() *= 0.05 / t;
  for (int i = 0; i < 6; ++i) (*step)[i] = x(i);
  return true;
}

void ApplyMove(const DiffusionContext& ctx, Move move, Particle* p, double best_weight, Rng& rng) {
  const FilterOptions& o = ctx.opt;
  const double decay = std::max(1.0 - best_weight, o.diffusion.min_sigma_fraction);
  const double st = decay * o.diffusion.sigma_t0_m, sr = decay * o.diffusion.sigma_r0_rad;
  Pose6& q = p->pose;
  switch (move) {
    case Move::kTranslateX: q.x += st * rng.Normal(); break;
    case Move::kTranslateY: q.y += st * rng.Normal(); break;
    case Move::kTranslateZ: q.z += st * rng.Normal(); break;
    case Move::kTranslateAll:
      q.x += st * rng.Normal();
      q.y += st * rng.Normal();
      q.z += st * rng.Normal();
      break;
    case Move::kRotateRoll: q.roll += sr * rng.Normal(); break;
    case Move::kRotatePitch: q.pitch += sr * rng.Normal(); break;
    case Move::kRotateYaw: q.yaw += sr * rng.Normal(); break;
    case Move::kRotateAll:
      q.roll += sr * rng.Normal();
      q.pitch += sr * rng.Normal();
      q.yaw += sr * rng.Normal();
      break;
    case Move::kFlipRoll: q.roll += M_PI; break;
    case Move::kFlipPitch: q.pitch += M_PI; break;
    case Move::kFlipYaw: q.yaw += M_PI; break;
    case Move::kNeighbourCell:
    case Move::kOtherLevel: {
      const int target = MoveCell(ctx, p->cell, move, rng);
      if (target >= 0) {
        const Eigen::Vector3d d = ctx.volumes.Get(target).Centre() - ctx.volumes.Get(p->cell).Centre();
        q.x += d.x();
        q.y += d.y();
        q.z += d.z();
        p->cell = target;
      }
      break;
    }
    case Move::kAlignDepth: {
      // Camera-frame origin c of the object; moving it by Δ·c/c_z changes its depth by Δ and
      // keeps its projection.
      const Eigen::Isometry3d& C = ctx.camera.base_to_camera;
      const Eigen::Vector3d c = C * Eigen::Vector3d(q.x, q.y, q.z);
      if (c.z() > 0) {
        const Eigen::Vector3d shift = C.linear().transpose() * (p->depth_offset / c.z() * c);
        q.x += shift.x();
        q.y += shift.y();
        q.z += shift.z();
      }
      break;
    }
    case Move::kIcpStep: {
      if (!p->icp_valid) break;
      // T_cam' = [Rot(ω) | τ] · T_cam, then back to the base frame.
      const Eigen::Isometry3d& C = ctx.camera.base_to_camera;
      const Eigen::Vector3d omega(p->icp_step[0], p->icp_step[1], p->icp_step[2]);
      Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
      if (omega.norm() > 0) D.linear() = Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix();
      D.translation() = Eigen::Vector3d(p->icp_step[3], p->icp_step[4], p->icp_step[5]);
      const Eigen::Isometry3d T = C.inverse() * D * C * PoseToTransform(q);
      q = TransformToPose(T);
      break;
    }
    case Move::kQuarterTurn: {
      // R' = R · R_axis(±π/2) about the object's x, y or z axis.
      const int axis = int(rng.UniformInt(3));
      const double angle = rng.UniformInt(2) ? M_PI / 2 : -M_PI / 2;
      Eigen::Isometry3d T = PoseToTransform(q);
      T.linear() = T.linear() * Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
      const Pose6 turned = TransformToPose(T);
      q.roll = turned.roll;
      q.pitch = turned.pitch;
      q.yaw = turned.yaw;
      break;
    }
    case Move::kOnPlane: {
      if (!ctx.plane) break;
      const Eigen::Isometry3d& C = ctx.camera.base_to_camera;
      const Eigen::Isometry3d T = C * PoseToTransform(q);  // object → camera
      const Eigen::Vector3d pc = T * ctx.pivot;
      const double angle = sr * rng.Normal();
      const double d1 = st * rng.Normal();
      const double d2 = st * rng.Normal();
      static const SupportSurfaceOptions kDefaults{};  // as PrepareScene finds the surfaces
      const int below = ctx.surfaces ? ctx.surfaces->Below(pc, kDefaults) : -1;
      if (ctx.surfaces && below < 0) break;  // over no support: unchanged
      const Eigen::Vector3d n = below >= 0 ? ctx.surfaces->patches[std::size_t(below)].plane.normal : ctx.plane->normal;
      const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
      Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
      D.linear() = Eigen::AngleAxisd(angle, n).toRotationMatrix();
      D.translation() = pc - D.linear() * pc + d1 * e1 + d2 * e2;
      q = TransformToPose(C.inverse() * D * T);
      break;
    }
    case Move::kCount: break;
  }
  q.roll = WrapAngle(q.roll);
  q.pitch = WrapAngle(q.pitch);
  q.yaw = WrapAngle(q.yaw);
  p->scored = false;
}

}  // namespace posefilter::filter
