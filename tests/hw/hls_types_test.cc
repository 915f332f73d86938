// tests/hw/hls_types_test.cc — our own ap_int / ap_fixed / hls::stream (src/hw/hls_types/)
// against shared/hls/SEMANTICS.md and every vector of shared/hls/test_vectors.md (transcribed
// below with its source line, and re-read from POSEFILTER_SHARED_DIR when present), plus
// exhaustive small-width checks against an exact rational model written independently here
// (int64 numerators over powers of two; rounding rules from the modes' definitions).
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

namespace {

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

// Raw W-bit word of any ap value (low 64 bits), through the public API.
template <class T>
uint64_t Raw(const T& x) {
  return x.range().to_uint64();
}

// Raw word as a signed/unsigned integer value (W <= 63).
template <class T>
int64_t RawValue(const T& x) {
  const uint64_t r = Raw(x);
  constexpr int W = T::width;
  if constexpr (T::sign_flag) {
    const int sh = 64 - W;
    return static_cast<int64_t>(r << sh) >> sh;
  } else {
    return static_cast<int64_t>(r);
  }
}

// Load raw bits into a fixed/int type.
template <class T>
T FromRaw(uint64_t raw) {
  T x;
  x.range() = raw;
  return x;
}

// ---- exact model: value = n · 2^-f (n int64) ----
int64_t FloorDiv(int64_t a, int64_t b) {  // b > 0
  int64_t q = a / b;
  if ((a % b) != 0 && a < 0) --q;
  return q;
}

// Quantize n·2^-k (drop k >= 0 bits) to an integer with mode q, from the modes' definitions:
// truncations go to floor / toward zero; roundings go to the nearest integer and differ only in
// where an exact tie goes (+inf, zero, -inf, away from zero, even).
int64_t RefQuantize(int64_t n, int k, ap_q_mode q) {
  if (k <= 0) return n * (int64_t{1} << -k);
  const int64_t d = int64_t{1} << k;
  const int64_t fl = FloorDiv(n, d);
  const int64_t rem = n - fl * d;  // 0 <= rem < d
  const int64_t twice = 2 * rem;
  const bool above = twice > d, tie = twice == d;
  switch (q) {
    case AP_TRN: return fl;
    case AP_TRN_ZERO: return (n < 0 && rem != 0) ? fl + 1 : fl;
    case AP_RND: return (above || tie) ? fl + 1 : fl;
    case AP_RND_ZERO: return (above || (tie && n < 0)) ? fl + 1 : fl;
    case AP_RND_MIN_INF: return above ? fl + 1 : fl;
    case AP_RND_INF: return (above || (tie && n >= 0)) ? fl + 1 : fl;
    case AP_RND_CONV: return (above || (tie && (fl & 1) != 0)) ? fl + 1 : fl;
  }
  return fl;
}

// Overflow of integer q into a W-bit signed/unsigned word (N = 0).
int64_t RefOverflow(int64_t q, int W, bool S, ap_o_mode o) {
  const int64_t lo = S ? -(int64_t{1} << (W - 1)) : 0;
  const int64_t hi = S ? (int64_t{1} << (W - 1)) - 1 : (int64_t{1} << W) - 1;
  if (q > lo && q <= hi) return q;
  if (q == lo) return (o == AP_SAT_SYM && S) ? -hi : q;  // symmetric range: min becomes -max
  switch (o) {
    case AP_SAT: return q < lo ? lo : hi;
    case AP_SAT_ZERO: return 0;
    case AP_SAT_SYM: return q < lo ? (S ? -hi : 0) : hi;
    default: {  // AP_WRAP: q mod 2^W into [lo, hi]
      const int64_t m = int64_t{1} << W;
      int64_t r = ((q % m) + m) % m;
      if (S && r > hi) r -= m;
      return r;
    }
  }
}

// Exact rational equality a·2^-fa == b·2^-fb for small values.
bool RatEq(int64_t a, int fa, int64_t b, int fb) {
  const int f = std::max(fa, fb);
  return a * (int64_t{1} << (f - fa)) == b * (int64_t{1} << (f - fb));
}
int RatCmp(int64_t a, int fa, int64_t b, int fb) {
  const int f = std::max(fa, fb);
  const int64_t x = a * (int64_t{1} << (f - fa)), y = b * (int64_t{1} << (f - fb));
  return (x > y) - (x < y);
}

template <int... Is, class F>
void ForEach(std::integer_sequence<int, Is...>, F&& f) {
  (f(std::integral_constant<int, Is>{}), ...);
}

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

// ---------------------------------------------------------------------------------------------
// Exhaustive small widths against the exact model
// ---------------------------------------------------------------------------------------------

// All raw values of a <Ws,Is,Ss> source converted to <W,I,S,Q,O>, directly and via double.
template <int Ws, int Is, bool Ss, int W, int I, bool S, ap_q_mode Q, ap_o_mode O>
int CountConversionMismatches() {
  using Src = ap_fixed_base<Ws, Is, Ss>;
  using Dst = ap_fixed_base<W, I, S, Q, O>;
  int bad = 0;
  for (uint64_t raw = 0; raw < (uint64_t{1} << Ws); ++raw) {
    const Src src = FromRaw<Src>(raw);
    const int64_t n = RawValue(src);
    const int64_t expect = RefOverflow(RefQuantize(n, (Ws - Is) - (W - I), Q), W, S, O);
    const Dst direct = src;
    const Dst via_double(src.to_double());
    Dst assigned;
    assigned = src;
    if (RawValue(direct) != expect || RawValue(via_double) != expect || RawValue(assigned) != expect) {
      if (bad < 3) {
        ADD_FAILURE() << "<" << Ws << "," << Is << "," << Ss << "> raw " << raw << " -> <" << W << ","
                      << I << "," << S << ",Q" << Q << ",O" << O << ">: got " << RawValue(direct)
                      << "/" << RawValue(via_double) << ", expected " << expect;
      }
      ++bad;
    }
  }
  return bad;
}

template <int Ws, int Is, bool Ss, int W, int I, bool S>
int AllModesFrom() {
  int bad = 0;
  ForEach(std::make_integer_sequence<int, 7>{}, [&](auto q) {
    ForEach(std::make_integer_sequence<int, 4>{}, [&](auto o) {
      bad += CountConversionMismatches<Ws, Is, Ss, W, I, S, static_cast<ap_q_mode>(q.value),
                                       static_cast<ap_o_mode>(o.value)>();
    });
  });
  return bad;
}

template <bool Ss>
int AllTargetsFrom() {
  // Source <10,4> (F = 6) is finer than every target below; targets W <= 6, F from -2 to 6.
  int bad = 0;
  bad += AllModesFrom<10, 4, Ss, 1, 1, true>() + AllModesFrom<10, 4, Ss, 1, 1, false>();
  bad += AllModesFrom<10, 4, Ss, 2, 1, true>() + AllModesFrom<10, 4, Ss, 2, 0, false>();
  bad += AllModesFrom<10, 4, Ss, 3, 3, true>() + AllModesFrom<10, 4, Ss, 3, 5, false>();
  bad += AllModesFrom<10, 4, Ss, 4, 2, true>() + AllModesFrom<10, 4, Ss, 4, 2, false>();
  bad += AllModesFrom<10, 4, Ss, 5, -1, true>() + AllModesFrom<10, 4, Ss, 5, 1, false>();
  bad += AllModesFrom<10, 4, Ss, 6, 3, true>() + AllModesFrom<10, 4, Ss, 6, 0, false>();
  bad += AllModesFrom<10, 4, Ss, 6, 8, true>() + AllModesFrom<10, 4, Ss, 5, 4, false>();
  return bad;
}

TEST(HlsExhaustive, ConversionEveryQuantizationAndOverflowMode) {
  EXPECT_EQ(AllTargetsFrom<true>(), 0);
  EXPECT_EQ(AllTargetsFrom<false>(), 0);
}

TEST(HlsExhaustive, ConversionFromCoarserTypeShiftsLeft) {
  // Source F = 1 to targets with more fraction bits: exact unless the integer part overflows.
  EXPECT_EQ((AllModesFrom<6, 5, true, 6, 2, true>()), 0);
  EXPECT_EQ((AllModesFrom<6, 5, true, 5, 1, false>()), 0);
  EXPECT_EQ((AllModesFrom<6, 5, false, 4, -1, true>()), 0);
}

// Binary ops: result type per SEMANTICS.md and the exact value.
template <class A, class B>
void CheckFixedPair() {
  constexpr int W1 = A::width, I1 = A::iwidth, W2 = B::width, I2 = B::iwidth;
  constexpr bool S1 = A::sign_flag, S2 = B::sign_flag;
  constexpr int F1 = W1 - I1, F2 = W2 - I2;
  using Sum = decltype(A() + B());
  using Dif = decltype(A() - B());
  using Mul = decltype(A() * B());
  using Div = decltype(A() / B());
  constexpr int ip = std::max(I1 + (S2 && !S1), I2 + (S1 && !S2)) + 1;
  static_assert(Sum::iwidth == ip && Sum::width == ip + std::max(F1, F2) && Sum::sign_flag == (S1 || S2));
  static_assert(Dif::iwidth == ip && Dif::width == ip + std::max(F1, F2) && Dif::sign_flag);
  static_assert(Mul::width == W1 + W2 && Mul::iwidth == I1 + I2 && Mul::sign_flag == (S1 || S2));
  static_assert(Div::width == S2 + W1 + std::max(F2, 0) && Div::iwidth == S2 + I1 + F2);
  int bad = 0;
  for (uint64_t ra = 0; ra < (uint64_t{1} << W1); ++ra) {
    for (uint64_t rb = 0; rb < (uint64_t{1} << W2); ++rb) {
      const A a = FromRaw<A>(ra);
      const B b = FromRaw<B>(rb);
      const int64_t na = RawValue(a), nb = RawValue(b);
      const int F = std::max(F1, F2);
      const int64_t sa = na * (int64_t{1} << (F - F1)), sb = nb * (int64_t{1} << (F - F2));
      bool ok = RatEq(RawValue(a + b), Sum::width - Sum::iwidth, sa + sb, F) &&
                RatEq(RawValue(a - b), Dif::width - Dif::iwidth, sa - sb, F) &&
                RatEq(RawValue(a * b), Mul::width - Mul::iwidth, na * nb, F1 + F2);
      const int c = RatCmp(na, F1, nb, F2);
      ok = ok && ((a < b) == (c < 0)) && ((a <= b) == (c <= 0)) && ((a > b) == (c > 0)) &&
           ((a >= b) == (c >= 0)) && ((a == b) == (c == 0)) && ((a != b) == (c != 0));
      if (nb != 0) {
        // Quotient raw = trunc(exact quotient · 2^Fr), with C's truncating division.
        constexpr int Fr = Div::width - Div::iwidth;
        const int e = F2 + Fr - F1;  // >= 0 for these pairs
        const int64_t q = (na * (int64_t{1} << e)) / nb;
        ok = ok && RawValue(a / b) == q;
      }
      // Compound assignment quantizes the exact sum/product into a's type.
      A acc = a;
      acc += b;
      const int64_t exp_add = RefOverflow(RefQuantize(sa + sb, F - F1, A::qmode), W1, S1, A::omode);
      A accm = a;
      accm *= b;
      const int64_t exp_mul = RefOverflow(RefQuantize(na * nb, F2, A::qmode), W1, S1, A::omode);
      ok = ok && RawValue(acc) == exp_add && RawValue(accm) == exp_mul;
      if (!ok && ++bad <= 3) {
        ADD_FAILURE() << "raw a=" << ra << " b=" << rb << " (values " << a.to_double() << ", "
                      << b.to_double() << ")";
      }
    }
  }
  EXPECT_EQ(bad, 0);
}

TEST(HlsExhaustive, FixedArithmeticAndComparisons) {
  CheckFixedPair<ap_fixed<5, 2>, ap_ufixed<4, 3>>();
  CheckFixedPair<ap_ufixed<6, 1, AP_RND_CONV, AP_SAT>, ap_fixed<5, 2>>();
  CheckFixedPair<ap_fixed<6, 6, AP_RND, AP_SAT_SYM>, ap_fixed<4, 1>>();
  CheckFixedPair<ap_ufixed<5, 7, AP_TRN_ZERO, AP_SAT_ZERO>, ap_fixed<6, 2>>();
  CheckFixedPair<ap_fixed<5, -1, AP_RND_INF, AP_WRAP>, ap_ufixed<3, 0>>();
  CheckFixedPair<ap_fixed<4, 2, AP_RND_MIN_INF, AP_SAT>, ap_fixed<6, 3>>();
}

template <int W1, bool S1, int W2, bool S2>
void CheckIntPair() {
  using A = ap_int_base<W1, S1>;
  using B = ap_int_base<W2, S2>;
  int bad = 0;
  for (uint64_t ra = 0; ra < (uint64_t{1} << W1); ++ra) {
    for (uint64_t rb = 0; rb < (uint64_t{1} << W2); ++rb) {
      const A a = FromRaw<A>(ra);
      const B b = FromRaw<B>(rb);
      const int64_t x = RawValue(a), y = RawValue(b);
      bool ok = RawValue(a + b) == x + y && RawValue(a - b) == x - y && RawValue(a * b) == x * y &&
                RawValue(a & b) == (x & y) && RawValue(a | b) == (x | y) && RawValue(a ^ b) == (x ^ y);
      ok = ok && (a < b) == (x < y) && (a == b) == (x == y) && (a >= b) == (x >= y);
      ok = ok && (a < static_cast<int>(y)) == (x < y) && (static_cast<int>(x) > b) == (x > y);
      if (y != 0) {
        ok = ok && RawValue(a / b) == x / y && RawValue(a % b) == x % y;
      }
      for (int sh = -W1 - 2; sh <= W1 + 2; ++sh) {
        // Reference: shift the W1-bit word, keep W1 bits (left) / sign-fill (right).
        const int64_t m = (int64_t{1} << W1) - 1;
        int64_t l, r;
        if (sh >= 0) {
          l = sh >= W1 ? 0 : ((x << sh) & m);
          r = sh >= W1 ? (x < 0 ? m : 0) : ((x >> sh) & m);
        } else {
          r = -sh >= W1 ? 0 : ((x << -sh) & m);
          l = -sh >= W1 ? (x < 0 ? m : 0) : ((x >> -sh) & m);
        }
        ok = ok && Raw(a << sh) == static_cast<uint64_t>(l) && Raw(a >> sh) == static_cast<uint64_t>(r);
      }
      // Compound assignment wraps into a's width.
      A c = a;
      c += b;
      ok = ok && Raw(c) == (static_cast<uint64_t>(x + y) & ((uint64_t{1} << W1) - 1));
      if (!ok && ++bad <= 3) ADD_FAILURE() << "a=" << x << " b=" << y;
    }
  }
  EXPECT_EQ(bad, 0);
}

TEST(HlsExhaustive, IntegerArithmeticShiftsAndComparisons) {
  static_assert(decltype(ap_int<5>() / ap_uint<4>())::width == 5);
  static_assert(decltype(ap_uint<4>() / ap_int<5>())::width == 5);
  static_assert(decltype(ap_int<5>() % ap_uint<4>())::width == 5);
  static_assert(decltype(ap_uint<6>() % ap_int<3>())::width == 3);
  CheckIntPair<5, true, 4, false>();
  CheckIntPair<4, false, 5, true>();
  CheckIntPair<6, true, 3, true>();
  CheckIntPair<6, false, 6, false>();
  CheckIntPair<1, true, 2, false>();
}

// ---------------------------------------------------------------------------------------------
// Wide values (64..128 bits), floating point edges, integer conversions
// ---------------------------------------------------------------------------------------------

TEST(HlsWide, Products128Bits) {
  const ap_uint<64> m(~uint64_t{0});
  auto p = m * m;  // (2^64-1)^2 = 2^128 - 2^65 + 1
  static_assert(decltype(p)::width == 128 && !decltype(p)::sign_flag);
  EXPECT_EQ(p.range(63, 0).to_uint64(), 1u);
  EXPECT_EQ(p.range(127, 64).to_uint64(), ~uint64_t{0} - 1);
  const ap_int<64> mn(std::numeric_limits<int64_t>::min());
  auto q = mn * mn;  // 2^126
  EXPECT_EQ(q.range(127, 64).to_uint64(), uint64_t{1} << 62);
  EXPECT_EQ(q.range(63, 0).to_uint64(), 0u);
  EXPECT_GT(q, 0);
  auto r = mn * ap_int<64>(1);
  EXPECT_LT(r, 0);
  EXPECT_EQ(r.to_int64(), std::numeric_limits<int64_t>::min());
  EXPECT_EQ(r.to_double(), -9223372036854775808.0);
}

TEST(HlsWide, ComparisonsAcrossSignednessAt128Bits) {
  ap_uint<128> big;
  big.range() = -1;  // all ones
  EXPECT_TRUE(big.and_reduce());
  const ap_int<128> minus_one(-1);
  EXPECT_TRUE(big > minus_one);
  EXPECT_TRUE(minus_one < big);
  EXPECT_FALSE(big == minus_one);
  EXPECT_TRUE(big > 0);
  EXPECT_EQ(big.countLeadingZeros(), 0);
  EXPECT_EQ(ap_uint<128>(1).countLeadingZeros(), 127);
  ap_int<128> most_neg;
  most_neg[127] = 1;
  EXPECT_TRUE(most_neg < minus_one);
  EXPECT_TRUE(most_neg < big);
  // Fixed formats far apart: <128,0> (LSB 2^-128) vs an integer.
  ap_ufixed<128, 0> tiny;
  tiny[0] = 1;
  EXPECT_TRUE(tiny > 0);
  EXPECT_TRUE(tiny < 1);
  EXPECT_TRUE((tiny < ap_ufixed<8, 100>(ap_uint<2>(0)) + ap_ufixed<2, 2>(1)));
  const ap_fixed<8, 120> huge = FromRaw<ap_fixed<8, 120>>(0x40);  // 2^118
  EXPECT_TRUE(huge > tiny);
  EXPECT_TRUE(-huge < tiny);
}

TEST(HlsWide, WrapAndSaturateFrom128Bits) {
  ap_uint<128> big;
  big.range() = -1;
  EXPECT_EQ(ap_int<64>(big).to_int64(), -1);
  EXPECT_EQ((ap_fixed<8, 8, AP_TRN, AP_SAT>(big).to_int()), 127);
  EXPECT_EQ((ap_ufixed<8, 8, AP_TRN, AP_SAT_SYM>(big).to_int()), 255);
  ap_int<128> neg;
  neg[127] = 1;
  EXPECT_EQ((ap_fixed<8, 8, AP_TRN, AP_SAT>(neg).to_int()), -128);
  EXPECT_EQ((ap_fixed<8, 8, AP_TRN, AP_SAT_SYM>(neg).to_int()), -127);
  EXPECT_EQ((ap_ufixed<8, 8, AP_TRN, AP_SAT>(neg).to_int()), 0);
  // Very fine sources rounded into coarse targets: all dropped bits > 128.
  ap_fixed<8, -130> eps = FromRaw<ap_fixed<8, -130>>(0x80);  // negative, tiny
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN>(eps).to_double()), -0.0625);
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN_ZERO>(eps).to_double()), 0.0);
  EXPECT_EQ((ap_fixed<8, 4, AP_RND>(eps).to_double()), 0.0);
}

