// tests/hw/hls_types_test.cc — our own ap_int / ap_fixed / hls::stream (src/hw/hls_types/):
// exhaustive small-width checks against the exact rational model of hls_test_model.h, wide
// (128-bit) arithmetic, bit access, constexpr use, aborts and the stream model.
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
