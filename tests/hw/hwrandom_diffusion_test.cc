// Tests of src/hw/diffusion.h: spreads decay with the best weight, each move changes only what
// it should, angle wrap-around, cell moves on the thesis pyramid, move frequencies,
// determinism per seed, elitism, parameter checks.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hw/diffusion.h"

namespace posefilter::hw {
namespace {

constexpr double kXyzLsb = 1.0 / 1024, kAngLsb = 1.0 / 256;

DiffusionParams OnlyMove(int move, double st0 = 0.1, double sr0 = 0.5, double min_frac = 0.0) {
  DiffusionParams p;
  double prob[kNumHwMoves] = {};
  prob[move] = 1;
  std::string why;
  EXPECT_TRUE(SetMoveProbabilities(&p, prob, &why));
  p.sigma_t0 = sigma_t(st0);
  p.sigma_r0 = sigma_t(sr0);
  p.min_fraction = weight_t(min_frac);
  return p;
}

// Every cell gets a valid 2 cm volume centred at a position derived from its (level,row,col).
void FillVolumes(HeuristicVolume* v) {
  for (int c = 0; c < kNumCells; ++c) {
    const CellRC rc = CellToRC(cell_index_t(c));
    const double cx = -1.0 + rc.col * 0.02 + rc.level * 0.003, cy = -0.6 + rc.row * 0.02, cz = 0.5 + rc.level * 0.1;
    v[c] = HeuristicVolume{xyz_t(cx - 0.01), xyz_t(cy - 0.01), xyz_t(cz - 0.05),
                           xyz_t(cx + 0.01), xyz_t(cy + 0.01), xyz_t(cz + 0.05)};
  }
}

Sample MakeSample(double x, double y, double z, double r, double p, double yw, int cell) {
  Sample s;
  s.x = xyz_t(x);
  s.y = xyz_t(y);
  s.z = xyz_t(z);
  s.roll = angle_t(r);
  s.pitch = angle_t(p);
  s.yaw = angle_t(yw);
  s.cell = cell;
  return s;
}

bool SameSample(const Sample& a, const Sample& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.roll == b.roll && a.pitch == b.pitch && a.yaw == b.yaw &&
         a.cell == b.cell;
}

struct Changed {
  bool x, y, z, roll, pitch, yaw, cell;
};
Changed Diff(const Sample& a, const Sample& b) {
  return {a.x != b.x, a.y != b.y, a.z != b.z, a.roll != b.roll, a.pitch != b.pitch, a.yaw != b.yaw, a.cell != b.cell};
}

TEST(HwRandomDiffusion, CellGeometryMatchesThePyramid) {
  for (int c = 0; c < kNumCells; ++c) {
    const int level = c < 300 ? 0 : (c < 1500 ? 1 : 2);
    const int local = c - kLevelOffset[level];
    const CellRC rc = CellToRC(cell_index_t(c));
    ASSERT_EQ(rc.level, level) << c;
    ASSERT_EQ(rc.row, local / kLevelCols[level]) << c;
    ASSERT_EQ(rc.col, local % kLevelCols[level]) << c;
    ASSERT_EQ(RCToCell(rc.level, rc.row, rc.col).to_int(), c);
  }
}

TEST(HwRandomDiffusion, SpreadDecaysLinearlyWithBestWeight) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  const double sigma0 = 0.1;
  auto measure = [&](int move, double w_best, double min_frac) {
    DiffusionParams p = OnlyMove(move, sigma0, sigma0, min_frac);
    DiffusionRng rng(99);
    const Sample s = MakeSample(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 400);
    double sum2 = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const Sample o = ApplyMove(s, rng.Draw(p), weight_t(w_best), p, vol);
      const double d = move == kHwTranslateX ? o.x.to_double() - s.x.to_double() : o.yaw.to_double() - s.yaw.to_double();
      sum2 += d * d;
    }
    return std::sqrt(sum2 / n);
  };
  for (int move : {int(kHwTranslateX), int(kHwRotateYaw)}) {
    const double s0 = measure(move, 0.0, 0.0), s5 = measure(move, 0.5, 0.0), s8 = measure(move, 0.8, 0.0);
    EXPECT_NEAR(s0, sigma0, 0.03 * sigma0) << move;
    EXPECT_NEAR(s5, 0.5 * sigma0, 0.03 * sigma0) << move;
    EXPECT_NEAR(s8, 0.2 * sigma0, 0.03 * sigma0) << move;
    // The floor: at w_best = 1 the spread is min_fraction·σ0, not 0.
    EXPECT_NEAR(measure(move, 1.0, 0.25), 0.25 * sigma0, 0.03 * sigma0) << move;
    EXPECT_EQ(measure(move, 1.0, 0.0), 0.0) << move;  // thesis: pure linear decay
  }
}