TEST(HlsFloat, DoubleEdgeCases) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(Raw(ap_fixed<8, 4>(nan)), 0u);
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN, AP_SAT>(inf).to_double()), 7.9375);
  EXPECT_EQ((ap_fixed<8, 4, AP_TRN, AP_SAT>(-inf).to_double()), -8.0);
  EXPECT_EQ(Raw(ap_fixed<8, 4>(inf)), 0u);  // 2^big mod 2^8
  EXPECT_EQ(Raw(ap_fixed<8, 4>(-0.0)), 0u);
  EXPECT_EQ(Raw(ap_fixed<8, 4>(std::numeric_limits<double>::denorm_min())), 0u);
  EXPECT_EQ(Raw(ap_fixed<8, 4, AP_RND_INF>(-std::numeric_limits<double>::denorm_min())), 0u);
  EXPECT_EQ(Raw(ap_fixed<8, 4, AP_TRN>(-std::numeric_limits<double>::denorm_min())), 0xffu);
  EXPECT_EQ((ap_ufixed<64, 64>(1e19).to_uint64()), 10000000000000000000ull);
  EXPECT_EQ((ap_fixed<100, 100>(-1e29).to_double()), -1e29);
  EXPECT_EQ((ap_fixed<20, 4>(1.0f / 3).to_float()), (ap_fixed<20, 4>(1.0 / 3).to_float()));
  EXPECT_EQ(ap_int<16>(-1e300).to_int(), 0);  // wraps: a multiple of 2^16
  // to_double of a 128-bit word rounds half to even.
  ap_uint<128> odd;
  odd.range(127, 0) = 0;
  odd[0] = 1;
  odd[54] = 1;  // 2^54 + 1: tie between 2^54 and 2^54 + 2 -> even (2^54)
  EXPECT_EQ(odd.to_double(), 18014398509481984.0);
  odd[1] = 1;  // 2^54 + 3 -> 2^54 + 4
  EXPECT_EQ(odd.to_double(), 18014398509481988.0);
}

