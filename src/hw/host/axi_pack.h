// src/hw/host/axi_pack.h — the bytes a board driver writes for the hw tops' interfaces (host
// side, not a kernel): every m_axi array (DDR) and every s_axilite struct (AXI4-Lite registers)
// of HwInitTop, HwWeighTop5/10 and HwUpdateTop, laid out as Vitis HLS lays out an aggregated
// struct, and read back. docs/HW_PACKING.md has the rule, its sources and each struct's table.
//
// The rule (AMD UG1399, Vitis HLS User Guide; UG1391, Vitis HLS Migration Guide):
//  * A struct argument of an AXI interface (m_axi, s_axilite) is aggregated into one wide word
//    with compact=none, its default for AXI ports ("Vitis HLS Alignment Rules and Semantics",
//    the table of interface arguments; compact=bit is refused on AXI ports: "Structs on the
//    Interface"). The fields follow in declaration order, the first at the least significant
//    end ("Structs on the Interface", "pragma HLS aggregate"); nested structs and arrays are
//    flattened in order, array elements from the lowest index up ("Vitis HLS Alignment Rules and
//    Semantics").
//  * compact=none keeps the C data layout, the one gcc gives the host's structs ("Vitis HLS
//    Memory Layout Model", "Data Alignment", "Data Structure Padding", "Structs": kernel structs
//    are padded as gcc pads them):
//      - an ap_[u]int<W> / ap_[u]fixed<W,…> field occupies the smallest power-of-two number of
//        bytes that holds W bits: 1 (W ≤ 8), 2 (≤ 16), 4 (≤ 32), 8 (≤ 64) ("Struct Padding and
//        Alignment"; UG1391 "Data Layout for Arbitrary Precision Types (ap_int library)": an
//        ap_int<5> takes 8 bits, a bool 8 bits); bool 1 byte, int and uint32_t 4 bytes;
//      - a scalar is aligned to its size, a struct to the largest alignment of its fields, an
//        array to its element's; each field starts at the next offset that is a multiple of its
//        alignment, and a struct's size is rounded up to a multiple of its alignment;
//      - an array of structs on an m_axi port holds element i at byte i · size (the element
//        stride is the struct's size; the port's bus word is that size rounded up to a power of
//        two, "Impact of Struct Size on Pipelining", which does not move the elements).
//  * Byte order: little endian. Byte k of the image is bits 8k+7 … 8k of the aggregated word,
//    so a field's value sits at the low end of its bytes. The bits of a field above W hold the
//    sign extension of a signed type (ap_int, ap_fixed, int) and 0 for an unsigned one, as the
//    vendor's C model stores them; the padding bytes between and after fields are 0. Unpack
//    reads only the W value bits of each field: what the hardware writes in the other bits is
//    not specified by UG1399 and does not matter.
//  * The flow: our tcl opens the Vivado IP flow (open_solution -flow_target vivado). There an
//    m_axi buffer may start at any byte (m_axi_alignment_byte_size 1; the Vitis kernel flow
//    assumes 64: "Default Settings of Vivado/Vitis Flows"), and where "Structs on the Interface"
//    aligns struct elements on 4 bytes in the Vitis kernel flow and on 1 byte in the Vivado IP
//    flow without saying more, we take the Vivado IP flow's value: no alignment beyond the
//    natural one above.
//  * Checked once against the vendor's public C-model headers (HLS_arbitrary_Precision_Types,
//    g++ -std=c++17, x86-64): Pack gives the field bytes of each struct's memory, and
//    sizeof(T) = PackedBytes<T>(). Not checked against RTL (no Vitis here).
//
// The API (header only, C++17 so that the HLS test benches compile it under Vitis's -std=c++17,
// and only the API common to the vendor's ap types: .range(hi, lo), .to_uint64(), constructors):
//   VisitFields(s, v)        one function per struct, its fields in declaration order: v(name, field)
//   LayoutOf<T>()            the layout of T: size, alignment, every scalar field (name, byte
//                            offset, bytes, bits, signedness)
//   ForEachScalar(obj, f)    f(scalar) for each scalar of obj, in the order of LayoutOf's fields
//   PackedBytes<T>()         bytes of one T as laid out
//   Pack(elems, count)       count T's → bytes (an m_axi buffer, or with count 1 a register image)
//   Unpack(bytes, count, out) the inverse (value bits only)
//   RegisterWords(bytes)     a register image as the 32-bit AXI4-Lite words, LSB first
//   DescribeLayout<T>(title) the layout as a printable table
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

#include "hw/top.h"