TEST(HwRandomDiffusion, EachMoveChangesOnlyWhatItShould) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  const Sample s = MakeSample(0.25, -0.5, 1.25, 0.5, -1.0, 2.0, 700);  // level 1, row 10, col 0
  MoveDraw d;
  d.z[0] = gauss_t(1.5);
  d.z[1] = gauss_t(-0.75);
  d.z[2] = gauss_t(2.0);
  d.aux = 0b01110;  // neighbour direction 6 (+1 row, same col), other level: coarser/finer bit 1
  DiffusionParams p = OnlyMove(0, 0.05, 0.2);
  const weight_t w(0.0);
  const double st = 0.05, sr = 0.2;
  for (int m = 0; m < kNumHwMoves; ++m) {
    d.move = m;
    const Sample o = ApplyMove(s, d, w, p, vol);
    const Changed c = Diff(s, o);
    const bool tx = m == kHwTranslateX || m == kHwTranslateAll, ty = m == kHwTranslateY || m == kHwTranslateAll,
               tz = m == kHwTranslateZ || m == kHwTranslateAll;
    const bool rr = m == kHwRotateRoll || m == kHwRotateAll || m == kHwFlipRoll || m == kHwQuarterRoll;
    const bool rp = m == kHwRotatePitch || m == kHwRotateAll || m == kHwFlipPitch;
    const bool ry = m == kHwRotateYaw || m == kHwRotateAll || m == kHwFlipYaw;
    const bool cell = m == kHwNeighbourCell || m == kHwOtherLevel;
    if (!cell) {  // cell moves shift by a centre difference (checked in CellMovesFollowThePyramid)
      EXPECT_EQ(c.x, tx) << "move " << m;
      EXPECT_EQ(c.y, ty) << "move " << m;
      EXPECT_EQ(c.z, tz) << "move " << m;
    } else {
      EXPECT_TRUE(c.x || c.y || c.z) << "move " << m;
    }
    EXPECT_EQ(c.roll, rr) << "move " << m;
    EXPECT_EQ(c.pitch, rp) << "move " << m;
    EXPECT_EQ(c.yaw, ry) << "move " << m;
    EXPECT_EQ(c.cell, cell) << "move " << m;
    // Sizes: σ·z rounded to the LSB (σ itself quantized to 2^-16).
    const double z0 = 1.5, z1 = -0.75, z2 = 2.0;
    if (m == kHwTranslateX) { EXPECT_NEAR(o.x.to_double() - 0.25, st * z0, kXyzLsb); }
    if (m == kHwTranslateAll) {
      EXPECT_NEAR(o.x.to_double() - 0.25, st * z0, kXyzLsb);
      EXPECT_NEAR(o.y.to_double() + 0.5, st * z1, kXyzLsb);
      EXPECT_NEAR(o.z.to_double() - 1.25, st * z2, kXyzLsb);
    }
    if (m == kHwRotatePitch) { EXPECT_NEAR(o.pitch.to_double() + 1.0, sr * z0, kAngLsb); }
    if (m == kHwRotateAll) {
      EXPECT_NEAR(o.roll.to_double() - 0.5, sr * z0, kAngLsb);
      EXPECT_NEAR(o.pitch.to_double() + 1.0, sr * z1, kAngLsb);
      EXPECT_NEAR(o.yaw.to_double() - 2.0, sr * z2, kAngLsb);
    }
    if (m == kHwFlipRoll) { EXPECT_NEAR(o.roll.to_double(), 0.5 + (kPiRaw - kTwoPiRaw) * kAngLsb, 1e-12); }
    if (m == kHwFlipYaw) { EXPECT_NEAR(o.yaw.to_double(), 2.0 + (kPiRaw - kTwoPiRaw) * kAngLsb, 1e-12); }
    if (m == kHwQuarterRoll) { EXPECT_NEAR(o.roll.to_double(), 0.5 - kHalfPiRaw * kAngLsb, 1e-12); }  // aux bit 4 = 0
  }
}