TEST(HlsInteger, ConversionsToCTypes) {
  const ap_fixed<12, 8> x(-100.75);
  EXPECT_EQ(static_cast<int>(x), -100);
  EXPECT_EQ(static_cast<long long>(x), -100);
  EXPECT_EQ(static_cast<unsigned char>(ap_fixed<12, 10>(300.5)), 44);
  EXPECT_TRUE(static_cast<bool>(ap_fixed<8, 4>(0.0625)));
  EXPECT_FALSE(static_cast<bool>(ap_fixed<8, 4>(0)));
  EXPECT_EQ(static_cast<double>(x), -100.75);
  EXPECT_EQ(x.to_ap_int_base().to_int(), -100);
  const ap_uint<10> idx = 7;
  const int table[10] = {0, 1, 2, 3, 4, 5, 6, 70, 8, 9};
  EXPECT_EQ(table[idx], 70);  // implicit conversion for indexing
  int sum = 0;
  for (ap_uint<4> i = 0; i < 10; ++i) sum += i;
  EXPECT_EQ(sum, 45);
  ap_int<8> c = 127;
  ++c;
  EXPECT_EQ(c.to_int(), -128);
  ap_uint<3> d = 0;
  d--;
  EXPECT_EQ(d.to_int(), 7);
}

TEST(HlsBits, RangeConcatAndBitRefWrites) {
  ap_uint<12> x = 0;
  x.range(3, 0) = 0xf;
  x.range(4, 11) = 0x01;  // reversed write: bit 11 gets bit 0 of the value
  EXPECT_EQ(x.to_uint64(), 0x80fu);
  ap_uint<4> hi = 0;
  ap_uint<8> lo = 0;
  (hi, lo) = ap_uint<12>(0xabc);
  EXPECT_EQ(hi.to_int(), 0xa);
  EXPECT_EQ(lo.to_int(), 0xbc);
  ap_uint<1> b1 = 1;
  // (A concatenation refers to its operands: use it within the full expression.)
  EXPECT_EQ(ap_uint<4>((b1, x[11], ap_uint<2>(2))).to_int(), 0xe);
  ap_fixed<8, 4> f(-1.5);
  EXPECT_EQ(f.range().to_uint64(), 0xe8u);
  f[7] = 0;
  EXPECT_EQ(f.to_double(), 6.5);
  f.set_bit(-4, true);  // LSB (relative to the binary point)
  EXPECT_EQ(f.to_double(), 6.5625);
  EXPECT_EQ(ap_uint<8>(ap_fixed<4, 2>(-0.5).concat(ap_uint<4>(3))).to_int(), 0xe3);
  ap_uint<8> r = 0b00010110;
  r.reverse();
  EXPECT_EQ(r.to_int(), 0b01101000);
  r.lrotate(3);
  EXPECT_EQ(r.to_int(), 0b01000011);
  r.rrotate(1);
  EXPECT_EQ(r.to_int(), 0b10100001);
  EXPECT_EQ((x.range(7, 0) + 1).to_int(), 0x10);
  EXPECT_TRUE(x.range(3, 0) == 15);
  EXPECT_EQ((x.range(11, 8) << 1).to_int(), 0x10);  // the range reads as ap_uint<12>
}

