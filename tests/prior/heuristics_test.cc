// Tests of the per-cell heuristic volumes (thesis §1.1.2, §7.4; docs/ALGORITHM.md §3).
#include <gtest/gtest.h>

#include <cmath>

#include "posefilter/error.h"
#include "posefilter/heuristics.h"
#include "posefilter/prior.h"
#include "prior/heuristics_workload.h"
#include "prior/volume_cache.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::ExpectInvalid;

TEST(Heuristics, FrontoParallelPlaneAtOneMetre) {
  const Camera cam;  // thesis camera, identity base_to_camera
  const DepthImage depth(cam.width, cam.height, 1.0f);
  const Box box{320, 240, 100, 80};
  const auto vols = ComputeHeuristics(depth, cam, {box});
  ASSERT_EQ(vols.size(), 1u);
  const Volume& v = vols[0];
  ASSERT_TRUE(v.valid);
  EXPECT_NEAR(v.min.z(), 1.0, 1e-9);
  EXPECT_NEAR(v.max.z(), 1.0, 1e-9);
  // x/y inside the back-projection of the box's pixels (u 270..369, v 200..279) at 1 m...
  const double xl = (270 - cam.cx) / cam.fx, xh = (369 - cam.cx) / cam.fx;
  const double yl = (200 - cam.cy) / cam.fy, yh = (279 - cam.cy) / cam.fy;
  EXPECT_GE(v.min.x(), xl - 1e-12);
  EXPECT_LE(v.max.x(), xh + 1e-12);
  EXPECT_GE(v.min.y(), yl - 1e-12);
  EXPECT_LE(v.max.y(), yh + 1e-12);
  // ...and spanning about its 10–90 % part.
  EXPECT_NEAR(v.max.x() - v.min.x(), 0.8 * (xh - xl), 0.05 * (xh - xl));
  EXPECT_NEAR(v.max.y() - v.min.y(), 0.8 * (yh - yl), 0.05 * (yh - yl));
  EXPECT_LT(v.min.x(), v.max.x());
  // Centre ≈ the back-projected box centre.
  EXPECT_NEAR(v.Centre().x(), (box.cx - cam.cx) / cam.fx, 0.01);
  EXPECT_NEAR(v.Centre().y(), (box.cy - cam.cy) / cam.fy, 0.01);

  // Full range with percentiles 0 and 1.
  HeuristicOptions all;
  all.percentile_lo = 0;
  all.percentile_hi = 1;
  all.max_samples = 100000;
  const Volume w = ComputeHeuristics(depth, cam, {box}, all)[0];
  EXPECT_NEAR(w.min.x(), xl, 1e-12);
  EXPECT_NEAR(w.max.x(), xh, 1e-12);
  EXPECT_NEAR(w.min.y(), yl, 1e-12);
  EXPECT_NEAR(w.max.y(), yh, 1e-12);
}

TEST(Heuristics, DepthExtensionAddsDepthBehindTheSurface) {
  const Camera cam;
  const DepthImage depth(cam.width, cam.height, 1.0f);
  HeuristicOptions opt;
  opt.depth_extension_m = 0.05;
  const Volume v = ComputeHeuristics(depth, cam, {{325, 224, 60, 60}}, opt)[0];
  ASSERT_TRUE(v.valid);
  EXPECT_NEAR(v.min.z(), 1.0, 1e-9);  // half the points are the surface
  EXPECT_GT(v.max.z(), 1.045);         // the other half 5 cm further along near-axial rays
  EXPECT_LE(v.max.z(), 1.05 + 1e-9);
  // x/y grow only a little (rays fan out by z ratio 1.05).
  const Volume v0 = ComputeHeuristics(depth, cam, {{325, 224, 60, 60}})[0];
  EXPECT_GE(v.max.x() - v.min.x(), v0.max.x() - v0.min.x() - 1e-12);
  EXPECT_LE(v.max.x() - v.min.x(), 1.06 * (v0.max.x() - v0.min.x()));
}