TEST(HwRandomDiffusion, CellMovesFollowThePyramid) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  DiffusionParams p = OnlyMove(kHwNeighbourCell);
  MoveDraw d;
  d.z[0] = d.z[1] = d.z[2] = gauss_t(0.0);
  const int cell = RCToCell(1, 10, 5).to_int();
  const Sample s = MakeSample(0.1, 0.2, 0.6, 0, 0, 0, cell);
  static const int kDr[8] = {-1, -1, -1, 0, 0, 1, 1, 1}, kDc[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
  auto centre = [&](int c, int axis) {
    const HeuristicVolume& v = vol[c];
    const double lo = axis == 0 ? v.x_min.to_double() : (axis == 1 ? v.y_min.to_double() : v.z_min.to_double());
    const double hi = axis == 0 ? v.x_max.to_double() : (axis == 1 ? v.y_max.to_double() : v.z_max.to_double());
    return 0.5 * (lo + hi);
  };
  for (int k = 0; k < 8; ++k) {
    d.move = kHwNeighbourCell;
    d.aux = k;
    const Sample o = ApplyMove(s, d, weight_t(0.5), p, vol);
    const int t = RCToCell(1, 10 + kDr[k], 5 + kDc[k]).to_int();
    ASSERT_EQ(o.cell.to_int(), t) << k;
    EXPECT_NEAR(o.x.to_double() - s.x.to_double(), centre(t, 0) - centre(cell, 0), kXyzLsb) << k;
    EXPECT_NEAR(o.y.to_double() - s.y.to_double(), centre(t, 1) - centre(cell, 1), kXyzLsb) << k;
    EXPECT_NEAR(o.z.to_double() - s.z.to_double(), centre(t, 2) - centre(cell, 2), kXyzLsb) << k;
  }
  // Other level: bit 3 = 0 → level 0 (coarser: row/2, col/2), 1 → level 2 (finer: 2r+1, 2c+1).
  d.move = kHwOtherLevel;
  d.aux = 0;
  EXPECT_EQ(ApplyMove(s, d, weight_t(0.5), p, vol).cell.to_int(), RCToCell(0, 5, 2).to_int());
  d.aux = 8;
  EXPECT_EQ(ApplyMove(s, d, weight_t(0.5), p, vol).cell.to_int(), RCToCell(2, 21, 11).to_int());
  // From the finest level to level 1 (bit 3 = 1 → level 1 as the second "other").
  const Sample f = MakeSample(0.1, 0.2, 0.6, 0, 0, 0, RCToCell(2, 59, 79).to_int());
  EXPECT_EQ(ApplyMove(f, d, weight_t(0.5), p, vol).cell.to_int(), RCToCell(1, 29, 39).to_int());
  // Off the grid: the corner cell of level 0 going up-left stays where it is.
  d.move = kHwNeighbourCell;
  d.aux = 0;
  const Sample corner = MakeSample(0.1, 0.2, 0.6, 0, 0, 0, 0);
  EXPECT_TRUE(SameSample(ApplyMove(corner, d, weight_t(0.5), p, vol), corner));
  // A target without a valid volume (min > max) is refused too.
  const int t = RCToCell(1, 9, 4).to_int();
  std::swap(vol[t].x_min, vol[t].x_max);
  EXPECT_TRUE(SameSample(ApplyMove(s, d, weight_t(0.5), p, vol), s));
}

