// Tests of the pyramid layout, box coding, the post-process (eq. 7.1–7.2 [ALGORITHM.md]) and raw file I/O.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <cstdint>
#include <limits>

#include "posefilter/error.h"
#include "posefilter/prior.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

using testing_util::ExpectError;
using testing_util::ExpectInvalid;
using testing_util::ReadFile;
using testing_util::ScratchDir;

PyramidLayout SmallLayout(int num_classes = 3) {
  PyramidLayout l;
  l.image_width = 40;
  l.image_height = 30;
  l.num_classes = num_classes;
  l.levels = {{3, 4, 20, 20}, {6, 8, 10, 10}};
  return l;
}

TEST(PyramidLayout, ThesisHas6300CellsAndValidLayout) {
  const PyramidLayout l = PyramidLayout::Thesis();
  EXPECT_EQ(l.CellCount(), 6300);
  EXPECT_EQ(l.RawValuesPerCell(), kRawValuesPerCell);
  std::string why;
  EXPECT_TRUE(l.IsValid(&why)) << why;
  ASSERT_EQ(l.levels.size(), 3u);
  EXPECT_DOUBLE_EQ(l.StrideX(0), 32);
  EXPECT_DOUBLE_EQ(l.StrideY(0), 32);
  EXPECT_DOUBLE_EQ(l.StrideX(2), 8);
  EXPECT_DOUBLE_EQ(l.levels[0].anchor_w, 128);
  EXPECT_DOUBLE_EQ(l.levels[1].anchor_h, 64);
  EXPECT_DOUBLE_EQ(l.levels[2].anchor_w, 32);
  EXPECT_EQ(l.LevelOffset(1), 300);
  EXPECT_EQ(l.LevelOffset(2), 1500);
}

TEST(PyramidLayout, IndexRoundTripsEveryCell) {
  const PyramidLayout l = PyramidLayout::Thesis();
  int expected = 0;
  for (int lev = 0; lev < 3; ++lev)
    for (int r = 0; r < l.levels[lev].rows; ++r)
      for (int c = 0; c < l.levels[lev].cols; ++c) {
        const int cell = l.CellIndex(lev, r, c);
        ASSERT_EQ(cell, expected++);  // level order, row-major
        int L, R, C;
        l.CellRowCol(cell, &L, &R, &C);
        ASSERT_EQ(L, lev);
        ASSERT_EQ(R, r);
        ASSERT_EQ(C, c);
        ASSERT_EQ(l.LevelOf(cell), lev);
      }
  EXPECT_EQ(expected, 6300);
}

TEST(PyramidLayout, OutOfRangeIndicesThrow) {
  const PyramidLayout l = PyramidLayout::Thesis();
  int a, b, c;
  EXPECT_THROW(l.CellRowCol(6300, &a, &b, &c), Error);
  EXPECT_THROW(l.CellRowCol(-1, &a, &b, &c), Error);
  EXPECT_THROW(l.CellIndex(3, 0, 0), Error);
  EXPECT_THROW(l.CellIndex(0, 15, 0), Error);
  EXPECT_THROW(l.CellIndex(1, 0, -1), Error);
  EXPECT_THROW(l.AnchorBox(7000), Error);
}

TEST(PyramidLayout, AnchorsTileTheImage) {
  const PyramidLayout l = PyramidLayout::Thesis();
  const Box first = l.AnchorBox(0);
  EXPECT_DOUBLE_EQ(first.cx, 15.5);  // centre of pixels 0..31
  EXPECT_DOUBLE_EQ(first.cy, 15.5);
  EXPECT_DOUBLE_EQ(first.w, 128);
  const Box last = l.AnchorBox(6299);  // level 2, row 59, col 79
  EXPECT_DOUBLE_EQ(last.cx, 639 - 3.5);
  EXPECT_DOUBLE_EQ(last.cy, 479 - 3.5);
  EXPECT_DOUBLE_EQ(last.w, 32);
  // Mean of all anchor centres of a level is the image centre.
  for (int lev = 0; lev < 3; ++lev) {
    double sx = 0, sy = 0;
    const int n = l.levels[lev].rows * l.levels[lev].cols;
    for (int i = 0; i < n; ++i) {
      const Box b = l.AnchorBox(l.LevelOffset(lev) + i);
      sx += b.cx;
      sy += b.cy;
    }
    EXPECT_NEAR(sx / n, 319.5, 1e-9);
    EXPECT_NEAR(sy / n, 239.5, 1e-9);
  }
}

