// tests/filter/estimate_scene_test.cc — EstimateScene (posefilter/estimate_scene.h): the
// per-object estimates are EstimatePose's, the pass is RunScenePass's over them, and an
// object's Error ends the call or, with keep_going, only that object.
#include <gtest/gtest.h>

#include "easy_case.h"
#include "posefilter/estimate_scene.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;

TEST(EstimateScene, EachObjectIsItsOwnEstimatePoseWithItsSeed) {
  const EasyCase c("box", 3);
  const FilterOptions o = EasyCase::Small(4);
  SceneEstimateObject a;
  a.mesh = &c.sc.target;
  a.cls = c.cls;
  SceneEstimateObject b = a;
  b.seed = 77;
  std::vector<std::size_t> seen;
  const std::vector<SceneEstimate> est = EstimateScene(c.in, c.prior, {a, b}, o, {.scene_pass = false},
                                                       [&](std::size_t i, const SceneEstimate& e) {
                                                         EXPECT_TRUE(e.estimated);
                                                         seen.push_back(i);
                                                       });
  EXPECT_EQ(seen, (std::vector<std::size_t>{0, 1}));
  FilterOptions o77 = o;
  o77.seed = 77;
  const EstimateResult ra = c.Run(o), rb = c.Run(o77);
  ASSERT_EQ(est.size(), 2u);
  EXPECT_TRUE(est[0].alone.T_cam_obj.isApprox(ra.T_cam_obj, 0));
  EXPECT_EQ(est[0].alone.weight, ra.weight);
  EXPECT_TRUE(est[1].alone.T_cam_obj.isApprox(rb.T_cam_obj, 0));
  EXPECT_EQ(est[1].alone.weight, rb.weight);
  for (const SceneEstimate& e : est) {
    EXPECT_FALSE(e.passed);
    EXPECT_EQ(e.result.weight, e.alone.weight);
    EXPECT_EQ(e.result.obj, c.sc.target.name);
  }
}

TEST(EstimateScene, ThePassIsRunScenePassOverTheSharedEstimates) {
  const EasyCase c("lshape", 5);
  const FilterOptions o = EasyCase::Small(4);
  SceneEstimateObject a;
  a.mesh = &c.sc.target;
  a.cls = c.cls;
  SceneEstimateObject b = a;
  b.seed = 9;
  EstimateSceneOptions so;
  so.pass_seed = 123;
  const std::vector<SceneEstimate> est = EstimateScene(c.in, c.prior, {a, b}, o, so);
  ASSERT_EQ(est.size(), 2u);
  ASSERT_TRUE(est[0].passed && est[1].passed);
  FilterOptions po = o;
  po.seed = 123;
  const std::vector<ScenePassResult> ref = RunScenePass(
      c.in, c.prior, {{a.mesh, c.cls, est[0].alone}, {b.mesh, c.cls, est[1].alone}}, po);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(est[i].pass.weight_alone, ref[i].weight_alone);
    EXPECT_EQ(est[i].pass.weight_masked, ref[i].weight_masked);
    EXPECT_EQ(est[i].pass.replaced, ref[i].replaced);
    EXPECT_TRUE(est[i].pass.estimate.T_cam_obj.isApprox(ref[i].estimate.T_cam_obj, 0));
    const EstimateResult& expected = ref[i].replaced ? ref[i].estimate : est[i].alone;
    EXPECT_TRUE(est[i].result.T_cam_obj.isApprox(expected.T_cam_obj, 0));
    EXPECT_EQ(est[i].result.iterations,
              est[i].alone.iterations + (ref[i].replaced ? ref[i].estimate.iterations : 0));
  }
  // One object of the shared prior: no pass, unless pass_min_objects is 1.
  EXPECT_FALSE(EstimateScene(c.in, c.prior, {a}, o, so)[0].passed);
  so.pass_min_objects = 1;
  EXPECT_TRUE(EstimateScene(c.in, c.prior, {a}, o, so)[0].passed);
}

TEST(EstimateScene, AnObjectsErrorEndsTheCallOrWithKeepGoingOnlyThatObject) {
  const EasyCase c("box", 3);
  const FilterOptions o = EasyCase::Small(3);
  SceneEstimateObject bad;
  bad.mesh = &c.sc.target;
  bad.cls = int(c.prior.classes.size()) + 4;  // out of range
  SceneEstimateObject good = bad;
  good.cls = c.cls;
  ExpectError([&] { EstimateScene(c.in, c.prior, {bad, good}, o); }, {"class"});
  EstimateSceneOptions so;
  so.keep_going = true;
  const std::vector<SceneEstimate> est = EstimateScene(c.in, c.prior, {bad, good}, o, so);
  EXPECT_FALSE(est[0].estimated);
  EXPECT_FALSE(est[0].error.empty());
  EXPECT_TRUE(est[1].estimated);
  EXPECT_FALSE(est[1].passed);  // one estimate left: no pass
  so.pass_min_objects = 0;
  ExpectError([&] { EstimateScene(c.in, c.prior, {good}, o, so); }, {"pass_min_objects"});
}

}  // namespace
}  // namespace posefilter
