// Stage 1 without a detector (posefilter/auto_prior.h): candidate regions above the support
// plane, the detections they give, and an estimate that starts from them.
#include "posefilter/auto_prior.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "posefilter/filter.h"
#include "posefilter/metrics.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

SynthScene SynthTableScene(const std::string& target, std::uint64_t seed, double occlusion = 0.0) {
  SynthOptions so;
  so.target = target;
  so.occlusion = occlusion;
  so.clutter = 0;
  return MakeSynthScene(so, seed);
}

// The pixel bounding box of the target's visible pixels (label 1): x0, y0, x1, y1.
std::array<int, 4> TargetPixelBox(const SynthScene& sc) {
  std::array<int, 4> b = {sc.camera.width, sc.camera.height, 0, 0};
  for (int v = 0; v < sc.camera.height; ++v)
    for (int u = 0; u < sc.camera.width; ++u)
      if (sc.labels[std::size_t(v) * sc.camera.width + u] == 1 && sc.depth.at(u, v) > 0)
        b = {std::min(b[0], u), std::min(b[1], v), std::max(b[2], u + 1), std::max(b[3], v + 1)};
  return b;
}

// Plane removal leaves the object's points: nearly every visible target pixel is in a region,
// nearly no table pixel is, and the target's region holds its whole silhouette.
TEST(AutoPriorTest, RegionsHoldTheObjectAndNotTheTable) {
  const SynthScene sc = SynthTableScene("box", 5);
  std::vector<int> labels;
  const std::vector<CandidateRegion> regions = FindCandidateRegions(sc.depth, sc.camera, {}, &labels);
  ASSERT_FALSE(regions.empty());
  ASSERT_EQ(labels.size(), sc.labels.size());
  int target = 0, target_in = 0, table = 0, table_in = 0;
  std::vector<int> target_region_votes(regions.size() + 1, 0);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (!(sc.depth.data[i] > 0)) {
      EXPECT_EQ(labels[i], 0);  // a missing pixel is in no region
      continue;
    }
    if (sc.labels[i] == 1) ++target, target_in += labels[i] > 0, ++target_region_votes[std::size_t(labels[i])];
    if (sc.labels[i] == 0) ++table, table_in += labels[i] > 0;
  }
  ASSERT_GT(target, 500);
  EXPECT_GT(double(target_in) / target, 0.95);
  EXPECT_LT(double(table_in) / table, 0.02);
  const int best = int(std::max_element(target_region_votes.begin() + 1, target_region_votes.end()) -
                       target_region_votes.begin());
  const CandidateRegion& r = regions[std::size_t(best - 1)];
  const auto b = TargetPixelBox(sc);
  EXPECT_LE(r.x0, b[0] + 2);
  EXPECT_LE(r.y0, b[1] + 2);
  EXPECT_GE(r.x1, b[2] - 2);
  EXPECT_GE(r.y1, b[3] - 2);
  EXPECT_NEAR(r.median_z, sc.distance_m, 0.15);
}

// The detections give the object a box on its silhouette, and the filter started from them
// finds the pose.
TEST(AutoPriorTest, DetectionsLeadTheFilterToThePose) {
  for (const char* target : {"box", "lshape"}) {
    SCOPED_TRACE(target);
    const SynthScene sc = SynthTableScene(target, 7);
    const std::vector<Detection> dets = AutoDetections(sc.depth, sc.camera, {{sc.target.name, sc.target.Diameter()}});
    ASSERT_FALSE(dets.empty());
    const auto b = TargetPixelBox(sc);
    const Box truth{0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3]), double(b[2] - b[0]), double(b[3] - b[1])};
    double best_iou = 0;
    for (const Detection& d : dets) {
      EXPECT_EQ(d.cls, sc.target.name);
      EXPECT_GT(d.score, 0.0);
      EXPECT_LE(d.score, 1.0);
      best_iou = std::max(best_iou, BoxIoU(DetectionBox(d), truth));
    }
    EXPECT_GT(best_iou, 0.5);
    const std::vector<std::string> classes = {sc.target.name};
    const Prior prior = PriorFromDetections(dets, PyramidLayout::Thesis(sc.camera.width, sc.camera.height, 1), classes);
    FilterOptions o;
    o.num_particles = 200;
    o.restarts = 2;
    o.threads = 2;
    const EstimateResult r = EstimatePose(SceneInput{sc.depth, sc.camera}, sc.target, prior, 0, o);
    const PoseErrors e = ComputePoseErrors(SamplePoints(sc.target), sc.target.Diameter(), r.T_cam_obj, sc.gt[0].T_cam_obj);
    EXPECT_TRUE(e.adds_ok) << "ADD-S " << 1000 * e.adds << " mm";
  }
}