TEST(HwRandomDiffusion, AnglesWrapToMinusPiPi) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  DiffusionParams p = OnlyMove(kHwFlipRoll);
  MoveDraw d;
  d.z[0] = d.z[1] = d.z[2] = gauss_t(0.0);
  d.aux = 0;
  // Every angle_t value: two flips give back the wrapped original; results in (−π, π].
  for (int raw = -2048; raw < 2048; ++raw) {
    Sample s = MakeSample(0, 0, 1, 0, 0, 0, 10);
    s.roll = FixedFromRaw<12, 4>(ap_int<12>(raw));
    d.move = kHwFlipRoll;
    const Sample o1 = ApplyMove(s, d, weight_t(0.0), p, vol);
    const Sample o2 = ApplyMove(o1, d, weight_t(0.0), p, vol);
    const int r1 = RawOf(o1.roll).to_int(), r2 = RawOf(o2.roll).to_int();
    ASSERT_GT(r1, -kPiRaw) << raw;
    ASSERT_LE(r1, kPiRaw) << raw;
    ASSERT_EQ(((r1 - raw - kPiRaw) % kTwoPiRaw + kTwoPiRaw) % kTwoPiRaw, 0) << raw;  // ≡ a + π (mod 2π)
    if (raw > -kPiRaw && raw <= kPiRaw) { ASSERT_EQ(r2, raw) << raw; }
  }
  // Rotation noise across the boundary: yaw 3.1 + 0.2·1.5 = 3.4 → 3.4 − 2π.
  DiffusionParams pr = OnlyMove(kHwRotateYaw, 0.01, 0.2);
  d.move = kHwRotateYaw;
  d.z[0] = gauss_t(1.5);
  const Sample s = MakeSample(0, 0, 1, 0, 0, 3.1, 10);
  const Sample o = ApplyMove(s, d, weight_t(0.0), pr, vol);
  EXPECT_NEAR(o.yaw.to_double(), 3.1 + 0.3 - kTwoPiRaw * kAngLsb, 2 * kAngLsb);
  // Huge noise is clamped to ±π before the wrap.
  DiffusionParams big = OnlyMove(kHwRotateYaw, 0.01, 3.9);
  d.z[0] = gauss_t(4.0);
  const Sample ob = ApplyMove(MakeSample(0, 0, 1, 0, 0, 0.0, 10), d, weight_t(0.0), big, vol);
  EXPECT_EQ(RawOf(ob.yaw).to_int(), kPiRaw);
}

TEST(HwRandomDiffusion, MoveFrequenciesFollowTheThresholds) {
  DiffusionParams p = ThesisDiffusionParams();
  DiffusionRng rng(5);
  std::vector<double> count(kNumHwMoves, 0);
  const int n = 26000;
  for (int i = 0; i < n; ++i) count[rng.Draw(p).move] += 1;
  EXPECT_EQ(count[kHwQuarterRoll], 0);  // thesis: not a move
  double chi = 0;
  for (int m = 0; m < kNumThesisMoves; ++m) chi += (count[m] - n / 13.0) * (count[m] - n / 13.0) / (n / 13.0);
  EXPECT_LT(chi, 32.9);  // chi-square, 12 dof, p = 0.001
  // Skewed probabilities are honoured too.
  double prob[kNumHwMoves] = {};
  prob[kHwTranslateAll] = 3;
  prob[kHwFlipPitch] = 1;
  std::string why;
  ASSERT_TRUE(SetMoveProbabilities(&p, prob, &why));
  int all = 0, flip = 0;
  for (int i = 0; i < 8000; ++i) {
    const int m = rng.Draw(p).move;
    ASSERT_TRUE(m == kHwTranslateAll || m == kHwFlipPitch) << m;
    all += m == kHwTranslateAll;
    flip += m == kHwFlipPitch;
  }
  EXPECT_NEAR(all / 8000.0, 0.75, 0.02);
}

