// Diffusion (§7.6): spreads of every move, the linear σ decay, flips and cell moves.
#include "filter/diffusion.h"

#include <gtest/gtest.h>

#include <cmath>

namespace posefilter::filter {
namespace {

struct Fixture {
  Camera camera;
  PyramidLayout layout = PyramidLayout::Thesis(640, 480, 1);
  std::vector<Volume> volumes;
  FilterOptions opt;
  Fixture() {
    volumes.resize(layout.CellCount());
    for (int c = 0; c < layout.CellCount(); ++c) {
      const Box b = layout.AnchorBox(c);
      volumes[c].min = Eigen::Vector3d(b.cx / 1000, b.cy / 1000, 0.8);
      volumes[c].max = volumes[c].min + Eigen::Vector3d(0.02, 0.02, 0.1);
      volumes[c].valid = true;
    }
  }
};

Particle Start() {
  Particle p;
  p.pose = Pose6{0.1, -0.2, 0.9, 0.3, -0.4, 0.5};
  p.cell = 0;
  p.scored = true;
  return p;
}

// Standard deviation of a coordinate after many independent applications of `move`.
double Spread(const DiffusionContext& ctx, Move move, double best_weight, double Pose6::*field) {
  Rng rng(9);
  const int n = 20000;
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    Particle p = Start();
    ApplyMove(ctx, move, &p, best_weight, rng);
    const double d = p.pose.*field - Start().pose.*field;
    s += d;
    s2 += d * d;
  }
  const double mean = s / n;
  EXPECT_NEAR(mean, 0.0, 0.05 * std::sqrt(s2 / n) + 1e-12);
  return std::sqrt(s2 / n - mean * mean);
}

TEST(DiffusionTest, TranslationAndRotationSpreadsDecayLinearlyWithTheBestWeight) {
  Fixture f;
  f.opt.diffusion.sigma_t0_m = 0.02;
  f.opt.diffusion.sigma_r0_rad = 0.3;
  f.opt.diffusion.min_sigma_fraction = 0.05;
  const prior::VolumeCache volumes(f.volumes);
  DiffusionContext ctx(f.camera, f.layout, volumes, f.opt);
  EXPECT_NEAR(Spread(ctx, Move::kTranslateX, 0.0, &Pose6::x), 0.02, 0.0006);
  EXPECT_NEAR(Spread(ctx, Move::kTranslateZ, 0.5, &Pose6::z), 0.01, 0.0003);
  EXPECT_NEAR(Spread(ctx, Move::kTranslateAll, 0.75, &Pose6::y), 0.005, 0.00015);
  EXPECT_NEAR(Spread(ctx, Move::kRotatePitch, 0.0, &Pose6::pitch), 0.3, 0.01);
  EXPECT_NEAR(Spread(ctx, Move::kRotateAll, 0.5, &Pose6::yaw), 0.15, 0.005);
  // σ never decays below min_sigma_fraction·σ0.
  EXPECT_NEAR(Spread(ctx, Move::kTranslateY, 1.0, &Pose6::y), 0.001, 0.00004);
  // A single-axis move leaves the other coordinates alone.
  Rng rng(1);
  Particle p = Start();
  ApplyMove(ctx, Move::kTranslateX, &p, 0.0, rng);
  EXPECT_EQ(p.pose.y, Start().pose.y);
  EXPECT_EQ(p.pose.roll, Start().pose.roll);
  EXPECT_FALSE(p.scored);
}

TEST(DiffusionTest, FlipsAddPiAndWrap) {
  Fixture f;
  const prior::VolumeCache volumes(f.volumes);
  DiffusionContext ctx(f.camera, f.layout, volumes, f.opt);
  Rng rng(1);
  Particle p = Start();
  ApplyMove(ctx, Move::kFlipYaw, &p, 0.0, rng);
  EXPECT_NEAR(p.pose.yaw, 0.5 - M_PI, 1e-12);
  ApplyMove(ctx, Move::kFlipRoll, &p, 0.0, rng);
  EXPECT_NEAR(p.pose.roll, 0.3 - M_PI, 1e-12);
  EXPECT_EQ(p.pose.x, Start().pose.x);
}

TEST(DiffusionTest, CellMovesReachNeighboursAndOtherLevelsAndCarryTheParticle) {
  Fixture f;
  const prior::VolumeCache volumes(f.volumes);
  DiffusionContext ctx(f.camera, f.layout, volumes, f.opt);
  Rng rng(4);
  const int start = f.layout.CellIndex(1, 10, 20);
  int moved = 0;
  for (int i = 0; i < 200; ++i) {
    Particle p = Start();
    p.cell = start;
    ApplyMove(ctx, Move::kNeighbourCell, &p, 0.0, rng);
    int level, row, col;
    f.layout.CellRowCol(p.cell, &level, &row, &col);
    EXPECT_EQ(level, 1);
    EXPECT_LE(std::abs(row - 10), 1);
    EXPECT_LE(std::abs(col - 20), 1);
    EXPECT_NE(p.cell, start);
    const Eigen::Vector3d shift = f.volumes[p.cell].Centre() - f.volumes[start].Centre();
    EXPECT_NEAR(p.pose.x - Start().pose.x, shift.x(), 1e-12);
    ++moved;
  }
  EXPECT_EQ(moved, 200);
  // Other level: the cell that contains this cell's centre.
  for (int i = 0; i < 50; ++i) {
    Particle p = Start();
    p.cell = start;
    ApplyMove(ctx, Move::kOtherLevel, &p, 0.0, rng);
    int level, row, col;
    f.layout.CellRowCol(p.cell, &level, &row, &col);
    ASSERT_NE(level, 1);
    if (level == 0) {
      EXPECT_EQ(row, 5);
      EXPECT_EQ(col, 10);
    } else {
      EXPECT_EQ(row, 21);
      EXPECT_EQ(col, 41);
    }
  }
  // A neighbour without a valid volume is never entered.
  for (auto& v : f.volumes) v.valid = false;
  f.volumes[start].valid = true;
  const prior::VolumeCache only_start(f.volumes);
  const DiffusionContext ctx_only_start(f.camera, f.layout, only_start, f.opt);
  Particle p = Start();
  p.cell = start;
  ApplyMove(ctx_only_start, Move::kNeighbourCell, &p, 0.0, rng);
  EXPECT_EQ(p.cell, start);
  EXPECT_EQ(p.pose.x, Start().pose.x);
}

TEST(DiffusionTest, PickMoveFollowsTheProbabilities) {
  Fixture f;
  f.opt.diffusion.move_probabilities.fill(0.0);
  f.opt.diffusion.move_probabilities[int(Move::kRotateYaw)] = 3;
  f.opt.diffusion.move_probabilities[int(Move::kFlipPitch)] = 1;
  const prior::VolumeCache volumes(f.volumes);
  DiffusionContext ctx(f.camera, f.layout, volumes, f.opt);
  Rng rng(2);
  int yaw = 0, flip = 0;
  for (int i = 0; i < 40000; ++i) {
    const Move m = ctx.PickMove(rng.Uniform());
    ASSERT_TRUE(m == Move::kRotateYaw || m == Move::kFlipPitch);
    (m == Move::kRotateYaw ? yaw : flip)++;
  }
  EXPECT_NEAR(yaw / 40000.0, 0.75, 0.01);
}

}  // namespace
}  // namespace posefilter::filter

