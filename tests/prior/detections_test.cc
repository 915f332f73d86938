// Tests of the detection list form of the stage-1 prior: JSON I/O and conversion to a pyramid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/prior.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::ExpectInvalid;
using testing_util::ScratchDir;

TEST(DetectionsJson, RoundTrip) {
  const std::vector<Detection> dets = {{"004_sugar_box", 0.87, 250.5, 120.25, 80, 140},
                                       {"025_mug", 0.0, 0, 0, 1, 2},
                                       {"061_foam_brick", 1.0, 600, 400, 60, 79.5}};
  const ScratchDir dir("prior");
  const std::string path = dir.Path("dets.json");
  WriteDetectionsJson(dets, path);
  const auto back = ReadDetectionsJson(path);
  ASSERT_EQ(back.size(), dets.size());
  for (size_t i = 0; i < dets.size(); ++i) {
    EXPECT_EQ(back[i].cls, dets[i].cls);
    EXPECT_DOUBLE_EQ(back[i].score, dets[i].score);
    EXPECT_DOUBLE_EQ(back[i].x, dets[i].x);
    EXPECT_DOUBLE_EQ(back[i].y, dets[i].y);
    EXPECT_DOUBLE_EQ(back[i].w, dets[i].w);
    EXPECT_DOUBLE_EQ(back[i].h, dets[i].h);
  }
}

TEST(DetectionsJson, AcceptsBareListAndObjectForm) {
  const ScratchDir dir("prior");
  const auto a = ReadDetectionsJson(
      dir.Write("list.json", R"([{"class": "025_mug", "score": 0.5, "bbox": [1, 2, 3, 4]}])"));
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].cls, "025_mug");
  EXPECT_DOUBLE_EQ(a[0].h, 4);
  const auto b = ReadDetectionsJson(dir.Write(
      "obj.json",
      R"({"detections": [{"class": "x", "score": 1, "bbox": [1, 2, 3, 4], "extra": 7}]})"));
  ASSERT_EQ(b.size(), 1u);
  EXPECT_DOUBLE_EQ(b[0].score, 1);
}

