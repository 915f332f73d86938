// Scene normals on demand (render/scene_normals.h): a prepared tile holds exactly what
// ComputeSceneNormals computes for the whole image, and only the tiles under the windows are
// computed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "posefilter/error.h"
#include "posefilter/synth.h"
#include "render/scene_normals.h"

namespace posefilter {
namespace {

using render::SceneNormalTiles;

// Noise, holes and a table edge: normals, missing readings and depth steps.
SynthScene Scene() {
  SynthOptions so;
  so.target = "torus";
  return MakeSynthScene(so, 3);
}

// Whether pixel (u, v)'s three values are bitwise those of `all`.
bool SameNormal(const float* tiles, const std::vector<float>& all, int width, int u, int v) {
  const std::size_t i = 3 * (std::size_t(v) * width + u);
  return std::memcmp(tiles + i, all.data() + i, 3 * sizeof(float)) == 0;
}

TEST(SceneNormalTilesTest, PreparedWindowsHoldTheWholeImagesNormals) {
  const SynthScene sc = Scene();
  const int w = sc.depth.width, h = sc.depth.height;
  const std::vector<float> all = ComputeSceneNormals(sc.depth, sc.camera, 1);
  // Inside; over the right and bottom edges; over the top-left corner; empty.
  const std::vector<PixelRect> windows = {{100, 80, 200, 150}, {w - 50, h - 30, 100, 100}, {-20, -10, 50, 40}, {10, 10, 0, 5}};
  SceneNormalTiles tiles(w, h);
  EXPECT_EQ(tiles.tiles_computed(), 0);
  tiles.Prepare(sc.depth, sc.camera, windows, 2);

  int nonzero = 0, checked = 0;
  for (const PixelRect& r : windows)
    for (int v = std::max(r.v0, 0); v < std::min(r.v0 + r.height, h); ++v)
      for (int u = std::max(r.u0, 0); u < std::min(r.u0 + r.width, w); ++u) {
        ASSERT_TRUE(SameNormal(tiles.data(), all, w, u, v)) << "pixel " << u << ", " << v;
        ++checked;
        nonzero += all[3 * (std::size_t(v) * w + u) + 2] != 0.f;
      }
  EXPECT_EQ(checked, 200 * 150 + 50 * 30 + 30 * 30);
  EXPECT_GT(nonzero, checked / 2);  // the windows hold real normals, not only zeros

  // The tiles computed are those overlapping a non-empty window, counted independently.
  constexpr int T = SceneNormalTiles::kTile;
  int expected = 0;
  for (int tv = 0; tv * T < h; ++tv)
    for (int tu = 0; tu * T < w; ++tu) {
      bool hit = false;
      for (const PixelRect& r : windows)
        hit = hit || (r.width > 0 && r.height > 0 && r.u0 < (tu + 1) * T && tu * T < r.u0 + r.width &&
                      r.v0 < (tv + 1) * T && tv * T < r.v0 + r.height);
      expected += hit;
    }
  EXPECT_EQ(tiles.tiles_total(), ((w + T - 1) / T) * ((h + T - 1) / T));
  EXPECT_EQ(tiles.tiles_computed(), expected);
  EXPECT_LT(expected, tiles.tiles_total() / 4);

  tiles.Prepare(sc.depth, sc.camera, windows, 2);  // nothing left to compute there
  EXPECT_EQ(tiles.tiles_computed(), expected);

  // The rest of the image, on one thread: now the whole array is ComputeSceneNormals's.
  tiles.Prepare(sc.depth, sc.camera, {PixelRect{0, 0, w, h}}, 1);
  EXPECT_EQ(tiles.tiles_computed(), tiles.tiles_total());
  EXPECT_EQ(std::memcmp(tiles.data(), all.data(), all.size() * sizeof(float)), 0);
}

TEST(SceneNormalTilesTest, RejectsADepthImageOfAnotherSize) {
  const SynthScene sc = Scene();
  SceneNormalTiles tiles(sc.depth.width - 1, sc.depth.height);
  EXPECT_THROW(tiles.Prepare(sc.depth, sc.camera, {PixelRect{0, 0, 10, 10}}, 1), Error);
}

}  // namespace
}  // namespace posefilter