TEST(Heuristics, InvalidWithoutEnoughDepth) {
  const Camera cam;
  DepthImage depth(cam.width, cam.height, 1.0f);
  // Missing depth in the left half.
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < 320; ++u) depth.at(u, v) = 0;
  // Beyond max_depth in the top-right corner.
  for (int v = 0; v < 100; ++v)
    for (int u = 500; u < 640; ++u) depth.at(u, v) = 5.0f;
  // Exactly 4 valid pixels around (318.., 400) and 5 around (318.., 300).
  for (int i = 0; i < 4; ++i) depth.at(316 + i, 400) = 1.0f;
  for (int i = 0; i < 5; ++i) depth.at(315 + i, 300) = 1.0f;
  const std::vector<Box> boxes = {
      {100, 240, 80, 80},   // 0: all missing
      {320, 240, 0, 0},     // 1: empty box
      {-500, 240, 80, 80},  // 2: entirely outside the image
      {570, 50, 60, 60},    // 3: all beyond 4 m
      {310, 400, 20, 1},    // 4: one row holding 4 valid pixels
      {310, 300, 20, 1},    // 5: one row holding 5 valid pixels
      {400, 240, 80, 80},   // 6: fine
      {320, 240, 1e300, 1e300},  // 7: huge but finite: the whole image
  };
  const auto vols = ComputeHeuristics(depth, cam, boxes);
  EXPECT_FALSE(vols[0].valid);
  EXPECT_FALSE(vols[1].valid);
  EXPECT_FALSE(vols[2].valid);
  EXPECT_FALSE(vols[3].valid);
  EXPECT_FALSE(vols[4].valid);
  EXPECT_TRUE(vols[5].valid);
  EXPECT_TRUE(vols[6].valid);
  EXPECT_TRUE(vols[7].valid);
  EXPECT_NEAR(vols[7].max.z(), 1.0, 1e-9);  // the 5 m corner is ignored
  HeuristicOptions far;
  far.max_depth_m = 6;
  EXPECT_TRUE(ComputeHeuristics(depth, cam, {boxes[3]}, far)[0].valid);
  EXPECT_NEAR(ComputeHeuristics(depth, cam, {boxes[3]}, far)[0].min.z(), 5.0, 1e-6);
}

TEST(Heuristics, MapsIntoTheBaseFrame) {
  Camera cam;
  // Camera 0.8 m above the base origin looking straight down: base x = cam x, base y = −cam y,
  // base z = 0.8 − cam z. base_to_camera maps base → camera.
  Eigen::Isometry3d cam_to_base = Eigen::Isometry3d::Identity();
  cam_to_base.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  cam_to_base.translation() << 0.1, 0.2, 0.8;
  cam.base_to_camera = cam_to_base.inverse();
  DepthImage depth(cam.width, cam.height);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) depth.at(u, v) = float(0.6 + 0.0005 * u);  // tilted
  HeuristicOptions opt;
  opt.percentile_lo = 0;
  opt.percentile_hi = 1;
  opt.max_samples = 100000;
  const Box box{200.3, 150.7, 31, 17};
  const Volume vol = ComputeHeuristics(depth, cam, {box}, opt)[0];
  ASSERT_TRUE(vol.valid);
  // Brute force over pixels whose centre lies in [cx − w/2, cx + w/2) × [cy − h/2, cy + h/2).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  int n = 0;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      if (u < box.cx - box.w / 2 || u >= box.cx + box.w / 2) continue;
      if (v < box.cy - box.h / 2 || v >= box.cy + box.h / 2) continue;
      ++n;
      const Eigen::Vector3d p = cam_to_base * cam.Backproject(u, v, depth.at(u, v));
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  EXPECT_EQ(n, 31 * 17);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(vol.min[k], lo[k], 1e-9) << "axis " << k;
    EXPECT_NEAR(vol.max[k], hi[k], 1e-9) << "axis " << k;
  }
  // Plausibility: the surface is 0.69–0.71 m below a camera 0.8 m up → base z ≈ 0.09–0.11 m.
  EXPECT_GT(vol.min.z(), 0.09);
  EXPECT_LT(vol.max.z(), 0.11);
  EXPECT_GT(vol.min.y(), 0.2);  // rows above the image centre: cam y < 0 → base y > 0.2
  // Depth extension moves points away from the camera: downwards in the base frame.
  opt.depth_extension_m = 0.03;
  const Volume ext = ComputeHeuristics(depth, cam, {box}, opt)[0];
  EXPECT_LT(ext.min.z(), vol.min.z() - 0.025);
  EXPECT_NEAR(ext.max.z(), vol.max.z(), 1e-9);
}

