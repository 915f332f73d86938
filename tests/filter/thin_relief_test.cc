// Thin objects and the support band (src/filter/scene_prep.h, ThinRelief and ForThickness;
// docs/ALGORITHM.md §12, "Thin objects"): an object thinner than kThinObjectM gets back the
// removed support pixels standing above half their support's band, and only those; a thicker
// object, a wall's pixels and pixels below the surface stay removed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "filter/scene_prep.h"
#include "posefilter/camera.h"
#include "posefilter/support_plane.h"

namespace posefilter {
namespace {

// A level surface facing the camera 1.3 m away (height above it = 1.3 m − z), σ₁ 1.6 mm:
// its band at 1.3 m is 3 · 1.6 mm · 1.69 = 8.1 mm, half of it 4.06 mm. Every pixel of a
// 16 × 12 image lies on it, removed, at the heights `h` (metres, row-major; NaN: no reading).
struct ThinReliefFrame {
  filter::PreparedScene scene;
  DepthImage depth;
};

ThinReliefFrame MakeThinReliefFrame(const std::vector<double>& h, bool support) {
  Camera cam;
  cam.width = 16;
  cam.height = 12;
  cam.fx = cam.fy = 500;
  cam.cx = 8;
  cam.cy = 6;
  ThinReliefFrame f;
  f.depth = DepthImage(cam.width, cam.height, 0.f);
  SupportSurface s;
  s.plane.found = true;
  s.plane.normal = Eigen::Vector3d(0, 0, -1);
  s.plane.offset = 1.3;
  s.plane.sigma_1m = 0.0016;
  s.origin = Eigen::Vector3d(0, 0, 1.3);
  s.e1 = Eigen::Vector3d::UnitX();
  s.e2 = Eigen::Vector3d::UnitY();
  s.outline = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  s.support = support;
  f.scene.surfaces.patches = {s};
  f.scene.surfaces.supports = support ? 1 : 0;
  f.scene.scoring.camera = cam;
  f.scene.scoring.depth = DepthImage(cam.width, cam.height, 0.f);
  f.scene.support = f.scene.scoring.depth;
  f.scene.removed_by.assign(f.depth.data.size(), 0);
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (h[i] != h[i]) continue;
    f.depth.data[i] = float(1.3 - h[i]);
    f.scene.removed_by[i] = 1;
  }
  return f;
}

const double kThinNoReading = std::numeric_limits<double>::quiet_NaN();

TEST(ThinReliefTest, AThinObjectGetsBackThePixelsAboveHalfItsSupportsBand) {
  // Heights: in the lower half of the band (stay removed), in its upper half (come back),
  // below the surface (stay), no reading (stay).
  const std::vector<double> h = {0.002, 0.0035, 0.0055, 0.0075, -0.006, -0.0075, kThinNoReading, 0.005};
  const ThinReliefFrame f = MakeThinReliefFrame(h, true);
  const SupportSurfaceOptions opt;
  const double band = f.scene.surfaces.patches[0].Band(1.3 - 0.0055, opt);
  ASSERT_GT(band, 0.0075);  // every height above lies inside the band: removed by FrameScene
  ASSERT_LT(0.5 * band, 0.005);
  EXPECT_EQ(filter::ThinRelief(f.scene, f.depth, 0.012), (std::vector<std::size_t>{2, 3, 7}));
  // A thicker object (its relief stands out of the band), or no thickness: nothing.
  EXPECT_TRUE(filter::ThinRelief(f.scene, f.depth, filter::kThinObjectM).empty());
  EXPECT_TRUE(filter::ThinRelief(f.scene, f.depth, 0).empty());
  // A wall's (structure's) pixels are never the object's relief.
  EXPECT_TRUE(filter::ThinRelief(MakeThinReliefFrame(h, false).scene, f.depth, 0.012).empty());
}

TEST(ThinReliefTest, ForThicknessPutsThePixelsBackInBothDepthsAndSharesTheFrameOtherwise) {
  const std::vector<double> h = {0.002, 0.006, kThinNoReading, 0.007};
  ThinReliefFrame f = MakeThinReliefFrame(h, true);
  auto frame = std::make_shared<const filter::PreparedScene>(f.scene);
  EXPECT_EQ(filter::ForThickness(frame, f.depth, 0.1).get(), frame.get());
  const auto thin = filter::ForThickness(frame, f.depth, 0.01);
  ASSERT_NE(thin.get(), frame.get());
  for (std::size_t i : {std::size_t(1), std::size_t(3)}) {
    EXPECT_EQ(thin->scoring.depth.data[i], f.depth.data[i]) << i;
    EXPECT_EQ(thin->support.data[i], f.depth.data[i]) << i;
    EXPECT_EQ(thin->removed_by[i], 0) << i;
  }
  for (std::size_t i : {std::size_t(0), std::size_t(2), std::size_t(4)}) {
    EXPECT_EQ(thin->scoring.depth.data[i], 0.f) << i;
    EXPECT_EQ(thin->support.data[i], 0.f) << i;
  }
  EXPECT_EQ(thin->removed_by[0], 1);
  // The frame's own scene is unchanged.
  EXPECT_TRUE(std::all_of(frame->scoring.depth.data.begin(), frame->scoring.depth.data.end(), [](float z) { return z == 0; }));
}

}  // namespace
}  // namespace posefilter