namespace posefilter::filter {
namespace {

TEST(DiffusionTest, AlignDepthShiftsAlongTheViewingRayByTheMeasuredOffset) {
  Fixture f;
  // A base frame rotated and shifted against the camera.
  f.camera.base_to_camera.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  f.camera.base_to_camera.translation() = Eigen::Vector3d(0.1, -0.05, 0.3);
  const prior::VolumeCache volumes(f.volumes);
  DiffusionContext ctx(f.camera, f.layout, volumes, f.opt);
  Rng rng(1);
  Particle p = Start();
  p.depth_offset = 0.025;
  const Eigen::Vector3d before = f.camera.base_to_camera * Eigen::Vector3d(p.pose.x, p.pose.y, p.pose.z);
  ApplyMove(ctx, Move::kAlignDepth, &p, 0.0, rng);
  const Eigen::Vector3d after = f.camera.base_to_camera * Eigen::Vector3d(p.pose.x, p.pose.y, p.pose.z);
  EXPECT_NEAR(after.z() - before.z(), 0.025, 1e-12);                       // depth moved by the offset
  EXPECT_NEAR(after.x() / after.z(), before.x() / before.z(), 1e-12);      // same pixel
  EXPECT_NEAR(after.y() / after.z(), before.y() / before.z(), 1e-12);
  EXPECT_EQ(p.pose.roll, Start().pose.roll);
}

}  // namespace
}  // namespace posefilter::filter

namespace posefilter::filter {
namespace {

TEST(DiffusionTest, QuarterTurnRotatesNinetyDegreesAboutAnObjectAxis) {
  Fixture f;
  const prior::VolumeCache volumes(f.volumes);
  DiffusionContext ctx(f.camera, f.layout, volumes, f.opt);
  Rng rng(8);
  for (int i = 0; i < 30; ++i) {
    Particle p = Start();
    ApplyMove(ctx, Move::kQuarterTurn, &p, 0.0, rng);
    const Eigen::Matrix3d R0 = PoseToTransform(Start().pose).linear();
    const Eigen::Matrix3d R1 = PoseToTransform(p.pose).linear();
    const Eigen::AngleAxisd rel(R0.transpose() * R1);  // rotation in the object frame
    EXPECT_NEAR(rel.angle(), M_PI / 2, 1e-9);
    EXPECT_NEAR(rel.axis().cwiseAbs().maxCoeff(), 1.0, 1e-9);  // about x, y or z
    EXPECT_EQ(p.pose.x, Start().pose.x);
  }
}

}  // namespace
}  // namespace posefilter::filter