TEST(PyramidLayout, IsValidNamesTheProblem) {
  std::string why;
  PyramidLayout l = PyramidLayout::Thesis();
  l.levels.clear();
  ExpectInvalid(l, "levels");
  l = PyramidLayout::Thesis();
  l.levels[1].rows = 0;
  ExpectInvalid(l, "level 1");
  l = PyramidLayout::Thesis();
  l.levels[2].anchor_w = std::nan("");
  ExpectInvalid(l, "anchor");
  l = PyramidLayout::Thesis();
  l.num_classes = 0;
  EXPECT_FALSE(l.IsValid(&why));
  l = PyramidLayout::Thesis(10, 10);  // 80 columns over 10 pixels
  EXPECT_FALSE(l.IsValid(&why));
  l = PyramidLayout::Thesis(0, 480);
  EXPECT_FALSE(l.IsValid(&why));
}

TEST(BoxCoding, EncodeDecodeAreInverse) {
  const Box anchor{100.5, 200.5, 64, 32};
  const Box boxes[] = {{130, 180, 90, 50}, {10, 470, 20, 200}, {100.5, 200.5, 64, 32}};
  for (const Box& b : boxes) {
    float raw[4];
    EncodeBox(anchor, b, raw);
    const Box d = DecodeBoxUnclipped(anchor, raw);
    EXPECT_NEAR(d.cx, b.cx, 1e-4);
    EXPECT_NEAR(d.cy, b.cy, 1e-4);
    EXPECT_NEAR(d.w, b.w, 1e-4);
    EXPECT_NEAR(d.h, b.h, 1e-4);
    // Within the image and the 200 px clip, DecodeBox changes nothing.
    const Box c = DecodeBox(anchor, raw);
    EXPECT_NEAR(c.cx, b.cx, 1e-4);
    EXPECT_NEAR(c.w, b.w, 1e-4);
  }
  // The formula itself: cx = ax + tx·aw, w = aw·e^tw.
  const float raw[4] = {0.5f, -0.25f, std::log(2.f), 0};
  const Box d = DecodeBoxUnclipped(anchor, raw);
  EXPECT_NEAR(d.cx, 132.5, 1e-5);
  EXPECT_NEAR(d.cy, 192.5, 1e-5);
  EXPECT_NEAR(d.w, 128, 1e-4);
  EXPECT_NEAR(d.h, 32, 1e-5);
}

TEST(BoxCoding, EncodeRejectsDegenerateBox) {
  float raw[4];
  EXPECT_THROW(EncodeBox({10, 10, 32, 32}, {10, 10, 0, 5}, raw), Error);
  EXPECT_THROW(EncodeBox({10, 10, 32, 32}, {10, 10, -3, 5}, raw), Error);
  EXPECT_THROW(EncodeBox({10, 10, 32, 32}, {std::nan(""), 10, 3, 5}, raw), Error);
}

TEST(BoxCoding, ClipsTo200PixelsAndIntoTheImage) {
  const Box anchor{320, 240, 128, 128};
  const float big[4] = {0, 0, 2.f, 0.5f};  // 128·e² ≈ 946 px wide, 128·e^0.5 ≈ 211 px high
  Box b = DecodeBox(anchor, big);
  EXPECT_DOUBLE_EQ(b.w, 200);
  EXPECT_DOUBLE_EQ(b.h, 200);
  const float huge[4] = {0, 0, 1000.f, -1000.f};  // e^1000 = inf, e^-1000 = 0
  b = DecodeBox(anchor, huge);
  EXPECT_DOUBLE_EQ(b.w, 200);
  EXPECT_DOUBLE_EQ(b.h, 1);
  const float off[4] = {10.f, -10.f, 0, 0};  // centre far right and above the image
  b = DecodeBox(anchor, off);
  EXPECT_DOUBLE_EQ(b.cx, 639);
  EXPECT_DOUBLE_EQ(b.cy, 0);
  b = DecodeBox(anchor, off, 100, 50, 40);
  EXPECT_DOUBLE_EQ(b.cx, 99);
  EXPECT_DOUBLE_EQ(b.w, 40);
}

