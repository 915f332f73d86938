// tests/hw/hls_types_vectors_test.cc — our own ap_int / ap_fixed / hls::stream (src/hw/hls_types/)
// against shared/hls/SEMANTICS.md and every vector of shared/hls/test_vectors.md (transcribed
// below with its source line, and re-read from POSEFILTER_SHARED_DIR when present).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "ap_fixed.h"
#include "ap_int.h"
#include "hls_stream.h"

#include "hls_test_model.h"

namespace {

using namespace hls_test;

// ---------------------------------------------------------------------------------------------
// Transcribed vectors (shared/hls/test_vectors.md; line numbers in comments)
// ---------------------------------------------------------------------------------------------

template <ap_q_mode Q>
std::pair<double, uint64_t> ToFixed84(double in) {
  ap_fixed<8, 4, Q, AP_WRAP> x(in);
  return {x.to_double(), Raw(x)};
}

struct QVector {
  int line;
  double in;
  ap_q_mode q;
  double value;
  uint64_t raw;
};

std::pair<double, uint64_t> ToFixed84Q(double in, ap_q_mode q) {
  switch (q) {
    case AP_RND: return ToFixed84<AP_RND>(in);
    case AP_RND_ZERO: return ToFixed84<AP_RND_ZERO>(in);
    case AP_RND_MIN_INF: return ToFixed84<AP_RND_MIN_INF>(in);
    case AP_RND_INF: return ToFixed84<AP_RND_INF>(in);
    case AP_RND_CONV: return ToFixed84<AP_RND_CONV>(in);
    case AP_TRN: return ToFixed84<AP_TRN>(in);
    case AP_TRN_ZERO: return ToFixed84<AP_TRN_ZERO>(in);
  }
  return {0, 0};
}

TEST(HlsVectors, A_DoubleToFixed84QuantizationModes) {
  const QVector kA[] = {
      {11, 1.0625, AP_TRN, 1.0625, 0x11},          {12, -1.0625, AP_TRN, -1.0625, 0xef},
      {13, 1.03125, AP_RND, 1.0625, 0x11},         {14, -1.03125, AP_RND, -1.0, 0xf0},
      {15, 1.03125, AP_RND_ZERO, 1.0, 0x10},       {16, -1.03125, AP_RND_ZERO, -1.0, 0xf0},
      {17, 1.03125, AP_RND_MIN_INF, 1.0, 0x10},    {18, -1.03125, AP_RND_MIN_INF, -1.0625, 0xef},
      {19, 1.03125, AP_RND_INF, 1.0625, 0x11},     {20, -1.03125, AP_RND_INF, -1.0625, 0xef},
      {21, 1.03125, AP_RND_CONV, 1.0, 0x10},       {22, 1.09375, AP_RND_CONV, 1.125, 0x12},
      {23, -1.03125, AP_RND_CONV, -1.0, 0xf0},     {24, -1.03125, AP_TRN_ZERO, -1.0, 0xf0},
      {25, 1.03125, AP_TRN_ZERO, 1.0, 0x10},
  };
  for (const QVector& v : kA) {
    const auto [value, raw] = ToFixed84Q(v.in, v.q);
    EXPECT_EQ(value, v.value) << "test_vectors.md line " << v.line;
    EXPECT_EQ(raw, v.raw) << "test_vectors.md line " << v.line;
  }
}

TEST(HlsVectors, A_Ug1399QuantizationModes) {
  // line 27-28: ap_fixed<3,2,Q,AP_SAT>
  EXPECT_EQ((ap_fixed<3, 2, AP_RND, AP_SAT>(1.25).to_double()), 1.5);
  EXPECT_EQ((ap_fixed<3, 2, AP_RND, AP_SAT>(-1.25).to_double()), -1.0);
  EXPECT_EQ((ap_fixed<3, 2, AP_RND_ZERO, AP_SAT>(1.25).to_double()), 1.0);
  EXPECT_EQ((ap_fixed<3, 2, AP_RND_ZERO, AP_SAT>(-1.25).to_double()), -1.0);
  EXPECT_EQ((ap_fixed<3, 2, AP_RND_MIN_INF, AP_SAT>(1.25).to_double()), 1.0);
  EXPECT_EQ((ap_fixed<3, 2, AP_RND_MIN_INF, AP_SAT>(-1.25).to_double()), -1.5);
}

TEST(HlsVectors, B_OverflowModes) {
  auto check = [](auto x, double value, int64_t raw, int line) {
    EXPECT_EQ(x.to_double(), value) << "test_vectors.md line " << line;
    if (raw >= 0) {
      EXPECT_EQ(Raw(x), static_cast<uint64_t>(raw)) << "test_vectors.md line " << line;
    }
  };
  check(ap_fixed<8, 4>(8.0), -8, 0x80, 33);
  check(ap_fixed<8, 4>(9.5), -6.5, 0x98, 34);
  check(ap_fixed<8, 4, AP_TRN, AP_SAT>(9.5), 7.9375, 0x7f, 35);
  check(ap_fixed<8, 4, AP_TRN, AP_SAT>(-9.5), -8, 0x80, 36);
  check(ap_fixed<8, 4, AP_TRN, AP_SAT_SYM>(-9.5), -7.9375, 0x81, 37);
  check(ap_fixed<8, 4, AP_TRN, AP_SAT_ZERO>(9.5), 0, 0x00, 38);
  check(ap_ufixed<8, 4>(-1.5), 14.5, 0xe8, 39);
  check(ap_ufixed<8, 4, AP_TRN, AP_SAT>(-1.5), 0, 0x00, 40);
  check(ap_ufixed<8, 4, AP_TRN, AP_SAT>(17.0), 15.9375, 0xff, 41);
  check(ap_fixed<8, 4, AP_RND, AP_SAT>(7.96875), 7.9375, 0x7f, 42);
  check(ap_fixed<8, 4, AP_RND, AP_WRAP>(7.96875), -8, 0x80, 43);
  check(ap_fixed<8, -2>(0.1), 0.099609375, 0x66, 44);
  check(ap_ufixed<8, 10>(1000.0), 1000, 0xfa, 45);
  check(ap_ufixed<18, 0>(0.999999), 0x3ffff / 262144.0, 0x3ffff, 46);  // printed 0.99999619
  EXPECT_NEAR((ap_ufixed<18, 0>(0.999999).to_double()), 0.99999619, 5e-9);  // line 46
  check(ap_ufixed<18, 0>(1.0), 0, 0x00000, 47);
  check(ap_ufixed<22, 9>(4938.0), 330, -1, 48);
  check(ap_ufixed<8, 4>(ap_fixed<8, 4>(-2.5)), 13.5, -1, 49);
  check(ap_ufixed<8, 4, AP_TRN, AP_SAT>(ap_fixed<8, 4>(-2.5)), 0, -1, 50);
  {  // line 51: 3.75 + 3.75 is exact in ap_fixed<7,4>; assigned back to <6,3> it wraps
    ap_fixed<6, 3> a(3.75);
    auto sum = a + a;
    static_assert(decltype(sum)::width == 7 && decltype(sum)::iwidth == 4);
    EXPECT_EQ(sum.to_double(), 7.5);
    a = sum;
    EXPECT_EQ(a.to_double(), -0.5);
  }
}

TEST(HlsModes, SatSymMakesTheSignedMinimumMinusMax) {
  // SEMANTICS.md §1 "SAT_SYM: signed minimum becomes -max", also without an overflow.
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN, AP_SAT_SYM>(-8.0).to_double()), -7.9375);
  EXPECT_EQ((ap_fixed<8, 4, AP_RND_INF, AP_SAT_SYM>(-7.96875).to_double()), -7.9375);
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN, AP_SAT_SYM>(-7.9375).to_double()), -7.9375);
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN, AP_SAT>(-8.0).to_double()), -8.0);
  EXPECT_EQ((ap_ufixed<8, 4, AP_TRN, AP_SAT_SYM>(-1.0).to_double()), 0.0);
  EXPECT_EQ((ap_ufixed<8, 4, AP_TRN, AP_SAT_SYM>(99.0).to_double()), 15.9375);
}

