// tests/hw_systemc/sc_fixed_diff_test.cc — differential tests of our ap_fixed / ap_ufixed
// (src/hw/hls_types/) against SystemC's sc_fixed / sc_ufixed (Debian libsystemc-dev), which
// SEMANTICS.md §1 reports bit-identical to the vendor's 2019.1 header for conversion,
// assignment, + − × and comparisons (not for shifts, division or double -> ap_int).
// Bit patterns are compared. Every case is seeded (a local SplitMix64: this binary links only
// GoogleTest and SystemC, not posefilter, so posefilter::Rng is not available here).
//
// libsystemc provides main() and calls sc_main(), defined at the end to run GoogleTest.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

// Debian's libsystemc is built as C++17: its API-version symbol is sc_api_version_..._cxx201703L,
// so this C++20 test must announce the same standard to link.
#ifndef SC_CPLUSPLUS
#define SC_CPLUSPLUS 201703L
#endif
#include <systemc>
#include <type_traits>

#include "ap_fixed.h"

namespace {

using sc_dt::sc_fixed;
using sc_dt::sc_ufixed;

// ---- seeded generator (SplitMix64) ----
class SplitMix {
 public:
  explicit SplitMix(uint64_t seed) : s_(seed) {}
  uint64_t Next() {
    uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  int Int(int lo, int hi) {  // [lo, hi]
    return lo + static_cast<int>(Next() % static_cast<uint64_t>(hi - lo + 1));
  }

 private:
  uint64_t s_;
};

constexpr sc_dt::sc_q_mode ScQ(ap_q_mode q) {
  switch (q) {
    case AP_RND: return sc_dt::SC_RND;
    case AP_RND_ZERO: return sc_dt::SC_RND_ZERO;
    case AP_RND_MIN_INF: return sc_dt::SC_RND_MIN_INF;
    case AP_RND_INF: return sc_dt::SC_RND_INF;
    case AP_RND_CONV: return sc_dt::SC_RND_CONV;
    case AP_TRN: return sc_dt::SC_TRN;
    case AP_TRN_ZERO: return sc_dt::SC_TRN_ZERO;
  }
  return sc_dt::SC_TRN;
}
constexpr sc_dt::sc_o_mode ScO(ap_o_mode o) {
  switch (o) {
    case AP_SAT: return sc_dt::SC_SAT;
    case AP_SAT_ZERO: return sc_dt::SC_SAT_ZERO;
    case AP_SAT_SYM: return sc_dt::SC_SAT_SYM;
    case AP_WRAP: return sc_dt::SC_WRAP;
    case AP_WRAP_SM: return sc_dt::SC_WRAP_SM;
  }
  return sc_dt::SC_WRAP;
}

// The SystemC twin of an ap type.
template <int W, int I, bool S, ap_q_mode Q = AP_TRN, ap_o_mode O = AP_WRAP, int N = 0>
struct Fmt {
  using Ap = ap_fixed_base<W, I, S, Q, O, N>;
  using Sc = std::conditional_t<S, sc_fixed<W, I, ScQ(Q), ScO(O), N>, sc_ufixed<W, I, ScQ(Q), ScO(O), N>>;
};

struct Bits {
  uint64_t lo, hi;
  bool operator==(const Bits& o) const { return lo == o.lo && hi == o.hi; }
};
template <class T>
Bits ApBits(const T& x) {
  constexpr int W = T::width;
  return Bits{x.range(std::min(W, 64) - 1, 0).to_uint64(), W > 64 ? x.range(W - 1, 64).to_uint64() : 0};
}
template <class T>
Bits ScBits(const T& x, int W) {
  return Bits{static_cast<uint64_t>(x.range(std::min(W, 64) - 1, 0).to_uint64()),
              W > 64 ? static_cast<uint64_t>(x.range(W - 1, 64).to_uint64()) : 0};
}
std::string Hex(const Bits& b) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%016llx_%016llx", static_cast<unsigned long long>(b.hi),
                static_cast<unsigned long long>(b.lo));
  return buf;
}

