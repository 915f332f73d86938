// QuantilePair (src/prior/quantiles.h) against the definition: sort and take the ranks.
#include "prior/quantiles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace posefilter::prior {
namespace {

// The definition: nearest rank lround(p·(n − 1)) of the sorted values, the upper rank at least
// the lower one.
void BySorting(std::vector<double> v, double p_lo, double p_hi, double* lo, double* hi) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  const std::size_t r_lo = std::size_t(std::lround(p_lo * double(n - 1)));
  const std::size_t r_hi = std::max(r_lo, std::size_t(std::lround(p_hi * double(n - 1))));
  *lo = v[r_lo];
  *hi = v[r_hi];
}

TEST(QuantilePair, MatchesSortingOnRandomSamples) {
  std::mt19937 gen(7);
  QuantileScratch scratch;  // reused across calls, as ComputeHeuristics does
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::size_t n = 1 + gen() % (trial < 200 ? 8 : 900);
    std::vector<double> v(n);
    const int kind = trial % 4;
    for (double& x : v) {
      switch (kind) {
        case 0: x = std::uniform_real_distribution<double>(-2, 3)(gen); break;
        case 1: x = double(gen() % 5) * 0.25; break;  // many ties
        case 2: x = std::normal_distribution<double>(0.8, 0.01)(gen); break;
        default: x = (gen() % 10 == 0) ? 1e6 : std::uniform_real_distribution<double>(0, 1)(gen); break;  // outliers
      }
    }
    const double ps[][2] = {{0.1, 0.9}, {0, 1}, {0.5, 0.5}, {0.9, 0.1}, {0.25, 0.26}};
    for (const auto& p : ps) {
      double lo = -1, hi = -1, want_lo, want_hi;
      QuantilePair(v.data(), n, p[0], p[1], &lo, &hi, scratch);
      BySorting(v, p[0], p[1], &want_lo, &want_hi);
      ASSERT_EQ(lo, want_lo) << "trial " << trial << " n " << n << " p " << p[0];
      ASSERT_EQ(hi, want_hi) << "trial " << trial << " n " << n << " p " << p[1];
      ++checked;
    }
  }
  EXPECT_EQ(checked, 10000);
}

TEST(QuantilePair, ConstantAndSingleSamples) {
  QuantileScratch scratch;
  double lo = 0, hi = 0;
  const std::vector<double> one = {0.42};
  QuantilePair(one.data(), one.size(), 0.1, 0.9, &lo, &hi, scratch);
  EXPECT_EQ(lo, 0.42);
  EXPECT_EQ(hi, 0.42);
  const std::vector<double> same(300, -1.5);
  QuantilePair(same.data(), same.size(), 0.1, 0.9, &lo, &hi, scratch);
  EXPECT_EQ(lo, -1.5);
  EXPECT_EQ(hi, -1.5);
}

}  // namespace
}  // namespace posefilter::prior