TEST(HlsModes, WrapWithSaturatedMsbs) {
  // AP_WRAP, N > 0 (SystemC semantics, differential-tested in hw_systemc_test): on overflow the
  // N MSBs saturate — signed: sign bit = source sign, the other N-1 = its inverse; unsigned:
  // ones upward, zeros downward — and the remaining bits wrap.
  EXPECT_EQ(Raw(ap_fixed<8, 4, AP_TRN, AP_WRAP, 1>(9.5)), 0x18u);   // 0x98 with sign 0
  EXPECT_EQ(Raw(ap_fixed<8, 4, AP_TRN, AP_WRAP, 2>(9.5)), 0x58u);   // bits 7..6 = 01
  EXPECT_EQ(Raw(ap_fixed<8, 4, AP_TRN, AP_WRAP, 2>(-9.5)), 0xa8u);  // -152 = ..0x68, bits = 10
  EXPECT_EQ(Raw(ap_ufixed<8, 4, AP_TRN, AP_WRAP, 2>(17.0)), 0xd0u);
  EXPECT_EQ(Raw(ap_ufixed<8, 4, AP_TRN, AP_WRAP, 2>(-1.5)), 0x28u);
  EXPECT_EQ(Raw(ap_fixed<8, 4, AP_TRN, AP_WRAP, 2>(7.5)), 0x78u);  // no overflow: unchanged
}

