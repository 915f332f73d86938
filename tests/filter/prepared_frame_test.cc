// A depth frame prepared once (posefilter/prepared_frame.h): estimates, weighings and the
// scene pass on the prepared frame with an object's mask and seeds equal, bit for bit, those on
// the SceneInput that holds the same mask and seeds (on a table scene, whose support surfaces
// the preparation finds once); they prepare no frame again (FramesPrepared), except an estimate
// whose support.plane differs from the frame's; and bad frames, masks and seeds are errors.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/prepared_model.h"
#include "posefilter/prior.h"
#include "posefilter/scene_pass.h"
#include "posefilter/synth.h"
#include "posefilter/table_world.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;

const TableWorld& FrameWorld() {
  static const TableWorld* w = new TableWorld({MakeCylinder(0.04, 0.14, 48, "cylinder"), MakeBox(0.12, 0.08, 0.16, "box"),
                                               MakeBox(0.06, 0.06, 0.06, "cube")});
  return *w;
}

struct FrameCase {
  TableScene scene;
  Prior prior;
  std::vector<int> targets;  // indices into scene.objects
};

// The first table scene from seed 3 on with at least two targets.
const FrameCase& TwoTargetCase() {
  static const FrameCase* made = [] {
    TableSceneOptions o;
    o.min_objects = 3;
    o.max_objects = 3;
    for (std::uint64_t s = 3;; ++s) {
      auto c = std::make_unique<FrameCase>();
      c->scene = FrameWorld().MakeScene(o, s);
      for (std::size_t i = 0; i < c->scene.objects.size(); ++i)
        if (c->scene.objects[i].target) c->targets.push_back(int(i));
      if (c->targets.size() < 2) continue;
      const std::vector<std::string> classes = FrameWorld().ClassNames();
      c->prior = PriorFromDetections(c->scene.detections, PyramidLayout::Thesis(640, 480, int(classes.size())), classes);
      return c.release();
    }
  }();
  return *made;
}

const Mesh& MeshOf(const FrameCase& c, int object) {
  return FrameWorld().models()[std::size_t(c.scene.objects[std::size_t(object)].model)].mesh;
}

// Object i's instance mask (as the scene's segmentation gives it) and, as a seed, its true
// pose moved by 1 cm.
ObjectInput ObjectOf(const FrameCase& c, int object) {
  ObjectInput in;
  in.mask.resize(c.scene.masks.size());
  for (std::size_t p = 0; p < in.mask.size(); ++p) in.mask[p] = c.scene.masks[p] == object + 1 ? 1 : 0;
  Eigen::Isometry3d T = c.scene.objects[std::size_t(object)].T_cam_obj;
  T.translation() += Eigen::Vector3d(0.01, 0, 0);
  in.seeds = {{T, 1.0}};
  return in;
}

FilterOptions SmallFrameOptions() {
  FilterOptions o;
  o.num_particles = 40;
  o.stop.max_iterations = 6;
  o.restarts = 1;
  o.threads = 2;
  o.polish.turns = false;  // a short polish: the frame's preparation is what is compared
  o.polish.climbers = 1;
  return o;
}

void ExpectSameFrameEstimate(const EstimateResult& a, const EstimateResult& b, const std::string& what) {
  EXPECT_TRUE(a.T_cam_obj.matrix() == b.T_cam_obj.matrix()) << what;
  EXPECT_EQ(a.weight, b.weight) << what;
  EXPECT_EQ(a.cell, b.cell) << what;
  EXPECT_EQ(a.iterations, b.iterations) << what;
  EXPECT_EQ(a.best_weight_history, b.best_weight_history) << what;
  EXPECT_EQ(a.stats.weighings, b.stats.weighings) << what;
  EXPECT_EQ(a.stats.fragments, b.stats.fragments) << what;
}

TEST(PreparedFrame, EstimatesAndWeighingsEqualThoseOnTheSceneInput) {
  const FrameCase& c = TwoTargetCase();
  const FilterOptions o = SmallFrameOptions();
  const std::uint64_t before = FramesPrepared();
  const std::shared_ptr<const PreparedFrame> frame = PrepareFrame(SceneInput{c.scene.depth, c.scene.camera}, o);
  EXPECT_EQ(FramesPrepared() - before, 1u);
  EXPECT_TRUE(frame->support_plane());
  EXPECT_GT(frame->surfaces().supports, 0) << "the table is found once, with the frame";
  for (int object : c.targets) {
    const std::string what = "object " + std::to_string(object);
    const Mesh& mesh = MeshOf(c, object);
    const int cls = c.prior.ClassIndex(mesh.name);
    const std::shared_ptr<const PreparedModel> model = PrepareModel(mesh, o);
    // Nothing, seeds only, and mask and seeds.
    std::vector<ObjectInput> inputs(3);
    inputs[1].seeds = ObjectOf(c, object).seeds;
    inputs[2] = ObjectOf(c, object);
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      const ObjectInput& in = inputs[k];
      const SceneInput scene{c.scene.depth, c.scene.camera, in.mask, in.seeds};
      const EstimateResult plain = EstimatePose(scene, *model, c.prior, cls, o);
      const std::uint64_t shared_before = FramesPrepared();
      const EstimateResult shared = EstimatePose(*frame, in, *model, c.prior, cls, o);
      const EstimateResult on_mesh = EstimatePose(*frame, in, mesh, c.prior, cls, o);
      const std::vector<std::pair<Pose6, int>> hyp = {{plain.pose_base, plain.cell}};
      const std::vector<double> w = WeighPoses(*frame, in, *model, c.prior, cls, o, hyp);
      EXPECT_EQ(FramesPrepared(), shared_before) << what << ", input " << k << ": the frame is prepared again";
      ExpectSameFrameEstimate(plain, shared, what + ", input " + std::to_string(k));
      ExpectSameFrameEstimate(plain, on_mesh, what + ", input " + std::to_string(k) + ", mesh");
      EXPECT_EQ(w, WeighPoses(scene, *model, c.prior, cls, o, hyp)) << what << ", input " << k;
      EXPECT_EQ(w, WeighPoses(*frame, in, mesh, c.prior, cls, o, hyp)) << what << ", input " << k;
      if (!in.seeds.empty()) EXPECT_GT(plain.weight, 0.3) << what << ", input " << k << ": seeded 1 cm from the truth";
    }
  }
}