TEST(BoxCoding, IoU) {
  EXPECT_DOUBLE_EQ(BoxIoU({0, 0, 10, 10}, {0, 0, 10, 10}), 1);
  EXPECT_DOUBLE_EQ(BoxIoU({0, 0, 10, 10}, {20, 0, 10, 10}), 0);
  EXPECT_NEAR(BoxIoU({0, 0, 10, 10}, {5, 0, 10, 10}), 50.0 / 150.0, 1e-12);
  EXPECT_NEAR(BoxIoU({0, 0, 20, 20}, {0, 0, 10, 10}), 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(BoxCoverage({0, 0, 10, 10}, {0, 0, 20, 20}), 1);    // anchor inside
  EXPECT_NEAR(BoxCoverage({0, 0, 20, 20}, {0, 0, 10, 10}), 0.25, 1e-12);
  EXPECT_NEAR(BoxCoverage({0, 0, 10, 10}, {5, 5, 10, 10}), 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(BoxCoverage({0, 0, 10, 10}, {30, 0, 10, 10}), 0);
  EXPECT_DOUBLE_EQ(BoxCoverage({0, 0, 0, 10}, {0, 0, 10, 10}), 0);
}

// Hand-computed eq. 7.2 [ALGORITHM.md]: Prob_j = e^{p_j} / (Σ e^{p_i}·(1 + e^c)).
TEST(PostProcess, MatchesHandComputedSoftmaxTimesSigmoid) {
  const PyramidLayout l = SmallLayout(3);
  const int per = l.RawValuesPerCell();
  ASSERT_EQ(per, 8);
  std::vector<float> raw(size_t(l.CellCount()) * per, 0.f);
  // Cell 5: logits (1, 2, 3), c = 0.5. Cell 40: logits (−40, 0, 500), c = −30 (overflow test).
  float* r = &raw[5 * per];
  r[0] = 1;
  r[1] = 2;
  r[2] = 3;
  r[7] = 0.5f;
  r = &raw[40 * per];
  r[0] = -40;
  r[1] = 0;
  r[2] = 500;
  r[7] = -30;
  raw[41 * per + 7] = 800;  // cell 41: huge background logit → ~0 probability
  const std::vector<std::string> classes = {"a", "b", "c"};
  const Prior p = PostProcessPyramid(raw, l, classes);
  ASSERT_EQ(p.prob.size(), size_t(l.CellCount()) * 3);
  const double denom = (std::exp(1.0) + std::exp(2.0) + std::exp(3.0)) * (1 + std::exp(0.5));
  EXPECT_NEAR(p.Prob(5, 0), std::exp(1.0) / denom, 1e-6);
  EXPECT_NEAR(p.Prob(5, 1), std::exp(2.0) / denom, 1e-6);
  EXPECT_NEAR(p.Prob(5, 2), std::exp(3.0) / denom, 1e-6);
  // All-zero cell: uniform softmax × sigmoid(0) = 1/3 · 1/2.
  EXPECT_NEAR(p.Prob(0, 1), 1.0 / 6.0, 1e-7);
  // Large logits/confidences stay finite.
  EXPECT_NEAR(p.Prob(40, 2), 1.0, 1e-6);
  EXPECT_GE(p.Prob(40, 0), 0.f);
  EXPECT_LT(p.Prob(40, 0), 1e-30);
  EXPECT_TRUE(std::isfinite(p.Prob(41, 0)));
  EXPECT_LT(p.Prob(41, 0), 1e-30);
  for (float v : p.prob) ASSERT_TRUE(std::isfinite(v));
  // Per-cell probabilities sum to sigmoid(−c) ≤ 1.
  for (int cell = 0; cell < l.CellCount(); ++cell) {
    double s = 0;
    for (int j = 0; j < 3; ++j) s += p.Prob(cell, j);
    ASSERT_LE(s, 1 + 1e-6);
  }
  EXPECT_NEAR(p.Prob(5, 0) + p.Prob(5, 1) + p.Prob(5, 2), 1 / (1 + std::exp(0.5)), 1e-6);
  // Helpers.
  EXPECT_EQ(p.ClassIndex("b"), 1);
  EXPECT_EQ(p.ClassIndex("z"), -1);
  double mass = 0;
  for (int cell = 0; cell < l.CellCount(); ++cell) mass += p.Prob(cell, 2);
  EXPECT_NEAR(p.ClassMass(2), mass, 1e-9);
  EXPECT_THROW(p.ClassMass(3), Error);
}

TEST(PostProcess, DecodesBoxesFromTheirAnchors) {
  const PyramidLayout l = SmallLayout(3);
  const int per = l.RawValuesPerCell();
  std::vector<float> raw(size_t(l.CellCount()) * per, 0.f);
  const int cell = l.CellIndex(1, 2, 3);
  const Box anchor = l.AnchorBox(cell);
  const Box want{anchor.cx + 2, anchor.cy - 1, 15, 7};
  EncodeBox(anchor, want, &raw[size_t(cell) * per + 3]);
  raw[size_t(cell + 1) * per + 5] = 5;  // next cell: tw = 5 → clipped width
  PostProcessOptions opt;
  opt.max_box_px = 25;
  const Prior p = PostProcessPyramid(raw, l, {"a", "b", "c"}, opt);
  EXPECT_NEAR(p.boxes[cell].cx, want.cx, 1e-4);
  EXPECT_NEAR(p.boxes[cell].cy, want.cy, 1e-4);
  EXPECT_NEAR(p.boxes[cell].w, want.w, 1e-4);
  EXPECT_NEAR(p.boxes[cell].h, want.h, 1e-4);
  EXPECT_DOUBLE_EQ(p.boxes[cell + 1].w, 25);
  EXPECT_DOUBLE_EQ(p.boxes[0].w, 20);  // zero raw → the anchor itself
  EXPECT_DOUBLE_EQ(p.boxes[0].cx, l.AnchorBox(0).cx);
}

TEST(PostProcess, RejectsBadInput) {
  const PyramidLayout l = SmallLayout(3);
  const std::vector<std::string> classes = {"a", "b", "c"};
  std::vector<float> raw(size_t(l.CellCount()) * 8, 0.f);
  std::vector<float> short_raw(raw.begin(), raw.end() - 1);
  ExpectError([&] { PostProcessPyramid(short_raw, l, classes); }, {"expected", "values"});
  ExpectError([&] { PostProcessPyramid(raw, l, {"a", "b"}); }, {"num_classes"});
  std::vector<float> nan_raw = raw;
  nan_raw[9 * 8 + 7] = std::numeric_limits<float>::quiet_NaN();
  ExpectError([&] { PostProcessPyramid(nan_raw, l, classes); }, {"cell 9", "confidence"});
  nan_raw = raw;
  nan_raw[2 * 8 + 4] = std::numeric_limits<float>::infinity();
  ExpectError([&] { PostProcessPyramid(nan_raw, l, classes); }, {"cell 2", "ty"});
  PostProcessOptions bad;
  bad.max_box_px = 0;
  ExpectInvalid(bad, "max_box_px");
  ExpectError([&] { PostProcessPyramid(raw, l, classes, bad); }, {"max_box_px"});
  PyramidLayout broken = l;
  broken.levels.clear();
  ExpectError([&] { PostProcessPyramid(raw, broken, classes); }, {"layout"});
}

TEST(UniformPrior, EqualProbabilityAndAnchorBoxes) {
  const PyramidLayout l = PyramidLayout::Thesis();
  const Prior p = UniformPrior(l, YcbVideoClassNames());
  ASSERT_EQ(p.prob.size(), 6300u * 21);
  for (float v : p.prob) ASSERT_FLOAT_EQ(v, 1.f / 6300);
  EXPECT_NEAR(p.ClassMass(4), 1.0, 1e-4);
  for (int c = 0; c < 6300; c += 97) {
    const Box a = l.AnchorBox(c);
    EXPECT_DOUBLE_EQ(p.boxes[c].cx, a.cx);
    EXPECT_DOUBLE_EQ(p.boxes[c].w, std::min(200.0, a.w));
  }
  const Prior q = UniformPrior(l, YcbVideoClassNames(), 50);
  EXPECT_DOUBLE_EQ(q.boxes[0].w, 50);  // 128 px anchor clipped
  EXPECT_THROW(UniformPrior(l, {"only_one"}), Error);
}

TEST(YcbVideo, ClassNamesMatchTheModelsFolder) {
  const auto names = YcbVideoClassNames();
  ASSERT_EQ(names.size(), 21u);
  EXPECT_EQ(names.front(), "002_master_chef_can");
  EXPECT_EQ(names.back(), "061_foam_brick");
  for (size_t i = 1; i < names.size(); ++i) EXPECT_LT(names[i - 1], names[i]);  // official order
  const fs::path models = testing_util::YcbvDataDir() / "models";
  if (!fs::exists(models)) GTEST_SKIP() << "no shared data at " << models;
  for (const auto& n : names) EXPECT_TRUE(fs::exists(models / (n + ".ply"))) << n;
}

TEST(RawFile, RoundTripIsBitExactAndLittleEndian) {
  const PyramidLayout l = SmallLayout(3);
  std::vector<float> raw(size_t(l.CellCount()) * 8);
  for (size_t i = 0; i < raw.size(); ++i) raw[i] = float(std::sin(0.37 * i) * 7.5);
  raw[0] = 1.0f;
  const ScratchDir dir("prior");
  const std::string path = dir.Path("roundtrip.pyr");
  WriteRawPyramid(raw, l, path);
  EXPECT_EQ(fs::file_size(path), raw.size() * 4);
  // 1.0f little-endian = 00 00 80 3f.
  const std::string bytes = ReadFile(path);
  ASSERT_GE(bytes.size(), 4u);
  EXPECT_EQ(std::uint8_t(bytes[0]), 0x00);
  EXPECT_EQ(std::uint8_t(bytes[2]), 0x80);
  EXPECT_EQ(std::uint8_t(bytes[3]), 0x3f);
  const std::vector<float> back = ReadRawPyramid(path, l);
  ASSERT_EQ(back.size(), raw.size());
  for (size_t i = 0; i < raw.size(); ++i) ASSERT_EQ(back[i], raw[i]);
}

TEST(RawFile, BadFilesThrowNamingTheFileAndExpectedSize) {
  const PyramidLayout l = PyramidLayout::Thesis();
  const std::string expected_bytes = std::to_string(6300 * 26 * 4);  // 655200
  const ScratchDir dir("prior");
  const std::string missing = dir.Path("does_not_exist.pyr");
  ExpectError([&] { ReadRawPyramid(missing, l); }, {missing, expected_bytes});

  // The floats' bytes as a file (host order: little-endian, as the format).
  auto write_floats = [&](const std::string& name, const std::vector<float>& values) {
    return dir.Write(name, std::string(reinterpret_cast<const char*>(values.data()), values.size() * 4));
  };
  const std::string wrong = write_floats("wrong_size.pyr", std::vector<float>(6300 * 26 - 3, 0.f));
  ExpectError([&] { ReadRawPyramid(wrong, l); }, {wrong, expected_bytes});

  std::vector<float> v(6300 * 26, 0.f);
  v[26 * 100 + 3] = std::numeric_limits<float>::quiet_NaN();
  const std::string nan = write_floats("nan.pyr", v);
  ExpectError([&] { ReadRawPyramid(nan, l); }, {nan, "cell 100", "NaN"});

  ExpectError([&] { ReadRawPyramid(fs::temp_directory_path().string(), l); },
              {fs::temp_directory_path().string()});
  ExpectError([&] { WriteRawPyramid(std::vector<float>(5), l, dir.Path("x.pyr")); },
              {"expected"});
  ExpectError([&] { WriteRawPyramid(v, l, "/nonexistent_dir_pf/x.pyr"); },
              {"/nonexistent_dir_pf/x.pyr"});
}

}  // namespace
}  // namespace posefilter