TEST(Heuristics, SubsamplingStaysCloseToTheFullStatistics) {
  const Camera cam;
  DepthImage depth(cam.width, cam.height);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) depth.at(u, v) = float(0.8 + 0.001 * u + 0.0005 * v);
  const Box box{300, 250, 200, 200};
  HeuristicOptions full;
  full.max_samples = 1000000;
  HeuristicOptions sub;  // 400 samples out of 40000 pixels
  const Volume a = ComputeHeuristics(depth, cam, {box}, full)[0];
  const Volume b = ComputeHeuristics(depth, cam, {box}, sub)[0];
  ASSERT_TRUE(a.valid && b.valid);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(a.min[k], b.min[k], 0.02) << k;
    EXPECT_NEAR(a.max[k], b.max[k], 0.02) << k;
  }
  // Deterministic.
  const Volume c = ComputeHeuristics(depth, cam, {box}, sub)[0];
  EXPECT_EQ(b.min, c.min);
  EXPECT_EQ(b.max, c.max);
}

TEST(Heuristics, EveryBoxOfAThesisPyramidGetsAVolume) {
  // The thesis's 6300 cells, every box at the 200 px clip (the timing of this workload is
  // bench/prior_bench.cc's BM_HeuristicsThesisPyramid).
  const testing_util::HeuristicsWorkload w = testing_util::ThesisPyramidWorkload();
  const Camera& cam = w.cam;
  const DepthImage& depth = w.depth;
  const std::vector<Box>& boxes = w.boxes;
  const HeuristicOptions& opt = w.opt;
  ASSERT_EQ(boxes.size(), 6300u);
  const auto vols = ComputeHeuristics(depth, cam, boxes, opt);
  ASSERT_EQ(vols.size(), boxes.size());
  const auto one_thread = ComputeHeuristics(depth, cam, boxes, opt, 1);  // the same with any thread count
  for (std::size_t i = 0; i < vols.size(); ++i) {
    ASSERT_EQ(one_thread[i].min, vols[i].min) << i;
    ASSERT_EQ(one_thread[i].max, vols[i].max) << i;
  }
  for (const Volume& v : vols) {
    ASSERT_TRUE(v.valid);
    // Depths lie in [0.7, 1.0) m and the extension adds 5 cm behind them.
    EXPECT_GE(v.min.z(), 0.69);
    EXPECT_LE(v.max.z(), 1.06);
  }
}

TEST(Heuristics, RejectsBadInput) {
  const Camera cam;
  const DepthImage depth(cam.width, cam.height, 1.0f);
  ExpectError([&] { ComputeHeuristics(DepthImage(320, 240, 1.f), cam, {{1, 1, 5, 5}}); },
              {"320", "640"});
  ExpectError([&] { ComputeHeuristics(depth, cam, {{1, 1, 5, 5}, {std::nan(""), 1, 5, 5}}); },
              {"box 1"});
  ExpectError([&] { ComputeHeuristics(depth, cam, {{1, 1, -5, 5}}); }, {"box 0"});
  Camera bad = cam;
  bad.fx = -1;
  ExpectError([&] { ComputeHeuristics(depth, bad, {{1, 1, 5, 5}}); }, {"camera"});
  HeuristicOptions opt;
  std::string why;
  EXPECT_TRUE(opt.IsValid(&why));
  opt.percentile_lo = 0.9;
  opt.percentile_hi = 0.1;
  ExpectInvalid(opt, "percentile");
  ExpectError([&] { ComputeHeuristics(depth, cam, {}, opt); }, {"percentile"});
  opt = {};
  opt.depth_extension_m = -0.1;
  ExpectInvalid(opt, "depth_extension_m");
  opt = {};
  opt.max_samples = 0;
  ExpectInvalid(opt, "max_samples");
  opt = {};
  opt.max_depth_m = 0;
  ExpectInvalid(opt, "max_depth_m");
  opt = {};
  opt.min_valid_pixels = 0;
  ExpectInvalid(opt, "min_valid_pixels");
}