TEST(HlsVectors, B_Ug1399OverflowModes) {
  // lines 53-54
  EXPECT_EQ((ap_fixed<4, 4, AP_RND, AP_SAT>(19).to_int()), 7);
  EXPECT_EQ((ap_fixed<4, 4, AP_RND, AP_SAT>(-19).to_int()), -8);
  EXPECT_EQ((ap_ufixed<4, 4, AP_RND, AP_SAT>(19).to_int()), 15);
  EXPECT_EQ((ap_ufixed<4, 4, AP_RND, AP_SAT>(-19).to_int()), 0);
  EXPECT_EQ((ap_fixed<4, 4, AP_RND, AP_SAT_ZERO>(19).to_int()), 0);
  EXPECT_EQ((ap_fixed<4, 4, AP_RND, AP_SAT_ZERO>(-19).to_int()), 0);
  EXPECT_EQ((ap_ufixed<4, 4, AP_RND, AP_SAT_ZERO>(19).to_int()), 0);
  EXPECT_EQ((ap_ufixed<4, 4, AP_RND, AP_SAT_ZERO>(-19).to_int()), 0);
  EXPECT_EQ((ap_fixed<4, 4, AP_RND, AP_SAT_SYM>(19).to_int()), 7);
  EXPECT_EQ((ap_fixed<4, 4, AP_RND, AP_SAT_SYM>(-19).to_int()), -7);
}

template <class T, int W, int I, bool S>
void ExpectType(const T&, int line) {
  EXPECT_EQ(T::width, W) << "test_vectors.md line " << line;
  EXPECT_EQ(T::iwidth, I) << "test_vectors.md line " << line;
  EXPECT_EQ(T::sign_flag, S) << "test_vectors.md line " << line;
}

