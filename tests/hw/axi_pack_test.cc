// Tests of src/hw/host/axi_pack.h, the host's byte images of the hw tops' m_axi buffers and
// s_axilite struct registers (the rule: docs/HW_PACKING.md):
//   HwAxiPackLayout    — the size, alignment and every field's offset, bytes and bits of each
//                        type that crosses a top's port, against tables written here from the rule;
//   HwAxiPackRoundTrip — Pack → Unpack is bit-identical on random values, and each field's bytes
//                        hold its value bits (sign-extended for signed types), for every type;
//   HwAxiPackImage     — hand-checked bytes of one Sample and of WeighConfig fields, the padding
//                        bytes, the m_axi element stride and the 32-bit register words.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "hw/host/axi_pack.h"

namespace posefilter::hw {
namespace {

namespace axi = posefilter::hw::axi;

// ---- Independent walkers over a value's scalars (declaration order, arrays flattened) ----
template <class T, class F>
void ForEachScalar(T& obj, F&& f) {
  using U = std::remove_const_t<T>;
  if constexpr (axi::Scalar<U>::kIs) {
    f(obj);
  } else if constexpr (std::is_array_v<U>) {
    for (auto& e : obj) ForEachScalar(e, f);
  } else {
    axi::VisitFields(obj, [&](const char*, auto& m) { ForEachScalar(m, f); });
  }
}
template <class T>
std::vector<uint64_t> ScalarBits(const T& obj) {
  std::vector<uint64_t> bits;
  ForEachScalar(obj, [&](const auto& x) { bits.push_back(axi::RawBits(x)); });
  return bits;
}
template <class T>
void FillRandom(T* obj, std::mt19937_64* rng) {
  ForEachScalar(*obj, [&](auto& x) { axi::SetRawBits(x, (*rng)()); });
}

// ---- Expected layouts ----
struct Expected {
  const char* name;
  int offset, bytes, bits;
  bool is_signed;
};

template <class T>
void ExpectLayout(int size, int align, const std::vector<Expected>& fields) {
  const axi::Layout& l = axi::LayoutOf<T>();
  EXPECT_EQ(l.size, size);
  EXPECT_EQ(l.align, align);
  EXPECT_EQ(axi::PackedBytes<T>(), size);
  ASSERT_EQ(l.fields.size(), fields.size()) << axi::DescribeLayout<T>();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const axi::FieldLayout& f = l.fields[i];
    EXPECT_EQ(f.name, fields[i].name) << "field " << i;
    EXPECT_EQ(f.offset, fields[i].offset) << f.name;
    EXPECT_EQ(f.bytes, fields[i].bytes) << f.name;
    EXPECT_EQ(f.bits, fields[i].bits) << f.name;
    EXPECT_EQ(f.is_signed, fields[i].is_signed) << f.name;
  }
}

// Storage: the smallest power of two bytes ≥ W/8 (1: W ≤ 8, 2: ≤ 16, 4: ≤ 32, 8: ≤ 64);
// alignment = storage; a struct aligns to its largest field and rounds its size up to that.

TEST(HwAxiPackLayout, ScalarsTakeThePowerOfTwoBytesThatHoldTheirBits) {
  ExpectLayout<prob_t>(1, 1, {{"", 0, 1, 8, false}});              // ufixed<8,0>
  ExpectLayout<hypothesis_t>(1, 1, {{"", 0, 1, 8, false}});        // uint<8>
  ExpectLayout<depth_t>(2, 2, {{"", 0, 2, 12, false}});            // ufixed<12,2>: 12 bits → 2 bytes
  ExpectLayout<xyz_t>(2, 2, {{"", 0, 2, 13, true}});               // fixed<13,3>
  ExpectLayout<particle_index_t>(2, 2, {{"", 0, 2, 10, false}});   // uint<10>
  ExpectLayout<face_t>(4, 4, {{"", 0, 4, 30, false}});             // uint<30>: 30 bits → 4 bytes
  ExpectLayout<weight_t>(4, 4, {{"", 0, 4, 18, false}});           // ufixed<18,1>: 18 bits → 4, not 3
  ExpectLayout<depth_off_t>(4, 4, {{"", 0, 4, 18, true}});         // fixed<18,3>
  ExpectLayout<class_sum_t>(4, 4, {{"", 0, 4, 21, false}});        // ufixed<21,13>
  ExpectLayout<int>(4, 4, {{"", 0, 4, 32, true}});
  ExpectLayout<uint32_t>(4, 4, {{"", 0, 4, 32, false}});
  ExpectLayout<bool>(1, 1, {{"", 0, 1, 1, false}});                // a bool is padded to 8 bits
  ExpectLayout<ap_uint<1>>(1, 1, {{"", 0, 1, 1, false}});
  ExpectLayout<ap_uint<17>>(4, 4, {{"", 0, 4, 17, false}});
  ExpectLayout<ap_int<33>>(8, 8, {{"", 0, 8, 33, true}});
  ExpectLayout<ap_uint<64>>(8, 8, {{"", 0, 8, 64, false}});
}

TEST(HwAxiPackLayout, SampleWindowAndHeuristicVolume) {
  // Sample: six fixed<13|12,·> and a uint<13>, all 2 bytes, no padding: 7 × 2 = 14.
  ExpectLayout<Sample>(14, 2,
                       {{"x", 0, 2, 13, true},
                        {"y", 2, 2, 13, true},
                        {"z", 4, 2, 13, true},
                        {"roll", 6, 2, 12, true},
                        {"pitch", 8, 2, 12, true},
                        {"yaw", 10, 2, 12, true},
                        {"cell", 12, 2, 13, false}});
  // Window: two uint<10> (2 bytes) then two uint<8> (1 byte): 2 + 2 + 1 + 1 = 6, a multiple of 2.
  ExpectLayout<Window>(6, 2,
                       {{"u0", 0, 2, 10, false}, {"v0", 2, 2, 10, false}, {"width", 4, 1, 8, false},
                        {"height", 5, 1, 8, false}});
  // HeuristicVolume: six xyz_t = 12.
  ExpectLayout<HeuristicVolume>(12, 2,
                                {{"x_min", 0, 2, 13, true},
                                 {"y_min", 2, 2, 13, true},
                                 {"z_min", 4, 2, 13, true},
                                 {"x_max", 6, 2, 13, true},
                                 {"y_max", 8, 2, 13, true},
                                 {"z_max", 10, 2, 13, true}});
}

TEST(HwAxiPackLayout, RasterCoreOutput) {
  // inlier_sum ufixed<42,32> → 8 bytes at 0; four uint<32> at 8, 12, 16; depth_diff_sum
  // fixed<56,36> → 8 bytes, aligned to 8: 20 → 24 (bytes 20..23 padding); three uint<32> at
  // 32, 36, 40; two uint<12> (2 bytes) at 44, 46; end 48 = 6 × 8.
  ExpectLayout<RasterCoreOutput>(48, 8,
                                 {{"inlier_sum", 0, 8, 42, false},
                                  {"n_raster", 8, 4, 32, false},
                                  {"n_occluded", 12, 4, 32, false},
                                  {"n_depth", 16, 4, 32, false},
                                  {"depth_diff_sum", 24, 8, 56, true},
                                  {"depth_diff_count", 32, 4, 32, false},
                                  {"n_edge", 36, 4, 32, false},
                                  {"n_edge_continued", 40, 4, 32, false},
                                  {"faces_front", 44, 2, 12, false},
                                  {"faces_total", 46, 2, 12, false}});
}

TEST(HwAxiPackLayout, WeighConfig) {
  // Three ints at 0, 4, 8. cam (CameraParams: 16 four-byte fields — intr_t ufixed<28,12>,
  // trig_t fixed<18,2>, ctrans_t fixed<24,4> — size 64, align 4) at 12: fx 12, fy 16, cx 20,
  // cy 24, rot[k] 28 + 4k, trans[k] 64 + 4k; ends at 76. raster (RasterParams: two uint<1>
  // bytes at +0, +1, then six 4-byte fields from +4 — dist_t ufixed<24,4>, inv_thr_t
  // ufixed<20,12> — size 28, align 4) at 76: zbuffer 76, hard 77 (78, 79 padding), thr1 80, …,
  // near_plane 100; ends at 104. weight (WeightParams: four coef_t ufixed<16,1> at +0 … +6 and a
  // uint<1> at +8; 9 → size 10, align 2) at 104; ends at 114. grow_window aligned to 4: 116
  // (114, 115 padding), img_height 120, max_window 124. bbox[k][j] (xyz_t) at 128 + 2·(3k + j),
  // ends at 176, a multiple of 4.
  ExpectLayout<WeighConfig>(176, 4,
                            {{"num_cores", 0, 4, 32, true},
                             {"num_faces", 4, 4, 32, true},
                             {"img_width", 8, 4, 32, true},
                             {"cam.fx", 12, 4, 28, false},
                             {"cam.fy", 16, 4, 28, false},
                             {"cam.cx", 20, 4, 28, false},
                             {"cam.cy", 24, 4, 28, false},
                             {"cam.rot[0]", 28, 4, 18, true},
                             {"cam.rot[1]", 32, 4, 18, true},
                             {"cam.rot[2]", 36, 4, 18, true},
                             {"cam.rot[3]", 40, 4, 18, true},
                             {"cam.rot[4]", 44, 4, 18, true},
                             {"cam.rot[5]", 48, 4, 18, true},
                             {"cam.rot[6]", 52, 4, 18, true},
                             {"cam.rot[7]", 56, 4, 18, true},
                             {"cam.rot[8]", 60, 4, 18, true},
                             {"cam.trans[0]", 64, 4, 24, true},
                             {"cam.trans[1]", 68, 4, 24, true},
                             {"cam.trans[2]", 72, 4, 24, true},
                             {"raster.zbuffer", 76, 1, 1, false},
                             {"raster.hard", 77, 1, 1, false},
                             {"raster.thr1", 80, 4, 24, false},
                             {"raster.inv_thr1", 84, 4, 20, false},
                             {"raster.hard_thr", 88, 4, 24, false},
                             {"raster.align_band", 92, 4, 24, false},
                             {"raster.edge_band", 96, 4, 24, false},
                             {"raster.near_plane", 100, 4, 24, false},
                             {"weight.alpha", 104, 2, 16, false},
                             {"weight.beta", 106, 2, 16, false},
                             {"weight.gamma", 108, 2, 16, false},
                             {"weight.delta", 110, 2, 16, false},
                             {"weight.occlusion_aware", 112, 1, 1, false},
                             {"grow_window", 116, 4, 32, true},
                             {"img_height", 120, 4, 32, true},
                             {"max_window", 124, 4, 32, true},
                             {"bbox[0][0]", 128, 2, 13, true},
                             {"bbox[0][1]", 130, 2, 13, true},
                             {"bbox[0][2]", 132, 2, 13, true},
                             {"bbox[1][0]", 134, 2, 13, true},
                             {"bbox[1][1]", 136, 2, 13, true},
                             {"bbox[1][2]", 138, 2, 13, true},
                             {"bbox[2][0]", 140, 2, 13, true},
                             {"bbox[2][1]", 142, 2, 13, true},
                             {"bbox[2][2]", 144, 2, 13, true},
                             {"bbox[3][0]", 146, 2, 13, true},
                             {"bbox[3][1]", 148, 2, 13, true},
                             {"bbox[3][2]", 150, 2, 13, true},
                             {"bbox[4][0]", 152, 2, 13, true},
                             {"bbox[4][1]", 154, 2, 13, true},
                             {"bbox[4][2]", 156, 2, 13, true},
                             {"bbox[5][0]", 158, 2, 13, true},
                             {"bbox[5][1]", 160, 2, 13, true},
                             {"bbox[5][2]", 162, 2, 13, true},
                             {"bbox[6][0]", 164, 2, 13, true},
                             {"bbox[6][1]", 166, 2, 13, true},
                             {"bbox[6][2]", 168, 2, 13, true},
                             {"bbox[7][0]", 170, 2, 13, true},
                             {"bbox[7][1]", 172, 2, 13, true},
                             {"bbox[7][2]", 174, 2, 13, true}});
}

TEST(HwAxiPackLayout, InitTopRegisters) {
  // InitGenerators: two Lfsr18 (uint<18> → 4 bytes) at 0, 4; three Lfsr15 (uint<15> → 2) at
  // 8, 10, 12; 14 → 16 (alignment 4).
  ExpectLayout<InitGenerators>(16, 4,
                               {{"sampling.state", 0, 4, 18, false},
                                {"z.state", 4, 4, 18, false},
                                {"roll.state", 8, 2, 15, false},
                                {"pitch.state", 10, 2, 15, false},
                                {"yaw.state", 12, 2, 15, false}});
  // InitOptions: two bools.
  ExpectLayout<InitOptions>(2, 1, {{"use_tracker", 0, 1, 1, false}, {"leap", 1, 1, 1, false}});
  // InitReport: SamplingCounters (three uint<32>, 12 bytes) at 0, a bool at 12; 13 → 16.
  ExpectLayout<InitReport>(16, 4,
                           {{"counters.reads", 0, 4, 32, false},
                            {"counters.reads_linear", 4, 4, 32, false},
                            {"counters.draws", 8, 4, 32, false},
                            {"uniform_fallback", 12, 1, 1, false}});
}

TEST(HwAxiPackLayout, WeighAndUpdateTopRegisters) {
  // DepthDistributionCounts: two uint<32>.
  ExpectLayout<DepthDistributionCounts>(8, 4, {{"reads_shared", 0, 4, 32, false}, {"reads_unshared", 4, 4, 32, false}});
  // ResampleParams: five ints.
  ExpectLayout<ResampleParams>(20, 4,
                               {{"num_particles", 0, 4, 32, true},
                                {"num_elite", 4, 4, 32, true},
                                {"pool_size", 8, 4, 32, true},
                                {"region_cap", 12, 4, 32, true},
                                {"rotation_cap", 16, 4, 32, true}});
  // Lfsr18: one uint<18>.
  ExpectLayout<Lfsr18>(4, 4, {{"state", 0, 4, 18, false}});
  // ResampleCounters: four uint32_t.
  ExpectLayout<ResampleCounters>(16, 4,
                                 {{"draws", 0, 4, 32, false},
                                  {"cdf_reads", 4, 4, 32, false},
                                  {"cdf_reads_linear", 8, 4, 32, false},
                                  {"pool", 12, 4, 32, false}});
  // DiffusionParams: move_thr = 15 × uint<15> (2 bytes) at 0 … 28; sigma_t0, sigma_r0 (ufixed<18,2>)
  // and min_fraction (ufixed<18,1>), 4 bytes, at 32 (30, 31 padding), 36, 40; sigma_floor_lsb
  // (uint<1>) at 44; cam_row_z = 3 × fixed<18,2> (4 bytes) at 48 (45 … 47 padding), 52, 56;
  // cam_origin = 3 × fixed<15,5> (2 bytes) at 60, 62, 64; 66 → 68 (alignment 4).
  ExpectLayout<DiffusionParams>(68, 4,
                                {{"move_thr[0]", 0, 2, 15, false},
                                 {"move_thr[1]", 2, 2, 15, false},
                                 {"move_thr[2]", 4, 2, 15, false},
                                 {"move_thr[3]", 6, 2, 15, false},
                                 {"move_thr[4]", 8, 2, 15, false},
                                 {"move_thr[5]", 10, 2, 15, false},
                                 {"move_thr[6]", 12, 2, 15, false},
                                 {"move_thr[7]", 14, 2, 15, false},
                                 {"move_thr[8]", 16, 2, 15, false},
                                 {"move_thr[9]", 18, 2, 15, false},
                                 {"move_thr[10]", 20, 2, 15, false},
                                 {"move_thr[11]", 22, 2, 15, false},
                                 {"move_thr[12]", 24, 2, 15, false},
                                 {"move_thr[13]", 26, 2, 15, false},
                                 {"move_thr[14]", 28, 2, 15, false},
                                 {"sigma_t0", 32, 4, 18, false},
                                 {"sigma_r0", 36, 4, 18, false},
                                 {"min_fraction", 40, 4, 18, false},
                                 {"sigma_floor_lsb", 44, 1, 1, false},
                                 {"cam_row_z[0]", 48, 4, 18, true},
                                 {"cam_row_z[1]", 52, 4, 18, true},
                                 {"cam_row_z[2]", 56, 4, 18, true},
                                 {"cam_origin[0]", 60, 2, 15, true},
                                 {"cam_origin[1]", 62, 2, 15, true},
                                 {"cam_origin[2]", 64, 2, 15, true}});
  // DiffusionRng: two Lfsr15 (2 bytes) at 0, 2; two GaussianSource (Lfsr18 at +0, Lfsr15 at
  // +4, a bool at +6; 7 → 8, alignment 4) at 4 and 12; ends at 20.
  ExpectLayout<DiffusionRng>(20, 4,
                             {{"move_lfsr.state", 0, 2, 15, false},
                              {"aux_lfsr.state", 2, 2, 15, false},
                              {"g0.u1.state", 4, 4, 18, false},
                              {"g0.u2.state", 8, 2, 15, false},
                              {"g0.cos_from_sqrt", 10, 1, 1, false},
                              {"g1.u1.state", 12, 4, 18, false},
                              {"g1.u2.state", 16, 2, 15, false},
                              {"g1.cos_from_sqrt", 18, 1, 1, false}});
}

// ---- Round trips and per-field bytes, every type that crosses a port ----

// The bytes a field must hold: its value bits, above them the sign extension (signed) or 0.
uint64_t FieldImage(uint64_t value_bits, int bits, int bytes, bool is_signed) {
  uint64_t u = bits >= 64 ? value_bits : value_bits & ((uint64_t(1) << bits) - 1);
  if (is_signed && bits < 64 && ((u >> (bits - 1)) & 1)) u |= ~uint64_t(0) << bits;
  return bytes >= 8 ? u : u & ((uint64_t(1) << (8 * bytes)) - 1);
}
uint64_t ReadLe(const uint8_t* p, int bytes) {
  uint64_t u = 0;
  for (int k = 0; k < bytes; ++k) u |= uint64_t(p[k]) << (8 * k);
  return u;
}

template <class T>
class HwAxiPackRoundTrip : public ::testing::Test {};
using PortTypes = ::testing::Types<Sample, Window, HeuristicVolume, RasterCoreOutput, WeighConfig, InitGenerators,
                                   InitOptions, InitReport, ResampleParams, Lfsr18, DiffusionParams, DiffusionRng,
                                   ResampleCounters, DepthDistributionCounts, prob_t, depth_t, xyz_t, face_t, weight_t,
                                   particle_index_t, depth_off_t, hypothesis_t, class_sum_t, int>;
TYPED_TEST_SUITE(HwAxiPackRoundTrip, PortTypes);

TYPED_TEST(HwAxiPackRoundTrip, RandomValuesSurviveBitForBitAndSitAtTheirOffsets) {
  using T = TypeParam;
  const axi::Layout& l = axi::LayoutOf<T>();
  std::mt19937_64 rng(0x5EED0000u + l.size);
  constexpr int kCount = 7;  // an m_axi buffer of 7 elements
  std::vector<T> in(kCount), out(kCount);
  for (T& x : in) FillRandom(&x, &rng);
  const std::vector<uint8_t> bytes = axi::Pack(in.data(), kCount);
  ASSERT_EQ(bytes.size(), std::size_t(kCount) * std::size_t(l.size));
  axi::Unpack(bytes.data(), kCount, out.data());
  for (int i = 0; i < kCount; ++i) {
    const std::vector<uint64_t> a = ScalarBits(in[i]), b = ScalarBits(out[i]);
    ASSERT_EQ(a.size(), l.fields.size());
    EXPECT_EQ(a, b) << "element " << i;
    // Element i starts at i · size; each field's bytes hold its bits.
    const uint8_t* e = bytes.data() + std::size_t(i) * std::size_t(l.size);
    for (std::size_t k = 0; k < l.fields.size(); ++k) {
      const axi::FieldLayout& f = l.fields[k];
      EXPECT_EQ(ReadLe(e + f.offset, f.bytes), FieldImage(a[k], f.bits, f.bytes, f.is_signed)) << f.name;
    }
  }
  EXPECT_EQ(axi::Pack(out.data(), kCount), bytes);
}

TYPED_TEST(HwAxiPackRoundTrip, PaddingBytesAreZeroAndFieldTopBitsExtendTheSign) {
  using T = TypeParam;
  const axi::Layout& l = axi::LayoutOf<T>();
  // Every value bit 1 (unpacked from all-ones bytes): signed fields are −1 and fill their bytes,
  // unsigned fields keep 0 above their W bits, and every byte outside the fields is 0.
  const std::vector<uint8_t> ones(std::size_t(l.size), uint8_t(0xFF));
  T x;
  axi::Unpack(ones.data(), 1, &x);
  const std::vector<uint8_t> bytes = axi::Pack(&x, 1);
  std::vector<int> expected(std::size_t(l.size), 0x00);  // the padding value
  for (const axi::FieldLayout& f : l.fields) {
    const uint64_t image = FieldImage(~uint64_t(0), f.bits, f.bytes, f.is_signed);
    for (int k = 0; k < f.bytes; ++k) expected[std::size_t(f.offset + k)] = int((image >> (8 * k)) & 0xFF);
  }
  for (int k = 0; k < l.size; ++k) EXPECT_EQ(int(bytes[std::size_t(k)]), expected[std::size_t(k)]) << "byte " << k;
}

// The padding bytes (outside every field) of the structs that have them, derived above.
std::vector<int> PaddingBytes(const axi::Layout& l) {
  std::vector<int> covered(std::size_t(l.size), 0), pad;
  for (const axi::FieldLayout& f : l.fields)
    for (int k = 0; k < f.bytes; ++k) covered[std::size_t(f.offset + k)] = 1;
  for (int k = 0; k < l.size; ++k)
    if (!covered[std::size_t(k)]) pad.push_back(k);
  return pad;
}

TEST(HwAxiPackLayout, PaddingBytesAreWhereTheRulePutsThem) {
  using V = std::vector<int>;
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<Sample>()), V{});
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<Window>()), V{});
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<HeuristicVolume>()), V{});
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<RasterCoreOutput>()), (V{20, 21, 22, 23}));
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<WeighConfig>()), (V{78, 79, 113, 114, 115}));
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<InitGenerators>()), (V{14, 15}));
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<InitReport>()), (V{13, 14, 15}));
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<DiffusionParams>()), (V{30, 31, 45, 46, 47, 66, 67}));
  EXPECT_EQ(PaddingBytes(axi::LayoutOf<DiffusionRng>()), (V{11, 19}));
}

