// src/hw/hls_types/ap_fixed.h — our own ap_fixed<W,I,Q,O,N> / ap_ufixed<W,I,Q,O,N>
// (1 <= W <= 128; I = integer bits including the sign, any value: <8,-2> has LSB 2^-10,
// <8,10> has LSB 4), bit-exact to shared/hls/SEMANTICS.md §1. Same file name and public API
// as the vendor header (a Vitis build swaps in the vendor's by include path).
//
// A value is raw·2^-F with F = W − I; `raw` is the W-bit two's-complement (or unsigned) word.
// Quantization (Q) and overflow (O, N) apply only when a value is constructed or assigned
// into a type; binary operators return exact, wider types (SEMANTICS.md §1):
//   *    : <W1+W2, I1+I2>,                                      signed iff S1||S2
//   + -  : I = max(I1+(S2&&!S1), I2+(S1&&!S2)) + 1, F = max(F1,F2); '-' always signed
//   /    : <S2+W1+max(F2,0), S2+I1+F2>; quotient truncated toward zero (keeps the dividend's F)
//   & | ^: as + without the +1
//   unary −: <W+1, I+1, signed>;  << >>: the operand's type, raw shift, no quantization/overflow
// ap_int<W> operands act as ap_fixed<W,W>, C integers as ap_fixed<bits,bits> of their type.
// Comparisons are exact across formats. There are no operators with float/double and no
// implicit conversion to or from them: `ap_fixed<8,4> x(1.5)` and `x.to_double()` are the
// explicit, software-side conversions (kernels never compute in double).
// Conversion from double is exact before quantization; NaN gives 0, ±Inf overflows.
// Deviations (C simulation only): division by zero and out-of-range bit indices abort with a
// message. AP_WRAP_SM is not supported (compile error).
#pragma once

#include "ap_int.h"

template <int W, int I, bool S, ap_q_mode Q = AP_TRN, ap_o_mode O = AP_WRAP, int N = 0>
struct ap_fixed_base {
  static_assert(W >= 1 && W <= ap_detail::kMaxWidth, "ap_types: ap_fixed width must be in [1, 128]");
  using storage_type = ap_detail::storage_t<W, S>;
  static constexpr int width = W;
  static constexpr int iwidth = I;
  static constexpr int fwidth = W - I;  // F: fractional bits (may be negative or > W)
  static constexpr bool sign_flag = S;
  static constexpr ap_q_mode qmode = Q;
  static constexpr ap_o_mode omode = O;
  static constexpr int nbits = N;

  // Raw word, normalized (sign- or zero-extended above W). Implementation detail: kernels use
  // range() for raw bits, as with the vendor header.
  storage_type V;

  // ---- construction (quantization + overflow of this type) ----
  constexpr ap_fixed_base() : V(0) {}
  constexpr ap_fixed_base(const ap_fixed_base&) = default;

  template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>
  constexpr ap_fixed_base(const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& o)
      : V(from_raw<W2 - I2>(o.V)) {}

  template <int W2, bool S2>
  constexpr ap_fixed_base(const ap_int_base<W2, S2>& o) : V(from_raw<0>(o.V)) {}

  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr ap_fixed_base(T v) : V(from_raw<0>(ap_detail::cint_ap_t<T>(v).V)) {}

  // Raw bits of a range / bit / concatenation are an unsigned integer value.
  template <class P>
  constexpr ap_fixed_base(const ap_range_ref<P>& r) : ap_fixed_base(r.get()) {}
  template <class P>
  constexpr ap_fixed_base(const ap_bit_ref<P>& b) : ap_fixed_base(ap_int_base<1, false>(b)) {}
  template <class H, class L>
  constexpr ap_fixed_base(const ap_concat_ref<H, L>& c) : ap_fixed_base(c.get()) {}

  // From floating point: exact before quantization (SEMANTICS.md §1). Explicit.
  constexpr explicit ap_fixed_base(double d) : V(from_double(d)) {}
  constexpr explicit ap_fixed_base(float f) : V(from_double(static_cast<double>(f))) {}

