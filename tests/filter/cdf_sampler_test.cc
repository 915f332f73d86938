// Importance sampling with the threshold tracker: statistics, zero weights, saved reads.
#include "filter/cdf_sampler.h"

#include <gtest/gtest.h>

#include <cmath>

#include "posefilter/error.h"
#include "posefilter/rng.h"

namespace posefilter::filter {
namespace {

TEST(CdfSamplerTest, DrawFrequenciesFollowTheWeights) {
  const std::vector<double> w = {1, 0, 2, 3, 0, 4};
  CdfSampler s(w, 32);
  EXPECT_DOUBLE_EQ(s.cdf().back(), 1.0);
  Rng rng(3);
  std::vector<int> hits(w.size(), 0);
  const int n = 200000;
  for (int i = 0; i < n; ++i) ++hits[s.Sample(1.0 - rng.Uniform())];
  EXPECT_EQ(hits[1], 0);  // zero weight: never drawn
  EXPECT_EQ(hits[4], 0);
  for (int i : {0, 2, 3, 5}) {
    const double p = w[i] / 10.0;
    const double sigma = std::sqrt(p * (1 - p) / n);
    EXPECT_NEAR(hits[i] / double(n), p, 5 * sigma) << "index " << i;
  }
}

TEST(CdfSamplerTest, TrackerGivesTheSameIndexAsALinearScanWithFewerReads) {
  Rng rng(11);
  std::vector<double> w(6300);
  for (auto& x : w) x = rng.Uniform() < 0.05 ? rng.Uniform() : 0.0;  // sparse, like a heatmap
  CdfSampler tracked(w, 32), plain(w, 1);
  for (int i = 0; i < 2000; ++i) {
    const double u = 1.0 - rng.Uniform();
    const int a = tracked.Sample(u);
    // Reference: first index with c_i >= u, by a full scan.
    int ref = 0;
    while (plain.cdf()[ref] < u) ++ref;
    EXPECT_EQ(a, ref);
    EXPECT_EQ(plain.Sample(u), ref);
  }
  EXPECT_EQ(tracked.reads_linear(), plain.reads());
  EXPECT_LT(tracked.reads() * 10, tracked.reads_linear());  // the tracker saves > 10× reads
}

TEST(CdfSamplerTest, RejectsInvalidWeights) {
  EXPECT_THROW(CdfSampler({}, 4), Error);
  EXPECT_THROW(CdfSampler({0, 0}, 4), Error);
  EXPECT_THROW(CdfSampler({1, -1}, 4), Error);
  EXPECT_THROW(CdfSampler(std::vector<double>{1, std::nan("")}, 4), Error);
}

}  // namespace
}  // namespace posefilter::filter
