// src/hw/hls_types/ap_int.h — our own ap_int<W> / ap_uint<W> (1 <= W <= 128), bit-exact to the
// vendor semantics of shared/hls/SEMANTICS.md §1 (Xilinx 2019.1 arbitrary-precision types).
// Same file name and public API as the vendor header, so a Vitis build swaps in the vendor's by
// include path. Including this header also defines ap_fixed / ap_ufixed (as the vendor's does).
//
// Result types of integer operators (W1,S1 op W2,S2; SEMANTICS.md §1, test_vectors.md §C):
//   *    : W1+W2,                                   signed iff S1||S2
//   + -  : max(W1+(S2&&!S1), W2+(S1&&!S2)) + 1,     '+' signed iff S1||S2, '-' always signed
//   /    : W1+S2 (quotient truncated toward zero),  signed iff S1||S2
//   %    : min(W1, W2+(!S2&&S1)),                   signedness of the dividend (C semantics)
//   & | ^: max(W1+(S2&&!S1), W2+(S1&&!S2)),         signed iff S1||S2
//   << >>: the left operand's type, bits shifted out are lost; a negative *signed* amount
//          shifts the other way.
// C integer operands act as ap_int/ap_uint of their C width (int -> ap_int<32>, bool -> 1 bit).
// Comparisons are exact across widths and signedness. Compound `a op= b` is `a = a op b`.
// A result wider than 128 bits is a compile error (cast an operand to a narrower type).
//
// Deviations (stricter than the vendor, C simulation only): out-of-range bit/range indices and
// division by zero print a message and abort; conversion from double is `explicit` and
// truncates toward zero for every value (the vendor's ap_int<8>(-0.1) == +1 quirk is not
// reproduced — never convert double to ap_int in kernels).
#pragma once

#include "ap_common.h"

// ---------------------------------------------------------------------------------------------
// Proxies: bit reference, range reference, concatenation.
// ---------------------------------------------------------------------------------------------

// Reference to raw bit `idx` of an ap_int_base / ap_fixed_base (P may be const).
template <class P>
struct ap_bit_ref {
  P* p;
  int idx;
  static constexpr int width = 1;

  constexpr ap_bit_ref(const ap_bit_ref&) = default;
  constexpr ap_bit_ref(P* parent, int index) : p(parent), idx(index) {
    AP_CHECK(index >= 0 && index < P::width, "bit index %d out of range [0, %d)", index,
             P::width);
  }
  constexpr ap_detail::u128 get_bits() const { return (p->raw_bits() >> idx) & 1; }
  constexpr void set_bits(ap_detail::u128 v) {
    static_assert(!std::is_const_v<P>, "ap_types: assignment to a bit of a const value");
    const ap_detail::u128 m = static_cast<ap_detail::u128>(1) << idx;
    p->set_raw_bits((p->raw_bits() & ~m) | ((v & 1) ? m : 0));
  }
  constexpr bool get() const { return get_bits() != 0; }
  constexpr operator bool() const { return get(); }
  constexpr bool to_bool() const { return get(); }
  constexpr bool operator~() const { return !get(); }
  constexpr bool operator!() const { return !get(); }
  constexpr int length() const { return 1; }

  constexpr ap_bit_ref& operator=(bool v) {
    set_bits(v ? 1 : 0);
    return *this;
  }
  constexpr ap_bit_ref& operator=(const ap_bit_ref& o) { return *this = o.get(); }
  template <class Q>
  constexpr ap_bit_ref& operator=(const ap_bit_ref<Q>& o) {
    return *this = o.get();
  }
  template <class T, std::enable_if_t<ap_detail::is_cint_v<T> && !std::is_same_v<T, bool>, int> = 0>
  constexpr ap_bit_ref& operator=(T v) {
    return *this = (v != 0);
  }
  template <int W2, bool S2>
  constexpr ap_bit_ref& operator=(const ap_int_base<W2, S2>& v) {
    return *this = !v.is_zero();
  }
};

