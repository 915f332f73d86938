// Instance masks as a stage-1 prior (posefilter/mask_prior.h) and label PNG I/O.
#include "posefilter/mask_prior.h"

#include <gtest/gtest.h>

#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;

class MaskPriorTest : public testing_util::ScratchDirTest {
 protected:
  MaskPriorTest() : ScratchDirTest("mask") {}
};

// A 40 × 30 label image: id 3 on columns 5..9 of rows 2..4, id 7 on one pixel (20, 10).
LabelImage TwoInstances() {
  LabelImage l{40, 30, std::vector<std::uint16_t>(40 * 30, 0)};
  for (int v = 2; v <= 4; ++v)
    for (int u = 5; u <= 9; ++u) l.ids[std::size_t(v) * 40 + u] = 3;
  l.ids[10 * 40 + 20] = 7;
  return l;
}

TEST_F(MaskPriorTest, InstancesBoxesAndDetections) {
  const std::vector<InstanceMask> m = MasksFromLabels(TwoInstances(), {{3, "mug"}, {7, "bowl"}, {9, "unused"}}, "m.png");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].id, 3);
  EXPECT_EQ(m[0].cls, "mug");
  EXPECT_EQ(m[0].area, 15);
  EXPECT_DOUBLE_EQ(m[0].box.cx, 7);
  EXPECT_DOUBLE_EQ(m[0].box.cy, 3);
  EXPECT_DOUBLE_EQ(m[0].box.w, 5);
  EXPECT_DOUBLE_EQ(m[0].box.h, 3);
  EXPECT_EQ(m[0].pixels[2 * 40 + 5], 1);
  EXPECT_EQ(m[0].pixels[10 * 40 + 20], 0);
  EXPECT_EQ(m[1].cls, "bowl");
  EXPECT_EQ(m[1].area, 1);
  const Detection d = MaskDetection(m[0], 0.8);
  EXPECT_EQ(d.cls, "mug");
  EXPECT_DOUBLE_EQ(d.score, 0.8);
  EXPECT_DOUBLE_EQ(d.x, 4.5);  // the pixels' full extent, as ProjectedBox
  EXPECT_DOUBLE_EQ(d.y, 1.5);
  EXPECT_DOUBLE_EQ(d.w, 5);
  EXPECT_DOUBLE_EQ(d.h, 3);
}

TEST_F(MaskPriorTest, UnknownIdsAndEmptyMasksAreErrorsNamingTheFile) {
  ExpectError([] { MasksFromLabels(TwoInstances(), {{3, "mug"}}, "seg.png"); }, {"seg.png", "mask id 7", "class map"});
  ExpectError([] { MasksFromLabels(TwoInstances(), {{1, "mug"}}, "seg.png"); }, {"seg.png", "mask ids 3, 7"});
  ExpectError([] { MasksFromLabels(LabelImage{4, 4, std::vector<std::uint16_t>(16, 0)}, {{1, "mug"}}, "seg.png"); },
              {"seg.png", "mask is empty"});
  // A 16-bit mask with a thousand unmapped ids: the first ten and a count, not a 5 kB line.
  LabelImage many{100, 10, std::vector<std::uint16_t>(1000)};
  for (int i = 0; i < 1000; ++i) many.ids[std::size_t(i)] = std::uint16_t(i + 1);
  try {
    MasksFromLabels(many, {{5000, "mug"}}, "seg16.png");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("mask ids 1, 2, 3, 4, 5, 6, 7, 8, 9, 10 and 990 more"), std::string::npos) << what;
    EXPECT_LT(what.size(), 120u) << what;
  }
}

TEST_F(MaskPriorTest, ClassMapsAsObjectsListsAndTheYcbVideoDefault) {
  const auto a = ReadMaskClasses(Write("a.json", R"({"1": "mug", "12": "bowl"})"));
  EXPECT_EQ(a.size(), 2u);
  EXPECT_EQ(a.at(12), "bowl");
  const auto b = ReadMaskClasses(Write("b.json", R"(["mug", "bowl"])"));
  EXPECT_EQ(b.at(2), "bowl");
  const auto y = YcbVideoMaskClasses();
  EXPECT_EQ(y.size(), 21u);
  EXPECT_EQ(y.at(1), "002_master_chef_can");
  EXPECT_EQ(y.at(21), "061_foam_brick");
  ExpectError([&] { ReadMaskClasses(Path("missing.json")); }, {"missing.json", "cannot open"});
  ExpectError([&] { ReadMaskClasses(Write("c.json", "{")); }, {"c.json", "malformed"});
  ExpectError([&] { ReadMaskClasses(Write("d.json", R"({"x": "mug"})")); }, {"d.json", "'x'", "not an integer"});
  ExpectError([&] { ReadMaskClasses(Write("e.json", R"({"0": "mug"})")); }, {"e.json", "[1, 65535]"});
  ExpectError([&] { ReadMaskClasses(Write("f.json", R"({"1": ""})")); }, {"f.json", "non-empty string"});
  ExpectError([&] { ReadMaskClasses(Write("g.json", R"([])")); }, {"g.json", "empty"});
  ExpectError([&] { ReadMaskClasses(Write("h.json", "3")); }, {"h.json", "object"});
}

TEST_F(MaskPriorTest, LabelPngsRoundTripAndBadFilesAreErrors) {
  LabelImage l = TwoInstances();
  l.ids[0] = 65535;
  SaveLabelPng(l, Path("l.png"));
  const LabelImage r = LoadLabelPng(Path("l.png"));
  EXPECT_EQ(r.width, 40);
  EXPECT_EQ(r.height, 30);
  EXPECT_EQ(r.ids, l.ids);
  // 8-bit label images (YCB-Video's label.png) read as they are.
  std::vector<std::uint8_t> gray(12, 0);
  gray[5] = 21;
  SaveGray8Png(gray, 4, 3, Path("g.png"));
  EXPECT_EQ(LoadLabelPng(Path("g.png")).ids[5], 21);
  ExpectError([&] { LoadLabelPng(Path("none.png")); }, {"none.png", "label"});
  ExpectError([&] { LoadLabelPng(Write("bad.png", "not a png")); }, {"bad.png", "not a PNG"});
  RgbImage rgb(4, 3);
  SaveRgbPng(rgb, Path("rgb.png"));
  ExpectError([&] { LoadLabelPng(Path("rgb.png")); }, {"rgb.png", "single-channel"});
}

}  // namespace
}  // namespace posefilter
