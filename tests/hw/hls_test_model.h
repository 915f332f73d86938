// tests/hw/hls_test_model.h — what the tests of our ap_int / ap_fixed (hls_types_*_test.cc)
// share: raw-bit access and an exact rational model of the types (int64 numerators over powers
// of two; rounding and overflow rules from the modes' definitions, written independently of
// src/hw/hls_types/).
#pragma once

#include <cstdint>
#include <utility>

#include "ap_fixed.h"
#include "ap_int.h"

namespace hls_test {

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
inline int64_t FloorDiv(int64_t a, int64_t b) {  // b > 0
  int64_t q = a / b;
  if ((a % b) != 0 && a < 0) --q;
  return q;
}

// Quantize n·2^-k (drop k >= 0 bits) to an integer with mode q, from the modes' definitions:
// truncations go to floor / toward zero; roundings go to the nearest integer and differ only in
// where an exact tie goes (+inf, zero, -inf, away from zero, even).
inline int64_t RefQuantize(int64_t n, int k, ap_q_mode q) {
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
inline int64_t RefOverflow(int64_t q, int W, bool S, ap_o_mode o) {
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
inline bool RatEq(int64_t a, int fa, int64_t b, int fb) {
  const int f = std::max(fa, fb);
  return a * (int64_t{1} << (f - fa)) == b * (int64_t{1} << (f - fb));
}
inline int RatCmp(int64_t a, int fa, int64_t b, int fb) {
  const int f = std::max(fa, fb);
  const int64_t x = a * (int64_t{1} << (f - fa)), y = b * (int64_t{1} << (f - fb));
  return (x > y) - (x < y);
}

template <int... Is, class F>
void ForEach(std::integer_sequence<int, Is...>, F&& f) {
  (f(std::integral_constant<int, Is>{}), ...);
}


}  // namespace hls_test