// ---- Hand-checked images ----

TEST(HwAxiPackImage, OneSampleByteByByte) {
  Sample s;
  s.x = xyz_t(-0.5);     // raw −512 = 13-bit 0x1E00, sign-extended to 16 bits 0xFE00 → 00 FE
  s.y = xyz_t(0.25);     // raw 256 = 0x0100 → 00 01
  s.z = xyz_t(0.75);     // raw 768 = 0x0300 → 00 03
  s.roll = angle_t(-1);  // fixed<12,4>: raw −256 = 0xF00, sign-extended 0xFF00 → 00 FF
  s.pitch = angle_t(0.5);         // raw 128 = 0x0080 → 80 00
  s.yaw = angle_t(-0.00390625);   // raw −1 = 0xFFF, sign-extended 0xFFFF → FF FF
  s.cell = 6299;                  // 0x189B → 9B 18
  const std::vector<uint8_t> expected = {0x00, 0xFE, 0x00, 0x01, 0x00, 0x03, 0x00,
                                         0xFF, 0x80, 0x00, 0xFF, 0xFF, 0x9B, 0x18};
  EXPECT_EQ(axi::Pack(&s, 1), expected);
  Sample back;
  axi::Unpack(expected.data(), 1, &back);
  EXPECT_EQ(back.x.to_double(), -0.5);
  EXPECT_EQ(back.yaw.to_double(), -0.00390625);
  EXPECT_EQ(back.cell.to_int(), 6299);
  // Unpack reads the value bits only: a field's top bits may hold anything.
  std::vector<uint8_t> dirty = expected;
  dirty[1] = 0x1E;  // x's bits 15…13 cleared: still −0.5
  dirty[13] = 0xF8;  // cell's bits 15…13 set: still 6299
  axi::Unpack(dirty.data(), 1, &back);
  EXPECT_EQ(back.x.to_double(), -0.5);
  EXPECT_EQ(back.cell.to_int(), 6299);
}