  // Source raw word with F2 fractional bits -> this type.
  template <int F2, class St>
  static AP_INLINE constexpr storage_type from_raw(St raw) {
    return ap_detail::convert_from<W, S, Q, O, N>(raw, F2 - (W - I));
  }
  static constexpr storage_type from_double(double d) {
    const ap_detail::double_parts p = ap_detail::split_double(d);
    return ap_detail::convert<W, S, Q, O, N>(p.x.neg, p.x.u, -p.exp2 - (W - I));
  }

  // ---- assignment (quantization + overflow of this type) ----
  constexpr ap_fixed_base& operator=(const ap_fixed_base&) = default;
  template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>
  constexpr ap_fixed_base& operator=(const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& o) {
    V = from_raw<W2 - I2>(o.V);
    return *this;
  }
  template <int W2, bool S2>
  constexpr ap_fixed_base& operator=(const ap_int_base<W2, S2>& o) {
    V = from_raw<0>(o.V);
    return *this;
  }
  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr ap_fixed_base& operator=(T v) {
    V = from_raw<0>(ap_detail::cint_ap_t<T>(v).V);
    return *this;
  }
  template <class P>
  constexpr ap_fixed_base& operator=(const ap_range_ref<P>& r) {
    return *this = r.get();
  }
  template <class H, class L>
  constexpr ap_fixed_base& operator=(const ap_concat_ref<H, L>& c) {
    return *this = c.get();
  }

  // ---- raw bits (zero-extended W-bit word) ----
  constexpr ap_detail::u128 raw_bits() const {
    return static_cast<ap_detail::u128>(V) & ap_detail::mask128(W);
  }
  constexpr void set_raw_bits(ap_detail::u128 b) { V = ap_detail::norm<W, S>(b); }

  // ---- conversion out ----
  // Nearest double (half to even); exact for W <= 53.
  double to_double() const { return ap_detail::to_double(V, W - I); }
  float to_float() const { return ap_detail::to_float(V, W - I); }
  explicit operator double() const { return to_double(); }
  explicit operator float() const { return to_float(); }
  explicit operator long double() const { return static_cast<long double>(to_double()); }

  // Integer part truncated toward zero ("C native"; SEMANTICS.md §1), then the C type's width.
  constexpr int64_t to_int64() const {
    return static_cast<int64_t>(ap_detail::convert_from<64, true, AP_TRN_ZERO, AP_WRAP, 0>(V, W - I));
  }
  constexpr uint64_t to_uint64() const { return static_cast<uint64_t>(to_int64()); }
  constexpr int to_int() const { return static_cast<int>(to_int64()); }
  constexpr unsigned to_uint() const { return static_cast<unsigned>(to_int64()); }
  constexpr long to_long() const { return static_cast<long>(to_int64()); }
  constexpr unsigned long to_ulong() const { return static_cast<unsigned long>(to_int64()); }
  constexpr ap_int_base<ap_detail::max_i(I, 1), S> to_ap_int_base() const {
    return ap_int_base<ap_detail::max_i(I, 1), S>(*this);
  }
  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr explicit operator T() const {
    if constexpr (std::is_same_v<T, bool>) {
      return V != 0;
    } else {
      return static_cast<T>(to_int64());
    }
  }

  // ---- queries ----
  constexpr int length() const { return W; }
  constexpr bool is_zero() const { return V == 0; }
  constexpr bool is_neg() const { return ap_detail::is_neg(V); }
  constexpr bool sign() const { return ap_detail::is_neg(V); }
  constexpr bool and_reduce() const { return raw_bits() == ap_detail::mask128(W); }
  constexpr bool nand_reduce() const { return !and_reduce(); }
  constexpr bool or_reduce() const { return V != 0; }
  constexpr bool nor_reduce() const { return V == 0; }
  constexpr bool xor_reduce() const {
    const ap_detail::u128 b = raw_bits();
    return ((std::popcount(static_cast<uint64_t>(b)) + std::popcount(static_cast<uint64_t>(b >> 64))) & 1) != 0;
  }
  constexpr bool xnor_reduce() const { return !xor_reduce(); }
  constexpr int countLeadingZeros() const {
    const ap_detail::u128 b = raw_bits();
    const uint64_t h = static_cast<uint64_t>(b >> 64), l = static_cast<uint64_t>(b);
    const int lz128 = h ? std::countl_zero(h) : 64 + std::countl_zero(l);
    return lz128 - (128 - W);
  }