TEST(HwRandomDiffusion, ModuleIsDeterministicPerSeedAndKeepsTheElite) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  static Sample in[kMaxParticles], a[kMaxParticles], b[kMaxParticles], c[kMaxParticles];
  particle_index_t sel[kMaxParticles];
  static depth_off_t zero_off[kMaxParticles];  // zero-initialised side-band
  for (int i = 0; i < kMaxParticles; ++i) {
    in[i] = MakeSample(0.001 * i, -0.3, 0.8, 0.01 * (i % 300), -0.5, 1.0, 300 + i);
    sel[i] = (i * 7) % kMaxParticles;
  }
  DiffusionParams p = ThesisDiffusionParams();
  DiffusionRng r1(123), r2(123), r3(124);
  CycleTrace trace;
  Diffuse(in, zero_off, sel, kMaxParticles, 10, weight_t(0.3), p, vol, r1, a, &trace);
  Diffuse(in, zero_off, sel, kMaxParticles, 10, weight_t(0.3), p, vol, r2, b, nullptr);
  Diffuse(in, zero_off, sel, kMaxParticles, 10, weight_t(0.3), p, vol, r3, c, nullptr);
  int differ_seed = 0, moved = 0;
  for (int j = 0; j < kMaxParticles; ++j) {
    ASSERT_TRUE(SameSample(a[j], b[j])) << j;
    differ_seed += !SameSample(a[j], c[j]);
    if (j < 10) { ASSERT_TRUE(SameSample(a[j], in[sel[j].to_int()])) << "elite " << j; }
    else moved += !SameSample(a[j], in[sel[j].to_int()]);
  }
  EXPECT_GT(differ_seed, kMaxParticles / 2);
  // The sources of one DiffusionRng are distinct streams, for seed 0 too.
  for (uint32_t seed : {0u, 1u, 77u}) {
    DiffusionRng r(seed);
    int same = 0;
    for (int i = 0; i < 1000; ++i) {
      const MoveDraw d = r.Draw(p);
      same += (d.z[0] == d.z[2]) + (d.z[1] == d.z[2]);
    }
    EXPECT_LT(same, 50) << "seed " << seed;
  }
  EXPECT_GT(moved, (kMaxParticles - 10) / 2);
  // The on-chip copies of the samples, their side-band and the volumes (one burst each), then
  // the pipelined loop, which ends with the write burst's latency.
  ASSERT_EQ(trace.count, 4);
  EXPECT_STREQ(trace.records[0].loop, "DIFFUSION_LOAD_SAMPLES");
  EXPECT_EQ(trace.records[0].trips, uint64_t(kMaxParticles));
  EXPECT_EQ(trace.records[0].memory, uint64_t(kAxiReadLatency));
  EXPECT_EQ(trace.records[2].trips, uint64_t(kNumCells));
  EXPECT_STREQ(trace.records[3].loop, "DIFFUSION_SAMPLES");
  EXPECT_EQ(trace.records[3].trips, uint64_t(kMaxParticles));
  EXPECT_EQ(trace.records[3].ii, 1u);
  EXPECT_EQ(trace.records[3].depth, uint32_t(kDiffusionDepth + kAxiWriteLatency));
  EXPECT_EQ(trace.records[3].memory, uint64_t(kAxiWriteLatency));
}

