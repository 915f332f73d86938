// The float engines' random numbers: determinism per seed and distribution statistics.
#include "posefilter/rng.h"

#include <gtest/gtest.h>

#include <cmath>

namespace posefilter {
namespace {

TEST(RngTest, SameSeedSameStreamDifferentSeedDifferentStream) {
  Rng a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const auto x = a.NextU64();
    EXPECT_EQ(x, b.NextU64());
    differs |= x != c.NextU64();
  }
  EXPECT_TRUE(differs);
  Rng s1(7), s2(7);
  Rng child1 = s1.Split(), child2 = s2.Split();
  EXPECT_EQ(child1.NextU64(), child2.NextU64());
  EXPECT_NE(child1.NextU64(), s1.NextU64());
}

TEST(RngTest, KnownFirstOutputsPinTheAlgorithm) {
  // xoshiro256** seeded by splitmix64(seed): any change to the generator, its seeding or a
  // draw function changes these. Values recorded from this implementation (seeds 0 and
  // 12345); each draw function starts from a fresh Rng(seed).
  struct Known {
    std::uint64_t seed;
    std::uint64_t u64[4];
    double uniform[3];   // exact: top 53 bits × 2^-53, no rounding
    std::uint64_t int100[4], int7[4];
    double normal[4];    // libm log/sin/cos: to 4 ulps
    std::uint64_t split_child_first, parent_after_split;
  };
  const Known known[] = {
      {0,
       {0x99EC5F36CB75F2B4ull, 0xBF6E1F784956452Aull, 0x1A5F849D4933E6E0ull, 0x6AA594F1262D2D2Cull},
       {0x1.33d8be6d96ebep-1, 0x1.7edc3ef092ac8p-1, 0x1.a5f849d4933ep-4},
       {20, 82, 68, 32},
       {4, 5, 2, 3},
       {-1.3559302271143727, -0.01896499060631051, 0.23335097938940202, -0.40372109705088766},
       0x4F55E185CA2C7F86ull, 0xBF6E1F784956452Aull},
      {12345,
       {0xBE6A36374160D49Bull, 0x214AAA0637A688C6ull, 0xF69D16DE9954D388ull, 0x0C60048C4E96E033ull},
       {0x1.7cd46c6e82c1ap-1, 0x1.0a555031bd344p-3, 0x1.ed3a2dbd32a9ap-1},
       {83, 98, 56, 95},
       {4, 5, 0, 0},
       {1.203377073436398, 1.1293985674055409, 0.76904290672850784, 2.4536525156535842},
       0x13D5A26D632F423Eull, 0x214AAA0637A688C6ull},
  };
  for (const Known& k : known) {
    SCOPED_TRACE(::testing::Message() << "seed " << k.seed);
    Rng r(k.seed);
    for (std::uint64_t x : k.u64) EXPECT_EQ(r.NextU64(), x);
    Rng u(k.seed);
    for (double x : k.uniform) EXPECT_EQ(u.Uniform(), x);
    // Uniform() is the top 53 bits of NextU64() scaled to [0, 1).
    EXPECT_EQ(k.uniform[0], double(k.u64[0] >> 11) * 0x1.0p-53);
    Rng i100(k.seed), i7(k.seed);
    for (std::uint64_t x : k.int100) EXPECT_EQ(i100.UniformInt(100), x);
    for (std::uint64_t x : k.int7) EXPECT_EQ(i7.UniformInt(7), x);
    Rng n(k.seed);
    for (double x : k.normal) EXPECT_DOUBLE_EQ(n.Normal(), x);
    // Split() consumes one output of the parent and seeds the child from it.
    Rng parent(k.seed);
    Rng child = parent.Split();
    EXPECT_EQ(child.NextU64(), k.split_child_first);
    EXPECT_EQ(parent.NextU64(), k.parent_after_split);
  }
}

TEST(RngTest, UniformAndUniformIntStatistics) {
  Rng r(1);
  const int n = 200000;
  double s = 0;
  std::vector<int> bins(7, 0);
  for (int i = 0; i < n; ++i) {
    const double u = r.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    s += u;
    ++bins[r.UniformInt(7)];
  }
  EXPECT_NEAR(s / n, 0.5, 0.003);
  for (int b : bins) EXPECT_NEAR(b / double(n), 1.0 / 7, 0.004);
}

TEST(RngTest, NormalHasZeroMeanUnitVarianceNoSkewNoExcessKurtosis) {
  Rng r(2);
  const int n = 400000;
  double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  for (int i = 0; i < n; ++i) {
    const double z = r.Normal();
    m1 += z;
    m2 += z * z;
    m3 += z * z * z;
    m4 += z * z * z * z;
  }
  m1 /= n, m2 /= n, m3 /= n, m4 /= n;
  EXPECT_NEAR(m1, 0.0, 0.01);
  EXPECT_NEAR(m2, 1.0, 0.01);
  EXPECT_NEAR(m3, 0.0, 0.03);
  EXPECT_NEAR(m4 / (m2 * m2) - 3.0, 0.0, 0.06);
}

}  // namespace
}  // namespace posefilter