  // ---- bits: [] and bit() are raw indices; get_bit/set_bit are relative to the binary point
  // (raw index i + W − I; SEMANTICS.md §1) ----
  constexpr ap_bit_ref<ap_fixed_base> operator[](int i) { return ap_bit_ref<ap_fixed_base>(this, i); }
  constexpr ap_bit_ref<const ap_fixed_base> operator[](int i) const {
    return ap_bit_ref<const ap_fixed_base>(this, i);
  }
  constexpr ap_bit_ref<ap_fixed_base> bit(int i) { return (*this)[i]; }
  constexpr ap_bit_ref<const ap_fixed_base> bit(int i) const { return (*this)[i]; }
  constexpr bool get_bit(int i) const { return (*this)[i + W - I].get(); }
  constexpr void set_bit(int i, bool v) { (*this)[i + W - I] = v; }

  constexpr ap_range_ref<ap_fixed_base> range(int hi, int lo) {
    return ap_range_ref<ap_fixed_base>(this, hi, lo);
  }
  constexpr ap_range_ref<const ap_fixed_base> range(int hi, int lo) const {
    return ap_range_ref<const ap_fixed_base>(this, hi, lo);
  }
  constexpr ap_range_ref<ap_fixed_base> range() { return range(W - 1, 0); }
  constexpr ap_range_ref<const ap_fixed_base> range() const { return range(W - 1, 0); }
  constexpr ap_range_ref<ap_fixed_base> operator()(int hi, int lo) { return range(hi, lo); }
  constexpr ap_range_ref<const ap_fixed_base> operator()(int hi, int lo) const { return range(hi, lo); }

  template <class T, std::enable_if_t<ap_detail::concatable_v<T>, int> = 0>
  constexpr auto concat(const T& lo) const {
    return ap_int_base<W + std::remove_cv_t<T>::width, false>((*this, lo));
  }

  // ---- unary ----
  constexpr ap_fixed_base operator+() const { return *this; }
  constexpr ap_fixed_base<W + 1, I + 1, true> operator-() const {
    static_assert(W + 1 <= ap_detail::kMaxWidth, "ap_types: result wider than 128 bits");
    using R = ap_fixed_base<W + 1, I + 1, true>;
    using C = ap_detail::calc_t<W + 1>;
    R r;
    r.V = ap_detail::norm<W + 1, true>(static_cast<C>(C(0) - ap_detail::widen<C>(V)));
    return r;
  }
  constexpr ap_fixed_base operator~() const {
    ap_fixed_base r;
    r.V = ap_detail::norm<W, S>(~static_cast<ap_detail::u128>(V));
    return r;
  }
  constexpr bool operator!() const { return V == 0; }

  // ---- increments: x = x ± 1 with this type's quantization/overflow ----
  constexpr ap_fixed_base& operator++() { return *this = *this + ap_fixed_base<1, 1, false>(1); }
  constexpr ap_fixed_base& operator--() { return *this = *this - ap_fixed_base<1, 1, false>(1); }
  constexpr ap_fixed_base operator++(int) {
    ap_fixed_base t = *this;
    ++*this;
    return t;
  }
  constexpr ap_fixed_base operator--(int) {
    ap_fixed_base t = *this;
    --*this;
    return t;
  }

  // ---- shifts: raw, type-preserving, no quantization/overflow handling ----
  constexpr ap_fixed_base shl(int n) const {
    if (n < 0) return shr(-n);
    ap_fixed_base r;
    r.V = n >= W ? 0 : ap_detail::norm<W, S>(ap_detail::widen<ap_detail::calc_t<W>>(V) << n);
    return r;
  }
  constexpr ap_fixed_base shr(int n) const {
    if (n < 0) return shl(-n);
    ap_fixed_base r;
    if (n >= W) {
      r.V = ap_detail::is_neg(V) ? static_cast<storage_type>(-1) : 0;
    } else {
      r.V = static_cast<storage_type>(V >> n);
    }
    return r;
  }