namespace posefilter::hw::axi {

// ---- Field visitors: one per struct that crosses a top's port (or is nested in one) ----
// v(name, field) for each field in declaration order; S is the struct, const or not (packing
// visits a const struct, unpacking a mutable one).

template <class S, class T>
using IfStruct = std::enable_if_t<std::is_same_v<std::remove_const_t<S>, T>, int>;

template <class S, class V, IfStruct<S, Sample> = 0>
void VisitFields(S& s, V&& v) {
  v("x", s.x);
  v("y", s.y);
  v("z", s.z);
  v("roll", s.roll);
  v("pitch", s.pitch);
  v("yaw", s.yaw);
  v("cell", s.cell);
}
template <class S, class V, IfStruct<S, HeuristicVolume> = 0>
void VisitFields(S& s, V&& v) {
  v("x_min", s.x_min);
  v("y_min", s.y_min);
  v("z_min", s.z_min);
  v("x_max", s.x_max);
  v("y_max", s.y_max);
  v("z_max", s.z_max);
}
template <class S, class V, IfStruct<S, Window> = 0>
void VisitFields(S& s, V&& v) {
  v("u0", s.u0);
  v("v0", s.v0);
  v("width", s.width);
  v("height", s.height);
}
template <class S, class V, IfStruct<S, RasterCoreOutput> = 0>
void VisitFields(S& s, V&& v) {
  v("inlier_sum", s.inlier_sum);
  v("n_raster", s.n_raster);
  v("n_occluded", s.n_occluded);
  v("n_depth", s.n_depth);
  v("depth_diff_sum", s.depth_diff_sum);
  v("depth_diff_count", s.depth_diff_count);
  v("n_edge", s.n_edge);
  v("n_edge_continued", s.n_edge_continued);
  v("faces_front", s.faces_front);
  v("faces_total", s.faces_total);
}
template <class S, class V, IfStruct<S, CameraParams> = 0>
void VisitFields(S& s, V&& v) {
  v("fx", s.fx);
  v("fy", s.fy);
  v("cx", s.cx);
  v("cy", s.cy);
  v("rot", s.rot);
  v("trans", s.trans);
}
template <class S, class V, IfStruct<S, RasterParams> = 0>
void VisitFields(S& s, V&& v) {
  v("zbuffer", s.zbuffer);
  v("hard", s.hard);
  v("thr1", s.thr1);
  v("inv_thr1", s.inv_thr1);
  v("hard_thr", s.hard_thr);
  v("align_band", s.align_band);
  v("edge_band", s.edge_band);
  v("near_plane", s.near_plane);
}
template <class S, class V, IfStruct<S, WeightParams> = 0>
void VisitFields(S& s, V&& v) {
  v("alpha", s.alpha);
  v("beta", s.beta);
  v("gamma", s.gamma);
  v("delta", s.delta);
  v("occlusion_aware", s.occlusion_aware);
}
template <class S, class V, IfStruct<S, WeighConfig> = 0>
void VisitFields(S& s, V&& v) {
  v("num_cores", s.num_cores);
  v("num_faces", s.num_faces);
  v("img_width", s.img_width);
  v("cam", s.cam);
  v("raster", s.raster);
  v("weight", s.weight);
  v("grow_window", s.grow_window);
  v("img_height", s.img_height);
  v("max_window", s.max_window);
  v("bbox", s.bbox);
}
template <class S, class V, IfStruct<S, DepthDistributionCounts> = 0>
void VisitFields(S& s, V&& v) {
  v("reads_shared", s.reads_shared);
  v("reads_unshared", s.reads_unshared);
}

// The LFSRs (Lfsr18, Lfsr15): one register each.
template <class T>
struct IsLfsr : std::false_type {};
template <int W, int kTap, unsigned kSeed, int kLeap>
struct IsLfsr<FibonacciLfsr<W, kTap, kSeed, kLeap>> : std::true_type {};
template <class S, class V, std::enable_if_t<IsLfsr<std::remove_const_t<S>>::value, int> = 0>
void VisitFields(S& s, V&& v) {
  v("state", s.state);
}
template <class S, class V, IfStruct<S, InitGenerators> = 0>
void VisitFields(S& s, V&& v) {
  v("sampling", s.sampling);
  v("z", s.z);
  v("roll", s.roll);
  v("pitch", s.pitch);
  v("yaw", s.yaw);
}
template <class S, class V, IfStruct<S, InitOptions> = 0>
void VisitFields(S& s, V&& v) {
  v("use_tracker", s.use_tracker);
  v("leap", s.leap);
}
template <class S, class V, IfStruct<S, SamplingCounters> = 0>
void VisitFields(S& s, V&& v) {
  v("reads", s.reads);
  v("reads_linear", s.reads_linear);
  v("draws", s.draws);
}
template <class S, class V, IfStruct<S, InitReport> = 0>
void VisitFields(S& s, V&& v) {
  v("counters", s.counters);
  v("uniform_fallback", s.uniform_fallback);
}
template <class S, class V, IfStruct<S, ResampleParams> = 0>
void VisitFields(S& s, V&& v) {
  v("num_particles", s.num_particles);
  v("num_elite", s.num_elite);
  v("pool_size", s.pool_size);
  v("region_cap", s.region_cap);
  v("rotation_cap", s.rotation_cap);
}
template <class S, class V, IfStruct<S, ResampleCounters> = 0>
void VisitFields(S& s, V&& v) {
  v("draws", s.draws);
  v("cdf_reads", s.cdf_reads);
  v("cdf_reads_linear", s.cdf_reads_linear);
  v("pool", s.pool);
}
template <class S, class V, IfStruct<S, DiffusionParams> = 0>
void VisitFields(S& s, V&& v) {
  v("move_thr", s.move_thr);
  v("sigma_t0", s.sigma_t0);
  v("sigma_r0", s.sigma_r0);
  v("min_fraction", s.min_fraction);
  v("sigma_floor_lsb", s.sigma_floor_lsb);
  v("cam_row_z", s.cam_row_z);
  v("cam_origin", s.cam_origin);
}
template <class S, class V, IfStruct<S, GaussianSource> = 0>
void VisitFields(S& s, V&& v) {
  v("u1", s.u1);
  v("u2", s.u2);
  v("cos_from_sqrt", s.cos_from_sqrt);
}
template <class S, class V, IfStruct<S, DiffusionRng> = 0>
void VisitFields(S& s, V&& v) {
  v("move_lfsr", s.move_lfsr);
  v("aux_lfsr", s.aux_lfsr);
  v("g0", s.g0);
  v("g1", s.g1);
}

// ---- Scalars: storage bytes, value bits, raw bits in and out ----

// Bytes of a W-bit arbitrary-precision field: the smallest power of two ≥ W/8 (≤ 8: fields
// wider than 64 bits do not cross our ports).
constexpr int StorageBytes(int bits) { return bits <= 8 ? 1 : bits <= 16 ? 2 : bits <= 32 ? 4 : 8; }

// Scalar<T>: kBits value bits, kSigned, Get (the W raw bits, zero-extended) and Set (from raw
// bits). Not a scalar: kIs = false.
template <class T, class = void>
struct Scalar {
  static constexpr bool kIs = false;
};
template <int W>
struct Scalar<ap_uint<W>> {
  static_assert(W <= 64, "axi_pack: fields wider than 64 bits are not supported");
  static constexpr bool kIs = true, kSigned = false;
  static constexpr int kBits = W;
  static uint64_t Get(const ap_uint<W>& x) { return x.to_uint64(); }
  static void Set(ap_uint<W>& x, uint64_t v) { x = ap_uint<W>(v); }
};
template <int W>
struct Scalar<ap_int<W>> {
  static_assert(W <= 64, "axi_pack: fields wider than 64 bits are not supported");
  static constexpr bool kIs = true, kSigned = true;
  static constexpr int kBits = W;
  static uint64_t Get(const ap_int<W>& x) { return ap_uint<W>(x.range(W - 1, 0)).to_uint64(); }
  static void Set(ap_int<W>& x, uint64_t v) { x.range(W - 1, 0) = ap_uint<W>(v); }
};
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
struct Scalar<ap_fixed<W, I, Q, O, N>> {
  static_assert(W <= 64, "axi_pack: fields wider than 64 bits are not supported");
  static constexpr bool kIs = true, kSigned = true;
  static constexpr int kBits = W;
  static uint64_t Get(const ap_fixed<W, I, Q, O, N>& x) { return ap_uint<W>(x.range(W - 1, 0)).to_uint64(); }
  static void Set(ap_fixed<W, I, Q, O, N>& x, uint64_t v) { x.range(W - 1, 0) = ap_uint<W>(v); }
};
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
struct Scalar<ap_ufixed<W, I, Q, O, N>> {
  static_assert(W <= 64, "axi_pack: fields wider than 64 bits are not supported");
  static constexpr bool kIs = true, kSigned = false;
  static constexpr int kBits = W;
  static uint64_t Get(const ap_ufixed<W, I, Q, O, N>& x) { return ap_uint<W>(x.range(W - 1, 0)).to_uint64(); }
  static void Set(ap_ufixed<W, I, Q, O, N>& x, uint64_t v) { x.range(W - 1, 0) = ap_uint<W>(v); }
};
template <>
struct Scalar<bool> {  // one byte, 0 or 1 (UG1391: a bool is padded to 8 bits)
  static constexpr bool kIs = true, kSigned = false;
  static constexpr int kBits = 1;
  static uint64_t Get(const bool& x) { return x ? 1 : 0; }
  static void Set(bool& x, uint64_t v) { x = (v & 1) != 0; }
};
template <class T>  // int, uint32_t, …: their C size
struct Scalar<T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>>> {
  static constexpr bool kIs = true, kSigned = std::is_signed_v<T>;
  static constexpr int kBits = 8 * int(sizeof(T));
  static uint64_t Get(const T& x) { return uint64_t(std::make_unsigned_t<T>(x)); }
  static void Set(T& x, uint64_t v) { x = T(std::make_unsigned_t<T>(v)); }
};

// The W raw bits of a scalar field, and back (the common API of the vendor's and our types).
template <class T>
uint64_t RawBits(const T& x) {
  return Scalar<T>::Get(x);
}
template <class T>
void SetRawBits(T& x, uint64_t v) {
  constexpr int W = Scalar<T>::kBits;
  Scalar<T>::Set(x, W >= 64 ? v : v & ((uint64_t(1) << W) - 1));
}

// ---- Walking a value's scalars ----

namespace detail {
struct NullVisitor {
  template <class M>
  void operator()(const char*, M&) const {}
};
template <class T, class = void>
struct HasFields : std::false_type {};
template <class T>
struct HasFields<T, std::void_t<decltype(VisitFields(std::declval<T&>(), std::declval<NullVisitor&>()))>>
    : std::true_type {};
}  // namespace detail

// f(scalar) for every scalar of obj (const or not) in declaration order, nested structs and
// arrays flattened (arrays from index 0 up): the order of LayoutOf<T>().fields.
template <class Obj, class F>
void ForEachScalar(Obj& obj, F&& f) {
  using T = std::remove_const_t<Obj>;
  if constexpr (Scalar<T>::kIs) {
    f(obj);
  } else if constexpr (std::is_array_v<T>) {
    for (int i = 0; i < int(std::extent_v<T>); ++i) ForEachScalar(obj[i], f);
  } else {
    static_assert(detail::HasFields<T>::value, "axi_pack: no VisitFields for this type");
    VisitFields(obj, [&](const char*, auto& member) { ForEachScalar(member, f); });
  }
}

// ---- Layouts ----

struct FieldLayout {
  std::string name;  // e.g. "cam.rot[4]", "bbox[7][2]"; "" for a scalar element type
  int offset = 0;    // bytes from the start of the struct
  int bytes = 0;     // storage bytes
  int bits = 0;      // value bits (W)
  bool is_signed = false;
};

struct Layout {
  int size = 0;   // bytes, a multiple of align
  int align = 1;  // bytes
  std::vector<FieldLayout> fields;  // every scalar, in ForEachScalar's order
};

namespace detail {

constexpr int AlignUp(int offset, int align) { return (offset + align - 1) / align * align; }

// prefix + sub, with a '.' before a nested struct's field name (not before "[i]" or "").
inline std::string Join(const std::string& prefix, const std::string& sub) {
  if (sub.empty() || sub[0] == '[') return prefix + sub;
  return prefix + "." + sub;
}

template <class T>
const Layout& LayoutOfImpl();

// Places a member of layout m named `name` at the next offset of *out aligned for it.
inline void Append(Layout* out, int* offset, const std::string& name, const Layout& m) {
  *offset = AlignUp(*offset, m.align);
  for (const FieldLayout& f : m.fields) {
    FieldLayout g = f;
    g.name = Join(name, f.name);
    g.offset += *offset;
    out->fields.push_back(g);
  }
  *offset += m.size;
  out->align = std::max(out->align, m.align);
}

template <class T>
Layout BuildLayout() {
  Layout l;
  if constexpr (Scalar<T>::kIs) {
    constexpr int bytes = StorageBytes(Scalar<T>::kBits);
    l.size = l.align = bytes;
    l.fields.push_back(FieldLayout{"", 0, bytes, Scalar<T>::kBits, Scalar<T>::kSigned});
  } else if constexpr (std::is_array_v<T>) {
    int offset = 0;  // elements back to back: the element size is a multiple of its alignment
    for (int i = 0; i < int(std::extent_v<T>); ++i) {
      std::string index = std::to_string(i);  // "[i]", built by appending (g++ 12 warns on "[" + s)
      index.insert(index.begin(), '[');
      index.push_back(']');
      Append(&l, &offset, index, LayoutOfImpl<std::remove_extent_t<T>>());
    }
    l.size = offset;
  } else {
    static_assert(HasFields<T>::value, "axi_pack: no VisitFields for this type");
    const T proto{};
    int offset = 0;
    VisitFields(proto, [&](const char* name, const auto& member) {
      Append(&l, &offset, name, LayoutOfImpl<std::remove_cv_t<std::remove_reference_t<decltype(member)>>>());
    });
    l.size = AlignUp(offset, l.align);
  }
  return l;
}

template <class T>
const Layout& LayoutOfImpl() {
  static const Layout layout = BuildLayout<T>();
  return layout;
}

// One object to or from its bytes: a const object is packed into `bytes` (uint8_t*), a mutable
// one unpacked from them (const uint8_t*); scalar k at LayoutOf<T>().fields[k].offset.
template <class Obj, class Byte>
void Transfer(Obj& obj, Byte* bytes) {
  const std::vector<FieldLayout>& fields = LayoutOfImpl<std::remove_const_t<Obj>>().fields;
  std::size_t k = 0;
  ForEachScalar(obj, [&](auto& x) {
    using T = std::remove_const_t<std::remove_reference_t<decltype(x)>>;
    constexpr int W = Scalar<T>::kBits, n = StorageBytes(W);
    Byte* p = bytes + fields[k++].offset;
    if constexpr (std::is_const_v<Obj>) {
      uint64_t u = RawBits(x);
      if (Scalar<T>::kSigned && W < 64 && ((u >> (W - 1)) & 1)) u |= ~uint64_t(0) << W;  // sign extension
      for (int b = 0; b < n; ++b) p[b] = uint8_t(u >> (8 * b));
    } else {
      uint64_t u = 0;
      for (int b = 0; b < n; ++b) u |= uint64_t(p[b]) << (8 * b);
      SetRawBits(x, u);
    }
  });
}

}  // namespace detail

// ---- The API ----

template <class T>
const Layout& LayoutOf() {
  return detail::LayoutOfImpl<std::remove_cv_t<T>>();
}

template <class T>
int PackedBytes() {
  return LayoutOf<T>().size;
}

// count elements as the bytes of an m_axi buffer (element i at i · PackedBytes<T>()), or, with
// count = 1, a struct argument's s_axilite register image.
template <class T>
std::vector<uint8_t> Pack(const T* elems, int count) {
  const int size = PackedBytes<T>();
  std::vector<uint8_t> bytes(std::size_t(count) * std::size_t(size), uint8_t(0));  // padding = 0
  for (int i = 0; i < count; ++i) detail::Transfer(elems[i], bytes.data() + std::size_t(i) * std::size_t(size));
  return bytes;
}

// The inverse of Pack: count elements from bytes (count · PackedBytes<T>() of them).
template <class T>
void Unpack(const uint8_t* bytes, int count, T* out) {
  const int size = PackedBytes<T>();
  for (int i = 0; i < count; ++i) detail::Transfer(out[i], bytes + std::size_t(i) * std::size_t(size));
}

// A register image as the 32-bit words of the AXI4-Lite bus: word k = bytes 4k … 4k+3, little
// endian (the image's last word zero-filled). The generated driver header (x<top>_hw.h) gives
// the offset of an argument's first word.
inline std::vector<uint32_t> RegisterWords(const std::vector<uint8_t>& bytes) {
  std::vector<uint32_t> words((bytes.size() + 3) / 4, 0u);
  for (std::size_t k = 0; k < bytes.size(); ++k) words[k / 4] |= uint32_t(bytes[k]) << (8 * (k % 4));
  return words;
}

// The layout as a table a driver writer can read.
template <class T>
std::string DescribeLayout(const std::string& title = "layout") {
  const Layout& l = LayoutOf<T>();
  std::string s = title + ": " + std::to_string(l.size) + " bytes, alignment " + std::to_string(l.align) + "\n";
  char line[160];
  std::snprintf(line, sizeof line, "  %-28s %6s %5s %4s %s\n", "field", "offset", "bytes", "bits", "signed");
  s += line;
  for (const FieldLayout& f : l.fields) {
    std::snprintf(line, sizeof line, "  %-28s %6d %5d %4d %s\n", f.name.empty() ? "(value)" : f.name.c_str(), f.offset,
                  f.bytes, f.bits, f.is_signed ? "yes" : "no");
    s += line;
  }
  return s;
}

}  // namespace posefilter::hw::axi