// Reference to raw bits [hi:lo] of an ap_int_base / ap_fixed_base, read as ap_uint<P::width>
// (hi < lo reads/writes the bits reversed). P may be const (read-only).
template <class P>
struct ap_range_ref {
  P* p;
  int hi, lo;
  static constexpr int pwidth = P::width;

  constexpr ap_range_ref(const ap_range_ref&) = default;
  constexpr ap_range_ref(P* parent, int h, int l) : p(parent), hi(h), lo(l) {
    AP_CHECK(h >= 0 && h < P::width && l >= 0 && l < P::width,
             "range(%d, %d) out of range [0, %d)", h, l, P::width);
  }
  constexpr int length() const { return (hi >= lo ? hi - lo : lo - hi) + 1; }
  constexpr ap_detail::u128 get_bits() const {
    const ap_detail::u128 all = p->raw_bits();
    if (hi >= lo) return (all >> lo) & ap_detail::mask128(hi - lo + 1);
    return ap_detail::reverse_bits(all >> hi, lo - hi + 1);
  }
  constexpr void set_bits(ap_detail::u128 v) {
    static_assert(!std::is_const_v<P>, "ap_types: assignment to a range of a const value");
    const int n = length();
    const int base = hi >= lo ? lo : hi;
    v &= ap_detail::mask128(n);
    if (hi < lo) v = ap_detail::reverse_bits(v, n);
    const ap_detail::u128 m = ap_detail::mask128(n) << base;
    p->set_raw_bits((p->raw_bits() & ~m) | (v << base));
  }
  constexpr ap_int_base<pwidth, false> get() const;
  constexpr operator ap_int_base<pwidth, false>() const;
  constexpr uint64_t to_uint64() const { return static_cast<uint64_t>(get_bits()); }
  constexpr int64_t to_int64() const { return static_cast<int64_t>(get_bits()); }
  constexpr unsigned to_uint() const { return static_cast<unsigned>(get_bits()); }
  constexpr int to_int() const { return static_cast<int>(get_bits()); }
  constexpr bool and_reduce() const { return get_bits() == ap_detail::mask128(length()); }
  constexpr bool or_reduce() const { return get_bits() != 0; }
  constexpr bool xor_reduce() const { return (std::popcount(static_cast<uint64_t>(get_bits())) +
                                              std::popcount(static_cast<uint64_t>(get_bits() >> 64))) & 1; }

  constexpr ap_range_ref& operator=(const ap_range_ref& o) {
    set_bits(o.get_bits());
    return *this;
  }
  template <class Q>
  constexpr ap_range_ref& operator=(const ap_range_ref<Q>& o) {
    set_bits(o.get_bits());
    return *this;
  }
  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr ap_range_ref& operator=(T v) {
    set_bits(static_cast<ap_detail::u128>(v));  // two's complement bits of v
    return *this;
  }
  template <int W2, bool S2>
  constexpr ap_range_ref& operator=(const ap_int_base<W2, S2>& v) {
    set_bits(static_cast<ap_detail::u128>(v.V));
    return *this;
  }
  template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>
  constexpr ap_range_ref& operator=(const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& v) {
    set_bits(static_cast<ap_detail::u128>(v.V));  // raw bits
    return *this;
  }
};

// Handles of concatenation operands: objects by pointer, proxies by value.
template <class T>
struct ap_obj_handle {
  T* p;
  static constexpr int width = std::remove_const_t<T>::width;
  constexpr ap_detail::u128 get_bits() const { return p->raw_bits(); }
  constexpr void set_bits(ap_detail::u128 v) {
    static_assert(!std::is_const_v<T>, "ap_types: assignment to a concatenation of a const value");
    p->set_raw_bits(v);
  }
};

