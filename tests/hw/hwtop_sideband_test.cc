// Tests of the glue kernels of src/hw/top.h added for accuracy (ours): the sample memory's
// side-band word (MeanDepthOffset: the mean depth difference Δ = Σ(z_s − z_r) / count a raster
// core reports, in depth_off_t F15) and the per-particle window growth (ParticleWindowHw),
// both against double references.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hw/top.h"

namespace posefilter::hw {
namespace {

RasterCoreOutput WithDiff(double sum_m, unsigned count) {
  RasterCoreOutput o{};
  o.depth_diff_sum = diff_sum_t(sum_m);
  o.depth_diff_count = count;
  return o;
}

TEST(HwTopSideBand, MeanDepthOffsetMatchesDoubleToOneLsb) {
  // Sums are F20; the quotient is truncated at F20 and rounded to F15: error ≤ 2^-16 + 2^-20.
  const double tol = 1.0 / 65536 + 1.0 / (1 << 20);
  Lfsr15 lfsr(3);
  for (int i = 0; i < 500; ++i) {
    const unsigned count = 1 + lfsr.Draw().to_uint() % 5000;
    const double mean = (lfsr.Draw().to_int() / 32768.0 - 0.5) * 0.1;  // ±5 cm
    const RasterCoreOutput o = WithDiff(mean * count, count);
    const double exact = o.depth_diff_sum.to_double() / count;
    EXPECT_NEAR(MeanDepthOffset(o).to_double(), exact, tol) << i;
  }
  EXPECT_EQ(MeanDepthOffset(WithDiff(0.0, 0)).to_double(), 0.0);        // no fragment in the band
  EXPECT_NEAR(MeanDepthOffset(WithDiff(-0.03, 1)).to_double(), -0.03, tol);  // sign kept
  // Saturation at fixed<18,3>'s range (±4 m) instead of wrapping.
  EXPECT_GT(MeanDepthOffset(WithDiff(100.0, 2)).to_double(), 3.99);
  EXPECT_LT(MeanDepthOffset(WithDiff(-100.0, 2)).to_double(), -3.99);
}

// The reference's ParticleWindow (src/filter/particle_filter.cc) in double, on the quantized
// pose and corners; *margin = the distance of the extreme projections to the next integer
// (floor/ceil decisions), to skip cases the 2^-8 px projection may round the other way.
Window FloatParticleWindow(const Sample& s, const Window& cw, const double K[4], const double C[12],
                           const double bbox[8][3], int max_px, int img_w, int img_h, double* margin) {
  const double r = s.roll.to_double(), p = s.pitch.to_double(), y = s.yaw.to_double();
  const double cr = std::cos(r), sr = std::sin(r), cp = std::cos(p), sp = std::sin(p), cy = std::cos(y), sy = std::sin(y);
  const double R[9] = {cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,
                       sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,
                       -sp,     cp * sr,                cp * cr};
  const double t[3] = {s.x.to_double(), s.y.to_double(), s.z.to_double()};
  double lo[2] = {1e30, 1e30}, hi[2] = {-1e30, -1e30};
  *margin = 1;
  for (int k = 0; k < 8; ++k) {
    double b[3], c[3];
    for (int i = 0; i < 3; ++i) b[i] = R[3 * i] * bbox[k][0] + R[3 * i + 1] * bbox[k][1] + R[3 * i + 2] * bbox[k][2] + t[i];
    for (int i = 0; i < 3; ++i) c[i] = C[4 * i] * b[0] + C[4 * i + 1] * b[1] + C[4 * i + 2] * b[2] + C[4 * i + 3];
    if (c[2] < 0.05) return cw;
    const double uv[2] = {K[0] * c[0] / c[2] + K[2], K[1] * c[1] / c[2] + K[3]};
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], uv[a]);
      hi[a] = std::max(hi[a], uv[a]);
    }
  }
  for (int a = 0; a < 2; ++a)
    for (double v : {lo[a], hi[a]}) *margin = std::min(*margin, std::fabs(v - std::round(v)));
  Window w = cw;
  const int l[2] = {cw.u0.to_int(), cw.v0.to_int()}, sz[2] = {cw.width.to_int(), cw.height.to_int()};
  const int lim[2] = {img_w, img_h};
  for (int a = 0; a < 2; ++a) {
    const long aa = std::max(0L, std::min(long(l[a]), long(std::floor(lo[a]))));
    const long bb = std::min(long(lim[a]), std::max(long(l[a]) + sz[a], long(std::ceil(hi[a])) + 1));
    if (bb - aa > std::max(max_px, sz[a])) continue;
    if (a == 0) { w.u0 = int(aa); w.width = int(bb - aa); }
    else { w.v0 = int(aa); w.height = int(bb - aa); }
  }
  return w;
}