// Doubles that exercise a <W,I> format: exact ties and near-ties, values around the range
// limits (overflow), tiny values and arbitrary mantissas.
double RandomDouble(SplitMix& rng, int W, int I) {
  const int F = W - I;
  const int kind = rng.Int(0, 3);
  const double lsb = std::ldexp(1.0, -F);
  if (kind == 0) {  // integer multiple of the LSB plus a tie / near-tie / random fraction
    const int wbits = std::min(W + 2, 50);
    const double n = static_cast<double>(static_cast<int64_t>(rng.Next() >> (64 - wbits)) -
                                         (int64_t{1} << (wbits - 1)));
    const int frac_kind = rng.Int(0, 3);
    double frac = 0;
    if (frac_kind == 1) frac = 0.5;
    if (frac_kind == 2) frac = 0.5 + (rng.Int(0, 1) ? 1 : -1) * std::ldexp(1.0, -rng.Int(2, 20));
    if (frac_kind == 3) frac = static_cast<double>(rng.Next() >> 11) * std::ldexp(1.0, -53);
    return (n + frac) * lsb;
  }
  if (kind == 1) {  // around the limits of the range
    const double lim = std::ldexp(1.0, I - (rng.Int(0, 1)));
    const double d = static_cast<double>(rng.Int(-4, 4)) * lsb * 0.5;
    return (rng.Int(0, 1) ? lim : -lim) + d;
  }
  // arbitrary mantissa, exponent from well below the LSB to well above the range
  const double m = static_cast<double>(rng.Next() >> 11) * std::ldexp(1.0, -53);
  const int e = rng.Int(-F - 8, I + 8);
  return (rng.Int(0, 1) ? -m : m) * std::ldexp(1.0, e);
}

constexpr int kDoubleCases = 1500;

template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
int DiffFromDouble(uint64_t seed) {
  using F = Fmt<W, I, S, Q, O, N>;
  SplitMix rng(seed);
  int bad = 0;
  for (int i = 0; i < kDoubleCases; ++i) {
    const double d = RandomDouble(rng, W, I);
    const typename F::Ap a(d);
    const typename F::Sc s(d);
    const Bits ab = ApBits(a), sb = ScBits(s, W);
    if (!(ab == sb)) {
      if (++bad <= 3) {
        ADD_FAILURE() << "double " << d << " -> <" << W << "," << I << "," << S << ",Q" << Q << ",O" << O
                      << ",N" << N << ">: ours " << Hex(ab) << " SystemC " << Hex(sb);
      }
    }
  }
  return bad;
}

template <int... Is, class Fn>
void ForEach(std::integer_sequence<int, Is...>, Fn&& f) {
  (f(std::integral_constant<int, Is>{}), ...);
}

// Every Q × O (N = 0), plus AP_WRAP with N = 1, 2, 3 saturated MSBs.
template <class Fn>
void AllModes(Fn&& fn) {
  ForEach(std::make_integer_sequence<int, 7>{}, [&](auto q) {
    ForEach(std::make_integer_sequence<int, 4>{}, [&](auto o) {
      fn(std::integral_constant<ap_q_mode, static_cast<ap_q_mode>(q.value)>{},
         std::integral_constant<ap_o_mode, static_cast<ap_o_mode>(o.value)>{}, std::integral_constant<int, 0>{});
    });
    ForEach(std::integer_sequence<int, 1, 2, 3>{}, [&](auto n) {
      fn(std::integral_constant<ap_q_mode, static_cast<ap_q_mode>(q.value)>{},
         std::integral_constant<ap_o_mode, AP_WRAP>{}, n);
    });
  });
}

template <int W, int I, bool S>
int DiffFromDoubleAllModes(uint64_t seed) {
  int bad = 0;
  AllModes([&](auto q, auto o, auto n) {
    bad += DiffFromDouble<W, I, S, decltype(q)::value, decltype(o)::value, decltype(n)::value>(
        seed + 1000 * decltype(q)::value + 100 * decltype(o)::value + decltype(n)::value);
  });
  return bad;
}

