// The raster core's cycle model against counts made by hand: the loop records of a
// one-particle RasterCore call on a tiny mesh whose covered boxes are known in advance, and the
// round composition of several particles on M cores. The pipeline depths come from the one
// table (hw/latency.h); trips and entries must be what the kernels' loop nests execute.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "hw/cycle_model.h"
#include "hw/latency.h"
#include "hw/raster_core.h"

namespace posefilter::hw {
namespace {

// An FT that maps object (x, y, z) to screen (128·x, 128·y) at W = 1 m: vertices at k/128 m
// (exact in xyz_t) land on pixel k exactly.
void PushScaleFt(hls::stream<ft_t>& s) {
  const double ft[kFtElements] = {128, 0, 0, 0, 0, 128, 0, 0, 0, 0, 0, 1};
  for (double e : ft) s.write(ft_t(e));
}

void PushFace(hls::stream<Vertex>& s, const int px[3][2]) {
  for (int k = 0; k < 3; ++k) {
    Vertex v;
    v.x = xyz_t(px[k][0] / 128.0);
    v.y = xyz_t(px[k][1] / 128.0);
    v.z = xyz_t(0);
    s.write(v);
  }
}

struct OneParticle {
  RasterCoreOutput out;
  ParticleWork work;
  CycleTrace trace;
};

// One particle with the three faces below in a 40 × 30 window at the image origin, flat scene
// depth 1 m.
std::unique_ptr<OneParticle> RunTinyMesh(bool zbuffer) {
  const int ww = 40, wh = 30;
  // Face 0: front (2·Area = 20·20 > 0), box u 10…30, v 10…30 clipped to 10…29 → 21 × 20 = 420
  // pixels.
  // Face 1: face 0 reversed: back-facing, culled (3 vertex clocks, no pixels).
  // Face 2: front, box u 35…45 clipped to 35…39 (5 columns), v 0…8 (9 rows) → 45 pixels.
  const int f0[3][2] = {{10, 10}, {10, 30}, {30, 10}};
  const int f1[3][2] = {{10, 10}, {30, 10}, {10, 30}};
  const int f2[3][2] = {{35, 0}, {35, 8}, {45, 0}};
  hls::stream<Window> info;
  hls::stream<depth_t> depth;
  hls::stream<ft_t> ft;
  hls::stream<Vertex> verts;
  hls::stream<RasterCoreOutput> out;
  Window w;
  w.u0 = 0;
  w.v0 = 0;
  w.width = ww;
  w.height = wh;
  info.write(w);
  for (int i = 0; i < ww * wh; ++i) depth.write(depth_t(1.0));
  PushScaleFt(ft);
  PushFace(verts, f0);
  PushFace(verts, f1);
  PushFace(verts, f2);
  RasterParams prm = DefaultRasterParams();
  prm.zbuffer = zbuffer ? 1 : 0;
  auto r = std::make_unique<OneParticle>();
  auto mem = std::make_unique<RasterCoreMemory>();
  RasterCore(1, 3, prm, info, depth, ft, verts, out, *mem, &r->trace);
  r->out = out.read();
  r->work = ParticleWorkFromTrace(r->trace);
  return r;
}

TEST(HwRasterCycleModel, TinyMeshMatchesTheHandCount) {
  for (const bool zbuffer : {false, true}) {
    SCOPED_TRACE(zbuffer ? "z-buffer mode" : "thesis mode");
    const auto r = RunTinyMesh(zbuffer);
    ASSERT_EQ(r->out.faces_front.to_uint(), 2u);  // the culled face is not front
    // By hand: 40·30 fill clocks; 12 FT words; 3 faces · 3 vertices; 420 + 45 box pixels;
    // the z pass reads 40·(30 + 1) words (one flush row).
    const std::uint64_t fill = 1200 + kRcFillDepth;
    const std::uint64_t ft = 12 + kRcFtReadDepth;
    const std::uint64_t vertex = 9 + kRcVertexDepth;
    const std::uint64_t pixel = 465 + kRcPixelDepth;
    const std::uint64_t zpass = zbuffer ? 1240 + kRcZpassDepth : 0;
    EXPECT_EQ(r->work.fill, fill);
    EXPECT_EQ(r->work.ft, ft);
    EXPECT_EQ(r->work.vertex, vertex);
    EXPECT_EQ(r->work.pixel, pixel);
    EXPECT_EQ(r->work.zpass, zpass);
    // The pixel stage is the slower one here: it starts after the vertex stage's depth.
    const std::uint64_t faces = std::max(vertex, pixel + kRcVertexDepth);
    EXPECT_EQ(r->work.Faces(), faces);
    EXPECT_EQ(r->work.Compute(), ft + faces + zpass);
    EXPECT_EQ(r->work.Total(), kRcWindowReadCycles + fill + ft + faces + zpass + kRcOutputCycles);
    // Every covered pixel of face 0 is a fragment: in the thesis's mode each one is counted as
    // it is rasterized; face 2's 5 × 9 box lies left of its hypotenuse only in part.
    EXPECT_GT(r->out.n_raster.to_uint(), 200u);
  }
}

TEST(HwRasterCycleModel, TheVertexStageBoundsAFaceHeavyParticle) {
  ParticleWork w;
  w.vertex = 3 * 2048 + kRcVertexDepth;  // 2048 faces
  w.pixel = 1000 + kRcPixelDepth;        // few pixels
  EXPECT_EQ(w.Faces(), w.vertex);
  w.pixel = 0;  // nothing forwarded
  EXPECT_EQ(w.Faces(), w.vertex);
}

TEST(HwRasterCycleModel, RoundsSerialiseFillAndTheSlowestCoreOfEachRound) {
  std::vector<ParticleWork> w(5);
  for (int p = 0; p < 5; ++p) {
    w[p].fill = 100;
    w[p].ft = 12;
    w[p].vertex = 400;
    w[p].pixel = 200 + 100 * p;  // p = 0, 1: vertex-bound; p ≥ 2: pixel-bound (with the offset)
    w[p].zpass = 100;
  }
  const auto compute = [&](int p) { return 12u + std::max<std::uint64_t>(400, 200 + 100 * p + kRcVertexDepth) + 100u; };
  for (int p = 0; p < 5; ++p) EXPECT_EQ(w[p].Compute(), compute(p));
  // M = 2: rounds {0,1}, {2,3}, {4}; distributor fills 150, 90 (< core fill 100), 80.
  const std::vector<std::uint64_t> fill = {150, 90, 80};
  const std::uint64_t expect = (150 + compute(1)) + (100 + compute(3)) + (100 + compute(4));
  EXPECT_EQ(ComposeRounds(w, fill, 2), expect);
  // M = 1: every particle its own round.
  std::uint64_t one = 0;
  for (int p = 0; p < 5; ++p) one += 100 + w[p].Compute();
  EXPECT_EQ(ComposeRounds(w, std::vector<std::uint64_t>(5, 0), 1), one);
}

}  // namespace
}  // namespace posefilter::hw