TEST(HlsConstexpr, UsableInConstantExpressions) {
  constexpr ap_fixed<8, 4> a(1.5);
  constexpr ap_fixed<8, 4, AP_RND, AP_SAT> b(100.0);
  constexpr auto c = a * b;
  static_assert(a.V == 24);
  static_assert(b.V == 127);
  static_assert(c == ap_fixed<16, 8>(11.90625));
  static_assert(ap_uint<8>(0x81).shl(1) == 2);
  constexpr ap_uint<18> r(0x2ABCD);
  static_assert(r.range(7, 0).to_uint64() == 0xcd);
  EXPECT_EQ(c.to_double(), 11.90625);
}

// ---------------------------------------------------------------------------------------------
// Kernel bugs abort in C simulation
// ---------------------------------------------------------------------------------------------

TEST(HlsDeathTest, DivisionByZeroAborts) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const ap_fixed<8, 4> a(1.0), z(0);
  EXPECT_DEATH((void)(a / z), "division by zero");
  EXPECT_DEATH((void)(ap_int<8>(3) / ap_int<8>(0)), "division by zero");
  EXPECT_DEATH((void)(ap_int<8>(3) % ap_int<8>(0)), "modulo by zero");
}

TEST(HlsDeathTest, OutOfRangeBitIndexAborts) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  ap_uint<8> x = 0;
  EXPECT_DEATH((void)x[8], "bit index 8 out of range");
  EXPECT_DEATH((void)x.range(9, 0), "range\\(9, 0\\) out of range");
  ap_fixed<8, 4> f(0);
  EXPECT_DEATH((void)f.get_bit(4), "bit index 8 out of range");
  EXPECT_DEATH((void)f.get_bit(-5), "bit index -1 out of range");
}