TEST(HlsVectors, C_ResultTypesOfFixedArithmetic) {
  const ap_fixed<8, 4> a(3.5);
  const ap_ufixed<6, 2> b(1.75);
  auto m = a * b;  // line 59
  ExpectType<decltype(m), 14, 6, true>(m, 59);
  EXPECT_EQ(m.to_double(), 6.125);
  auto p = a + b;  // line 60
  ExpectType<decltype(p), 9, 5, true>(p, 60);
  EXPECT_EQ(p.to_double(), 5.25);
  auto s = a - b;  // line 61
  ExpectType<decltype(s), 9, 5, true>(s, 61);
  EXPECT_EQ(s.to_double(), 1.75);
  auto d = a / b;  // line 62
  ExpectType<decltype(d), 12, 8, true>(d, 62);
  EXPECT_EQ(d.to_double(), 2.0);
  auto n = -b;  // line 63
  ExpectType<decltype(n), 7, 3, true>(n, 63);
  EXPECT_EQ(n.to_double(), -1.75);
  auto t = a * 3;  // line 64
  ExpectType<decltype(t), 40, 36, true>(t, 64);
  EXPECT_EQ(t.to_double(), 10.5);
  const ap_ufixed<13, 3> u1(1.5), u2(2.25);
  auto diff = u1 - u2;  // line 65
  ExpectType<decltype(diff), 14, 4, true>(diff, 65);
  EXPECT_EQ(diff.to_double(), -0.75);
  auto prod = diff * ap_ufixed<18, 0>(0.5);  // line 66
  ExpectType<decltype(prod), 32, 4, true>(prod, 66);
  EXPECT_EQ(prod.to_double(), -0.375);
  auto q1 = ap_fixed<8, 4>(-1) / ap_fixed<8, 4>(3);  // line 67
  ExpectType<decltype(q1), 13, 9, true>(q1, 67);
  EXPECT_EQ(q1.to_double(), -0.3125);
  auto q2 = ap_fixed<8, 4>(1) / ap_fixed<8, 4>(3);  // line 68
  ExpectType<decltype(q2), 13, 9, true>(q2, 68);
  EXPECT_EQ(q2.to_double(), 0.3125);
  auto q3 = ap_ufixed<2, 1>(1) / ap_ufixed<22, 9>(3.0);  // line 69
  ExpectType<decltype(q3), 15, 14, false>(q3, 69);
  EXPECT_EQ(q3.to_double(), 0.0);
  auto q4 = ap_ufixed<16, 0>(40000 / 65536.0) / ap_ufixed<16, 0>(50000 / 65536.0);  // line 70
  ExpectType<decltype(q4), 32, 16, false>(q4, 70);
  EXPECT_NEAR(q4.to_double(), 0.799987793, 5e-10);
  EXPECT_EQ(Raw(q4), 52428u);  // trunc(40000·2^16 / 50000)
}

TEST(HlsVectors, C_ResultTypesOfIntegerArithmetic) {
  auto s1 = ap_uint<8>(200) + ap_uint<8>(100);  // line 71
  static_assert(decltype(s1)::width == 9 && !decltype(s1)::sign_flag);
  EXPECT_EQ(s1.to_int(), 300);
  auto d1 = ap_uint<8>(100) - ap_uint<8>(200);  // line 72
  static_assert(decltype(d1)::width == 9 && decltype(d1)::sign_flag);
  EXPECT_EQ(d1.to_int(), -100);
  EXPECT_FALSE(ap_uint<5>(3) - ap_uint<5>(4) >= 1);  // line 73
  ap_uint<5> w = ap_uint<5>(3) - ap_uint<5>(4);       // line 74
  EXPECT_EQ(w.to_int(), 31);
  auto q = ap_uint<16>(1000) / ap_uint<12>(3);  // line 75
  static_assert(decltype(q)::width == 16 && !decltype(q)::sign_flag);
  EXPECT_EQ(q.to_int(), 333);
  auto q2 = ap_int<8>(-7) / ap_int<8>(2);  // line 76
  static_assert(decltype(q2)::width == 9);
  EXPECT_EQ(q2.to_int(), -3);
  EXPECT_EQ((ap_int<8>(-7) % ap_int<8>(2)).to_int(), -1);
  ap_ufixed<4, 2> u(3.75);  // line 77
  ap_ufixed<4, 2> old = u++;
  EXPECT_EQ(old.to_double(), 3.75);
  EXPECT_EQ(u.to_double(), 0.75);
  auto neg = -(ap_fixed<6, 3>(-4));  // line 78
  static_assert(decltype(neg)::width == 7 && decltype(neg)::iwidth == 4);
  EXPECT_EQ(neg.to_double(), 4.0);
  ap_fixed<6, 3> back = neg;
  EXPECT_EQ(back.to_double(), -4.0);
}