TEST(HwAxiPackImage, WeighConfigFieldsAndRegisterWords) {
  WeighConfig cfg{};
  cfg.num_faces = 12;                   // int at 4: 0C 00 00 00
  cfg.cam.trans[2] = ctrans_t(-0.5);    // fixed<24,4> at 72: raw −2^19 = 0xF80000, sign-extended
                                        // 0xFFF80000 → 00 00 F8 FF
  cfg.raster.zbuffer = 1;               // uint<1> at 76: 01
  cfg.raster.thr1 = dist_t(1.0 / 256);  // ufixed<24,4> at 80: raw 2^12 = 0x1000 → 00 10 00 00
  cfg.weight.occlusion_aware = 1;       // uint<1> at 112: 01, then padding 113 … 115
  cfg.grow_window = -2;                 // int at 116: FE FF FF FF
  cfg.bbox[7][2] = xyz_t(-0.0625);      // fixed<13,3> at 174: raw −64 = 0x1FC0, sign-extended 0xFFC0 → C0 FF
  const std::vector<uint8_t> b = axi::Pack(&cfg, 1);
  ASSERT_EQ(b.size(), 176u);
  auto at = [&](int offset, int n) { return std::vector<uint8_t>(b.begin() + offset, b.begin() + offset + n); };
  using B = std::vector<uint8_t>;
  EXPECT_EQ(at(4, 4), (B{0x0C, 0x00, 0x00, 0x00}));
  EXPECT_EQ(at(72, 4), (B{0x00, 0x00, 0xF8, 0xFF}));
  EXPECT_EQ(at(76, 4), (B{0x01, 0x00, 0x00, 0x00}));
  EXPECT_EQ(at(80, 4), (B{0x00, 0x10, 0x00, 0x00}));
  EXPECT_EQ(at(112, 8), (B{0x01, 0x00, 0x00, 0x00, 0xFE, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(at(174, 2), (B{0xC0, 0xFF}));
  // As AXI4-Lite words: word k = bytes 4k … 4k+3, little endian.
  const std::vector<uint32_t> w = axi::RegisterWords(b);
  ASSERT_EQ(w.size(), 44u);
  EXPECT_EQ(w[1], 12u);
  EXPECT_EQ(w[18], 0xFFF80000u);
  EXPECT_EQ(w[19], 1u);
  EXPECT_EQ(w[29], 0xFFFFFFFEu);
  EXPECT_EQ(w[43], 0xFFC00000u);
  // A register image whose size is not a multiple of 4 ends in a zero-filled word.
  EXPECT_EQ(axi::RegisterWords({0x01, 0x02, 0x03, 0x04, 0x05}), (std::vector<uint32_t>{0x04030201u, 0x05u}));
}

TEST(HwAxiPackImage, DepthDiffSumIsSignExtendedToItsEightBytes) {
  RasterCoreOutput o{};
  o.depth_diff_sum = diff_sum_t(-1.0);  // fixed<56,36>: raw −2^20 → 00 00 F0 FF FF FF FF FF at 24
  o.faces_total = 2048;                 // uint<12> at 46: 0x800 → 00 08
  const std::vector<uint8_t> b = axi::Pack(&o, 1);
  EXPECT_EQ(std::vector<uint8_t>(b.begin() + 20, b.begin() + 32),
            (std::vector<uint8_t>{0, 0, 0, 0, 0x00, 0x00, 0xF0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(b[46], 0x00);
  EXPECT_EQ(b[47], 0x08);
}

TEST(HwAxiPackImage, AnArrayOfStructsHasTheStructSizeAsItsStride) {
  Sample s[3];
  for (int i = 0; i < 3; ++i) {
    s[i] = Sample{};
    s[i].cell = 100 + i;
  }
  const std::vector<uint8_t> b = axi::Pack(s, 3);
  ASSERT_EQ(b.size(), 42u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(b[std::size_t(14 * i + 12)], 100 + i);
  // The model memory xyz_t vmem[3][1024] is one buffer of 3 × 1024 two-byte words, row-major.
  static xyz_t vmem[3][kMaxVertices];
  vmem[1][0] = xyz_t(0.5);  // word 1024: raw 512 = 0x0200 at byte 2048
  const std::vector<uint8_t> m = axi::Pack(&vmem[0][0], 3 * kMaxVertices);
  ASSERT_EQ(m.size(), std::size_t(6 * kMaxVertices));
  EXPECT_EQ(m[2048], 0x00);
  EXPECT_EQ(m[2049], 0x02);
}

TEST(HwAxiPackImage, DescribeLayoutListsEveryField) {
  const std::string t = axi::DescribeLayout<WeighConfig>("WeighConfig");
  EXPECT_NE(t.find("WeighConfig: 176 bytes, alignment 4"), std::string::npos) << t;
  EXPECT_NE(t.find("cam.trans[2]"), std::string::npos) << t;
  EXPECT_NE(t.find("bbox[7][2]"), std::string::npos) << t;
  const std::string s = axi::DescribeLayout<Sample>("Sample");
  EXPECT_NE(s.find("cell"), std::string::npos) << s;
}

}  // namespace
}  // namespace posefilter::hw
