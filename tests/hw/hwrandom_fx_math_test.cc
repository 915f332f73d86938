// Tests of src/hw/fx_math.h: exhaustive or dense sweeps against std:: in double, with the
// maximum error stated in ulps of the output format (see the header's accuracy table).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "hw/fx_math.h"
#include "posefilter/rng.h"

namespace posefilter::hw {
namespace {

constexpr double kUlp16 = 1.0 / 65536.0;  // ap_fixed<18,2>
constexpr double kUlp13 = 1.0 / 8192.0;   // ap_fixed<18,5>

TEST(HwRandomFxMath, SinCosExhaustiveOverAngleT) {
  double max_s = 0, max_c = 0;
  for (int raw = -2048; raw < 2048; ++raw) {
    const angle_t a = FixedFromRaw<12, 4>(ap_int<12>(raw));
    const double ad = raw / 256.0;
    ASSERT_DOUBLE_EQ(a.to_double(), ad);
    ap_fixed<18, 2> s, c;
    SinCos(a, &s, &c);
    max_s = std::max(max_s, std::fabs(s.to_double() - std::sin(ad)));
    max_c = std::max(max_c, std::fabs(c.to_double() - std::cos(ad)));
  }
  EXPECT_LE(max_s, 1.0 * kUlp16) << "sin max error " << max_s / kUlp16 << " ulp";
  EXPECT_LE(max_c, 1.0 * kUlp16) << "cos max error " << max_c / kUlp16 << " ulp";
  // Not trivially exact either (the bound is meaningful): some rounding shows up.
  EXPECT_GT(max_s, 0.0);
}

TEST(HwRandomFxMath, SinCosTurnsEvery15BitPhase) {
  double max_err = 0;
  for (int raw = 0; raw < 32768; ++raw) {
    ap_fixed<18, 2> s, c;
    SinCosTurns<15>(UFixedFromRaw<15, 0>(ap_uint<15>(raw)), &s, &c);
    const double th = 2 * M_PI * raw / 32768.0;
    max_err = std::max({max_err, std::fabs(s.to_double() - std::sin(th)), std::fabs(c.to_double() - std::cos(th))});
  }
  EXPECT_LE(max_err, 1.0 * kUlp16) << max_err / kUlp16 << " ulp";
}

TEST(HwRandomFxMath, SinCosQuadrantSignsAndSpecialValues) {
  ap_fixed<18, 2> s, c;
  SinCosTurns<15>(UFixedFromRaw<15, 0>(ap_uint<15>(0)), &s, &c);
  EXPECT_EQ(s.to_double(), 0.0);
  EXPECT_EQ(c.to_double(), 1.0);
  SinCosTurns<15>(UFixedFromRaw<15, 0>(ap_uint<15>(8192)), &s, &c);  // quarter turn
  EXPECT_EQ(s.to_double(), 1.0);
  EXPECT_EQ(c.to_double(), 0.0);
  SinCosTurns<15>(UFixedFromRaw<15, 0>(ap_uint<15>(16384)), &s, &c);  // half turn
  EXPECT_EQ(s.to_double(), 0.0);
  EXPECT_EQ(c.to_double(), -1.0);
  SinCosTurns<15>(UFixedFromRaw<15, 0>(ap_uint<15>(24576)), &s, &c);  // three quarters
  EXPECT_EQ(s.to_double(), -1.0);
  EXPECT_EQ(c.to_double(), 0.0);
}

TEST(HwRandomFxMath, CosFromSinEq53WithQuadrantSign) {
  // Against the exact root of the quantized input: ≤ 0.5 ulp plus the root's rounding.
  double max_err = 0;
  for (int raw = -65536; raw <= 65536; raw += 7) {
    const ap_fixed<18, 2> s = FixedFromRaw<18, 2>(ap_int<18>(raw));
    const double sd = raw / 65536.0;
    const double want = std::sqrt(std::max(0.0, 1 - sd * sd));
    const ap_fixed<18, 2> cp = CosFromSin(s, false);
    const ap_fixed<18, 2> cn = CosFromSin(s, true);
    max_err = std::max(max_err, std::fabs(cp.to_double() - want));
    EXPECT_EQ(cn.to_double(), -cp.to_double());
  }
  EXPECT_LE(max_err, 0.5 * kUlp16 + 1e-12) << max_err / kUlp16 << " ulp";
}

template <int W, int I>
double SqrtMaxUlpExhaustive() {
  const double lsb = std::ldexp(1.0, -(W - I));
  double max_ulp = 0;
  for (uint32_t raw = 0; raw < (1u << W); ++raw) {
    const ap_ufixed<W, I> x = UFixedFromRaw<W, I>(ap_uint<W>(raw));
    const double want = std::sqrt(raw * lsb);
    const double max_val = ((1u << W) - 1) * lsb;
    const double got = Sqrt<W, I>(x).to_double();
    const double err = std::fabs(got - std::min(want, max_val)) / lsb;
    max_ulp = std::max(max_ulp, err);
  }
  return max_ulp;
}

TEST(HwRandomFxMath, SqrtExhaustiveRoundsToNearest) {
  EXPECT_LE((SqrtMaxUlpExhaustive<18, 5>()), 0.5 + 1e-9);
  EXPECT_LE((SqrtMaxUlpExhaustive<18, 0>()), 0.5 + 1e-9);  // saturates at 1 − 2^-18 only
  EXPECT_LE((SqrtMaxUlpExhaustive<12, 12>()), 0.5 + 1e-9);  // integers
  EXPECT_LE((SqrtMaxUlpExhaustive<16, 3>()), 0.5 + 1e-9);
}

TEST(HwRandomFxMath, SqrtDenseWideFormat) {
  // ufixed<30,10>: 2^30 inputs is too many; a strided sweep plus the top of the range.
  const double lsb = std::ldexp(1.0, -20);
  double max_ulp = 0;
  for (uint64_t raw = 0; raw < (1ull << 30); raw += 104729) {
    const double got = Sqrt<30, 10>(UFixedFromRaw<30, 10>(ap_uint<30>(raw))).to_double();
    max_ulp = std::max(max_ulp, std::fabs(got - std::sqrt(raw * lsb)) / lsb);
  }
  const double top = Sqrt<30, 10>(UFixedFromRaw<30, 10>(ap_uint<30>((1ull << 30) - 1))).to_double();
  max_ulp = std::max(max_ulp, std::fabs(top - std::sqrt(((1ull << 30) - 1) * lsb)) / lsb);
  EXPECT_LE(max_ulp, 0.5 + 1e-9);
}

TEST(HwRandomFxMath, LogExhaustive) {
  double max_ulp = 0;
  for (uint32_t raw = 1; raw < (1u << 18); ++raw) {
    const ap_fixed<18, 5> got = Log(UFixedFromRaw<18, 0>(ap_uint<18>(raw)));
    const double want = std::log(raw / 262144.0);
    max_ulp = std::max(max_ulp, std::fabs(got.to_double() - want) / kUlp13);
  }
  EXPECT_LE(max_ulp, 0.52) << max_ulp;
}

TEST(HwRandomFxMath, LogOfZeroSaturatesToMostNegative) {
  EXPECT_EQ(Log(UFixedFromRaw<18, 0>(ap_uint<18>(0))).to_double(), -16.0);
  // The smallest positive input is representable: ln 2^-18 = −12.48.
  EXPECT_NEAR(Log(UFixedFromRaw<18, 0>(ap_uint<18>(1))).to_double(), -18 * std::log(2.0), kUlp13);
}

TEST(HwRandomFxMath, ReciprocalNormalisedMantissaDense) {
  // x ∈ [1, 2) in ufixed<29,1> → 1/x in ufixed<32,1>: the resampler's normalisation.
  Rng rng(7);
  const double out_lsb = std::ldexp(1.0, -31);
  double max_ulp = 0;
  for (int t = 0; t < 200000; ++t) {
    const uint32_t raw = (1u << 28) | uint32_t(rng.NextU64() & ((1u << 28) - 1));
    const double x = raw / double(1u << 28);
    const double got = Reciprocal<32, 1>(UFixedFromRaw<29, 1>(ap_uint<29>(raw))).to_double();
    max_ulp = std::max(max_ulp, std::fabs(got - 1.0 / x) / out_lsb);
  }
  EXPECT_LE(max_ulp, 0.5 + 1e-6) << max_ulp;
  // m ∈ [0.5, 1) in ufixed<32,0> → 1/m ∈ (1, 2] in ufixed<32,2> (the post-process's use).
  const double lsb30 = std::ldexp(1.0, -30);
  double max30 = 0;
  for (int t = 0; t < 200000; ++t) {
    const uint64_t raw = (1ull << 31) | (rng.NextU64() & ((1ull << 31) - 1));
    const double got = Reciprocal<32, 2>(UFixedFromRaw<32, 0>(ap_uint<32>(raw))).to_double();
    max30 = std::max(max30, std::fabs(got - std::ldexp(1.0, 32) / double(raw)) / lsb30);
  }
  EXPECT_LE(max30, 0.5 + 1e-6) << max30;
}

TEST(HwRandomFxMath, ReciprocalExhaustiveSmallFormat) {
  // ufixed<16,8> → ufixed<20,10>: every input; results beyond 2^10 saturate.
  const double in_lsb = 1.0 / 256, out_lsb = 1.0 / 1024, out_max = ((1 << 20) - 1) * out_lsb;
  double max_ulp = 0;
  for (uint32_t raw = 1; raw < (1u << 16); ++raw) {
    const double want = std::min(1.0 / (raw * in_lsb), out_max);
    const double got = Reciprocal<20, 10>(UFixedFromRaw<16, 8>(ap_uint<16>(raw))).to_double();
    max_ulp = std::max(max_ulp, std::fabs(got - want) / out_lsb);
  }
  EXPECT_LE(max_ulp, 0.5 + 1e-9) << max_ulp;
  EXPECT_EQ((Reciprocal<20, 10>(UFixedFromRaw<16, 8>(ap_uint<16>(0))).to_double()), out_max);
}

TEST(HwRandomFxMath, DivideRoundsToNearestAndSaturates) {
  // Weight-merger shape: inlier sum ufixed<24,16> / pixel count ufixed<16,16> → ufixed<18,1>.
  Rng rng(11);
  const double out_lsb = std::ldexp(1.0, -17), out_max = ((1 << 18) - 1) * out_lsb;
  double max_ulp = 0;
  for (int t = 0; t < 100000; ++t) {
    const uint32_t d = 1 + uint32_t(rng.UniformInt(40000));
    const uint32_t n_raw = uint32_t(rng.UniformInt(uint64_t(d) * 256 + 1));  // n ≤ d: quotient ≤ 1
    const double want = (n_raw / 256.0) / d;
    const double got =
        Divide<18, 1>(UFixedFromRaw<24, 16>(ap_uint<24>(n_raw)), UFixedFromRaw<16, 16>(ap_uint<16>(d))).to_double();
    max_ulp = std::max(max_ulp, std::fabs(got - want) / out_lsb);
  }
  EXPECT_LE(max_ulp, 0.5 + 1e-9) << max_ulp;
  // Division by zero and an overflowing quotient saturate to the maximum.
  EXPECT_EQ((Divide<18, 1>(UFixedFromRaw<24, 16>(ap_uint<24>(256)), UFixedFromRaw<16, 16>(ap_uint<16>(0))).to_double()),
            out_max);
  EXPECT_EQ((Divide<18, 1>(UFixedFromRaw<24, 16>(ap_uint<24>(256 * 500)), UFixedFromRaw<16, 16>(ap_uint<16>(2)))
                 .to_double()),
            out_max);
}

}  // namespace
}  // namespace posefilter::hw