// (hi, lo) concatenation: width H::width + L::width, first operand in the high bits. Reads as
// ap_uint; assignable when both parts are (`(a, b) = x`).
template <class H, class L>
struct ap_concat_ref {
  H h;
  L l;
  static constexpr int width = H::width + L::width;
  static_assert(width <= ap_detail::kMaxWidth, "ap_types: concatenation wider than 128 bits");
  constexpr ap_detail::u128 get_bits() const {
    return (h.get_bits() << L::width) | (l.get_bits() & ap_detail::mask128(L::width));
  }
  constexpr void set_bits(ap_detail::u128 v) {
    l.set_bits(v & ap_detail::mask128(L::width));
    h.set_bits(L::width >= 128 ? 0 : (v >> L::width));
  }
  constexpr ap_int_base<width, false> get() const;
  constexpr operator ap_int_base<width, false>() const;
  constexpr uint64_t to_uint64() const { return static_cast<uint64_t>(get_bits()); }
  constexpr int length() const { return width; }
  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr ap_concat_ref& operator=(T v) {
    set_bits(static_cast<ap_detail::u128>(v));
    return *this;
  }
  template <int W2, bool S2>
  constexpr ap_concat_ref& operator=(const ap_int_base<W2, S2>& v) {
    set_bits(static_cast<ap_detail::u128>(v.V));
    return *this;
  }
  template <class P>
  constexpr ap_concat_ref& operator=(const ap_range_ref<P>& v) {
    set_bits(v.get_bits());
    return *this;
  }
};

namespace ap_detail {
template <class T>
struct is_value_proxy : std::false_type {};
template <class P>
struct is_value_proxy<ap_range_ref<P>> : std::true_type {};
template <class H, class L>
struct is_value_proxy<ap_concat_ref<H, L>> : std::true_type {};
template <class T>
inline constexpr bool is_value_proxy_v = is_value_proxy<std::remove_cv_t<std::remove_reference_t<T>>>::value;

template <class T>
struct is_ap_obj : std::false_type {};
template <int W, bool S>
struct is_ap_obj<ap_int_base<W, S>> : std::true_type {};
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
struct is_ap_obj<ap_fixed_base<W, I, S, Q, O, N>> : std::true_type {};

template <class T>
struct is_concat_proxy : std::false_type {};
template <class P>
struct is_concat_proxy<ap_bit_ref<P>> : std::true_type {};
template <class H, class L>
struct is_concat_proxy<ap_concat_ref<H, L>> : std::true_type {};

template <class T>
constexpr auto concat_handle(T& x) {
  if constexpr (is_ap_obj<std::remove_const_t<T>>::value) {
    return ap_obj_handle<T>{&x};
  } else {
    return std::remove_const_t<T>(x);
  }
}
template <class T>
inline constexpr bool concatable_v =
    is_ap_obj<std::remove_cv_t<std::remove_reference_t<T>>>::value ||
    is_concat_proxy<std::remove_cv_t<std::remove_reference_t<T>>>::value;
}  // namespace ap_detail

// Comma concatenation (a, b): `a` high. Operands: ap_int/ap_uint/ap_fixed/ap_ufixed (raw bits),
// bit references and nested concatenations.
template <class A, class B,
          std::enable_if_t<ap_detail::concatable_v<A> && ap_detail::concatable_v<B> &&
                               (std::remove_cvref_t<A>::width + std::remove_cvref_t<B>::width <=
                                ap_detail::kMaxWidth),
                           int> = 0>
constexpr auto operator,(A&& a, B&& b) {
  auto ha = ap_detail::concat_handle(a);
  auto hb = ap_detail::concat_handle(b);
  return ap_concat_ref<decltype(ha), decltype(hb)>{ha, hb};
}

// ---------------------------------------------------------------------------------------------
// ap_int_base<W,S>
// ---------------------------------------------------------------------------------------------

template <int W, bool S>
struct ap_int_base {
  static_assert(W >= 1 && W <= ap_detail::kMaxWidth, "ap_types: ap_int width must be in [1, 128]");
  using storage_type = ap_detail::storage_t<W, S>;
  static constexpr int width = W;
  static constexpr bool sign_flag = S;

  // Raw value, normalized (sign- or zero-extended above W). Implementation detail: kernels
  // use range()/[] for raw bits, as with the vendor header.
  storage_type V;

  // ---- construction ----
  constexpr ap_int_base() : V(0) {}
  constexpr ap_int_base(const ap_int_base&) = default;

