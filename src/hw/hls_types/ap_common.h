// src/hw/hls_types/ap_common.h — internals shared by our ap_int.h / ap_fixed.h (not a vendor
// header name: a Vitis build never sees it). Semantics: shared/hls/SEMANTICS.md §1.
//
// Everything here is header-only, heap-free, exception-free and constexpr-friendly. Values are
// held in the narrowest of {32, 64, 128}-bit C++ integers that fits W, always *normalized*:
// the bits above W are copies of the sign bit (signed types) or zeros (unsigned types).
// Arithmetic runs in a modular unsigned "compute" integer (64 or 128 bits, chosen from the
// result width at compile time) and is normalized back; because every exact result of + − ×
// fits its result width, modular arithmetic gives the exact bits.
//
// Conversions (quantization + overflow) work on a 129-bit two's-complement value held as
// {neg, u}: value = u − neg·2^128. That covers every source up to 128 bits, signed or not.
#pragma once

#include <stdint.h>

#include <bit>
#include <type_traits>

#ifndef __SYNTHESIS__
#include <cstdio>
#include <cstdlib>
#endif

// Quantization modes (order as SystemC's sc_q_mode; SEMANTICS.md §1 "Quantization").
enum ap_q_mode {
  AP_RND,          // round half toward +inf
  AP_RND_ZERO,     // round half toward zero
  AP_RND_MIN_INF,  // round half toward -inf
  AP_RND_INF,      // round half away from zero
  AP_RND_CONV,     // round half to even
  AP_TRN,          // truncate toward -inf (floor); the default
  AP_TRN_ZERO      // truncate toward zero
};

// Overflow modes (order as SystemC's sc_o_mode). AP_WRAP_SM is declared for source
// compatibility only: SEMANTICS.md does not specify it, so using it is a compile error.
enum ap_o_mode {
  AP_SAT,       // saturate to max / min
  AP_SAT_ZERO,  // overflow gives 0
  AP_SAT_SYM,   // saturate to +max / -max (signed; the minimum also becomes -max), max / 0
  AP_WRAP,      // keep the low W bits (N > 0: the N MSBs saturate, SystemC semantics)
  AP_WRAP_SM    // not supported
};

template <int W, bool S>
struct ap_int_base;
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
struct ap_fixed_base;

// Simulation-only checks of kernel bugs (out-of-range bit index, division by zero): print and
// abort in C simulation, vanish under __SYNTHESIS__.
#ifndef __SYNTHESIS__
#define AP_CHECK(cond, ...)                      \
  do {                                           \
    if (!(cond)) {                               \
      std::fprintf(stderr, "ap_types: " __VA_ARGS__); \
      std::fputc('\n', stderr);                  \
      std::abort();                              \
    }                                            \
  } while (0)
#else
#define AP_CHECK(cond, ...) \
  do {                      \
  } while (0)
#endif

#define AP_INLINE inline __attribute__((always_inline))

