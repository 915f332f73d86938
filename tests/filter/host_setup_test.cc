// The host-side set-up shared by the float and hw engines (src/filter/host_setup.h): the
// volume options' depth extension, the minimum window side, cell windows, hypothesis labels
// in both engines' modes, the pool size and niche caps, the hard threshold's scaling.
#include "filter/host_setup.h"

#include <gtest/gtest.h>

namespace posefilter::filter {
namespace {

TEST(HostSetupTest, DepthExtensionDefaultsToHalfTheDiameter) {
  FilterOptions o;
  o.heuristics.depth_extension_m = 0;
  EXPECT_DOUBLE_EQ(VolumeOptions(o, 0.2).depth_extension_m, 0.1);
  o.heuristics.depth_extension_m = 0.03;  // set: kept
  EXPECT_DOUBLE_EQ(VolumeOptions(o, 0.2).depth_extension_m, 0.03);
}

TEST(HostSetupTest, MinWindowSideIsTheProjectedDiameter) {
  FilterOptions o;
  o.render.min_window_diameters = 1.0;
  o.render.near_m = 0.05;
  Camera cam;
  cam.fx = 500;
  // No volume: 1 m.
  EXPECT_DOUBLE_EQ(MinWindowSide(o, 0.1, cam, nullptr), 50.0);
  Volume v;
  v.valid = true;
  v.min = Eigen::Vector3d(0, 0, 0.4);
  v.max = Eigen::Vector3d(0, 0, 0.6);  // centre 0.5 m in front (identity base → camera)
  EXPECT_DOUBLE_EQ(MinWindowSide(o, 0.1, cam, &v), 100.0);
  v.min.z() = v.max.z() = 0.01;  // nearer than near_m counts as near_m
  EXPECT_DOUBLE_EQ(MinWindowSide(o, 0.1, cam, &v), 1000.0);
}

TEST(HostSetupTest, CellWindowIsCentredBoundedAndSaturated) {
  const Box box{100, 50, 20, 10};
  PixelRect r = CellWindow(box, 40, 200, 640, 480);  // sides raised to min_side
  EXPECT_EQ(r.width, 40);
  EXPECT_EQ(r.height, 40);
  EXPECT_EQ(r.u0, 80);
  EXPECT_EQ(r.v0, 30);
  r = CellWindow(box, 0, 8, 640, 480);  // capped at max_px
  EXPECT_EQ(r.width, 8);
  EXPECT_EQ(r.height, 8);
  r = CellWindow(Box{5, 470, 30, 30}, 0, 200, 640, 480);  // shifted into the image
  EXPECT_EQ(r.u0, 0);
  EXPECT_EQ(r.v0, 450);
}

TEST(HostSetupTest, HypothesisLabelsInBothEnginesModes) {
  const Box a{10.2, 20, 30, 40}, a2{9.8, 20.3, 30.1, 39.9}, b{11, 20, 30, 40}, c{50, 50, 10, 10};
  HypothesisLabeller unbounded;  // float engines: 0, 1, 2, … for every new box
  EXPECT_EQ(unbounded.Label(a), 0);
  EXPECT_EQ(unbounded.Label(b), 1);
  EXPECT_EQ(unbounded.Label(a2), 0);  // the same box to the pixel
  EXPECT_EQ(unbounded.Label(c), 2);
  EXPECT_EQ(unbounded.count(), 3);
  HypothesisLabeller bounded(1, 2, 0);  // hw engine's kind: from 1, at most 2 labels, 0 beyond
  EXPECT_EQ(bounded.Label(a), 1);
  EXPECT_EQ(bounded.Label(b), 2);
  EXPECT_EQ(bounded.Label(c), 0);
  EXPECT_EQ(bounded.Label(a2), 1);
  EXPECT_EQ(bounded.count(), 2);
}

TEST(HostSetupTest, PoolSizeAndNicheCaps) {
  FilterOptions o;
  o.num_elite = 10;
  o.resample_pool = 0.25;
  EXPECT_EQ(ResamplePoolSize(o, 510), 128);  // round(127.5)
  EXPECT_EQ(ResamplePoolSize(o, 20), 10);    // at least the elite
  o.num_elite = 0;
  o.resample_pool = 0.01;
  EXPECT_EQ(ResamplePoolSize(o, 20), 1);  // at least 1
  EXPECT_EQ(NicheCap(0.34, 128), 44);      // ceil(43.52)
  EXPECT_EQ(NicheCap(0.001, 128), 1);
  EXPECT_EQ(NicheCap(1.0, 128), 128);
}

TEST(HostSetupTest, HardThresholdScalesWithThr1InTheCallersPrecision) {
  InlierParams p;
  p.thr1_m = 1.0f / 256;
  p.hard_thr_m = 0.005f;
  const float thr_f = 0.02f;
  EXPECT_EQ(ScaledHardThreshold<float>(p, thr_f), p.hard_thr_m * thr_f / p.thr1_m);
  const double thr_d = 0.02;
  EXPECT_EQ(ScaledHardThreshold<double>(p, thr_d), double(p.hard_thr_m) * thr_d / double(p.thr1_m));
  EXPECT_EQ(ScaledHardThreshold<double>(p, double(p.thr1_m)), double(p.hard_thr_m));
}

}  // namespace
}  // namespace posefilter::filter