TEST(HlsVectors, C_RulesForLogicAndCIntegerOperands) {
  // lines 80-83: logic ops as plus without +1; int -> 32 bits signed, bool -> 1 bit unsigned.
  auto l = ap_fixed<8, 4>(3.5) & ap_ufixed<6, 2>(1.75);
  static_assert(decltype(l)::width == 8 && decltype(l)::iwidth == 4 && decltype(l)::sign_flag);
  EXPECT_EQ(l.to_double(), 1.5);  // 0011.1000 & 0001.1100
  auto li = ap_int<5>(-3) | ap_uint<6>(8);
  static_assert(decltype(li)::width == 7 && decltype(li)::sign_flag);
  EXPECT_EQ(li.to_int(), -3);
  auto bi = ap_uint<3>(5) + true;
  static_assert(decltype(bi)::width == 4 && !decltype(bi)::sign_flag);
  EXPECT_EQ(bi.to_int(), 6);
  auto ii = ap_uint<3>(5) * 2;
  static_assert(decltype(ii)::width == 35 && decltype(ii)::sign_flag);
  auto mo = ap_uint<8>(200) % ap_int<4>(7);
  static_assert(decltype(mo)::width == 4 && !decltype(mo)::sign_flag);
  EXPECT_EQ(mo.to_int(), 4);
}

TEST(HlsVectors, D_ShiftsBitsRangesConcat) {
  auto s1 = ap_fixed<8, 4>(3.5) << 2;  // line 90
  static_assert(std::is_same_v<decltype(s1), ap_fixed<8, 4>>);
  EXPECT_EQ(s1.to_double(), -2.0);
  EXPECT_EQ(Raw(s1), 0xe0u);
  EXPECT_EQ((ap_fixed<8, 4>(-3.5) >> 1).to_double(), -1.75);   // line 91
  EXPECT_EQ((ap_fixed<8, 4>(-3.25) >> 1).to_double(), -1.625);  // line 92
  EXPECT_EQ((ap_uint<8>(0x81) << 1).to_int(), 2);               // line 93
  // line 94: negative signed amount shifts the other way
  EXPECT_EQ((ap_uint<8>(0x10) << -2).to_int(), 4);
  EXPECT_EQ((ap_uint<8>(0x10) >> -2).to_int(), 0x40);
  EXPECT_EQ((ap_fixed<8, 4>(1.5) << -1).to_double(), 0.75);
  EXPECT_EQ((ap_fixed<8, 4>(1.5) >> ap_int<4>(-1)).to_double(), 3.0);
  EXPECT_EQ((ap_uint<8>(0x10) << ap_uint<4>(15)).to_int(), 0);  // unsigned amount never reverses
  const ap_fixed<8, 4> g(2.75);  // line 95
  EXPECT_TRUE(g.get_bit(-1));
  EXPECT_FALSE(g.get_bit(0));
  EXPECT_FALSE(g[0]);
  EXPECT_TRUE(g[3]);
  const ap_uint<18> r(0x2ABCD);
  EXPECT_EQ(r.range(7, 0).to_uint64(), 0xcdu);              // line 96
  EXPECT_EQ(r.range(0, 7).to_uint64(), 0xb3u);              // line 97
  EXPECT_EQ(ap_uint<8>(0xB4).range(0, 7).to_uint64(), 0x2du);  // line 98
  const ap_uint<5> a(31);                                   // line 99
  const ap_uint<13> b(6299);
  auto c = a.concat(b);
  static_assert(decltype(c)::width == 18 && !decltype(c)::sign_flag);
  EXPECT_EQ(c.to_uint64(), 0x3f89bu);
  EXPECT_EQ(ap_uint<18>((a, b)).to_uint64(), 0x3f89bu);
  ap_uint<18> viaRange;
  viaRange.range(17, 13) = a;
  viaRange.range(12, 0) = b;
  EXPECT_EQ(viaRange.to_uint64(), 0x3f89bu);
  ap_fixed<15, 1> raw_load;  // line 100
  raw_load.range() = 0x4001;
  EXPECT_NEAR(raw_load.to_double(), -0.99993896, 5e-9);
  EXPECT_EQ(raw_load.to_double(), (0x4001 - 32768) / 16384.0);
  const auto full = FromRaw<ap_ufixed<18, 0>>(0x3ffff);  // line 101
  EXPECT_NEAR(full.to_double(), 0.9999961853, 5e-11);
  EXPECT_FALSE((FromRaw<ap_ufixed<18, 0>>(131071) >= ap_ufixed<16, 0>(0.5)));  // line 102
  EXPECT_TRUE((FromRaw<ap_ufixed<18, 0>>(131072) >= ap_ufixed<16, 0>(0.5)));
  EXPECT_FALSE(ap_uint<8>(0).or_reduce());       // line 103
  EXPECT_TRUE(ap_uint<18>(0x3ffff).and_reduce());
  EXPECT_TRUE(ap_uint<4>(0b1011).xor_reduce());
  EXPECT_EQ(ap_uint<6>(ap_int<6>(-5)).to_int(), 59);  // line 104
  EXPECT_EQ(ap_int<10>(ap_int<6>(-5)).to_int(), -5);
  EXPECT_EQ(ap_int<10>(ap_uint<6>(59)).to_int(), 59);
}

