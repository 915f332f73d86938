// Tests of src/hw/postprocess.h (thesis §7.3): the exp ROM, PostProcess against the float
// PostProcessPyramid / DecodeBox on random and synthetic pyramids, clipping, the host-side
// parameter and input checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hwsample_test_util.h"
#include "posefilter/error.h"
#include "posefilter/prior.h"
#include "test_util.h"

namespace posefilter::hw {
namespace {

using namespace hwsample_test;

// Probability tolerance vs the float post-process (derivation): the raw values are rounded to
// 2^-12 (|δ| ≤ 2^-13 each), which moves ln Prob_j by ≤ 2^-13 (p_j) + 2^-13 (the softmax
// denominator's weighted mean of δp) + 2^-13 (c) → ≤ 3·2^-13 absolute on Prob ≤ 1; the exp ROM
// with its correction polynomial (≤ 2^-17 relative, ≤ 2^-23 absolute), the reciprocal
// (≤ 2^-29) and the truncation of D (2^-27) add < 2^-15; the output rounding to prob_t adds
// ≤ 2^-9. Total < 2^-9 + 2^-11. prob_t cannot hold more than 255/256, so the float value is
// compared after the same saturation.
constexpr double kProbTol = 1.0 / 512 + 1.0 / 2048;
constexpr double kProbMax = 255.0 / 256;

TEST(HwSamplePostProcess, ExpRomEntriesMatchExp) {
  for (int i = 0; i < kExpRomSize; ++i) {
    const double x = (i - 128) / 8.0;
    const double want = std::exp(x) * 16777216.0;
    EXPECT_NEAR(double(kExpRom.v[i]), want, 0.5 + want * 1e-15) << "entry " << i;
  }
  // The thesis's range: e^-16 ≈ 1.12e-7 … e^15.875 (last entry).
  EXPECT_EQ(kExpRom.v[128], 1u << 24);
}

TEST(HwSamplePostProcess, ExpRomEvaluationAccuracy) {
  // Interpolated (ours): the Taylor remainder of 1 + r + r²/2 is ≤ |r|³/6 ≈ 4.1e-5 for
  // |r| ≤ 1/16, plus the ROM/poly truncation (≤ 2^-23 absolute) → relative ≤ 2^-14 where
  // e^x ≥ 2^-6, ≤ 4.1e-5 relative + 2^-23 absolute below. In the top 1/16 of the range (x ≥ 15.9375) the last
  // entry is used with r up to 1/8: ≤ (1/8)³/6 = 3.3e-4.
  // Thesis mode (plain ROM at round(8x)): relative error up to e^{1/16} − 1 ≈ 6.5% (13% at
  // the top).
  double worst_interp = 0, worst_plain = 0, worst_top = 0;
  for (int k = -16 * 4096; k < 16 * 4096; k += 37) {
    const double x = k / 4096.0;
    const double want = std::exp(x);
    const double got = ExpRom(exp_arg_t(x), true).to_double();
    const double plain = ExpRom(exp_arg_t(x), false).to_double();
    if (x >= 15.9375) {
      worst_top = std::max(worst_top, std::fabs(got / want - 1));
    } else if (want >= 1.0 / 64) {
      worst_interp = std::max(worst_interp, std::fabs(got / want - 1));
      worst_plain = std::max(worst_plain, std::fabs(plain / want - 1));
    } else {
      EXPECT_NEAR(got, want, 4.1e-5 * want + std::ldexp(1.0, -23)) << "x = " << x;
    }
  }
  EXPECT_LE(worst_interp, std::ldexp(1.0, -14));
  EXPECT_LE(worst_top, 3.3e-4);
  EXPECT_LE(worst_plain, std::exp(1.0 / 16) - 1 + 1e-6);
  EXPECT_GE(worst_plain, 0.05);  // the plain ROM really is coarse: the correction matters
  // Clamping to the ROM range.
  EXPECT_NEAR(ExpRom(exp_arg_t(-40), true).to_double(), std::exp(-16.0), 1e-7);
  EXPECT_NEAR(ExpRom(exp_arg_t(30), true).to_double() / std::exp(16.0), 1.0, 1e-3);
}

TEST(HwSamplePostProcess, WideReciprocalAccuracy) {
  Rng rng(7);
  for (int t = 0; t < 2000; ++t) {
    const double x = std::exp(rng.Uniform(std::log(1.0), std::log(2.6e8)));
    recip_mant_t inv;
    int s = 0;
    WideReciprocal(ap_ufixed<56, 29>(x), &inv, &s);
    const double got = std::ldexp(inv.to_double(), -s);
    const double xq = ap_ufixed<56, 29>(x).to_double();
    EXPECT_NEAR(got * xq, 1.0, std::ldexp(1.0, -28)) << "x = " << x;
  }
  for (int t = 0; t < 2000; ++t) {
    const double x = std::exp(rng.Uniform(std::log(1.0 / 256), std::log(6300.0)));
    recip_mant_t inv;
    int s = 0;
    const class_sum_t xq(x);
    if (xq == 0) continue;
    WideReciprocal(xq, &inv, &s);
    EXPECT_NEAR(std::ldexp(inv.to_double(), -s) * xq.to_double(), 1.0, std::ldexp(1.0, -28));
  }
}

// Window of the float engine (filter/host_setup.cc CellWindow), restated for the test.
struct RefWindow {
  int u0, v0, width, height;
};
RefWindow FloatWindow(const Box& box, double min_side, int max_px, int image_w, int image_h) {
  RefWindow r;
  r.width = std::clamp(int(std::lround(std::max(box.w, min_side))), 1, std::min(max_px, image_w));
  r.height = std::clamp(int(std::lround(std::max(box.h, min_side))), 1, std::min(max_px, image_h));
  r.u0 = std::clamp(int(std::lround(box.cx - 0.5 * r.width)), 0, image_w - r.width);
  r.v0 = std::clamp(int(std::lround(box.cy - 0.5 * r.height)), 0, image_h - r.height);
  return r;
}

// Compares a hw post-process run with the float one cell by cell.
template <int NC>
void ExpectMatchesFloat(const std::vector<float>& raw, const std::string& what, int min_window = 0) {
  const PyramidLayout layout = PyramidLayout::Thesis(640, 480, NC);
  std::vector<std::string> classes;
  for (int j = 0; j < NC; ++j) classes.push_back("c" + std::to_string(j));
  const Prior ref = PostProcessPyramid(raw, layout, classes);
  const PostProcessParams prm = PostProcessParamsFor(layout, 200, kMaxWindow, min_window);
  HwPrior<NC> hw = RunPostProcess<NC>(raw, prm);

  double worst_prob = 0, worst_box = 0;
  int argmax_same = 0, argmax_clear = 0, window_diff = 0;
  for (int c = 0; c < kNumCells; ++c) {
    int hw_arg = 0, f_arg = 0;
    double f_max = -1, f_second = -1;
    for (int j = 0; j < NC; ++j) {
      const double h = D(hw.prob[c][j]), f = std::min<double>(ref.Prob(c, j), kProbMax);
      worst_prob = std::max(worst_prob, std::fabs(h - f));
      if (hw.prob[c][j] > hw.prob[c][hw_arg]) hw_arg = j;
      if (f > f_max) {
        f_second = f_max;
        f_max = f;
        f_arg = j;
      } else if (f > f_second) {
        f_second = f;
      }
    }
    // argmax: the hw's class is (within tolerance) a float maximum; where the float's top
    // two are further apart than the quantization can bridge, it is the same class.
    ASSERT_GE(ref.Prob(c, hw_arg), f_max - 2 * kProbTol) << what << " cell " << c;
    if (NC == 1 || f_max - f_second > 2 * kProbTol) {
      ++argmax_clear;
      EXPECT_EQ(hw_arg, f_arg) << what << " cell " << c;
    }
    argmax_same += hw_arg == f_arg;
    // Boxes within 1 px (rounding to integer pixels ≤ 0.5 + arithmetic ≤ 0.05).
    const Box& b = ref.boxes[c];
    const double dcx = std::fabs(BoxCentre(hw.boxes[c].xw) - b.cx);
    const double dcy = std::fabs(BoxCentre(hw.boxes[c].yh) - b.cy);
    const double dw = std::fabs(BoxSize(hw.boxes[c].xw) - b.w);
    const double dh = std::fabs(BoxSize(hw.boxes[c].yh) - b.h);
    worst_box = std::max({worst_box, dcx, dcy, dw, dh});
    // Windows: inside the image, sides in [1, 200], within 1 px of the float engine's.
    const Window& w = hw.windows[c];
    const int u0 = w.u0.to_int(), v0 = w.v0.to_int(), ww = w.width.to_int(), wh = w.height.to_int();
    std::string why;
    EXPECT_TRUE(WindowIsValid(w, 640, 480, &why)) << what << " cell " << c << ": " << why;
    const RefWindow r = FloatWindow(b, min_window, kMaxWindow, 640, 480);
    EXPECT_LE(std::abs(u0 - r.u0), 1) << what << " cell " << c;
    EXPECT_LE(std::abs(v0 - r.v0), 1) << what << " cell " << c;
    EXPECT_LE(std::abs(ww - r.width), 1) << what << " cell " << c;
    EXPECT_LE(std::abs(wh - r.height), 1) << what << " cell " << c;
    window_diff += (u0 != r.u0) + (v0 != r.v0) + (ww != r.width) + (wh != r.height);
  }
  EXPECT_LE(worst_prob, kProbTol) << what;
  EXPECT_LE(worst_box, 0.6) << what;
  // The class sums are the exact sums of the written probabilities, and close to the float
  // class masses (each cell within kProbTol).
  for (int j = 0; j < NC; ++j) {
    EXPECT_EQ(hw.class_sum[j], ClassSum<NC>(hw.prob.get(), j)) << what << " class " << j;
    EXPECT_NEAR(hw.class_sum[j].to_double(), ref.ClassMass(j), kNumCells * kProbTol) << what;
  }
  std::printf("[%s] worst |prob − float| = %.5f (tol %.5f), worst box error %.3f px, argmax same "
              "%d/%d cells (%d with a clear float winner), window coords off by 1 px: %d\n",
              what.c_str(), worst_prob, kProbTol, worst_box, argmax_same, kNumCells, argmax_clear,
              window_diff);
}

TEST(HwSamplePostProcess, RandomPyramidMatchesFloat21Classes) {
  ExpectMatchesFloat<21>(RandomRaw(21, 11), "random 21");
}

TEST(HwSamplePostProcess, RandomPyramidMatchesFloatFewClasses) {
  ExpectMatchesFloat<3>(RandomRaw(3, 12), "random 3");
  ExpectMatchesFloat<1>(RandomRaw(1, 13), "random 1");
}

TEST(HwSamplePostProcess, SyntheticDetectionPyramidMatchesFloat) {
  ExpectMatchesFloat<21>(SceneRaw(), "detections");
  // The detection classes keep their mass where the boxes are.
  HwPrior<21> hw = RunPostProcess<21>(SceneRaw(), ThesisPostProcessParams());
  const int banana = 9;  // "011_banana" in YcbVideoClassNames()
  ASSERT_EQ(YcbVideoClassNames()[banana], "011_banana");
  EXPECT_GT(hw.class_sum[banana].to_double(), 1.0);
}

TEST(HwSamplePostProcess, MinimumWindowMatchesFloat) {
  ExpectMatchesFloat<21>(RandomRaw(21, 14), "min window 90", 90);
}

TEST(HwSamplePostProcess, ThesisModeExpRomStaysWithinItsBound) {
  // exp_interpolate = false (the thesis's plain 8-bit ROM read): each e^x is off by a factor
  // within e^{±1/16} (ε = e^{1/16} − 1), e^{0} of the max logit is exact, so Prob_j moves by a
  // factor within (1 + ε)/(1 − ε)² (numerator, Σ, 1 + e^c) → relative ≤ 3.5ε ≈ 0.23, plus the
  // output rounding 2^-9 and the raw rounding of kProbTol. The interpolated mode's worst error
  // is several times smaller on the same pyramid.
  constexpr int NC = 21;
  const std::vector<float> raw = RandomRaw(NC, 15);
  const PyramidLayout layout = PyramidLayout::Thesis(640, 480, NC);
  std::vector<std::string> classes(NC, "c");
  const Prior ref = PostProcessPyramid(raw, layout, classes);
  PostProcessParams thesis = ThesisPostProcessParams();
  thesis.exp_interpolate = false;
  HwPrior<NC> plain = RunPostProcess<NC>(raw, thesis);
  HwPrior<NC> interp = RunPostProcess<NC>(raw, ThesisPostProcessParams());
  const double eps = std::exp(1.0 / 16) - 1;
  double err_plain = 0, err_interp = 0, worst_plain = 0, worst_interp = 0;
  for (int c = 0; c < kNumCells; ++c) {
    for (int j = 0; j < NC; ++j) {
      const double f = std::min<double>(ref.Prob(c, j), kProbMax);
      const double dp = std::fabs(D(plain.prob[c][j]) - f);
      ASSERT_LE(dp, 3.5 * eps * f + kProbTol) << "cell " << c << " class " << j;
      const double di = std::fabs(D(interp.prob[c][j]) - f);
      err_plain += dp;
      err_interp += di;
      worst_plain = std::max(worst_plain, dp);
      worst_interp = std::max(worst_interp, di);
    }
  }
  std::printf("[exp ROM] |prob − float| mean/worst: %.2e/%.4f plain (thesis), %.2e/%.4f interpolated\n",
              err_plain / (kNumCells * NC), worst_plain, err_interp / (kNumCells * NC), worst_interp);
  EXPECT_GT(worst_plain, 4 * worst_interp);
  EXPECT_GT(err_plain, err_interp);
}

TEST(HwSamplePostProcess, BoxesAndWindowsAreClipped) {
  constexpr int NC = 2;
  std::vector<float> raw(size_t(kNumCells) * (NC + 5), 0.f);
  auto cell_raw = [&](int cell) { return &raw[size_t(cell) * (NC + 5)]; };
  // Cell 19 (level 0, row 0, col 19: anchor centre x = 623.5): huge size and a far shift.
  float* a = cell_raw(19);
  a[NC + 0] = 3.0f;   // cx = 623.5 + 3·128 → clamped to 639
  a[NC + 1] = -2.0f;  // cy = 15.5 − 256 → clamped to 0
  a[NC + 2] = 6.0f;   // w = 128·e^6 → clipped to 200
  a[NC + 3] = -9.0f;  // h = 128·e^-9 = 0.016 → clipped to 1
  // Cell 300 (level 1, first cell): exact anchor (zeros).
  const PostProcessParams prm = ThesisPostProcessParams();
  HwPrior<NC> hw = RunPostProcess<NC>(raw, prm);
  EXPECT_EQ(BoxCentre(hw.boxes[19].xw), 639);
  EXPECT_EQ(BoxCentre(hw.boxes[19].yh), 0);
  EXPECT_EQ(BoxSize(hw.boxes[19].xw), 200);
  EXPECT_EQ(BoxSize(hw.boxes[19].yh), 1);
  // Window saturated to the image: right edge, top edge.
  EXPECT_EQ(hw.windows[19].u0.to_int(), 640 - 200);
  EXPECT_EQ(hw.windows[19].width.to_int(), 200);
  EXPECT_EQ(hw.windows[19].v0.to_int(), 0);
  EXPECT_EQ(hw.windows[19].height.to_int(), 1);
  // Level-1 anchor of cell 300: centre (7.5, 7.5) rounds to 8 (half up), 64×64 px.
  EXPECT_EQ(BoxCentre(hw.boxes[300].xw), 8);
  EXPECT_EQ(BoxSize(hw.boxes[300].xw), 64);
  EXPECT_EQ(hw.windows[300].u0.to_int(), 0);  // 7.5 − 32 < 0 → saturated
  // Equal logits, c = 0: every class 1/NC·1/2 = 0.25.
  EXPECT_EQ(D(hw.prob[300][0]), 0.25);
  EXPECT_EQ(D(hw.prob[300][1]), 0.25);
}

TEST(HwSamplePostProcess, ProbabilitiesSaturateBelowOne) {
  constexpr int NC = 1;
  std::vector<float> raw(size_t(kNumCells) * (NC + 5), 0.f);
  for (int c = 0; c < kNumCells; ++c) raw[size_t(c) * (NC + 5) + NC + 4] = -30.f;  // c → −∞
  HwPrior<NC> hw = RunPostProcess<NC>(raw, ThesisPostProcessParams());
  // Prob = 1/(1 + e^-16) rounds to 1.0 and must saturate to 255/256, not wrap to 0.
  for (int c = 0; c < kNumCells; ++c) ASSERT_EQ(D(hw.prob[c][0]), 255.0 / 256) << c;
  EXPECT_EQ(hw.class_sum[0].to_double(), kNumCells * 255.0 / 256);
}

TEST(HwSamplePostProcess, CycleTraceCountsRealTrips) {
  HwPrior<21> hw = RunPostProcess<21>(RandomRaw(21, 3), ThesisPostProcessParams());
  uint64_t reads = 0, exps = 0, cells = 0;
  for (int i = 0; i < hw.trace->count; ++i) {
    const LoopRecord& r = hw.trace->records[i];
    if (std::string(r.loop) == "PP_READ") reads += r.trips;
    if (std::string(r.loop) == "PP_EXP") exps += r.trips;
    if (std::string(r.loop) == "PP_CELLS") cells += r.trips;
  }
  EXPECT_EQ(reads, uint64_t(kNumCells) * 26);
  EXPECT_EQ(exps, uint64_t(kNumCells) * 21);
  EXPECT_EQ(cells, uint64_t(kNumCells));
}

TEST(HwSamplePostProcess, ParamsRejectUnsupportedLayouts) {
  using testing_util::ExpectError;
  PyramidLayout two = PyramidLayout::Thesis();
  two.levels.pop_back();
  ExpectError([&] { PostProcessParamsFor(two, 200); }, {"3 levels"});
  PyramidLayout grid = PyramidLayout::Thesis();
  grid.levels[1].rows = 31;
  ExpectError([&] { PostProcessParamsFor(grid, 200); }, {"level 1", "30×40"});
  ExpectError([&] { PostProcessParamsFor(PyramidLayout::Thesis(1280, 960), 200); }, {"1024"});
  ExpectError([&] { PostProcessParamsFor(PyramidLayout::Thesis(640, 480, 22), 200); }, {"num_classes"});
  ExpectError([&] { PostProcessParamsFor(PyramidLayout::Thesis(), 300); }, {"max_box_px"});
  ExpectError([&] { PostProcessParamsFor(PyramidLayout::Thesis(), 200, 250); }, {"max_window_px"});
  ExpectError([&] { PostProcessParamsFor(PyramidLayout::Thesis(), 200, 200, -1); }, {"min_window_px"});
  PyramidLayout big_anchor = PyramidLayout::Thesis();
  big_anchor.levels[0].anchor_w = 600;
  ExpectError([&] { PostProcessParamsFor(big_anchor, 200); }, {"anchor"});
  PyramidLayout bad = PyramidLayout::Thesis();
  bad.levels[0].anchor_h = -1;
  ExpectError([&] { PostProcessParamsFor(bad, 200); }, {"invalid pyramid layout"});
  // A valid layout gives the thesis parameters.
  const PostProcessParams p = PostProcessParamsFor(PyramidLayout::Thesis(), 200);
  const PostProcessParams t = ThesisPostProcessParams();
  for (int l = 0; l < kNumLevels; ++l) {
    EXPECT_EQ(p.stride_x[l], t.stride_x[l]);
    EXPECT_EQ(p.anchor_h[l], t.anchor_h[l]);
  }
}

TEST(HwSamplePostProcess, RawStreamRejectsBadInput) {
  using testing_util::ExpectError;
  hls::stream<raw_t> s;
  ExpectError([&] { RawPyramidToStream(std::vector<float>(10), 21, s); }, {"10 values", "expected"});
  std::vector<float> raw(size_t(kNumCells) * 26, 0.f);
  raw[26 * 5 + 3] = std::nanf("");
  hls::stream<raw_t> s2;
  ExpectError([&] { RawPyramidToStream(raw, 21, s2); }, {"value 133", "cell 5", "not finite"});
  EXPECT_EQ(s2.size(), 133u);  // the values before the bad one were written; drain them
  while (!s2.empty()) s2.read();
  // Out-of-range values saturate (documented): ±100 → ±32.
  hls::stream<raw_t> s3;
  std::vector<float> big(size_t(kNumCells) * 6, 100.f);
  big[1] = -100.f;
  RawPyramidToStream(big, 1, s3);
  EXPECT_NEAR(s3.read().to_double(), 32.0, 1e-3);
  EXPECT_EQ(s3.read().to_double(), -32.0);
  while (!s3.empty()) s3.read();
}

}  // namespace
}  // namespace posefilter::hw