TEST(HwRandomDiffusion, ParamsValidation) {
  DiffusionParams p;
  std::string why;
  EXPECT_TRUE(p.IsValid(&why));
  // The defaults are the thesis's equal move probabilities.
  DiffusionParams q;
  double equal[kNumHwMoves];
  for (int m = 0; m < kNumHwMoves; ++m) equal[m] = m < kNumThesisMoves ? 1.0 : 0.0;
  ASSERT_TRUE(SetMoveProbabilities(&q, equal, &why));
  for (int m = 0; m < kNumHwMoves; ++m) EXPECT_EQ(p.move_thr[m], q.move_thr[m]) << m;
  double bad[kNumHwMoves] = {};
  EXPECT_FALSE(SetMoveProbabilities(&p, bad, &why));  // all zero
  EXPECT_NE(why.find("all be 0"), std::string::npos);
  bad[2] = -1;
  bad[3] = 2;
  EXPECT_FALSE(SetMoveProbabilities(&p, bad, &why));
  EXPECT_NE(why.find(">= 0"), std::string::npos);
  bad[2] = NAN;
  EXPECT_FALSE(SetMoveProbabilities(&p, bad, &why));
  p = DiffusionParams{};
  p.move_thr[3] = 5;  // below move_thr[2]
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("non-decreasing"), std::string::npos);
  p = DiffusionParams{};
  for (int m = 0; m < kNumHwMoves; ++m) p.move_thr[m] = 100;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("last entry"), std::string::npos);
  p = DiffusionParams{};
  p.min_fraction = weight_t(1.5);
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("min_fraction"), std::string::npos);
}

}  // namespace
}  // namespace posefilter::hw

// ---- Ours: σ floor of one LSB, align-depth move (accuracy additions, not in the thesis) ----
namespace posefilter::hw {
namespace {

// Late diffusion: σ_t = 0.05·1 cm = 0.5 mm ≈ 0.51 LSB. A draw z = 0.9 gives 0.46 LSB: rounded to
// 0 without the floor; with it σ_t = 1 LSB and the move is round(0.9) = 1 LSB. Rotations: σ_r0
// = 0.02 → 1 mrad ≈ 0.26 LSB, raised to 1 LSB.
TEST(HwRandomDiffusion, SigmaFloorKeepsLateMovesAtOneLsb) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  const Sample s = MakeSample(0.25, -0.5, 1.25, 0.5, -1.0, 2.0, 700);
  MoveDraw d{};
  d.z[0] = d.z[1] = d.z[2] = gauss_t(0.9);
  const weight_t w(0.99);
  DiffusionParams off = OnlyMove(kHwTranslateAll, 0.01, 0.02, 0.05);
  DiffusionParams on = off;
  on.sigma_floor_lsb = 1;
  d.move = kHwTranslateAll;
  EXPECT_TRUE(SameSample(ApplyMove(s, d, w, off, vol), s));
  Sample o = ApplyMove(s, d, w, on, vol);
  EXPECT_NEAR(o.x.to_double() - s.x.to_double(), kXyzLsb, 1e-12);
  EXPECT_NEAR(o.z.to_double() - s.z.to_double(), kXyzLsb, 1e-12);
  d.move = kHwRotateAll;
  EXPECT_TRUE(SameSample(ApplyMove(s, d, w, off, vol), s));
  o = ApplyMove(s, d, w, on, vol);
  EXPECT_NEAR(o.yaw.to_double() - s.yaw.to_double(), kAngLsb, 1e-12);
  // A σ above the floor is untouched by it: 1 cm at w = 0 and z = 0.9 → 9.2 LSB either way.
  d.move = kHwTranslateX;
  EXPECT_TRUE(SameSample(ApplyMove(s, d, weight_t(0), off, vol), ApplyMove(s, d, weight_t(0), on, vol)));
  // Statistics with the module's Gaussians: the floor gives a spread of ≈ 1 LSB (the rounding
  // of N(0, 1 LSB) to integers has std √(1 + 1/12) ≈ 1.04 LSB), without it ≈ 0.56 LSB.
  DiffusionRng rng(5);
  double s_on = 0, s_off = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    MoveDraw r = rng.Draw(on);
    r.move = kHwTranslateX;
    const double a = (ApplyMove(s, r, w, on, vol).x.to_double() - s.x.to_double()) / kXyzLsb;
    const double b = (ApplyMove(s, r, w, off, vol).x.to_double() - s.x.to_double()) / kXyzLsb;
    s_on += a * a;
    s_off += b * b;
  }
  EXPECT_NEAR(std::sqrt(s_on / n), 1.04, 0.06);
  EXPECT_LT(std::sqrt(s_off / n), 0.7);
}