TEST(HlsVectors, E_ConversionsToIntegers) {
  const ap_fixed<8, 4> x(-7.5);  // line 109
  EXPECT_EQ(ap_int<8>(x).to_int(), -7);
  EXPECT_EQ(static_cast<int>(x), -7);
  EXPECT_EQ(x.to_int(), -7);
  EXPECT_EQ((ap_fixed<8, 8>(x).to_int()), -8);  // line 110
  EXPECT_EQ(ap_int<8>(-2.7).to_int(), -2);      // line 111
  EXPECT_EQ(ap_int<8>(300.0).to_int(), 44);     // line 112
  // line 113: the 2019.1 header gives +1 for ap_int<8>(-0.1); ours truncates toward zero for
  // every value (documented deviation: never convert double to ap_int in kernels).
  EXPECT_EQ(ap_int<8>(-0.1).to_int(), 0);
  EXPECT_EQ(ap_int<8>(-0.2).to_int(), 0);
}

TEST(HlsVectors, F_ThesisLfsr18) {
  // line 116: new = bit0 ^ bit7; x >>= 1; x[17] = new
  ap_uint<18> x = 0x2ABCD;
  const uint64_t expect[] = {0x155e6, 0x2aaf3, 0x15579, 0x2aabc, 0x3555e};
  auto step = [](ap_uint<18>& s) {
    const bool nb = s[0] ^ s[7];
    s >>= 1;
    s[17] = nb;
  };
  for (uint64_t e : expect) {
    step(x);
    EXPECT_EQ(x.to_uint64(), e);
  }
  ap_uint<18> y = 0x2ABCD;
  int period = 0;
  do {
    step(y);
    ++period;
  } while (y != 0x2ABCD && period < 300000);
  EXPECT_EQ(period, 262143);
}

TEST(HlsVectors, F_ThesisLfsr15AndAngles) {
  // lines 117-118
  ap_uint<15> x = 0x1234;
  const uint64_t expect[] = {0x091a, 0x448d, 0x6246};
  const double as_fixed[] = {0.14221191, -0.92889404, -0.46447754};
  const double angles[] = {0.4453125, -2.91796875, -1.4609375};
  const ap_fixed<12, 4> pi(3.14159265359);
  EXPECT_EQ(pi.to_double(), 3.140625);
  auto step = [](ap_uint<15>& s) {
    const bool nb = s[0] ^ s[1];
    s >>= 1;
    s[14] = nb;
  };
  for (int i = 0; i < 3; ++i) {
    step(x);
    EXPECT_EQ(x.to_uint64(), expect[i]);
    ap_fixed<15, 1> r;
    r.range() = x;
    EXPECT_NEAR(r.to_double(), as_fixed[i], 5e-9);
    ap_fixed<12, 4> angle = r * pi;
    EXPECT_EQ(angle.to_double(), angles[i]);
  }
  ap_uint<15> y = 0x1234;
  int period = 0;
  do {
    step(y);
    ++period;
  } while (y != 0x1234 && period < 40000);
  EXPECT_EQ(period, 32767);
}