  template <int W2, bool S2>
  constexpr ap_int_base(const ap_int_base<W2, S2>& o)
      : V(ap_detail::norm<W, S>(ap_detail::widen<ap_detail::calc_t<W>>(o.V))) {}

  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr ap_int_base(T v) : V(ap_detail::norm<W, S>(static_cast<ap_detail::calc_t<W>>(v))) {}

  // ap_fixed -> ap_int: integer part truncated toward zero, then wrapped (SEMANTICS.md §1).
  template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>
  constexpr ap_int_base(const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& f);

  // double/float -> ap_int: truncated toward zero, then wrapped (NaN -> 0). Explicit: kernels
  // never convert from floating point implicitly.
  constexpr explicit ap_int_base(double d) : V(from_double(d)) {}
  constexpr explicit ap_int_base(float f) : V(from_double(static_cast<double>(f))) {}

  template <class P>
  constexpr ap_int_base(const ap_range_ref<P>& r) : V(ap_detail::norm<W, S>(r.get_bits())) {}
  template <class P>
  constexpr ap_int_base(const ap_bit_ref<P>& b) : V(ap_detail::norm<W, S>(b.get_bits())) {}
  template <class H, class L>
  constexpr ap_int_base(const ap_concat_ref<H, L>& c) : V(ap_detail::norm<W, S>(c.get_bits())) {}

  static constexpr storage_type from_double(double d) {
    const ap_detail::double_parts p = ap_detail::split_double(d);
    return ap_detail::convert<W, S, AP_TRN_ZERO, AP_WRAP, 0>(p.x.neg, p.x.u, -p.exp2);
  }

  // ---- assignment ----
  constexpr ap_int_base& operator=(const ap_int_base&) = default;
  template <int W2, bool S2>
  constexpr ap_int_base& operator=(const ap_int_base<W2, S2>& o) {
    V = ap_int_base(o).V;
    return *this;
  }
  template <class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
  constexpr ap_int_base& operator=(T v) {
    V = ap_int_base(v).V;
    return *this;
  }
  template <int W2, int I2, bool S2, ap_q_mode Q2, ap_o_mode O2, int N2>
  constexpr ap_int_base& operator=(const ap_fixed_base<W2, I2, S2, Q2, O2, N2>& f) {
    V = ap_int_base(f).V;
    return *this;
  }
  template <class P>
  constexpr ap_int_base& operator=(const ap_range_ref<P>& r) {
    V = ap_detail::norm<W, S>(r.get_bits());
    return *this;
  }
  template <class P>
  constexpr ap_int_base& operator=(const ap_bit_ref<P>& b) {
    V = ap_detail::norm<W, S>(b.get_bits());
    return *this;
  }
  template <class H, class L>
  constexpr ap_int_base& operator=(const ap_concat_ref<H, L>& c) {
    V = ap_detail::norm<W, S>(c.get_bits());
    return *this;
  }

  // ---- raw bits (zero-extended W-bit word) ----
  constexpr ap_detail::u128 raw_bits() const {
    return static_cast<ap_detail::u128>(V) & ap_detail::mask128(W);
  }
  constexpr void set_raw_bits(ap_detail::u128 b) { V = ap_detail::norm<W, S>(b); }

  // ---- conversion to C types ----
  // Implicit, to (unsigned) long long (the low 64 bits for W > 64), so that array indexing,
  // switch and C expressions work as with the vendor header.
  using c_type = std::conditional_t<S, long long, unsigned long long>;
  constexpr operator c_type() const { return static_cast<c_type>(V); }

  constexpr int to_int() const { return static_cast<int>(V); }
  constexpr unsigned to_uint() const { return static_cast<unsigned>(V); }
  constexpr long to_long() const { return static_cast<long>(V); }
  constexpr unsigned long to_ulong() const { return static_cast<unsigned long>(V); }
  constexpr int64_t to_int64() const { return static_cast<int64_t>(V); }
  constexpr uint64_t to_uint64() const { return static_cast<uint64_t>(V); }
  constexpr bool to_bool() const { return V != 0; }
  double to_double() const { return static_cast<double>(V); }
  float to_float() const { return static_cast<float>(V); }

