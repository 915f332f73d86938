// tests/filter/scene_pass_test.cc — RunScenePass (posefilter/scene_pass.h): an estimate that
// lies on a better one's pixels is estimated again, and finds its own object.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "posefilter/filter.h"
#include "posefilter/pose.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"
#include "posefilter/scene_pass.h"
#include "posefilter/synth.h"

namespace posefilter {
namespace {

// A 20 × 20 × 14 cm box ("big") 0.8 m in front of the camera and a 20 × 18 × 6 cm plate 30 cm
// to its right, before a wall 1.5 m away; each has its detection, of the given scores. The
// plate's wrong estimate lies on the upper 90 % of the big box's front face, flush with its
// top and sides, where a false detection of the plate (score false_score) lies.
struct TwoBoxes {
  TwoBoxes(double big_score, double false_score) {
    Eigen::Isometry3d t_big = Eigen::Isometry3d::Identity(), t_plate = Eigen::Isometry3d::Identity();
    t_big.translation() = Eigen::Vector3d(0, 0, 0.8);  // front face at z = 0.73 m
    t_plate.translation() = Eigen::Vector3d(0.3, 0, 0.76);
    on_big = Eigen::Isometry3d::Identity();
    on_big.translation() = Eigen::Vector3d(0, -0.01, 0.76);  // y from −0.10 (the top) to 0.08 m
    truth = {t_big, t_plate};
    depth = DepthImage(cam.width, cam.height, 1.5f);
    for (int i = 0; i < 2; ++i) RenderDepth(meshes[i], truth[i], cam, &depth);
    prior = PriorFromDetections({BoxOf(0, t_big, big_score), BoxOf(1, t_plate, 0.9), BoxOf(1, on_big, false_score)},
                                PyramidLayout::Thesis(cam.width, cam.height, 2), {"big", "plate"});
  }
  // The detection of object i at T: its silhouette's bounding box.
  Detection BoxOf(int i, const Eigen::Isometry3d& T, double score) const {
    DepthImage alone(cam.width, cam.height, 0.f);
    RenderDepth(meshes[i], T, cam, &alone);
    int x0 = cam.width, y0 = cam.height, x1 = -1, y1 = -1;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x)
        if (alone.at(x, y) > 0) x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    return {meshes[i].name, score, double(x0), double(y0), double(x1 - x0 + 1), double(y1 - y0 + 1)};
  }
  // The most probable cell of class cls whose box holds the pixel of T's origin.
  int Cell(int cls, const Eigen::Isometry3d& T) const {
    const Eigen::Vector3d t = T.translation();
    const double u = cam.fx * t.x() / t.z() + cam.cx, v = cam.fy * t.y() / t.z() + cam.cy;
    int best = -1;
    for (int c = 0; c < prior.layout.CellCount(); ++c) {
      const Box& b = prior.boxes[std::size_t(c)];
      if (std::abs(u - b.cx) < b.w / 2 && std::abs(v - b.cy) < b.h / 2 &&
          (best < 0 || prior.Prob(c, cls) > prior.Prob(best, cls)))
        best = c;
    }
    return best;
  }
  // An estimate of object i at T (base = camera), weighed in the whole frame.
  EstimateResult At(int i, const Eigen::Isometry3d& T, const FilterOptions& o) const {
    EstimateResult e;
    e.obj = meshes[i].name;
    e.T_cam_obj = T;
    e.pose_base = TransformToPose(T);
    e.cell = Cell(i, T);
    e.weight = WeighPoses(SceneInput{depth, cam}, meshes[i], prior, i, o, {{e.pose_base, e.cell}})[0];
    return e;
  }
  Camera cam;
  Mesh meshes[2] = {MakeBox(0.20, 0.20, 0.14, "big"), MakeBox(0.20, 0.18, 0.06, "plate")};
  std::vector<Eigen::Isometry3d> truth;
  Eigen::Isometry3d on_big;
  DepthImage depth;
  Prior prior;
};

FilterOptions Budget() {
  FilterOptions o;
  o.num_particles = 128;
  o.restarts = 1;
  o.support.plane = false;
  return o;
}

TEST(ScenePass, AnEstimateLyingOnABetterOneIsEstimatedAgainAndFindsItsObject) {
  const FilterOptions o = Budget();
  // The detection scores make the big box's estimate weigh more: it settles first.
  const TwoBoxes s(0.99, 0.3);
  const EstimateResult big = s.At(0, s.truth[0], o), wrong = s.At(1, s.on_big, o);
  ASSERT_GT(big.weight, wrong.weight);
  const std::vector<ScenePassResult> r =
      RunScenePass(SceneInput{s.depth, s.cam}, s.prior, {{&s.meshes[0], 0, big}, {&s.meshes[1], 1, wrong}}, o);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_FALSE(r[0].reestimated);
  EXPECT_TRUE(r[0].estimate.T_cam_obj.isApprox(s.truth[0], 0));
  EXPECT_EQ(r[0].weight_masked, big.weight);
  EXPECT_TRUE(r[1].reestimated);
  ASSERT_TRUE(r[1].replaced);
  EXPECT_LT((r[1].estimate.T_cam_obj.translation() - s.truth[1].translation()).norm(), 0.02)
      << r[1].estimate.T_cam_obj.translation().transpose();
  EXPECT_EQ(r[1].estimate.obj, "plate");
}

}  // namespace
}  // namespace posefilter