TEST(HlsScDiff, ConversionFromDoubleEveryMode) {
  int bad = 0;
  bad += DiffFromDoubleAllModes<8, 4, true>(1);
  bad += DiffFromDoubleAllModes<8, 4, false>(2);
  bad += DiffFromDoubleAllModes<13, 3, true>(3);
  bad += DiffFromDoubleAllModes<12, 2, false>(4);
  bad += DiffFromDoubleAllModes<18, 0, false>(5);
  bad += DiffFromDoubleAllModes<21, 4, true>(6);
  bad += DiffFromDoubleAllModes<32, 16, true>(7);
  bad += DiffFromDoubleAllModes<5, -2, true>(8);
  bad += DiffFromDoubleAllModes<7, 10, false>(9);
  bad += DiffFromDoubleAllModes<48, 12, false>(10);
  bad += DiffFromDoubleAllModes<64, 32, true>(11);
  bad += DiffFromDoubleAllModes<64, 64, false>(12);
  bad += DiffFromDoubleAllModes<2, 1, true>(13);
  EXPECT_EQ(bad, 0);
}

// Random raw words of a source format assigned into a target with every mode.
template <int Ws, int Is, bool Ss, int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
int DiffFromFixed(uint64_t seed) {
  using Src = Fmt<Ws, Is, Ss>;
  using Dst = Fmt<W, I, S, Q, O, N>;
  SplitMix rng(seed);
  int bad = 0;
  for (int i = 0; i < 600; ++i) {
    const uint64_t lo = rng.Next(), hi = rng.Next();
    typename Src::Ap a;
    typename Src::Sc s;
    a.range(std::min(Ws, 64) - 1, 0) = lo;
    s.range(std::min(Ws, 64) - 1, 0) = static_cast<sc_dt::uint64>(lo);
    if constexpr (Ws > 64) {
      a.range(Ws - 1, 64) = hi;
      s.range(Ws - 1, 64) = static_cast<sc_dt::uint64>(hi);
    }
    (void)hi;
    if (!(ApBits(a) == ScBits(s, Ws))) {
      ADD_FAILURE() << "source raw load differs";
      return 1;
    }
    typename Dst::Ap ta = a;
    typename Dst::Sc ts = s;
    typename Dst::Ap ua;  // assignment into an existing value
    ua = a;
    const Bits ab = ApBits(ta), sb = ScBits(ts, W);
    if (!(ab == sb) || !(ApBits(ua) == sb)) {
      if (++bad <= 3) {
        ADD_FAILURE() << "<" << Ws << "," << Is << "," << Ss << "> " << Hex(ApBits(a)) << " -> <" << W << ","
                      << I << "," << S << ",Q" << Q << ",O" << O << ",N" << N << ">: ours " << Hex(ab)
                      << " SystemC " << Hex(sb);
      }
    }
  }
  return bad;
}

template <int Ws, int Is, bool Ss, int W, int I, bool S>
int DiffFromFixedAllModes(uint64_t seed) {
  int bad = 0;
  AllModes([&](auto q, auto o, auto n) {
    bad += DiffFromFixed<Ws, Is, Ss, W, I, S, decltype(q)::value, decltype(o)::value, decltype(n)::value>(
        seed + 1000 * decltype(q)::value + 100 * decltype(o)::value + decltype(n)::value);
  });
  return bad;
}

TEST(HlsScDiff, AssignmentBetweenFixedTypesEveryMode) {
  int bad = 0;
  bad += DiffFromFixedAllModes<16, 6, true, 8, 4, true>(21);
  bad += DiffFromFixedAllModes<16, 6, true, 8, 4, false>(22);
  bad += DiffFromFixedAllModes<20, 4, false, 13, 3, true>(23);
  bad += DiffFromFixedAllModes<20, 4, false, 6, 6, false>(24);
  bad += DiffFromFixedAllModes<64, 20, true, 18, 0, false>(25);
  bad += DiffFromFixedAllModes<64, 20, true, 40, 22, true>(26);
  bad += DiffFromFixedAllModes<40, -2, false, 5, -2, true>(27);
  bad += DiffFromFixedAllModes<100, 50, true, 64, 32, true>(28);
  bad += DiffFromFixedAllModes<128, 60, false, 70, 60, true>(29);
  bad += DiffFromFixedAllModes<8, 8, true, 12, 4, true>(30);  // coarser source: left shift
  EXPECT_EQ(bad, 0);
}