namespace ap_detail {

__extension__ typedef __int128 i128;
__extension__ typedef unsigned __int128 u128;

constexpr int kMaxWidth = 128;

constexpr int max_i(int a, int b) { return a > b ? a : b; }
constexpr int min_i(int a, int b) { return a < b ? a : b; }

// Storage of a W-bit value (normalized).
template <int W, bool S>
using storage_t = std::conditional_t<
    (W <= 32), std::conditional_t<S, int32_t, uint32_t>,
    std::conditional_t<(W <= 64), std::conditional_t<S, int64_t, uint64_t>,
                       std::conditional_t<S, i128, u128>>>;

// Modular compute type able to hold W bits.
template <int W>
using calc_t = std::conditional_t<(W <= 64), uint64_t, u128>;

template <class C>
constexpr int bits_of() {
  return static_cast<int>(sizeof(C) * 8);
}

// Low `n` bits set (0 <= n <= 128).
constexpr u128 mask128(int n) { return n >= 128 ? ~static_cast<u128>(0) : ((static_cast<u128>(1) << n) - 1); }

// Normalize the low W bits of a modular value `x` to the storage of <W,S>.
template <int W, bool S, class C>
AP_INLINE constexpr storage_t<W, S> norm(C x) {
  static_assert(W >= 1 && W <= kMaxWidth, "ap_types: width must be in [1, 128]");
  constexpr int B = bits_of<C>();
  static_assert(B >= W || B == 64 || B == 128, "ap_types: compute type too narrow");
  using St = storage_t<W, S>;
  if constexpr (B < W) {
    // Narrow compute type (only possible when the caller knows the value fits): widen.
    return norm<W, S>(static_cast<u128>(x));
  } else if constexpr (S) {
    constexpr int sh = B - W;
    if constexpr (B == 64) {
      return static_cast<St>(static_cast<int64_t>(static_cast<uint64_t>(x) << sh) >> sh);
    } else {
      return static_cast<St>(static_cast<i128>(static_cast<u128>(x) << sh) >> sh);
    }
  } else {
    if constexpr (W == B) {
      return static_cast<St>(x);
    } else {
      return static_cast<St>(x & ((static_cast<C>(1) << W) - 1));
    }
  }
}

// Widen normalized storage to a modular compute type (sign- or zero-extension).
template <class C, class St>
AP_INLINE constexpr C widen(St v) {
  return static_cast<C>(v);
}

// ---- 129-bit helpers for conversions ----
struct wide {
  bool neg;  // the value is u - 2^128
  u128 u;
};

// Is normalized storage negative? (No comparison on unsigned types: keeps -Wextra quiet.)
template <class St>
AP_INLINE constexpr bool is_neg(St v) {
  if constexpr (std::is_same_v<St, i128> || std::is_signed_v<St>) {
    return v < 0;
  } else {
    (void)v;
    return false;
  }
}

// Low `n` bits set in a U word (0 <= n <= bits of U).
template <class U>
AP_INLINE constexpr U mask_u(int n) {
  return n >= bits_of<U>() ? static_cast<U>(~static_cast<U>(0)) : static_cast<U>((static_cast<U>(1) << n) - 1);
}

// Does the (B+1)-bit value {neg, u} (value u − neg·2^B, B = bits of U) fit in `w` bits?
template <class U>
AP_INLINE constexpr bool fits_u(bool neg, U u, int w, bool is_signed) {
  constexpr int B = bits_of<U>();
  if (w <= 0) return !neg && u == 0;
  if (is_signed) {
    if (w >= B + 1) return true;
    const int k = w - 1;  // 0 .. B-1
    const U top = static_cast<U>(u >> k);
    return neg ? top == static_cast<U>(static_cast<U>(~static_cast<U>(0)) >> k) : top == 0;
  }
  if (neg) return false;
  if (w >= B) return true;
  return (u >> w) == 0;
}
AP_INLINE constexpr bool fits(bool neg, u128 u, int w, bool is_signed) {
  return fits_u<u128>(neg, u, w, is_signed);
}

// Exact 129-bit comparison a < b.
AP_INLINE constexpr bool wide_less(wide a, wide b) {
  if (a.neg != b.neg) return a.neg;
  return a.u < b.u;
}

template <class St>
AP_INLINE constexpr wide to_wide(St v) {
  return wide{is_neg(v), static_cast<u128>(v)};
}

// Convert an exact value X·2^(-d) to the target <W,S> with quantization Q and overflow O/N
// (SEMANTICS.md §1 "Quantization", overflow list); X is the (B+1)-bit two's-complement value
// {neg, u} = u − neg·2^B of a word type U (B = 64 or 128). d > 0 drops d bits of X, d < 0
// appends −d zero bits; the result is in units of the target LSB. Returns normalized storage.
// U = uint64_t serves every source of at most 64 bits into a target of at most 64 bits (the
// fast path); U = u128 serves the rest.
template <int W, bool S, ap_q_mode Q, ap_o_mode O, int N, class U>
AP_INLINE constexpr storage_t<W, S> convert_u(bool neg, U u, int d) {
  static_assert(O != AP_WRAP_SM, "ap_types: AP_WRAP_SM is not supported (not in SEMANTICS.md)");
  static_assert(N >= 0, "ap_types: saturation bits N must be >= 0");
  constexpr int B = bits_of<U>();
  static_assert(B == 128 || W <= B, "ap_types: 64-bit conversion path used for a wide target");
  constexpr U ones = static_cast<U>(~static_cast<U>(0));
  bool qneg = neg;
  U q = u;
  if (d > 0) {
    // Arithmetic shift right by d (floor), keeping the first dropped bit and the sticky OR.
    bool qb, r;
    if (d <= B) {
      qb = ((u >> (d - 1)) & 1) != 0;
      r = d >= 2 ? (u & mask_u<U>(d - 1)) != 0 : false;
      if (d == B) {
        q = neg ? ones : 0;
      } else {
        q = static_cast<U>((u >> d) | (neg ? static_cast<U>(ones << (B - d)) : 0));
      }
    } else {
      qb = neg;
      r = u != 0 || (neg && d >= B + 2);
      q = neg ? ones : 0;
    }
    bool carry = false;
    if constexpr (Q == AP_RND) {
      carry = qb;
    } else if constexpr (Q == AP_RND_ZERO) {
      carry = qb && (neg || r);
    } else if constexpr (Q == AP_RND_MIN_INF) {
      carry = qb && r;
    } else if constexpr (Q == AP_RND_INF) {
      carry = qb && (!neg || r);
    } else if constexpr (Q == AP_RND_CONV) {
      carry = qb && ((q & 1) != 0 || r);
    } else if constexpr (Q == AP_TRN) {
      carry = false;
    } else {  // AP_TRN_ZERO
      carry = neg && (qb || r);
    }
    if (carry) {
      q = static_cast<U>(q + 1);
      if (q == 0) qneg = false;  // -1 + 1 = 0 (a non-negative q cannot wrap: it is < 2^(B-1))
    }
  }
  const int e = d < 0 ? -d : 0;
  const U low = e >= B ? 0 : static_cast<U>(q << e);
  const storage_t<W, S> wrapped = norm<W, S>(low);
  if constexpr (O == AP_WRAP && N == 0) {
    return wrapped;
  } else {
    constexpr U maxv = S ? mask_u<U>(W - 1) : mask_u<U>(W);
    constexpr U minv = S ? static_cast<U>(~mask_u<U>(W - 1)) : 0;  // -2^(W-1), two's complement
    if (fits_u<U>(qneg, q, W - e, S)) {
      if constexpr (O == AP_SAT_SYM && S) {
        // SAT_SYM keeps the range symmetric: the signed minimum becomes -max (SEMANTICS.md §1).
        if (wrapped == norm<W, S>(minv)) return norm<W, S>(static_cast<U>(minv + 1));
      }
      return wrapped;
    }
    // Overflow.
    if constexpr (O == AP_SAT) {
      return norm<W, S>(qneg ? minv : maxv);
    } else if constexpr (O == AP_SAT_ZERO) {
      return norm<W, S>(static_cast<U>(0));
    } else if constexpr (O == AP_SAT_SYM) {
      if constexpr (S) {
        return norm<W, S>(qneg ? static_cast<U>(minv + 1) : maxv);
      } else {
        return norm<W, S>(qneg ? static_cast<U>(0) : maxv);
      }
    } else {  // AP_WRAP with N > 0: the N MSBs saturate, the rest wraps
      constexpr int n = N > W ? W : N;
      U bits = low & mask_u<U>(W);
      constexpr U top_mask = mask_u<U>(W) & static_cast<U>(~mask_u<U>(W - n));
      if constexpr (S) {
        constexpr U sign_bit = static_cast<U>(static_cast<U>(1) << (W - 1));
        bits &= static_cast<U>(~top_mask);
        if (qneg) {
          bits |= sign_bit;  // sign bit = original sign; the other N-1 saturated bits = 0
        } else {
          bits |= top_mask & static_cast<U>(~sign_bit);  // sign 0, the other N-1 bits = 1
        }
      } else {
        bits = qneg ? static_cast<U>(bits & ~top_mask) : static_cast<U>(bits | top_mask);
      }
      return norm<W, S>(bits);
    }
  }
}

// 129-bit entry point (any source, any target).
template <int W, bool S, ap_q_mode Q, ap_o_mode O, int N>
AP_INLINE constexpr storage_t<W, S> convert(bool neg, u128 u, int d) {
  if constexpr (W <= 64) {
    // A value that fits in 65 bits takes the 64-bit path.
    const u128 top = u >> 63;
    if (neg ? top == (~static_cast<u128>(0) >> 63) : top == 0) {
      return convert_u<W, S, Q, O, N, uint64_t>(neg, static_cast<uint64_t>(u), d);
    }
  }
  return convert_u<W, S, Q, O, N, u128>(neg, u, d);
}

// Convert normalized source storage with F2 fractional bits to <W,S,Q,O,N> with F fractional
// bits, choosing the word type at compile time.
template <int W, bool S, ap_q_mode Q, ap_o_mode O, int N, class St>
AP_INLINE constexpr storage_t<W, S> convert_from(St raw, int d) {
  if constexpr (bits_of<St>() <= 64 && W <= 64) {
    return convert_u<W, S, Q, O, N, uint64_t>(is_neg(raw), static_cast<uint64_t>(raw), d);
  } else {
    return convert_u<W, S, Q, O, N, u128>(is_neg(raw), static_cast<u128>(raw), d);
  }
}

// ---- double / float ----

// 2^e as a double (exact for -1074 <= e <= 1023).
constexpr double pow2d(int e) {
  if (e >= -1022 && e <= 1023) {
    return std::bit_cast<double>(static_cast<uint64_t>(e + 1023) << 52);
  }
  double r = 1.0;
  if (e > 0) {
    while (e-- > 0) r *= 2.0;
  } else {
    while (e++ < 0) r *= 0.5;
  }
  return r;
}

constexpr float pow2f(int e) {
  if (e >= -126 && e <= 127) {
    return std::bit_cast<float>(static_cast<uint32_t>(e + 127) << 23);
  }
  float r = 1.0f;
  if (e > 0) {
    while (e-- > 0) r *= 2.0f;
  } else {
    while (e++ < 0) r *= 0.5f;
  }
  return r;
}

// A double as an exact 129-bit integer X and a binary exponent: value = X · 2^exp2.
// NaN gives X = 0; ±Inf gives ±1 · 2^4096 (overflows every format: saturates / wraps to 0).
struct double_parts {
  wide x;
  int exp2;
};

constexpr double_parts split_double(double v) {
  const uint64_t b = std::bit_cast<uint64_t>(v);
  const bool sign = (b >> 63) != 0;
  const int ef = static_cast<int>((b >> 52) & 0x7ff);
  const uint64_t frac = b & ((static_cast<uint64_t>(1) << 52) - 1);
  uint64_t m;
  int exp2;
  if (ef == 0x7ff) {
    if (frac != 0) return double_parts{wide{false, 0}, 0};  // NaN -> 0
    m = 1;
    exp2 = 4096;
  } else if (ef == 0) {
    m = frac;
    exp2 = -1074;
  } else {
    m = frac | (static_cast<uint64_t>(1) << 52);
    exp2 = ef - 1075;
  }
  if (m == 0) return double_parts{wide{false, 0}, 0};
  const u128 um = m;
  return double_parts{sign ? wide{true, ~um + 1} : wide{false, um}, exp2};
}

// Exact value raw·2^-F of normalized storage, rounded to double (half to even).
template <class St>
AP_INLINE double to_double(St raw, int F) {
  return static_cast<double>(raw) * pow2d(-F);
}
template <class St>
AP_INLINE float to_float(St raw, int F) {
  return static_cast<float>(raw) * pow2f(-F);
}

// ---- C integer operands ----
template <class T>
inline constexpr bool is_cint_v = std::is_integral_v<T>;

template <class T>
inline constexpr int cint_width_v = std::is_same_v<T, bool> ? 1 : static_cast<int>(sizeof(T) * 8);
template <class T>
inline constexpr bool cint_signed_v = std::is_signed_v<T>;

// Sign-magnitude truncating division (quotient toward zero, C semantics) on modular values.
// `a`, `b` are modular two's-complement words of type C whose true values have the given signs.
template <class C>
AP_INLINE constexpr C div_trunc(C a, bool a_neg, C b, bool b_neg) {
  const C ma = a_neg ? static_cast<C>(~a + 1) : a;
  const C mb = b_neg ? static_cast<C>(~b + 1) : b;
  const C q = ma / mb;
  return (a_neg != b_neg) ? static_cast<C>(~q + 1) : q;
}
template <class C>
AP_INLINE constexpr C mod_trunc(C a, bool a_neg, C b, bool b_neg) {
  const C ma = a_neg ? static_cast<C>(~a + 1) : a;
  const C mb = b_neg ? static_cast<C>(~b + 1) : b;
  const C r = ma % mb;
  return a_neg ? static_cast<C>(~r + 1) : r;
}

// Reverse the low n bits of x (1 <= n <= 128).
constexpr u128 reverse_bits(u128 x, int n) {
  u128 r = 0;
  for (int i = 0; i < n; ++i) {
    r = (r << 1) | ((x >> i) & 1);
  }
  return r;
}

}  // namespace ap_detail