// A camera looking along a tilted direction: C = Rx(a)·Rz(b), t = (0.1, −0.2, 0.9).
struct TestCamera {
  double rot[9], trans[3] = {0.1, -0.2, 0.9};
  TestCamera() {
    const double a = 2.3, b = 0.4;
    const double rx[9] = {1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a)};
    const double rz[9] = {std::cos(b), -std::sin(b), 0, std::sin(b), std::cos(b), 0, 0, 0, 1};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        rot[3 * r + c] = 0;
        for (int k = 0; k < 3; ++k) rot[3 * r + c] += rx[3 * r + k] * rz[3 * k + c];
      }
  }
  void ToCamera(const double p[3], double c[3]) const {
    for (int r = 0; r < 3; ++r) c[r] = rot[3 * r] * p[0] + rot[3 * r + 1] * p[1] + rot[3 * r + 2] * p[2] + trans[r];
  }
};

// Only the align-depth move, with TestCamera's geometry installed (fatal failure if refused).
void AlignDepthParams(const TestCamera& cam, DiffusionParams* p) {
  *p = OnlyMove(kHwAlignDepth);
  std::string why;
  ASSERT_TRUE(SetAlignDepthCamera(p, cam.rot, cam.trans, &why)) << why;
}

// Against src/filter/diffusion.cc's kAlignDepth in double: p' = p + Cᵀ(Δ·c/c_z). Tolerance per
// axis: the final rounding to xyz_t (½ LSB) + C quantized to 2^-17 (≤ 3·2^-17·|v| in c_z) + o
// rounded to 2^-11 (× |k| ≤ 0.2) — well below 1 LSB for |Δ| ≤ 0.1 m and c_z ≥ 0.5 m; the
// depth then changes by Δ and the projection stays put (both to the same tolerance).
TEST(HwRandomDiffusion, AlignDepthMatchesTheFloatMoveAlongTheViewingRay) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  const TestCamera cam;
  DiffusionParams p;
  ASSERT_NO_FATAL_FAILURE(AlignDepthParams(cam, &p));
  MoveDraw d{};
  d.move = kHwAlignDepth;
  Lfsr15 lfsr(77);
  int tested = 0;
  for (int i = 0; i < 400; ++i) {
    const double u[4] = {lfsr.Draw().to_int() / 32768.0, lfsr.Draw().to_int() / 32768.0,
                         lfsr.Draw().to_int() / 32768.0, lfsr.Draw().to_int() / 32768.0};
    const Sample s = MakeSample(-0.8 + 1.6 * u[0], -0.8 + 1.6 * u[1], -0.8 + 1.6 * u[2], 0.1, 0.2, 0.3, 400);
    const depth_off_t off = depth_off_t(ap_fixed<18, 3, AP_RND, AP_SAT>(-0.1 + 0.2 * u[3]));
    const double q[3] = {s.x.to_double(), s.y.to_double(), s.z.to_double()};
    double c[3];
    cam.ToCamera(q, c);
    const Sample o = ApplyMove(s, d, weight_t(0.5), p, vol, off);
    EXPECT_TRUE(o.roll == s.roll && o.pitch == s.pitch && o.yaw == s.yaw && o.cell == s.cell);
    if (c[2] < 0.5) {
      if (c[2] <= 0) EXPECT_TRUE(SameSample(o, s)) << "behind the camera: no move";
      continue;
    }
    ++tested;
    const double k = off.to_double() / c[2];
    const double out[3] = {o.x.to_double(), o.y.to_double(), o.z.to_double()};
    for (int a = 0; a < 3; ++a) {
      double ref = q[a];
      for (int r = 0; r < 3; ++r) ref += cam.rot[3 * r + a] * k * c[r];  // Cᵀ(k·c)
      EXPECT_NEAR(out[a], ref, 0.75 * kXyzLsb) << "axis " << a << " sample " << i;
    }
    double c2[3];
    cam.ToCamera(out, c2);
    EXPECT_NEAR(c2[2] - c[2], off.to_double(), 1.5 * kXyzLsb) << i;
    EXPECT_NEAR(c2[0] / c2[2], c[0] / c[2], 2.0 * kXyzLsb / c[2]) << i;
    EXPECT_NEAR(c2[1] / c2[2], c[1] / c[2], 2.0 * kXyzLsb / c[2]) << i;
  }
  EXPECT_GT(tested, 100);
  // Δ = 0 or the thesis default geometry (all 0): no move.
  const Sample s = MakeSample(0.1, 0.2, 0.3, 0, 0, 0, 400);
  EXPECT_TRUE(SameSample(ApplyMove(s, d, weight_t(0), p, vol, depth_off_t(0)), s));
  EXPECT_TRUE(SameSample(ApplyMove(s, d, weight_t(0), OnlyMove(kHwAlignDepth), vol, depth_off_t(0.05)), s));
  // A camera centre beyond fixed<15,5> is refused on the host.
  const double far[3] = {20, 20, 20};  // |o| = 34.6 m: some axis beyond 16 m
  std::string why;
  EXPECT_FALSE(SetAlignDepthCamera(&p, cam.rot, far, &why));
  EXPECT_NE(why.find("16 m"), std::string::npos);
}