// The filter's on-demand volumes (prior::VolumeCache): the validity of every box up front and
// each volume when first asked for, exactly ComputeHeuristics's values; nothing is computed
// for a box never asked for.
TEST(Heuristics, VolumeCacheGivesTheSameVolumesOnDemand) {
  testing_util::HeuristicsWorkload w = testing_util::ThesisPyramidWorkload();
  // Holes: missing depth on the left, too far at the top right, so that some cells have no volume.
  for (int v = 0; v < w.cam.height; ++v)
    for (int u = 0; u < 260; ++u) w.depth.at(u, v) = 0;
  for (int v = 0; v < 120; ++v)
    for (int u = 480; u < 640; ++u) w.depth.at(u, v) = 6.0f;
  w.boxes.push_back({320, 240, 0, 0});      // empty
  w.boxes.push_back({-500, 240, 80, 80});   // outside the image
  w.boxes.push_back({60, 240, 100, 100});   // all missing
  const std::vector<Volume> all = ComputeHeuristics(w.depth, w.cam, w.boxes, w.opt, 2);
  const prior::VolumeCache cache(w.depth, w.cam, w.boxes, w.opt, 2);
  ASSERT_EQ(cache.size(), int(all.size()));
  EXPECT_EQ(cache.computed(), 0);
  int valid = 0, asked = 0;
  for (int i = 0; i < cache.size(); ++i) {
    ASSERT_EQ(cache.Valid(i), all[std::size_t(i)].valid) << "box " << i;
    valid += cache.Valid(i);
  }
  EXPECT_GT(valid, 1000);
  EXPECT_LT(valid, cache.size() - 300);
  for (int i = 0; i < cache.size(); i += 7) {
    const Volume& v = cache.Get(i);
    ++asked;
    const Volume& ref = all[std::size_t(i)];
    ASSERT_EQ(v.valid, ref.valid) << "box " << i;
    EXPECT_EQ(v.min, ref.min) << "box " << i;
    EXPECT_EQ(v.max, ref.max) << "box " << i;
  }
  EXPECT_EQ(cache.computed(), asked);
  cache.Get(0);  // asked before: not computed again
  EXPECT_EQ(cache.computed(), asked);
  // A cache of given volumes has them all.
  const prior::VolumeCache given(all);
  EXPECT_EQ(given.computed(), given.size());
  EXPECT_EQ(given.Valid(5), all[5].valid);
  EXPECT_EQ(given.Get(5).max, all[5].max);
  // The inputs are checked like ComputeHeuristics's.
  ExpectError([&] { prior::VolumeCache(DepthImage(320, 240, 1.f), w.cam, w.boxes, w.opt, 1); }, {"320", "640"});
  const std::vector<Box> bad = {{1, 1, 5, 5}, {std::nan(""), 1, 5, 5}};
  ExpectError([&] { prior::VolumeCache(w.depth, w.cam, bad, w.opt, 1); }, {"box 1"});
  HeuristicOptions bad_opt = w.opt;
  bad_opt.max_samples = 0;
  ExpectError([&] { prior::VolumeCache(w.depth, w.cam, w.boxes, bad_opt, 1); }, {"max_samples"});
}

}  // namespace
}  // namespace posefilter