// ---------------------------------------------------------------------------------------------
// hls::stream
// ---------------------------------------------------------------------------------------------

TEST(HlsStream, FifoOrderWithApTypesAndOperators) {
  hls::stream<ap_fixed<13, 3>> s("xyz");
  EXPECT_STREQ(s.name(), "xyz");
  for (int i = 0; i < 50; ++i) s << ap_fixed<13, 3>(i * 0.0625 - 1.5);
  EXPECT_EQ(s.size(), 50u);
  for (int i = 0; i < 50; ++i) {
    ap_fixed<13, 3> v;
    if (i % 3 == 0) {
      v = s.read();
    } else if (i % 3 == 1) {
      s.read(v);
    } else {
      s >> v;
    }
    ASSERT_EQ(v.to_double(), i * 0.0625 - 1.5);
  }
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(s.size_high_water(), 50u);
}

TEST(HlsStream, NonBlockingAccess) {
  hls::stream<int> s("nb");
  int v = 7;
  EXPECT_FALSE(s.read_nb(v));
  EXPECT_EQ(v, 0);
  EXPECT_TRUE(s.write_nb(5));
  EXPECT_TRUE(s.read_nb(v));
  EXPECT_EQ(v, 5);
  EXPECT_TRUE(s.empty());
}

TEST(HlsStream, TimestampsTravelWithElements) {
  hls::stream<int> s("ts");
  s.write(1, 100);
  s.write(2, 250);
  s.write(3);  // unstamped: cycle 0
  EXPECT_EQ(s.front_cycle(), 100u);
  uint64_t t = 1;
  EXPECT_EQ(s.read(&t), 1);
  EXPECT_EQ(t, 100u);
  EXPECT_EQ(s.front_cycle(), 250u);
  EXPECT_EQ(s.read(), 2);  // a plain read drops the stamp
  EXPECT_EQ(s.read(&t), 3);
  EXPECT_EQ(t, 0u);
  // A consumer's start cycle is the max of its own time and its input's stamp.
  s.write(9, 40);
  uint64_t consumer = 30;
  s.read(&t);
  consumer = std::max(consumer, t);
  EXPECT_EQ(consumer, 40u);
  EXPECT_EQ(s.size_high_water(), 3u);
}

TEST(HlsStream, LeftoversAreReportedOnDestruction) {
  ::testing::internal::CaptureStderr();
  {
    hls::stream<int> s("leaky_fifo");
    s << 1;
    s << 2;
    s << 3;
    (void)s.read();
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("leaky_fifo"), std::string::npos) << err;
  EXPECT_NE(err.find("2 leftover"), std::string::npos) << err;
  ::testing::internal::CaptureStderr();
  {
    hls::stream<int> s("clean");
    s << 1;
    (void)s.read();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(HlsStreamDeathTest, ReadingAnEmptyStreamAbortsWithItsName) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  hls::stream<int> s("depth_fragments");
  EXPECT_DEATH((void)s.read(), "hls::stream 'depth_fragments': read while empty");
  int v;
  EXPECT_DEATH(s >> v, "depth_fragments");
  EXPECT_DEATH((void)s.front_cycle(), "depth_fragments");
  s << 1;
  (void)s.read();
  EXPECT_DEATH((void)s.read(), "depth_fragments");
}

}  // namespace