  // ---- queries ----
  constexpr int length() const { return W; }
  constexpr bool is_zero() const { return V == 0; }
  constexpr bool sign() const { return ap_detail::is_neg(V); }
  constexpr bool is_neg() const { return ap_detail::is_neg(V); }
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

  // ---- bits ----
  constexpr ap_bit_ref<ap_int_base> operator[](int i) { return ap_bit_ref<ap_int_base>(this, i); }
  constexpr ap_bit_ref<const ap_int_base> operator[](int i) const {
    return ap_bit_ref<const ap_int_base>(this, i);
  }
  constexpr ap_bit_ref<ap_int_base> bit(int i) { return (*this)[i]; }
  constexpr ap_bit_ref<const ap_int_base> bit(int i) const { return (*this)[i]; }
  constexpr bool get_bit(int i) const { return (*this)[i].get(); }
  constexpr void set_bit(int i, bool v) { (*this)[i] = v; }
  constexpr bool test(int i) const { return get_bit(i); }
  constexpr void set(int i) { set_bit(i, true); }
  constexpr void clear(int i) { set_bit(i, false); }
  constexpr void invert(int i) { set_bit(i, !get_bit(i)); }
  constexpr void reverse() { set_raw_bits(ap_detail::reverse_bits(raw_bits(), W)); }
  // Rotations by n (0 <= n < W) within the W bits.
  constexpr void lrotate(int n) {
    AP_CHECK(n >= 0 && n < W, "lrotate(%d) out of range [0, %d)", n, W);
    const ap_detail::u128 b = raw_bits();
    set_raw_bits(n == 0 ? b : ((b << n) | (b >> (W - n))));
  }
  constexpr void rrotate(int n) {
    AP_CHECK(n >= 0 && n < W, "rrotate(%d) out of range [0, %d)", n, W);
    const ap_detail::u128 b = raw_bits();
    set_raw_bits(n == 0 ? b : ((b >> n) | (b << (W - n))));
  }
  constexpr void b_not() { V = ap_detail::norm<W, S>(~static_cast<ap_detail::u128>(V)); }

  constexpr ap_range_ref<ap_int_base> range(int hi, int lo) { return ap_range_ref<ap_int_base>(this, hi, lo); }
  constexpr ap_range_ref<const ap_int_base> range(int hi, int lo) const {
    return ap_range_ref<const ap_int_base>(this, hi, lo);
  }
  constexpr ap_range_ref<ap_int_base> range() { return range(W - 1, 0); }
  constexpr ap_range_ref<const ap_int_base> range() const { return range(W - 1, 0); }
  constexpr ap_range_ref<ap_int_base> operator()(int hi, int lo) { return range(hi, lo); }
  constexpr ap_range_ref<const ap_int_base> operator()(int hi, int lo) const { return range(hi, lo); }

  // Concatenation by value: W + W2 bits, *this in the high bits.
  template <class T, std::enable_if_t<ap_detail::concatable_v<T>, int> = 0>
  constexpr auto concat(const T& lo) const {
    return ap_int_base<W + std::remove_cv_t<T>::width, false>((*this, lo));
  }

  // ---- unary ----
  constexpr ap_int_base operator+() const { return *this; }
  constexpr auto operator-() const;
  constexpr ap_int_base operator~() const {
    ap_int_base r;
    r.V = ap_detail::norm<W, S>(~static_cast<ap_detail::u128>(V));
    return r;
  }
  constexpr bool operator!() const { return V == 0; }

  // ---- increments (wrap) ----
  constexpr ap_int_base& operator++() {
    V = ap_detail::norm<W, S>(ap_detail::widen<ap_detail::calc_t<W>>(V) + 1);
    return *this;
  }
  constexpr ap_int_base& operator--() {
    V = ap_detail::norm<W, S>(ap_detail::widen<ap_detail::calc_t<W>>(V) - 1);
    return *this;
  }
  constexpr ap_int_base operator++(int) {
    ap_int_base t = *this;
    ++*this;
    return t;
  }
  constexpr ap_int_base operator--(int) {
    ap_int_base t = *this;
    --*this;
    return t;
  }