// Nothing above the table: no region, no detection — a clear empty result.
TEST(AutoPriorTest, AnEmptyTableHasNoCandidates) {
  const SynthScene sc = SynthTableScene("box", 5);
  DepthImage table = sc.depth;
  for (std::size_t i = 0; i < table.data.size(); ++i)
    if (sc.labels[i] != 0) table.data[i] = 0;  // only the table's pixels remain
  EXPECT_TRUE(FindCandidateRegions(table, sc.camera).empty());
  EXPECT_TRUE(AutoDetections(table, sc.camera, {{"box", 0.2}}).empty());
}

// A region larger than the object (touching objects) is tiled with boxes of the object's
// projected size; one of them holds the region's centre.
TEST(AutoPriorTest, ARegionLargerThanTheObjectIsTiled) {
  const SynthScene sc = SynthTableScene("box", 5);
  const double small = sc.target.Diameter() / 4;  // as if four objects stood there
  const std::vector<Detection> dets = AutoDetections(sc.depth, sc.camera, {{"part", small}});
  ASSERT_GT(dets.size(), 2u);
  const auto b = TargetPixelBox(sc);
  const double cx = 0.5 * (b[0] + b[2]), cy = 0.5 * (b[1] + b[3]);
  const AutoPriorOptions opt;
  bool centre_covered = false;
  for (const Detection& d : dets) {
    EXPECT_EQ(d.w, d.h);
    EXPECT_LE(d.score, opt.tile_score);
    centre_covered = centre_covered || (cx >= d.x && cx <= d.x + d.w && cy >= d.y && cy <= d.y + d.h);
  }
  EXPECT_TRUE(centre_covered);
  // With an object that fits the whole region among those looked for, the region is more
  // likely that object: the small one's tiles score less, the fitting one gets the region box.
  const std::vector<Detection> both =
      AutoDetections(sc.depth, sc.camera, {{"part", small}, {"whole", sc.target.Diameter()}});
  int parts = 0;
  double best_whole = 0;
  for (const Detection& d : both) {
    if (d.cls == "part") {
      ++parts;
      EXPECT_LE(d.score, opt.tile_score * opt.tile_weight_when_one_fits + 1e-12);
    } else {
      best_whole = std::max(best_whole, d.score);
    }
  }
  EXPECT_EQ(parts, int(dets.size()));
  EXPECT_GT(best_whole, opt.tile_score);
}

TEST(AutoPriorTest, BadInputsAreErrors) {
  const SynthScene sc = SynthTableScene("box", 5);
  testing_util::ExpectError([&] { FindCandidateRegions(DepthImage(10, 10, 1.f), sc.camera); }, {"size"});
  testing_util::ExpectError([&] { AutoDetections(sc.depth, sc.camera, {{"box", 0.0}}); }, {"'box'", "diameter"});
  AutoPriorOptions bad;
  bad.max_step_fraction = 0;
  testing_util::ExpectError([&] { FindCandidateRegions(sc.depth, sc.camera, bad); }, {"max_step_fraction"});
  bad = {};
  bad.min_height_m = 1;
  bad.max_height_m = 0.5;
  testing_util::ExpectError([&] { FindCandidateRegions(sc.depth, sc.camera, bad); }, {"min_height_m"});
}

}  // namespace
}  // namespace posefilter
