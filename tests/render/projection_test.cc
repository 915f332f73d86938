// ProjectedBox against analytic cases: a fronto-parallel square's box (centred, shifted,
// clipped by the image border), nothing in view, and the synthetic world's gt box.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "posefilter/error.h"
#include "posefilter/projection.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::At;
using testing_util::ExpectError;
using testing_util::FrontSquare;

// 640×480, fx ≠ fy so that a mix-up of the axes shows.
Camera TestCamera() { return testing_util::PinholeCamera(500, 400, 320, 240); }

// Analytic box of the square: its edges project to u = cx + fx·(x ± s/2)/z (same for v);
// the covered pixel centres are the integers strictly inside (edges chosen off-integer),
// clipped to the image.
Box Expected(const Camera& c, double s, double x, double y, double z) {
  const double ul = c.cx + c.fx * (x - s / 2) / z, ur = c.cx + c.fx * (x + s / 2) / z;
  const double vt = c.cy + c.fy * (y - s / 2) / z, vb = c.cy + c.fy * (y + s / 2) / z;
  for (const double e : {ul, ur, vt, vb})  // the analytic answer needs edges off pixel centres
    EXPECT_GT(std::abs(e - std::round(e)), 0.05) << "edge " << e << " too close to a pixel centre";
  const int u0 = std::max(0, int(std::ceil(ul))), u1 = std::min(c.width - 1, int(std::floor(ur)));
  const int v0 = std::max(0, int(std::ceil(vt))), v1 = std::min(c.height - 1, int(std::floor(vb)));
  return {0.5 * (u0 + u1), 0.5 * (v0 + v1), double(u1 - u0 + 1), double(v1 - v0 + 1)};
}

void ExpectBox(const Box& got, const Box& want) {
  EXPECT_DOUBLE_EQ(got.cx, want.cx);
  EXPECT_DOUBLE_EQ(got.cy, want.cy);
  EXPECT_DOUBLE_EQ(got.w, want.w);
  EXPECT_DOUBLE_EQ(got.h, want.h);
}

TEST(ProjectedBox, CentredFrontoParallelSquare) {
  const Camera cam = TestCamera();
  // s = 0.101 m at 1 m: u ∈ [294.75, 345.25] → columns 295..345 (51 px);
  // v ∈ [219.8, 260.2] → rows 220..260 (41 px).
  const Box b = ProjectedBox(FrontSquare(0.101f), At(0, 0, 1), cam);
  EXPECT_DOUBLE_EQ(b.cx, 320);
  EXPECT_DOUBLE_EQ(b.cy, 240);
  EXPECT_DOUBLE_EQ(b.w, 51);
  EXPECT_DOUBLE_EQ(b.h, 41);
  ExpectBox(b, Expected(cam, 0.101, 0, 0, 1));
}

TEST(ProjectedBox, ShiftedAndFartherSquare) {
  const Camera cam = TestCamera();
  for (const auto& [x, y, z] : {std::array<double, 3>{0.13, -0.071, 1.7}, {-0.21, 0.11, 0.9}, {0.05, 0.2, 2.3}}) {
    SCOPED_TRACE(testing::Message() << "x " << x << " y " << y << " z " << z);
    ExpectBox(ProjectedBox(FrontSquare(0.123f), At(x, y, z), cam), Expected(cam, 0.123, x, y, z));
  }
}

TEST(ProjectedBox, ClippedByTheImageBorder) {
  const Camera cam = TestCamera();
  // Centre projects to u = 320 + 500·0.65 = 645 (right of the image): columns ≥ 620 visible.
  const Box b = ProjectedBox(FrontSquare(0.101f), At(0.65, 0, 1), cam);
  ExpectBox(b, Expected(cam, 0.101, 0.65, 0, 1));
  EXPECT_DOUBLE_EQ(b.cx + b.w / 2, cam.width - 0.5);  // right edge = the image's
  EXPECT_LT(b.w, 51);
}

TEST(ProjectedBox, NothingInViewGivesAnEmptyBox) {
  const Camera cam = TestCamera();
  const Mesh sq = FrontSquare(0.1f);
  for (const Box& b : {ProjectedBox(sq, At(0, 0, -1), cam),     // behind the camera
                       ProjectedBox(sq, At(3, 0, 1), cam),       // right of the image
                       ProjectedBox(sq, At(0, -5, 1), cam)}) {   // above the image
    EXPECT_EQ(b.w, 0);
    EXPECT_EQ(b.h, 0);
  }
  // Seen from the back (rotated 180° about y): culled, no silhouette.
  Eigen::Isometry3d back = At(0, 0, 1);
  back.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_EQ(ProjectedBox(sq, back, cam).w, 0);
}

TEST(ProjectedBox, InvalidInputsThrow) {
  Camera bad = TestCamera();
  bad.fx = std::nan("");
  EXPECT_THROW(ProjectedBox(FrontSquare(0.1f), At(0, 0, 1), bad), Error);
  Mesh broken = FrontSquare(0.1f);
  broken.faces.push_back({0, 1, 7});
  ExpectError([&] { ProjectedBox(broken, At(0, 0, 1), TestCamera()); }, {"square"});  // face index out of range
}

// The synthetic world's gt box is the target's full silhouette: ProjectedBox must agree.
TEST(ProjectedBox, MatchesTheSynthSceneGtBox) {
  for (const char* kind : {"box", "torus"}) {
    SynthOptions opt;
    opt.target = kind;
    opt.occlusion = 0.4;
    const SynthScene s = MakeSynthScene(opt, 11);
    const Box b = ProjectedBox(s.target, s.gt[0].T_cam_obj, s.camera);
    ExpectBox(b, s.gt_box);
    EXPECT_GT(b.w, 10);
  }
}

}  // namespace
}  // namespace posefilter
