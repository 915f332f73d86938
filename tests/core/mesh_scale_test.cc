// Tests of the median-depth checks (src/core/mesh_scale.h): the one-pass range test against
// the median found by sorting, and the mesh-unit check built on it.
#include "core/mesh_scale.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/rng.h"

namespace posefilter {
namespace {

DepthImage Image(std::vector<float> z) {
  DepthImage d;
  d.width = int(z.size());
  d.height = 1;
  d.data = std::move(z);
  return d;
}

// The range test says what comparing MedianValidDepth with the bounds says, on random images
// (zeros among them), with bounds drawn around and exactly at the image's own depths.
TEST(MedianValidDepthWithin, AgreesWithTheSortedMedian) {
  Rng rng(7);
  int checked = 0, inside = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + int(rng.Uniform() * 40);
    std::vector<float> z(std::size_t(n), 0.f);
    for (float& v : z)
      if (rng.Uniform() < 0.8) v = float(0.2 + 3 * rng.Uniform());
    const DepthImage d = Image(z);
    const double median = MedianValidDepth(d);
    for (int b = 0; b < 6; ++b) {
      // Bounds: random, or one of them exactly a depth of the image (the boundary cases).
      double lo = 0.2 + 3 * rng.Uniform(), hi = 0.2 + 3 * rng.Uniform();
      if (b % 3 == 1) lo = z[std::size_t(rng.Uniform() * n)];
      if (b % 3 == 2) hi = z[std::size_t(rng.Uniform() * n)];
      if (lo > hi) std::swap(lo, hi);
      const bool expected = median > 0 && median >= lo && median <= hi;
      EXPECT_EQ(MedianValidDepthWithin(d, lo, hi), expected) << "trial " << trial << " bounds " << lo << " " << hi;
      ++checked;
      inside += expected;
    }
  }
  // Both answers occur often enough for the comparison to mean something.
  EXPECT_GT(inside, checked / 10);
  EXPECT_LT(inside, checked * 9 / 10);
}

TEST(MedianValidDepthWithin, IsFalseWithoutAValidPixel) {
  EXPECT_FALSE(MedianValidDepthWithin(Image({0.f, 0.f}), 0, 10));
  EXPECT_FALSE(MedianValidDepthWithin(Image({}), 0, 10));
}

TEST(CheckMeshScale, NamesTheMeshWhenItsUnitsDoNotSuitTheDepth) {
  const DepthImage d = Image({0.8f, 1.0f, 1.2f, 0.f});  // median 1.0 m
  EXPECT_NO_THROW(CheckMeshScale("cup", 0.1, d));
  EXPECT_NO_THROW(CheckMeshScale("cup", 0.0011, d));
  EXPECT_NO_THROW(CheckMeshScale("cup", 9.9, d));
  EXPECT_NO_THROW(CheckMeshScale("cup", 100.0, Image({0.f})));  // nothing to compare with
  try {
    CheckMeshScale("cup_mm", 100.0, d);
    FAIL() << "a 100 m mesh in a scene 1 m deep was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cup_mm"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--unit-scale"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CheckMeshScale("speck", 1e-5, d), Error);
}

}  // namespace
}  // namespace posefilter