TEST(HlsVectors, F_ThesisAccumulatorAndSampling) {
  // line 119: each += truncates to 8 fractional bits
  ap_ufixed<22, 14> acc = 0;
  const ap_ufixed<16, 0> v(65535 / 65536.0);
  for (int i = 0; i < 6300; ++i) acc += v;
  EXPECT_EQ(acc.to_double(), 6275.390625);
  EXPECT_EQ(Raw(acc), 0x188364u);
  ap_ufixed<30, 13> lossless = 0;
  for (int i = 0; i < 6300; ++i) lossless += v;
  EXPECT_EQ(lossless.to_double(), 6300 * (65535 / 65536.0));
  // line 120
  const ap_ufixed<13, 3> zmin(0.5), zmax(1.5);
  const auto rand01 = FromRaw<ap_ufixed<18, 0>>(200000);
  ap_fixed<21, 4> z = zmin + (zmax - zmin) * rand01;
  EXPECT_NEAR(z.to_double(), 1.262939453, 5e-10);
  // line 121
  const ap_ufixed<12, 2> dz(0.005);
  EXPECT_EQ(dz.to_double(), 0.0048828125);
  auto shifted = dz << 7;
  static_assert(std::is_same_v<decltype(shifted), ap_ufixed<12, 2>>);
  EXPECT_EQ((1 - shifted).to_double(), 0.375);
}

TEST(HlsVectors, G_StreamCsimModel) {
  // lines 124-126 (ours aborts on a blocking read of an empty stream: see HlsStream tests)
  hls::stream<int> s("g");
  EXPECT_TRUE(s.empty());
  EXPECT_FALSE(s.full());
  int out = 42;
  EXPECT_FALSE(s.read_nb(out));
  EXPECT_EQ(out, 0);  // default T
  for (int i = 0; i < 10000; ++i) ASSERT_TRUE(s.write_nb(i));  // unbounded
  EXPECT_FALSE(s.full());
  EXPECT_EQ(s.size(), 10000u);
  for (int i = 0; i < 10000; ++i) {
    int v;
    s >> v;
    ASSERT_EQ(v, i);
  }
  EXPECT_TRUE(s.empty());
  static_assert(!std::is_copy_constructible_v<hls::stream<int>>);
  static_assert(!std::is_copy_assignable_v<hls::stream<int>>);
}

// ---------------------------------------------------------------------------------------------
// Runtime re-read of test_vectors.md tables A and B (numeric rows), skipped without shared/.
// ---------------------------------------------------------------------------------------------

std::vector<std::string> SplitRow(const std::string& line) {
  std::vector<std::string> cells;
  std::string cur;
  for (size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|') {
      const size_t b = cur.find_first_not_of(' '), e = cur.find_last_not_of(' ');
      cells.push_back(b == std::string::npos ? "" : cur.substr(b, e - b + 1));
      cur.clear();
    } else {
      cur += line[i];
    }
  }
  return cells;
}

bool ParseNumber(const std::string& s, double* v, int* decimals) {
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  if (end == s.c_str()) return false;
  const std::string num(s.c_str(), static_cast<size_t>(end - s.c_str()));
  const size_t dot = num.find('.');
  *decimals = dot == std::string::npos ? 0 : static_cast<int>(num.size() - dot - 1);
  return true;
}

template <class T>
std::function<std::pair<double, uint64_t>(double)> Conv() {
  return [](double in) {
    T x(in);
    return std::make_pair(x.to_double(), Raw(x));
  };
}