// The module reads each draw's side-band word at the same index as its sample.
TEST(HwRandomDiffusion, ModuleReadsTheSideBandOfTheSelectedSample) {
  static HeuristicVolume vol[kNumCells];
  FillVolumes(vol);
  const TestCamera cam;
  DiffusionParams p;
  ASSERT_NO_FATAL_FAILURE(AlignDepthParams(cam, &p));
  static Sample in[kMaxParticles], out[kMaxParticles];
  static depth_off_t off[kMaxParticles];
  particle_index_t sel[kMaxParticles];
  // A point in front of the camera: c = C·p + t with p = Cᵀ((0, 0, 1) − t) has c_z = 1 m.
  double pc[3] = {0, 0, 0};
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < 3; ++r) pc[a] += cam.rot[3 * r + a] * ((r == 2 ? 1.0 : 0.0) - cam.trans[r]);
  for (int i = 0; i < kMaxParticles; ++i) {
    in[i] = MakeSample(pc[0], pc[1], pc[2], 0, 0, 0, 400);
    off[i] = depth_off_t(i % 2 ? 0.02 : 0.0);  // odd particles measured a 2 cm misalignment
    sel[i] = (i * 3 + 1) % kMaxParticles;
  }
  DiffusionRng rng(9);
  Diffuse(in, off, sel, kMaxParticles, 4, weight_t(0.5), p, vol, rng, out, nullptr);
  for (int j = 0; j < kMaxParticles; ++j) {
    const bool should_move = j >= 4 && sel[j].to_int() % 2 == 1;
    EXPECT_EQ(!SameSample(out[j], in[0]), should_move) << j;
    if (should_move) {
      double q[3] = {out[j].x.to_double(), out[j].y.to_double(), out[j].z.to_double()}, c[3];
      cam.ToCamera(q, c);
      EXPECT_NEAR(c[2], 1.02, 2 * kXyzLsb) << j;
    }
  }
}

}  // namespace
}  // namespace posefilter::hw