  // ---- compound assignment: a = a op b, quantized/overflowed to a's type ----
  template <class T>
  constexpr ap_fixed_base& operator+=(const T& b) { return *this = *this + b; }
  template <class T>
  constexpr ap_fixed_base& operator-=(const T& b) { return *this = *this - b; }
  template <class T>
  constexpr ap_fixed_base& operator*=(const T& b) { return *this = *this * b; }
  template <class T>
  constexpr ap_fixed_base& operator/=(const T& b) { return *this = *this / b; }
  template <class T>
  constexpr ap_fixed_base& operator&=(const T& b) { return *this = *this & b; }
  template <class T>
  constexpr ap_fixed_base& operator|=(const T& b) { return *this = *this | b; }
  template <class T>
  constexpr ap_fixed_base& operator^=(const T& b) { return *this = *this ^ b; }
  template <class T>
  constexpr ap_fixed_base& operator<<=(const T& n) { return *this = *this << n; }
  template <class T>
  constexpr ap_fixed_base& operator>>=(const T& n) { return *this = *this >> n; }
};

template <int W, int I, ap_q_mode Q = AP_TRN, ap_o_mode O = AP_WRAP, int N = 0>
using ap_fixed = ap_fixed_base<W, I, true, Q, O, N>;
template <int W, int I, ap_q_mode Q = AP_TRN, ap_o_mode O = AP_WRAP, int N = 0>
using ap_ufixed = ap_fixed_base<W, I, false, Q, O, N>;

// ap_fixed -> ap_int: integer part truncated toward zero, then wrapped.
template <int W, bool S>
template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>
constexpr ap_int_base<W, S>::ap_int_base(const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& f)
    : V(0) {
  V = ap_detail::convert_from<W, S, AP_TRN_ZERO, AP_WRAP, 0>(f.V, W2 - I2);
}

// ---------------------------------------------------------------------------------------------
// Fixed-point operators
// ---------------------------------------------------------------------------------------------
namespace ap_detail {
template <int W1, int I1, bool S1, int W2, int I2, bool S2>
struct fixed_rtype {
  static constexpr int F1 = W1 - I1, F2 = W2 - I2;
  static constexpr int F = max_i(F1, F2);
  static constexpr int plus_i = max_i(I1 + (S2 && !S1), I2 + (S1 && !S2)) + 1;
  static constexpr int plus_w = plus_i + F;
  static constexpr int logic_i = plus_i - 1;
  static constexpr int logic_w = logic_i + F;
  static constexpr int mult_w = W1 + W2, mult_i = I1 + I2;
  static constexpr int div_w = S2 + W1 + max_i(F2, 0), div_i = S2 + I1 + F2;
  static constexpr bool sign = S1 || S2;
};

// Any ap operand or C integer as an ap_fixed_base (identity for ap_fixed_base).
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
AP_INLINE constexpr const ap_fixed_base<W, I, S, Q, O, N>& as_fixed(const ap_fixed_base<W, I, S, Q, O, N>& x) {
  return x;
}
template <int W, bool S>
AP_INLINE constexpr ap_fixed_base<W, W, S> as_fixed(const ap_int_base<W, S>& x) {
  ap_fixed_base<W, W, S> r;
  r.V = x.V;
  return r;
}
template <class T, std::enable_if_t<is_cint_v<T>, int> = 0>
AP_INLINE constexpr ap_fixed_base<cint_width_v<T>, cint_width_v<T>, cint_signed_v<T>> as_fixed(T x) {
  return as_fixed(cint_ap_t<T>(x));
}

template <int W1, int I1, bool S1, ap_q_mode Q1, ap_o_mode O1, int N1, int W2, int I2, bool S2,
          ap_q_mode Q2, ap_o_mode O2, int N2>
AP_INLINE constexpr int cmp_fixed(const ap_fixed_base<W1, I1, S1, Q1, O1, N1>& a,
                                  const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& b) {
  constexpr int F1 = W1 - I1, F2 = W2 - I2, F = max_i(F1, F2);
  constexpr int s1 = F - F1, s2 = F - F2;
  if constexpr (W1 + s1 + (!S1) <= 64 && W2 + s2 + (!S2) <= 64) {
    const int64_t x = static_cast<int64_t>(static_cast<uint64_t>(static_cast<int64_t>(a.V)) << s1);
    const int64_t y = static_cast<int64_t>(static_cast<uint64_t>(static_cast<int64_t>(b.V)) << s2);
    return (x > y) - (x < y);
  } else {
    wide x = to_wide(a.V), y = to_wide(b.V);
    // Align; a value that cannot be shifted within 129 bits is beyond the other's range.
    if constexpr (s1 > 0) {
      if (!fits(x.neg, x.u, 129 - s1, true)) return x.neg ? -1 : 1;
      x.u = s1 >= 128 ? 0 : (x.u << s1);
    }
    if constexpr (s2 > 0) {
      if (!fits(y.neg, y.u, 129 - s2, true)) return y.neg ? 1 : -1;
      y.u = s2 >= 128 ? 0 : (y.u << s2);
    }
    return wide_less(y, x) - wide_less(x, y);
  }
}
}  // namespace ap_detail