TEST(HlsVectors, ParsedFromSharedMarkdown) {
  const std::filesystem::path path =
      std::filesystem::path(POSEFILTER_SHARED_DIR) / "hls" / "test_vectors.md";
  if (!std::filesystem::exists(POSEFILTER_SHARED_DIR)) GTEST_SKIP() << "no shared dir";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;  // shared/ exists, so the vectors must too
  const std::map<std::string, ap_q_mode> qmodes = {
      {"AP_RND", AP_RND}, {"AP_RND_ZERO", AP_RND_ZERO}, {"AP_RND_MIN_INF", AP_RND_MIN_INF},
      {"AP_RND_INF", AP_RND_INF}, {"AP_RND_CONV", AP_RND_CONV}, {"AP_TRN", AP_TRN},
      {"AP_TRN_ZERO", AP_TRN_ZERO}};
  const std::map<std::string, std::function<std::pair<double, uint64_t>(double)>> targets = {
      {"ap_fixed<8,4> (WRAP)", Conv<ap_fixed<8, 4>>()},
      {"ap_fixed<8,4,AP_TRN,AP_SAT>", Conv<ap_fixed<8, 4, AP_TRN, AP_SAT>>()},
      {"ap_fixed<8,4,AP_TRN,AP_SAT_SYM>", Conv<ap_fixed<8, 4, AP_TRN, AP_SAT_SYM>>()},
      {"ap_fixed<8,4,AP_TRN,AP_SAT_ZERO>", Conv<ap_fixed<8, 4, AP_TRN, AP_SAT_ZERO>>()},
      {"ap_ufixed<8,4> (WRAP)", Conv<ap_ufixed<8, 4>>()},
      {"ap_ufixed<8,4,AP_TRN,AP_SAT>", Conv<ap_ufixed<8, 4, AP_TRN, AP_SAT>>()},
      {"ap_fixed<8,4,AP_RND,AP_SAT>", Conv<ap_fixed<8, 4, AP_RND, AP_SAT>>()},
      {"ap_fixed<8,4,AP_RND,AP_WRAP>", Conv<ap_fixed<8, 4, AP_RND, AP_WRAP>>()},
      {"ap_fixed<8,-2>", Conv<ap_fixed<8, -2>>()},
      {"ap_ufixed<8,10>", Conv<ap_ufixed<8, 10>>()},
      {"ap_ufixed<18,0>", Conv<ap_ufixed<18, 0>>()},
      {"ap_ufixed<22,9>", Conv<ap_ufixed<22, 9>>()},
  };
  std::string line;
  int lineno = 0, section = 0, checked_a = 0, checked_b = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.rfind("## A.", 0) == 0) section = 1;
    if (line.rfind("## B.", 0) == 0) section = 2;
    if (line.rfind("## C.", 0) == 0) section = 3;
    if (line.empty() || line[0] != '|' || section == 0 || section == 3) continue;
    const std::vector<std::string> c = SplitRow(line);
    if (c.size() < 4) continue;
    double value = 0, input = 0;
    int vdec = 0, idec = 0;
    std::pair<double, uint64_t> got;
    if (section == 1) {
      if (!qmodes.count(c[1]) || !ParseNumber(c[0], &input, &idec) || !ParseNumber(c[2], &value, &vdec)) continue;
      got = ToFixed84Q(input, qmodes.at(c[1]));
      ++checked_a;
    } else {
      if (!targets.count(c[0]) || !ParseNumber(c[1], &input, &idec) || !ParseNumber(c[2], &value, &vdec)) continue;
      got = targets.at(c[0])(input);
      ++checked_b;
    }
    EXPECT_NEAR(got.first, value, 0.5 * std::pow(10.0, -vdec) + 1e-15) << "test_vectors.md line " << lineno;
    if (c[3].rfind("0x", 0) == 0) {
      EXPECT_EQ(got.second, std::stoull(c[3], nullptr, 16)) << "test_vectors.md line " << lineno;
    }
  }
  EXPECT_EQ(checked_a, 15);
  EXPECT_EQ(checked_b, 16);
}

}  // namespace
