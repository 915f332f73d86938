// Tests of src/hw/cdf.h (thesis §7.4 item 1, eq. 7.3 [ALGORITHM.md]): monotone, last value saturated,
// within 2^-17 of the double CDF of the same (quantized) probabilities; zero mass.
#include <gtest/gtest.h>

#include <cmath>

#include "hwsample_test_util.h"

namespace posefilter::hw {
namespace {

using namespace hwsample_test;

constexpr double kCdfTol = 1.0 / 131072;  // 2^-17: truncation < 2^-18 + reciprocal ≤ 2^-29
constexpr double kCdfMax = 1.0 - 1.0 / 262144;  // saturated last value, 1 − 2^-18

template <int NC>
void ExpectCdfGood(const prob_t prob[kNumCells][NC], int cls, const std::string& what) {
  const class_sum_t sum = ClassSum<NC>(prob, cls);
  bool fallback = true;
  auto trace = std::make_unique<CycleTrace>();
  const std::vector<cdf_t> cdf = RunCdf<NC>(prob, cls, sum, &fallback, trace.get());
  ASSERT_EQ(int(cdf.size()), kNumCells) << what;
  EXPECT_FALSE(fallback) << what;
  std::vector<double> w(kNumCells);
  for (int i = 0; i < kNumCells; ++i) w[i] = D(prob[i][cls]);
  const std::vector<double> ref = DoubleCdf(w);
  double worst = 0;
  for (int i = 0; i < kNumCells; ++i) {
    if (i > 0) {
      ASSERT_GE(cdf[i], cdf[i - 1]) << what << ": not monotone at " << i;
    }
    worst = std::max(worst, std::fabs(D(cdf[i]) - ref[i]));
  }
  EXPECT_EQ(D(cdf.back()), kCdfMax) << what << ": last value not saturated";
  EXPECT_LE(worst, kCdfTol) << what;
  // The trace counts one CDF_NORM trip per cell.
  bool seen = false;
  for (int i = 0; i < trace->count; ++i) {
    if (std::string(trace->records[i].loop) == "CDF_NORM") {
      EXPECT_EQ(trace->records[i].trips, uint64_t(kNumCells));
      seen = true;
    }
  }
  EXPECT_TRUE(seen);
  std::printf("[%s] class %d: Σ = %.4f, worst |cdf − double| = %.3g (tol %.3g)\n", what.c_str(), cls,
              sum.to_double(), worst, kCdfTol);
}

TEST(HwSampleCdf, PostProcessedPriorsMatchDoubleCdf) {
  HwPrior<21> scene = RunPostProcess<21>(SceneRaw(), ThesisPostProcessParams());
  ExpectCdfGood<21>(scene.prob.get(), 9, "detections, banana");
  ExpectCdfGood<21>(scene.prob.get(), 13, "detections, mug");
  // A class without a detection keeps only the detection prior's floor (1e-5 per cell),
  // which rounds to 0 in prob_t: no mass, the uniform fallback.
  bool fb = false;
  RunCdf<21>(scene.prob.get(), 0, scene.class_sum[0], &fb);
  EXPECT_EQ(scene.class_sum[0].to_double(), 0.0);
  EXPECT_TRUE(fb);
  HwPrior<21> rnd = RunPostProcess<21>(RandomRaw(21, 5), ThesisPostProcessParams());
  ExpectCdfGood<21>(rnd.prob.get(), 4, "random");
}

TEST(HwSampleCdf, ExtremeMasses) {
  auto prob = std::make_unique<prob_t[][1]>(kNumCells);
  // Every cell at the maximum 255/256: Σ = 6275.39 (near the top of class_sum_t).
  for (int i = 0; i < kNumCells; ++i) prob[i][0].range(7, 0) = 0xFF;
  ExpectCdfGood<1>(prob.get(), 0, "all max");
  // One LSB in a few cells: Σ = 2^-8·3 (the bottom of the range).
  for (int i = 0; i < kNumCells; ++i) prob[i][0] = 0;
  prob[17][0].range(7, 0) = 1;
  prob[4000][0].range(7, 0) = 1;
  prob[6299][0].range(7, 0) = 1;
  ExpectCdfGood<1>(prob.get(), 0, "three LSBs");
}

TEST(HwSampleCdf, SingleCellTakesAllTheMass) {
  auto prob = std::make_unique<prob_t[][2]>(kNumCells);
  for (int i = 0; i < kNumCells; ++i) prob[i][0] = prob[i][1] = 0;
  prob[1234][1].range(7, 0) = 77;
  bool fb = true;
  const std::vector<cdf_t> cdf = RunCdf<2>(prob.get(), 1, ClassSum<2>(prob.get(), 1), &fb);
  EXPECT_FALSE(fb);
  for (int i = 0; i < kNumCells; ++i) {
    if (i < 1234) {
      ASSERT_EQ(D(cdf[i]), 0.0) << i;
    } else {
      ASSERT_EQ(D(cdf[i]), kCdfMax) << i;  // 1 saturated
    }
  }
}

TEST(HwSampleCdf, ZeroMassFallsBackToUniform) {
  auto prob = std::make_unique<prob_t[][1]>(kNumCells);
  for (int i = 0; i < kNumCells; ++i) prob[i][0] = 0;
  bool fb = false;
  const std::vector<cdf_t> cdf = RunCdf<1>(prob.get(), 0, class_sum_t(0), &fb);
  EXPECT_TRUE(fb);
  ASSERT_EQ(int(cdf.size()), kNumCells);
  for (int i = 0; i < kNumCells; ++i) {
    ASSERT_NEAR(D(cdf[i]), (i + 1.0) / kNumCells, kCdfTol) << i;
  }
  EXPECT_EQ(D(cdf.back()), kCdfMax);
}

}  // namespace
}  // namespace posefilter::hw