// Generates OP for (fixed, fixed); (fixed, ap_int), (ap_int, fixed); (fixed, C int), (C int, fixed).
#define AP_FIXED_MIXED_OPS(OP)                                                                     \
  template <int W1, int I1, bool S1, ap_q_mode Q1, ap_o_mode O1, int N1, int W2, bool S2>         \
  constexpr auto operator OP(const ap_fixed_base<W1, I1, S1, Q1, O1, N1>& a,                       \
                             const ap_int_base<W2, S2>& b) {                                       \
    return a OP ap_detail::as_fixed(b);                                                            \
  }                                                                                                \
  template <int W1, bool S1, int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>         \
  constexpr auto operator OP(const ap_int_base<W1, S1>& a,                                         \
                             const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& b) {                     \
    return ap_detail::as_fixed(a) OP b;                                                            \
  }                                                                                                \
  template <int W1, int I1, bool S1, ap_q_mode Q1, ap_o_mode O1, int N1, class T,                 \
            std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>                                    \
  constexpr auto operator OP(const ap_fixed_base<W1, I1, S1, Q1, O1, N1>& a, T b) {                \
    return a OP ap_detail::as_fixed(b);                                                            \
  }                                                                                                \
  template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2, class T,                 \
            std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>                                    \
  constexpr auto operator OP(T a, const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& b) {                \
    return ap_detail::as_fixed(a) OP b;                                                            \
  }

#define AP_FIXED_BINARY_OP(OP, WEXPR, IEXPR, SEXPR, ...)                                         \
  template <int W1, int I1, bool S1, ap_q_mode Q1, ap_o_mode O1, int N1, int W2, int I2, bool S2, \
            ap_q_mode Q2, ap_o_mode O2, int N2>                                                    \
  constexpr auto operator OP(const ap_fixed_base<W1, I1, S1, Q1, O1, N1>& a,                       \
                             const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& b) {                     \
    using RT = ap_detail::fixed_rtype<W1, I1, S1, W2, I2, S2>;                                     \
    constexpr int WR = WEXPR;                                                                      \
    constexpr int IR = IEXPR;                                                                      \
    constexpr bool SR = SEXPR;                                                                     \
    ap_detail::check_width<WR>();                                                                  \
    ap_fixed_base<WR, IR, SR> r;                                                                   \
    __VA_ARGS__;                                                                                   \
    return r;                                                                                      \
  }                                                                                                \
  AP_FIXED_MIXED_OPS(OP)

// Align both raw words to the result's F (exact: the result type holds both).
#define AP_FIXED_ALIGNED(...)                                                                     \
  using C = ap_detail::calc_t<WR>;                                                                 \
  constexpr int FR = WR - IR;                                                                      \
  const C x = static_cast<C>(ap_detail::widen<C>(a.V) << (FR - (W1 - I1)));                        \
  const C y = static_cast<C>(ap_detail::widen<C>(b.V) << (FR - (W2 - I2)));                        \
  r.V = ap_detail::norm<WR, SR>(static_cast<C>(__VA_ARGS__))