  // ---- shifts (type-preserving) ----
  constexpr ap_int_base shl(int n) const {
    ap_int_base r;
    if (n < 0) return shr(-n);
    r.V = n >= W ? 0 : ap_detail::norm<W, S>(ap_detail::widen<ap_detail::calc_t<W>>(V) << n);
    return r;
  }
  constexpr ap_int_base shr(int n) const {
    ap_int_base r;
    if (n < 0) return shl(-n);
    if (n >= W) {
      r.V = ap_detail::is_neg(V) ? static_cast<storage_type>(-1) : 0;
    } else {
      r.V = static_cast<storage_type>(V >> n);  // arithmetic for signed (C++20), logical unsigned
    }
    return r;
  }

  // ---- compound assignment (a = a op b) ----
  template <class T>
  constexpr ap_int_base& operator+=(const T& b) { return *this = *this + b; }
  template <class T>
  constexpr ap_int_base& operator-=(const T& b) { return *this = *this - b; }
  template <class T>
  constexpr ap_int_base& operator*=(const T& b) { return *this = *this * b; }
  template <class T>
  constexpr ap_int_base& operator/=(const T& b) { return *this = *this / b; }
  template <class T>
  constexpr ap_int_base& operator%=(const T& b) { return *this = *this % b; }
  template <class T>
  constexpr ap_int_base& operator&=(const T& b) { return *this = *this & b; }
  template <class T>
  constexpr ap_int_base& operator|=(const T& b) { return *this = *this | b; }
  template <class T>
  constexpr ap_int_base& operator^=(const T& b) { return *this = *this ^ b; }
  template <class T>
  constexpr ap_int_base& operator<<=(const T& n) { return *this = *this << n; }
  template <class T>
  constexpr ap_int_base& operator>>=(const T& n) { return *this = *this >> n; }
};

template <int W>
using ap_int = ap_int_base<W, true>;
template <int W>
using ap_uint = ap_int_base<W, false>;

// Proxy member definitions that need ap_int_base complete.
template <class P>
constexpr ap_int_base<ap_range_ref<P>::pwidth, false> ap_range_ref<P>::get() const {
  return ap_int_base<pwidth, false>(*this);
}
template <class P>
constexpr ap_range_ref<P>::operator ap_int_base<ap_range_ref<P>::pwidth, false>() const {
  return get();
}
template <class H, class L>
constexpr ap_int_base<ap_concat_ref<H, L>::width, false> ap_concat_ref<H, L>::get() const {
  return ap_int_base<width, false>(*this);
}
template <class H, class L>
constexpr ap_concat_ref<H, L>::operator ap_int_base<ap_concat_ref<H, L>::width, false>() const {
  return get();
}

// ---------------------------------------------------------------------------------------------
// Integer operators
// ---------------------------------------------------------------------------------------------
namespace ap_detail {
template <int W1, bool S1, int W2, bool S2>
struct int_rtype {
  static constexpr int mult_w = W1 + W2;
  static constexpr int plus_w = max_i(W1 + (S2 && !S1), W2 + (S1 && !S2)) + 1;
  static constexpr int logic_w = max_i(W1 + (S2 && !S1), W2 + (S1 && !S2));
  static constexpr int div_w = W1 + S2;
  static constexpr int mod_w = min_i(W1, W2 + (!S2 && S1));
  static constexpr bool sign = S1 || S2;
};

template <class T>
using cint_ap_t = ap_int_base<cint_width_v<T>, cint_signed_v<T>>;

template <int WR>
AP_INLINE constexpr void check_width() {
  static_assert(WR <= kMaxWidth,
                "ap_types: result wider than 128 bits (cast an operand to a narrower type)");
}
}  // namespace ap_detail

