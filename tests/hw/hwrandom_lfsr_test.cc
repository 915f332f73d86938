// Tests of src/hw/lfsr.h: exact periods, zero-seed handling, the bit-level recurrence of
// Listing 5.1 / 7.6 [HARDWARE.md], leap stepping, and the angle source.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "hw/lfsr.h"

namespace posefilter::hw {
namespace {

// Steps until the state returns to the start; checks that no state repeats earlier and that
// every non-zero state is visited (the LFSR step is a bijection, so this is the full orbit).
template <typename Gen, int W, typename StepFn>
uint64_t OrbitLength(Gen& g, StepFn step, std::vector<uint8_t>* seen) {
  seen->assign(1u << W, 0);
  const uint32_t start = g.state.to_uint();
  (*seen)[start] = 1;
  uint64_t n = 0;
  while (true) {
    const uint32_t s = step(g);
    ++n;
    if (s == start) break;
    EXPECT_EQ((*seen)[s], 0) << "state " << s << " repeated after " << n << " steps";
    if ((*seen)[s]) return 0;
    (*seen)[s] = 1;
    if (n > (1u << W)) return 0;
  }
  return n;
}

TEST(HwRandomLfsr, Lfsr18FullPeriod) {
  Lfsr18 g(12345);
  std::vector<uint8_t> seen;
  const uint64_t p = OrbitLength<Lfsr18, 18>(g, [](Lfsr18& x) { return x.Next().to_uint(); }, &seen);
  EXPECT_EQ(p, uint64_t(kLfsr18Period));
  EXPECT_EQ(seen[0], 0);  // zero is never reached
  uint64_t visited = 0;
  for (uint8_t v : seen) visited += v;
  EXPECT_EQ(visited, uint64_t(kLfsr18Period));
}

TEST(HwRandomLfsr, Lfsr15FullPeriod) {
  Lfsr15 g(1);
  std::vector<uint8_t> seen;
  const uint64_t p = OrbitLength<Lfsr15, 15>(g, [](Lfsr15& x) { return x.Next().to_uint(); }, &seen);
  EXPECT_EQ(p, uint64_t(kLfsr15Period));
  EXPECT_EQ(seen[0], 0);
}

TEST(HwRandomLfsr, LeapKeepsFullPeriodWhenCoprime) {
  std::vector<uint8_t> seen;
  Lfsr18 a(777);
  EXPECT_EQ((OrbitLength<Lfsr18, 18>(a, [](Lfsr18& x) { return x.Draw().to_uint(); }, &seen)),
            uint64_t(kLfsr18Period));
  Lfsr15 b(777);
  EXPECT_EQ((OrbitLength<Lfsr15, 15>(b, [](Lfsr15& x) { return x.Draw().to_uint(); }, &seen)),
            uint64_t(kLfsr15Period));
  // A leap sharing a factor with the period shortens it: 18 steps → 262143 / gcd(18, ·) = 29127.
  Lfsr18 c(777);
  EXPECT_EQ((OrbitLength<Lfsr18, 18>(c, [](Lfsr18& x) { return x.Leap<18>().to_uint(); }, &seen)), 29127u);
}

TEST(HwRandomLfsr, MatchesListingRecurrence) {
  // Listing 5.1 [HARDWARE.md]: new = b_18 ^ b_11 = bit 0 ^ bit 7, shift right, new bit at 17.
  uint32_t s18 = 0x1D2C3;
  Lfsr18 g18(0x1D2C3);
  // Listing 7.6 [HARDWARE.md]: new = bit 0 ^ bit 1, new bit at 14.
  uint32_t s15 = 0x2345;
  Lfsr15 g15(0x2345);
  for (int i = 0; i < 2000; ++i) {
    s18 = (s18 >> 1) | ((((s18 >> 0) ^ (s18 >> 7)) & 1u) << 17);
    s15 = (s15 >> 1) | ((((s15 >> 0) ^ (s15 >> 1)) & 1u) << 14);
    ASSERT_EQ(g18.Next().to_uint(), s18) << i;
    ASSERT_EQ(g15.Next().to_uint(), s15) << i;
  }
  // Leap<K> is K single steps.
  Lfsr18 a(99), b(99);
  for (int i = 0; i < 100; ++i) {
    for (int k = 0; k < 17; ++k) a.Step();
    ASSERT_EQ(b.Draw().to_uint(), a.state.to_uint());
  }
}

TEST(HwRandomLfsr, ZeroSeedIsReplacedByDefault) {
  Lfsr18 a(0);
  EXPECT_EQ(a.state.to_uint(), kLfsr18DefaultSeed);
  Lfsr15 b(0);
  EXPECT_EQ(b.state.to_uint(), kLfsr15DefaultSeed);
  // Only the low bits count: a seed whose low 18 bits are zero is a zero seed too.
  Lfsr18 c(1u << 18);
  EXPECT_EQ(c.state.to_uint(), kLfsr18DefaultSeed);
  // The default-seeded generator runs (never sticks at 0).
  for (int i = 0; i < 1000; ++i) ASSERT_NE(a.Next().to_uint(), 0u);
  // A non-zero seed is kept.
  Lfsr15 d(0x1234);
  EXPECT_EQ(d.state.to_uint(), 0x1234u);
}

TEST(HwRandomLfsr, GeneratorModuleWritesNStatesAndTraces) {
  Lfsr18 g(5), ref(5);
  hls::stream<ap_uint<18> > out;
  CycleTrace trace;
  Lfsr18Generate(g, out, 510, &trace);
  int count = 0;
  while (!out.empty()) {
    ASSERT_EQ(out.read().to_uint(), ref.Next().to_uint());
    ++count;
  }
  EXPECT_EQ(count, 510);
  ASSERT_EQ(trace.count, 1);
  EXPECT_EQ(trace.records[0].trips, 510u);
  EXPECT_EQ(trace.records[0].ii, 1u);
}

TEST(HwRandomLfsr, AngleSourceCoversMinusPiToPi) {
  // Every 15-bit word: angle = fixed<15,1>(word)·π truncated to angle_t (LSB 2^-8).
  double lo = 10, hi = -10;
  for (uint32_t w = 0; w < 32768; ++w) {
    const double a = LfsrToAngle(ap_uint<15>(w)).to_double();
    const double r = (w >= 16384 ? double(w) - 32768 : double(w)) / 16384.0;
    ASSERT_LE(a, r * M_PI + 1e-5) << w;  // π is taken as 205887·2^-16
    ASSERT_GT(a, r * M_PI - 1.0 / 256 - 1e-5) << w;
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  EXPECT_LE(lo, -M_PI + 1.0 / 256);
  EXPECT_GE(hi, M_PI - 2.0 / 256);
  EXPECT_LT(hi, M_PI);
}

}  // namespace
}  // namespace posefilter::hw