// + − × of random operands: exact results compared, then each result assigned into a narrow
// target with every mode; comparisons.
template <class A, class B, int Wt, int It, bool St>
int DiffArithmetic(uint64_t seed) {
  SplitMix rng(seed);
  int bad = 0;
  constexpr int W1 = A::Ap::width, W2 = B::Ap::width;
  for (int i = 0; i < 800; ++i) {
    typename A::Ap a;
    typename A::Sc sa;
    typename B::Ap b;
    typename B::Sc sb;
    const uint64_t ra = rng.Next(), rb = rng.Next();
    a.range(std::min(W1, 64) - 1, 0) = ra;
    sa.range(std::min(W1, 64) - 1, 0) = static_cast<sc_dt::uint64>(ra);
    b.range(std::min(W2, 64) - 1, 0) = rb;
    sb.range(std::min(W2, 64) - 1, 0) = static_cast<sc_dt::uint64>(rb);
    const auto sum = a + b;
    const auto dif = a - b;
    const auto prod = a * b;
    using Sum = std::remove_const_t<decltype(sum)>;
    using Dif = std::remove_const_t<decltype(dif)>;
    using Prod = std::remove_const_t<decltype(prod)>;
    const typename Fmt<Sum::width, Sum::iwidth, Sum::sign_flag>::Sc ssum = sa + sb;
    const typename Fmt<Dif::width, Dif::iwidth, Dif::sign_flag>::Sc sdif = sa - sb;
    const typename Fmt<Prod::width, Prod::iwidth, Prod::sign_flag>::Sc sprod = sa * sb;
    bool ok = ApBits(sum) == ScBits(ssum, Sum::width) && ApBits(dif) == ScBits(sdif, Dif::width) &&
              ApBits(prod) == ScBits(sprod, Prod::width);
    // The SystemC twins must hold the exact results (no quantization happened there either).
    ok = ok && sc_dt::sc_fxval(ssum) == sa + sb && sc_dt::sc_fxval(sprod) == sa * sb;
    ok = ok && (a < b) == (sa < sb) && (a == b) == (sa == sb) && (a >= b) == (sa >= sb) &&
         (a != b) == (sa != sb);
    AllModes([&](auto q, auto o, auto n) {
      using T = Fmt<Wt, It, St, decltype(q)::value, decltype(o)::value, decltype(n)::value>;
      const typename T::Ap t1 = prod, t2 = sum, t3 = dif;
      const typename T::Sc s1 = sa * sb, s2 = sa + sb, s3 = sa - sb;
      ok = ok && ApBits(t1) == ScBits(s1, Wt) && ApBits(t2) == ScBits(s2, Wt) && ApBits(t3) == ScBits(s3, Wt);
    });
    if (!ok && ++bad <= 3) {
      ADD_FAILURE() << "a " << Hex(ApBits(a)) << " b " << Hex(ApBits(b)) << " (" << a.to_double() << ", "
                    << b.to_double() << ")";
    }
  }
  return bad;
}

TEST(HlsScDiff, ArithmeticAssignmentAndComparisons) {
  EXPECT_EQ((DiffArithmetic<Fmt<8, 4, true>, Fmt<6, 2, false>, 6, 3, true>(41)), 0);
  EXPECT_EQ((DiffArithmetic<Fmt<13, 3, false>, Fmt<18, 0, false>, 12, 2, false>(42)), 0);
  EXPECT_EQ((DiffArithmetic<Fmt<32, 16, true>, Fmt<32, 8, true>, 21, 4, true>(43)), 0);
  EXPECT_EQ((DiffArithmetic<Fmt<64, 40, true>, Fmt<60, 20, false>, 40, 30, true>(44)), 0);
  EXPECT_EQ((DiffArithmetic<Fmt<12, -3, true>, Fmt<9, 12, false>, 10, 8, false>(45)), 0);
}

}  // namespace

int sc_main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