#define AP_INT_BINARY_OP(OP, WEXPR, SEXPR, ...)                                                 \
  template <int W1, bool S1, int W2, bool S2>                                                    \
  constexpr auto operator OP(const ap_int_base<W1, S1>& a, const ap_int_base<W2, S2>& b) {       \
    using RT = ap_detail::int_rtype<W1, S1, W2, S2>;                                             \
    constexpr int WR = WEXPR;                                                                    \
    constexpr bool SR = SEXPR;                                                                   \
    ap_detail::check_width<WR>();                                                                \
    using C = ap_detail::calc_t<ap_detail::max_i(WR, ap_detail::max_i(W1, W2))>;                \
    const C x = ap_detail::widen<C>(a.V);                                                        \
    const C y = ap_detail::widen<C>(b.V);                                                        \
    ap_int_base<WR, SR> r;                                                                       \
    __VA_ARGS__;                                                                                 \
    return r;                                                                                    \
  }                                                                                              \
  template <int W1, bool S1, class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>       \
  constexpr auto operator OP(const ap_int_base<W1, S1>& a, T b) {                                \
    return a OP ap_detail::cint_ap_t<T>(b);                                                      \
  }                                                                                              \
  template <int W2, bool S2, class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>       \
  constexpr auto operator OP(T a, const ap_int_base<W2, S2>& b) {                                \
    return ap_detail::cint_ap_t<T>(a) OP b;                                                      \
  }

AP_INT_BINARY_OP(+, RT::plus_w, RT::sign, r.V = ap_detail::norm<WR, SR>(static_cast<C>(x + y)))
AP_INT_BINARY_OP(-, RT::plus_w, true, r.V = ap_detail::norm<WR, SR>(static_cast<C>(x - y)))
AP_INT_BINARY_OP(*, RT::mult_w, RT::sign, r.V = ap_detail::norm<WR, SR>(static_cast<C>(x * y)))
AP_INT_BINARY_OP(&, RT::logic_w, RT::sign, r.V = ap_detail::norm<WR, SR>(static_cast<C>(x & y)))
AP_INT_BINARY_OP(|, RT::logic_w, RT::sign, r.V = ap_detail::norm<WR, SR>(static_cast<C>(x | y)))
AP_INT_BINARY_OP(^, RT::logic_w, RT::sign, r.V = ap_detail::norm<WR, SR>(static_cast<C>(x ^ y)))
AP_INT_BINARY_OP(/, RT::div_w, RT::sign,
                 AP_CHECK(b.V != 0, "ap_int division by zero");
                 if (b.V != 0) r.V = ap_detail::norm<WR, SR>(
                     ap_detail::div_trunc<C>(x, ap_detail::is_neg(a.V), y, ap_detail::is_neg(b.V))))
AP_INT_BINARY_OP(%, RT::mod_w, S1,
                 AP_CHECK(b.V != 0, "ap_int modulo by zero");
                 if (b.V != 0) r.V = ap_detail::norm<WR, SR>(
                     ap_detail::mod_trunc<C>(x, ap_detail::is_neg(a.V), y, ap_detail::is_neg(b.V))))
#undef AP_INT_BINARY_OP

template <int W, bool S>
constexpr auto ap_int_base<W, S>::operator-() const {
  return ap_int_base<1, false>(0) - *this;
}

// Shifts: type of the left operand. A negative signed amount reverses the direction; an
// unsigned amount never does.
template <int W, bool S, class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
constexpr ap_int_base<W, S> operator<<(const ap_int_base<W, S>& a, T n) {
  if constexpr (std::is_signed_v<T>) {
    return a.shl(static_cast<int>(n < -1024 ? -1024 : (n > 1024 ? 1024 : n)));
  } else {
    return a.shl(static_cast<int>(n > 1024u ? 1024u : n));
  }
}
template <int W, bool S, class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>
constexpr ap_int_base<W, S> operator>>(const ap_int_base<W, S>& a, T n) {
  if constexpr (std::is_signed_v<T>) {
    return a.shr(static_cast<int>(n < -1024 ? -1024 : (n > 1024 ? 1024 : n)));
  } else {
    return a.shr(static_cast<int>(n > 1024u ? 1024u : n));
  }
}
template <int W, bool S, int W2, bool S2>
constexpr ap_int_base<W, S> operator<<(const ap_int_base<W, S>& a, const ap_int_base<W2, S2>& n) {
  return a << static_cast<typename ap_int_base<W2, S2>::c_type>(n);
}
template <int W, bool S, int W2, bool S2>
constexpr ap_int_base<W, S> operator>>(const ap_int_base<W, S>& a, const ap_int_base<W2, S2>& n) {
  return a >> static_cast<typename ap_int_base<W2, S2>::c_type>(n);
}