TEST(DetectionsJson, BadEntriesNameFileEntryAndKey) {
  const ScratchDir dir("prior");
  struct Case {
    const char* name;
    const char* text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"missing_score.json",
       R"([{"class": "a", "score": 0.5, "bbox": [1,2,3,4]}, {"class": "a", "bbox": [1,2,3,4]}])",
       {"detection 1", "\"score\"", "missing"}},
      {"missing_class.json", R"([{"score": 0.5, "bbox": [1,2,3,4]}])", {"detection 0", "\"class\""}},
      {"missing_bbox.json", R"({"detections": [{"class": "a", "score": 0.5}]})",
       {"detection 0", "\"bbox\""}},
      {"score_high.json", R"([{"class": "a", "score": 1.5, "bbox": [1,2,3,4]}])",
       {"detection 0", "\"score\"", "[0, 1]"}},
      {"score_neg.json", R"([{"class": "a", "score": -0.1, "bbox": [1,2,3,4]}])",
       {"detection 0", "\"score\""}},
      {"score_str.json", R"([{"class": "a", "score": "high", "bbox": [1,2,3,4]}])",
       {"detection 0", "\"score\"", "not a number"}},
      {"neg_size.json", R"([{"class": "a", "score": 0.5, "bbox": [1,2,-3,4]}])",
       {"detection 0", "\"bbox\"", "> 0"}},
      {"zero_size.json", R"([{"class": "a", "score": 0.5, "bbox": [1,2,3,0]}])",
       {"detection 0", "\"bbox\""}},
      {"short_bbox.json", R"([{"class": "a", "score": 0.5, "bbox": [1,2,3]}])",
       {"detection 0", "\"bbox\""}},
      {"class_num.json", R"([{"class": 3, "score": 0.5, "bbox": [1,2,3,4]}])",
       {"detection 0", "\"class\"", "string"}},
      {"not_object.json", R"([17])", {"detection 0"}},
      {"empty_list.json", R"([])", {"holds no detections"}},
      {"empty_obj.json", R"({"detections": []})", {"holds no detections"}},
      {"no_key.json", R"({"boxes": []})", {"\"detections\""}},
      {"malformed.json", R"([{"class": )", {"malformed JSON"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.Write(c.name, c.text);
    std::vector<std::string> parts = c.parts;
    parts.push_back(path);
    ExpectError([&] { ReadDetectionsJson(path); }, parts);
  }
  // An empty list is accepted on request.
  EXPECT_TRUE(ReadDetectionsJson(dir.Path("empty_list.json"), /*allow_empty=*/true).empty());
  const std::string missing = dir.Path("no_such_detections.json");
  ExpectError([&] { ReadDetectionsJson(missing); }, {missing});
}

// The brute-force expectation of the documented conversion for one class, one detection.
double ExpectedQ(const PyramidLayout& l, int cell, const Detection& d, double floor) {
  return std::max(floor, d.score * BoxCoverage(l.AnchorBox(cell), DetectionBox(d)));
}

TEST(DetectionPrior, PeaksOnTheDetectionWithFloorElsewhere) {
  const PyramidLayout l = PyramidLayout::Thesis();
  const auto classes = YcbVideoClassNames();
  const Detection det{"004_sugar_box", 0.9, 250, 150, 100, 120};  // centre (300, 210)
  const DetectionPriorOptions opt;
  const Prior p = PriorFromDetections({det}, l, classes, opt);
  const int cls = p.ClassIndex("004_sugar_box");
  ASSERT_EQ(cls, 2);
  const Box dbox = DetectionBox(det);

  int best = 0;
  for (int c = 1; c < l.CellCount(); ++c)
    if (p.Prob(c, cls) > p.Prob(best, cls)) best = c;
  // The best cell lies inside the detection, with the detection's score.
  EXPECT_NEAR(BoxCoverage(l.AnchorBox(best), dbox), 1.0, 1e-12);
  EXPECT_NEAR(p.Prob(best, cls), det.score, 1e-5);

  int overlapping = 0;
  for (int c = 0; c < l.CellCount(); ++c) {
    const double iou = BoxIoU(l.AnchorBox(c), dbox);
    // Probabilities equal the documented q = max(floor, score·coverage) (float32).
    ASSERT_NEAR(p.Prob(c, cls), ExpectedQ(l, c, det, opt.floor_prob), 1e-5) << "cell " << c;
    double sum = 0;
    for (int j = 0; j < 21; ++j) sum += p.Prob(c, j);
    ASSERT_LE(sum, 1 + 1e-5);
    if (iou > 0) {
      ++overlapping;
      // Decoded box = the detection box (clipped to 200 px: it is 100×120, so unchanged).
      ASSERT_NEAR(p.boxes[c].cx, dbox.cx, 1e-3) << "cell " << c;
      ASSERT_NEAR(p.boxes[c].cy, dbox.cy, 1e-3);
      ASSERT_NEAR(p.boxes[c].w, dbox.w, 1e-3);
      ASSERT_NEAR(p.boxes[c].h, dbox.h, 1e-3);
    } else {
      // Elsewhere: the anchor box and the floor, for every class — low but not zero.
      const Box a = l.AnchorBox(c);
      ASSERT_NEAR(p.boxes[c].cx, a.cx, 1e-6);
      ASSERT_NEAR(p.boxes[c].w, a.w, 1e-4);
      ASSERT_NEAR(p.Prob(c, cls), opt.floor_prob, 1e-7);
    }
    // Other classes keep exactly the floor everywhere.
    ASSERT_NEAR(p.Prob(c, 0), opt.floor_prob, 1e-7);
  }
  EXPECT_GT(overlapping, 50);
  // Far corner: non-zero.
  EXPECT_GT(p.Prob(0, cls), 0.f);
  // The detection carries most of the class mass (≈ 0.9·box area/stride² summed over the
  // levels = 221 against 6300 · floor_prob for the floor).
  double near = 0;
  for (int c = 0; c < l.CellCount(); ++c)
    if (BoxIoU(l.AnchorBox(c), dbox) > 0) near += p.Prob(c, cls);
  EXPECT_GT(near / p.ClassMass(cls), 0.95);
  EXPECT_NEAR(near, 0.9 * 12000 * (1.0 / 1024 + 1.0 / 256 + 1.0 / 64), 0.05 * near);
}

TEST(DetectionPrior, BigBoxesAreClippedAndBestDetectionGivesTheBox) {
  const PyramidLayout l = PyramidLayout::Thesis();
  const auto classes = YcbVideoClassNames();
  const Detection big{"024_bowl", 0.8, 100, 100, 300, 250};  // centre (250, 225)
  const Detection small{"025_mug", 0.95, 230, 205, 40, 40};  // centre (250, 225)
  const Prior p = PriorFromDetections({big, small}, l, classes);
  // A level-0 (128 px) anchor at the centre lies inside the big box (coverage 1 · 0.8) and
  // is 40²/128² covered by the small one (· 0.95 = 0.09); a level-2 (32 px) anchor lies inside
  // both, and the mug's higher score wins.
  const int c0 = l.CellIndex(0, 7, 7);  // anchor centre (239.5, 239.5)
  const int c2 = l.CellIndex(2, 28, 31);  // anchor centre (251.5, 227.5)
  EXPECT_NEAR(p.boxes[c0].w, 200, 1e-6);  // 300 px clipped to 200
  EXPECT_NEAR(p.boxes[c0].h, 200, 1e-6);
  EXPECT_NEAR(p.boxes[c0].cx, 250, 1e-3);
  EXPECT_NEAR(p.boxes[c2].w, 40, 1e-3);
  EXPECT_NEAR(p.boxes[c2].cy, 225, 1e-3);
  const int mug = p.ClassIndex("025_mug"), bowl = p.ClassIndex("024_bowl");
  EXPECT_GT(p.Prob(c2, mug), p.Prob(c2, bowl));
  EXPECT_GT(p.Prob(c0, bowl), p.Prob(c0, mug));
}

TEST(DetectionPrior, OverlappingClassesKeepSumAtMostOneAndTheFloor) {
  // A tiny pyramid with anchors equal to the detections, so IoU = 1 and Σ q > 1.
  PyramidLayout l;
  l.image_width = 64;
  l.image_height = 64;
  l.num_classes = 3;
  l.levels = {{2, 2, 32, 32}};
  const std::vector<std::string> classes = {"a", "b", "c"};
  const std::vector<Detection> dets = {{"a", 0.9, 0, 0, 32, 32}, {"b", 0.7, 0, 0, 32, 32}};
  DetectionPriorOptions opt;
  opt.floor_prob = 0.01;
  const Prior p = PriorFromDetections(dets, l, classes, opt);
  const int c = 0;  // anchor [−0.5, 31.5]², covered 31.5²/32² by the detections
  double sum = 0;
  for (int j = 0; j < 3; ++j) sum += p.Prob(c, j);
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_NEAR(p.Prob(c, 2), 0.01, 1e-6);
  EXPECT_GT(p.Prob(c, 0), p.Prob(c, 1));
  // The ratio of the parts above the floor is kept.
  const double cover = BoxCoverage(l.AnchorBox(c), DetectionBox(dets[0]));
  EXPECT_NEAR(cover, 31.5 * 31.5 / 1024, 1e-12);
  EXPECT_NEAR((p.Prob(c, 0) - 0.01) / (p.Prob(c, 1) - 0.01),
              (0.9 * cover - 0.01) / (0.7 * cover - 0.01), 1e-4);
  // Raw values stay inside the hw exp ROM's input range [−16, 16].
  const auto raw = DetectionsToRawPyramid(dets, l, classes, opt);
  for (size_t i = 0; i < raw.size(); ++i) {
    const int f = int(i % 8);
    if (f < 3 || f == 7) {
      EXPECT_GE(raw[i], -16.f);
      EXPECT_LE(raw[i], 16.f);
    }
  }
}

TEST(DetectionPrior, EmptyListGivesUniformPrior) {
  const PyramidLayout l = PyramidLayout::Thesis();
  const Prior p = PriorFromDetections({}, l, YcbVideoClassNames());
  const double floor = DetectionPriorOptions{}.floor_prob;
  for (float v : p.prob) ASSERT_NEAR(v, floor, floor * 1e-4);
  for (int c = 0; c < l.CellCount(); c += 111) EXPECT_NEAR(p.boxes[c].cx, l.AnchorBox(c).cx, 1e-6);
}

TEST(DetectionPrior, RejectsBadInput) {
  const ScratchDir dir("prior");
  const PyramidLayout l = PyramidLayout::Thesis();
  const auto classes = YcbVideoClassNames();
  ExpectError([&] { DetectionsToRawPyramid({{"999_unicorn", 0.5, 1, 1, 10, 10}}, l, classes); },
              {"999_unicorn", "unknown class"});
  ExpectError(
      [&] {
        DetectionsToRawPyramid({{"025_mug", 0.5, 1, 1, 10, 10}, {"025_mug", 2, 1, 1, 10, 10}}, l,
                               classes);
      },
      {"detection 1", "score"});
  ExpectError([&] { DetectionsToRawPyramid({{"025_mug", 0.5, 1, 1, 10, -1}}, l, classes); },
              {"detection 0", "bbox"});
  ExpectError([&] { DetectionsToRawPyramid({}, l, {"a", "b"}); }, {"num_classes"});
  DetectionPriorOptions opt;
  opt.floor_prob = 0;
  ExpectInvalid(opt, "floor_prob");
  ExpectError([&] { DetectionsToRawPyramid({}, l, classes, opt); }, {"floor_prob"});
  opt.floor_prob = 0.1;  // 21 × 0.1 > 1
  std::string why;
  EXPECT_TRUE(opt.IsValid(&why)) << why;
  ExpectError([&] { DetectionsToRawPyramid({}, l, classes, opt); }, {"floor_prob", "num_classes"});
  opt = {};
  opt.max_box_px = -5;
  ExpectInvalid(opt, "max_box_px");
  ExpectError([&] { WriteDetectionsJson({{"a", 0.5, 0, 0, 0, 1}}, dir.Path("bad_out.json")); },
              {"detection 0", "bbox"});
}

TEST(DetectionPrior, RawFileCarriesTheSamePrior) {
  // Detections → raw → file → post-process gives what PriorFromDetections gives.
  const PyramidLayout l = PyramidLayout::Thesis();
  const auto classes = YcbVideoClassNames();
  const std::vector<Detection> dets = {{"006_mustard_bottle", 0.6, 400, 50, 70, 180}};
  const ScratchDir dir("prior");
  const std::string path = dir.Path("from_dets.pyr");
  WriteRawPyramid(DetectionsToRawPyramid(dets, l, classes), l, path);
  const Prior a = PostProcessPyramid(ReadRawPyramid(path, l), l, classes);
  const Prior b = PriorFromDetections(dets, l, classes);
  ASSERT_EQ(a.prob.size(), b.prob.size());
  for (size_t i = 0; i < a.prob.size(); ++i) ASSERT_EQ(a.prob[i], b.prob[i]);
  for (size_t i = 0; i < a.boxes.size(); ++i) ASSERT_EQ(a.boxes[i].cx, b.boxes[i].cx);
}

}  // namespace
}  // namespace posefilter