TEST(PreparedFrame, AnEstimateWithAnotherSupportPlaneSettingPreparesTheFrameForItself) {
  const FrameCase& c = TwoTargetCase();
  FilterOptions o = SmallFrameOptions();
  const std::shared_ptr<const PreparedFrame> frame = PrepareFrame(SceneInput{c.scene.depth, c.scene.camera}, o);
  o.support.plane = false;
  const int object = c.targets[0];
  const Mesh& mesh = MeshOf(c, object);
  const int cls = c.prior.ClassIndex(mesh.name);
  const std::uint64_t before = FramesPrepared();
  const EstimateResult shared = EstimatePose(*frame, ObjectOf(c, object), mesh, c.prior, cls, o);
  EXPECT_EQ(FramesPrepared() - before, 1u);
  const ObjectInput in = ObjectOf(c, object);
  ExpectSameFrameEstimate(EstimatePose(SceneInput{c.scene.depth, c.scene.camera, in.mask, in.seeds}, mesh, c.prior, cls, o),
                     shared, "without the support plane");
}

TEST(PreparedFrame, TheScenePassOnThePreparedFrameEqualsTheOneOnTheSceneInput) {
  const FrameCase& c = TwoTargetCase();
  const FilterOptions o = SmallFrameOptions();
  const SceneInput scene{c.scene.depth, c.scene.camera};
  const std::shared_ptr<const PreparedFrame> frame = PrepareFrame(scene, o);
  std::vector<SceneObject> objects;
  for (int object : c.targets) {
    const Mesh& mesh = MeshOf(c, object);
    const int cls = c.prior.ClassIndex(mesh.name);
    objects.push_back({&mesh, cls, EstimatePose(*frame, {}, mesh, c.prior, cls, o), PrepareModel(mesh, o)});
  }
  // Both objects on one of them: the second must be re-estimated where the first leaves room.
  objects[1].estimate.T_cam_obj = objects[0].estimate.T_cam_obj;
  objects[1].estimate.pose_base = objects[0].estimate.pose_base;
  objects[1].estimate.cell = objects[0].estimate.cell;
  objects[1].estimate.weight = objects[0].estimate.weight - 0.01;
  const std::uint64_t before = FramesPrepared();
  const std::vector<ScenePassResult> shared = RunScenePass(*frame, c.prior, objects, o);
  EXPECT_EQ(FramesPrepared(), before) << "the pass's weighings and re-estimates prepared the frame again";
  const std::vector<ScenePassResult> plain = RunScenePass(scene, c.prior, objects, o);
  EXPECT_EQ(FramesPrepared() - before, 1u) << "the pass on a SceneInput prepares the frame once";
  ASSERT_EQ(shared.size(), plain.size());
  for (std::size_t i = 0; i < shared.size(); ++i) {
    ExpectSameFrameEstimate(plain[i].estimate, shared[i].estimate, "object " + std::to_string(i));
    EXPECT_EQ(plain[i].weight_masked, shared[i].weight_masked) << i;
    EXPECT_EQ(plain[i].reestimated, shared[i].reestimated) << i;
    EXPECT_EQ(plain[i].replaced, shared[i].replaced) << i;
  }
}

TEST(PreparedFrame, BadFramesMasksAndSeedsAreErrors) {
  const FrameCase& c = TwoTargetCase();
  const FilterOptions o = SmallFrameOptions();
  const SceneInput scene{c.scene.depth, c.scene.camera};
  ExpectError([&] { PrepareFrame(SceneInput{c.scene.depth, c.scene.camera, ObjectOf(c, c.targets[0]).mask}, o, "frame 3"); },
              {"frame 3", "no mask and no seeds"});
  ExpectError([&] { PrepareFrame(SceneInput{DepthImage(640, 480), c.scene.camera}, o, "frame 4"); },
              {"frame 4", "no valid pixel"});
  FilterOptions bad = o;
  bad.num_particles = 1;
  ExpectError([&] { PrepareFrame(scene, bad); }, {"num_particles"});
  const std::shared_ptr<const PreparedFrame> frame = PrepareFrame(scene, o);
  const Mesh& mesh = MeshOf(c, c.targets[0]);
  const int cls = c.prior.ClassIndex(mesh.name);
  ObjectInput short_mask;
  short_mask.mask.assign(10, 1);
  ExpectError([&] { EstimatePose(*frame, short_mask, mesh, c.prior, cls, o); }, {"mask holds 10 pixels"});
  ObjectInput empty_mask;
  empty_mask.mask.assign(c.scene.depth.data.size(), 0);
  ExpectError([&] { EstimatePose(*frame, empty_mask, mesh, c.prior, cls, o); }, {"mask is empty"});
  ObjectInput bad_seed;
  bad_seed.seeds = {{Eigen::Isometry3d::Identity(), 0.0}};
  ExpectError([&] { WeighPoses(*frame, bad_seed, mesh, c.prior, cls, o, {{Pose6{}, 0}}); }, {"pose seed 0"});
}

}  // namespace
}  // namespace posefilter