// Comparisons: exact values.
namespace ap_detail {
template <int W1, bool S1, int W2, bool S2>
AP_INLINE constexpr int cmp_int(const ap_int_base<W1, S1>& a, const ap_int_base<W2, S2>& b) {
  if constexpr (W1 + (!S1) <= 64 && W2 + (!S2) <= 64) {
    const int64_t x = static_cast<int64_t>(a.V), y = static_cast<int64_t>(b.V);
    return (x > y) - (x < y);
  } else {
    const wide x = to_wide(a.V), y = to_wide(b.V);
    return wide_less(y, x) - wide_less(x, y);
  }
}
}  // namespace ap_detail

#define AP_INT_CMP_OP(OP)                                                                     \
  template <int W1, bool S1, int W2, bool S2>                                                 \
  constexpr bool operator OP(const ap_int_base<W1, S1>& a, const ap_int_base<W2, S2>& b) {    \
    return ap_detail::cmp_int(a, b) OP 0;                                                     \
  }                                                                                           \
  template <int W1, bool S1, class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>    \
  constexpr bool operator OP(const ap_int_base<W1, S1>& a, T b) {                             \
    return ap_detail::cmp_int(a, ap_detail::cint_ap_t<T>(b)) OP 0;                            \
  }                                                                                           \
  template <int W2, bool S2, class T, std::enable_if_t<ap_detail::is_cint_v<T>, int> = 0>    \
  constexpr bool operator OP(T a, const ap_int_base<W2, S2>& b) {                             \
    return ap_detail::cmp_int(ap_detail::cint_ap_t<T>(a), b) OP 0;                            \
  }
AP_INT_CMP_OP(==)
AP_INT_CMP_OP(!=)
AP_INT_CMP_OP(<)
AP_INT_CMP_OP(>)
AP_INT_CMP_OP(<=)
AP_INT_CMP_OP(>=)
#undef AP_INT_CMP_OP

// Range / concatenation references in expressions behave as their ap_uint value.
#define AP_PROXY_BINARY_OP(OP)                                                                  \
  template <class A, class B,                                                                   \
            std::enable_if_t<ap_detail::is_value_proxy_v<A> || ap_detail::is_value_proxy_v<B>,  \
                             int> = 0>                                                          \
  constexpr auto operator OP(const A& a, const B& b) {                                          \
    if constexpr (ap_detail::is_value_proxy_v<A> && ap_detail::is_value_proxy_v<B>) {           \
      return a.get() OP b.get();                                                                \
    } else if constexpr (ap_detail::is_value_proxy_v<A>) {                                      \
      return a.get() OP b;                                                                      \
    } else {                                                                                    \
      return a OP b.get();                                                                      \
    }                                                                                           \
  }
AP_PROXY_BINARY_OP(+)
AP_PROXY_BINARY_OP(-)
AP_PROXY_BINARY_OP(*)
AP_PROXY_BINARY_OP(/)
AP_PROXY_BINARY_OP(%)
AP_PROXY_BINARY_OP(&)
AP_PROXY_BINARY_OP(|)
AP_PROXY_BINARY_OP(^)
AP_PROXY_BINARY_OP(==)
AP_PROXY_BINARY_OP(!=)
AP_PROXY_BINARY_OP(<)
AP_PROXY_BINARY_OP(>)
AP_PROXY_BINARY_OP(<=)
AP_PROXY_BINARY_OP(>=)
#undef AP_PROXY_BINARY_OP
template <class A, class B, std::enable_if_t<ap_detail::is_value_proxy_v<A>, int> = 0>
constexpr auto operator<<(const A& a, const B& n) {
  return a.get() << n;
}
template <class A, class B, std::enable_if_t<ap_detail::is_value_proxy_v<A>, int> = 0>
constexpr auto operator>>(const A& a, const B& n) {
  return a.get() >> n;
}

#include "ap_fixed.h"