TEST(HwTopWindow, GrownWindowMatchesTheReferenceRule) {
  const double K[4] = {525, 520, 319.5, 239.5};
  // C: a 0.3 rad tilt about x, translation (0.02, −0.05, 0.1).
  const double a = 0.3;
  const double C[12] = {1, 0, 0, 0.02, 0, std::cos(a), -std::sin(a), -0.05, 0, std::sin(a), std::cos(a), 0.1};
  WeighConfig cfg{};
  cfg.raster = DefaultRasterParams();
  cfg.img_width = 640;
  cfg.img_height = 480;
  cfg.max_window = 200;
  cfg.grow_window = 1;
  cfg.cam.fx = intr_t(K[0]);
  cfg.cam.fy = intr_t(K[1]);
  cfg.cam.cx = intr_t(K[2]);
  cfg.cam.cy = intr_t(K[3]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) cfg.cam.rot[3 * r + c] = trig_t(ap_fixed<18, 2, AP_RND, AP_SAT>(C[4 * r + c]));
    cfg.cam.trans[r] = ctrans_t(ap_fixed<24, 4, AP_RND, AP_SAT>(C[4 * r + 3]));
  }
  double Cq[12];  // the camera as quantized
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) Cq[4 * r + c] = cfg.cam.rot[3 * r + c].to_double();
    Cq[4 * r + 3] = cfg.cam.trans[r].to_double();
  }
  double bbox[8][3];
  const double half[3] = {0.05, 0.03, 0.08};
  for (int c = 0; c < 8; ++c)
    for (int k = 0; k < 3; ++k) {
      cfg.bbox[c][k] = xyz_t((c >> k) & 1 ? half[k] : -half[k]);
      bbox[c][k] = cfg.bbox[c][k].to_double();
    }
  ft_t pc[kFtElements];
  ProjectionTimesCamera(cfg.cam, pc);
  Lfsr15 lfsr(11);
  auto uni = [&] { return lfsr.Draw().to_int() / 32768.0; };
  int compared = 0, grown = 0;
  for (int i = 0; i < 300; ++i) {
    Sample s{};
    s.x = xyz_t(-0.3 + 0.6 * uni());
    s.y = xyz_t(-0.2 + 0.4 * uni());
    s.z = xyz_t(0.4 + 0.8 * uni());
    s.roll = angle_t(-3 + 6 * uni());
    s.pitch = angle_t(-3 + 6 * uni());
    s.yaw = angle_t(-3 + 6 * uni());
    Window cw;
    cw.u0 = int(600 * uni());
    cw.v0 = int(440 * uni());
    cw.width = 40;
    cw.height = 40;
    double margin;
    const Window ref = FloatParticleWindow(s, cw, K, Cq, bbox, 200, 640, 480, &margin);
    if (margin < 0.02) continue;  // 16-bit sines: projections within ≈ 0.01 px
    ++compared;
    const Window hw = ParticleWindowHw(s, cw, cfg, pc);
    EXPECT_EQ(hw.u0.to_int(), ref.u0.to_int()) << i;
    EXPECT_EQ(hw.v0.to_int(), ref.v0.to_int()) << i;
    EXPECT_EQ(hw.width.to_int(), ref.width.to_int()) << i;
    EXPECT_EQ(hw.height.to_int(), ref.height.to_int()) << i;
    grown += hw.width.to_int() != 40 || hw.height.to_int() != 40;
  }
  EXPECT_GT(compared, 250);
  EXPECT_GT(grown, 50);  // the rule is exercised, not just the cell window passed through
  // Off (the thesis): the cell window.
  cfg.grow_window = 0;
  Sample s{};
  s.z = xyz_t(0.8);
  Window cw;
  cw.u0 = 10;
  cw.v0 = 20;
  cw.width = 5;
  cw.height = 6;
  const Window w = ParticleWindowHw(s, cw, cfg, pc);
  EXPECT_TRUE(w.u0 == 10 && w.v0 == 20 && w.width == 5 && w.height == 6);
  // Behind the camera: the cell window even when growing.
  cfg.grow_window = 1;
  s.z = xyz_t(-0.5);
  const Window b = ParticleWindowHw(s, cw, cfg, pc);
  EXPECT_TRUE(b.u0 == 10 && b.v0 == 20 && b.width == 5 && b.height == 6);
}

}  // namespace
}  // namespace posefilter::hw