AP_FIXED_BINARY_OP(+, RT::plus_w, RT::plus_i, RT::sign, AP_FIXED_ALIGNED(x + y))
AP_FIXED_BINARY_OP(-, RT::plus_w, RT::plus_i, true, AP_FIXED_ALIGNED(x - y))
AP_FIXED_BINARY_OP(&, RT::logic_w, RT::logic_i, RT::sign, AP_FIXED_ALIGNED(x & y))
AP_FIXED_BINARY_OP(|, RT::logic_w, RT::logic_i, RT::sign, AP_FIXED_ALIGNED(x | y))
AP_FIXED_BINARY_OP(^, RT::logic_w, RT::logic_i, RT::sign, AP_FIXED_ALIGNED(x ^ y))
AP_FIXED_BINARY_OP(*, RT::mult_w, RT::mult_i, RT::sign, {
  using C = ap_detail::calc_t<WR>;
  r.V = ap_detail::norm<WR, SR>(static_cast<C>(ap_detail::widen<C>(a.V) * ap_detail::widen<C>(b.V)));
})
// Quotient raw = trunc((raw1 << max(F2,0)) / raw2) (SEMANTICS.md §1 "div").
AP_FIXED_BINARY_OP(/, RT::div_w, RT::div_i, RT::sign, {
  constexpr int sh = ap_detail::max_i(W2 - I2, 0);
  using C = ap_detail::calc_t<ap_detail::max_i(WR, ap_detail::max_i(W1 + sh, W2))>;
  AP_CHECK(b.V != 0, "ap_fixed division by zero");
  if (b.V != 0) {
    const C x = static_cast<C>(ap_detail::widen<C>(a.V) << sh);
    r.V = ap_detail::norm<WR, SR>(ap_detail::div_trunc<C>(x, ap_detail::is_neg(a.V),
                                                          ap_detail::widen<C>(b.V),
                                                          ap_detail::is_neg(b.V)));
  }
})
#undef AP_FIXED_ALIGNED
#undef AP_FIXED_BINARY_OP

#define AP_FIXED_CMP_OP(OP)                                                                        \
  template <int W1, int I1, bool S1, ap_q_mode Q1, ap_o_mode O1, int N1, int W2, int I2, bool S2, \
            ap_q_mode Q2, ap_o_mode O2, int N2>                                                    \
  constexpr bool operator OP(const ap_fixed_base<W1, I1, S1, Q1, O1, N1>& a,                       \
                             const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& b) {                     \
    return ap_detail::cmp_fixed(a, b) OP 0;                                                        \
  }                                                                                                \
  AP_FIXED_MIXED_OPS(OP)
AP_FIXED_CMP_OP(==)
AP_FIXED_CMP_OP(!=)
AP_FIXED_CMP_OP(<)
AP_FIXED_CMP_OP(>)
AP_FIXED_CMP_OP(<=)
AP_FIXED_CMP_OP(>=)
#undef AP_FIXED_CMP_OP
#undef AP_FIXED_MIXED_OPS

// Shifts: the operand's type; a negative signed amount reverses the direction.
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N, class T,
          std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
constexpr ap_fixed_base<W, I, S, Q, O, N> operator<<(const ap_fixed_base<W, I, S, Q, O, N>& a, T n) {
  if constexpr (std::is_signed_v<T>) {
    return a.shl(static_cast<int>(n < -1024 ? -1024 : (n > 1024 ? 1024 : n)));
  } else {
    return a.shl(static_cast<int>(n > 1024u ? 1024u : n));
  }
}
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N, class T,
          std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
constexpr ap_fixed_base<W, I, S, Q, O, N> operator>>(const ap_fixed_base<W, I, S, Q, O, N>& a, T n) {
  if constexpr (std::is_signed_v<T>) {
    return a.shr(static_cast<int>(n < -1024 ? -1024 : (n > 1024 ? 1024 : n)));
  } else {
    return a.shr(static_cast<int>(n > 1024u ? 1024u : n));
  }
}
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N, int W2, bool S2>
constexpr ap_fixed_base<W, I, S, Q, O, N> operator<<(const ap_fixed_base<W, I, S, Q, O, N>& a,
                                                     const ap_int_base<W2, S2>& n) {
  return a << static_cast<typename ap_int_base<W2, S2>::c_type>(n);
}
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N, int W2, bool S2>
constexpr ap_fixed_base<W, I, S, Q, O, N> operator>>(const ap_fixed_base<W, I, S, Q, O, N>& a,
                                                     const ap_int_base<W2, S2>& n) {
  return a >> static_cast<typename ap_int_base<W2, S2>::c_type>(n);
}
