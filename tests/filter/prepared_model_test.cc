// A mesh prepared once (posefilter/prepared_model.h): estimates and weighings on the prepared
// model equal, bit for bit, those that prepare the mesh on the fly (cpu and reference engines,
// on a table scene whose support plane makes the filter read the hull, the stable poses and a
// simplified coarse mesh); one model serves estimates on several threads at once; options it
// was not prepared for are prepared on the fly; and the Tracker prepares each mesh once per
// sequence (ModelLodsPrepared counts every preparation, TrackStats the tracker's own).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/prepared_model.h"
#include "posefilter/prior.h"
#include "posefilter/synth.h"
#include "posefilter/table_world.h"
#include "posefilter/tracker.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;

// A finely tessellated cylinder (800 faces: above every coarse budget, so the annealing's
// coarse level weighs a simplified mesh) standing among boxes on a table.
const TableWorld& PreparationWorld() {
  static const TableWorld* w = new TableWorld({MakeCylinder(0.04, 0.14, 200, "cylinder"),
                                               MakeBox(0.12, 0.08, 0.16, "box"), MakeBox(0.06, 0.06, 0.06, "cube")});
  return *w;
}

struct Case {
  TableScene scene;
  Prior prior;
  int cls = -1;
  SceneInput in;
};

// The first table scene from seed 1 on that holds the cylinder as a target.
const Case& CylinderCase() {
  static const Case* made = [] {
    TableSceneOptions o;
    o.min_objects = 3;
    o.max_objects = 3;
    for (std::uint64_t s = 1;; ++s) {
      auto c = std::make_unique<Case>();
      c->scene = PreparationWorld().MakeScene(o, s);
      bool found = false;
      for (const TableObject& obj : c->scene.objects) found = found || (obj.cls == "cylinder" && obj.target);
      if (!found) continue;
      const std::vector<std::string> classes = PreparationWorld().ClassNames();
      c->prior = PriorFromDetections(c->scene.detections, PyramidLayout::Thesis(640, 480, int(classes.size())), classes);
      c->cls = c->prior.ClassIndex("cylinder");
      c->in = SceneInput{c->scene.depth, c->scene.camera};
      return c.release();
    }
  }();
  return *made;
}

const Mesh& PreparationCylinder() { return PreparationWorld().models()[0].mesh; }

// A small budget that still anneals on the coarse level, starts particles in stable poses,
// reads the contact prior and polishes (stable re-search included).
FilterOptions Small(const std::string& engine) {
  FilterOptions o;
  o.engine = engine;
  o.num_particles = 48;
  o.stop.max_iterations = 8;
  o.restarts = 2;
  o.threads = 2;
  return o;
}

void ExpectSame(const EstimateResult& a, const EstimateResult& b, const std::string& what) {
  EXPECT_TRUE(a.T_cam_obj.matrix() == b.T_cam_obj.matrix()) << what;
  EXPECT_EQ(a.weight, b.weight) << what;
  EXPECT_EQ(a.cell, b.cell) << what;
  EXPECT_EQ(a.iterations, b.iterations) << what;
  EXPECT_EQ(a.obj, b.obj) << what;
  EXPECT_EQ(a.best_weight_history, b.best_weight_history) << what;
  EXPECT_EQ(a.stats.weighings, b.stats.weighings) << what;
  EXPECT_EQ(a.stats.faces_total, b.stats.faces_total) << what;
  EXPECT_EQ(a.stats.faces_front, b.stats.faces_front) << what;
  EXPECT_EQ(a.stats.fragments, b.stats.fragments) << what;
}

TEST(PreparedModel, EstimatesAndWeighingsEqualThoseThatPrepareTheMeshOnTheFly) {
  const Case& c = CylinderCase();
  ASSERT_GE(c.cls, 0);
  // The third case caps the window at 8 pixels: the cylinder is then weighed on every 4th
  // pixel (adaptive resolution), where the fine level too weighs a simplified mesh.
  for (const std::string engine : {"cpu", "reference", "cpu, fine factor 4"}) {
    FilterOptions o = Small(engine.substr(0, engine.find(',')));
    if (engine.find(',') != std::string::npos) o.render.max_window_px = 8;
    const std::uint64_t before = ModelLodsPrepared();
    const std::shared_ptr<const PreparedModel> model = PrepareModel(PreparationCylinder(), o);
    EXPECT_EQ(ModelLodsPrepared() - before, 1u) << engine;
    EXPECT_TRUE(model->Covers(o)) << engine;
    EXPECT_EQ(model->mesh().name, "cylinder");

    const std::uint64_t fly_before = ModelLodsPrepared();
    const EstimateResult on_the_fly = EstimatePose(c.in, PreparationCylinder(), c.prior, c.cls, o);
    EXPECT_EQ(ModelLodsPrepared() - fly_before, 1u) << engine << ": the mesh is prepared for the one estimate";

    const std::uint64_t prepared_before = ModelLodsPrepared();
    const EstimateResult prepared = EstimatePose(c.in, *model, c.prior, c.cls, o);
    const EstimateResult again = EstimatePose(c.in, *model, c.prior, c.cls, o);
    EXPECT_EQ(ModelLodsPrepared(), prepared_before) << engine << ": nothing prepared again";
    ExpectSame(on_the_fly, prepared, engine + ": prepared vs on the fly");
    ExpectSame(prepared, again, engine + ": the model is unchanged by an estimate");
    EXPECT_GT(prepared.weight, 0.3) << engine;

    const std::vector<std::pair<Pose6, int>> hyp = {{prepared.pose_base, prepared.cell},
                                                   {on_the_fly.pose_base, std::max(0, prepared.cell - 1)}};
    EXPECT_EQ(WeighPoses(c.in, PreparationCylinder(), c.prior, c.cls, o, hyp), WeighPoses(c.in, *model, c.prior, c.cls, o, hyp))
        << engine;
  }
}

TEST(PreparedModel, OneModelServesEstimatesOnSeveralThreadsAtOnce) {
  const Case& c = CylinderCase();
  FilterOptions o = Small("cpu");
  o.threads = 1;
  const std::shared_ptr<const PreparedModel> model = PrepareModel(PreparationCylinder(), o);
  std::vector<FilterOptions> seeds(4, o);
  std::vector<EstimateResult> serial, parallel(seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    seeds[i].seed = 100 + i;
    serial.push_back(EstimatePose(c.in, *model, c.prior, c.cls, seeds[i]));
  }
  std::vector<std::thread> workers;
  for (std::size_t i = 0; i < seeds.size(); ++i)
    workers.emplace_back([&, i] { parallel[i] = EstimatePose(c.in, *model, c.prior, c.cls, seeds[i]); });
  for (std::thread& t : workers) t.join();
  for (std::size_t i = 0; i < seeds.size(); ++i) ExpectSame(serial[i], parallel[i], "seed " + std::to_string(100 + i));
}

TEST(PreparedModel, OptionsItWasNotPreparedForArePreparedOnTheFly) {
  const Case& c = CylinderCase();
  const FilterOptions o = Small("cpu");
  const std::shared_ptr<const PreparedModel> model = PrepareModel(PreparationCylinder(), o);
  EXPECT_EQ(model->LodBudgets(), std::vector<int>{o.render.lod_max_faces});
  ASSERT_NE(model->Lod(o.render.lod_max_faces), nullptr);
  EXPECT_EQ(model->Lod(o.render.lod_max_faces)->faces.size(), PreparationCylinder().faces.size());  // 800 ≤ 4096: unchanged
  EXPECT_EQ(model->Lod(256), nullptr);

  FilterOptions coarser = o;
  coarser.render.lod_max_faces = 256;
  EXPECT_FALSE(model->Covers(coarser));
  const std::uint64_t before = ModelLodsPrepared();
  const EstimateResult fly = EstimatePose(c.in, *model, c.prior, c.cls, coarser);
  EXPECT_EQ(ModelLodsPrepared() - before, 1u) << "the missing level of detail is prepared for the estimate";
  ExpectSame(fly, EstimatePose(c.in, PreparationCylinder(), c.prior, c.cls, coarser), "lod 256");

  // Prepared for both: one level of detail each, and both covered.
  const std::shared_ptr<const PreparedModel> both = PrepareModel(PreparationCylinder(), {o, coarser});
  EXPECT_EQ(both->LodBudgets(), (std::vector<int>{o.render.lod_max_faces, 256}));
  EXPECT_TRUE(both->Covers(o));
  EXPECT_TRUE(both->Covers(coarser));
  ASSERT_NE(both->Lod(256), nullptr);
  EXPECT_LE(both->Lod(256)->faces.size(), 256u);
  EXPECT_EQ(both->Lod(256)->name, "cylinder");
}

TEST(PreparedModel, InvalidMeshesAndOptionsAreErrors) {
  ExpectError([] { PrepareModel(Mesh{}, FilterOptions{}); }, {"mesh"});
  ExpectError([] { PrepareModel(PreparationCylinder(), std::vector<FilterOptions>{}); }, {"no option set"});
  FilterOptions bad;
  bad.num_particles = 1;
  ExpectError([&] { PrepareModel(PreparationCylinder(), bad); }, {"num_particles"});
}

// ---- The tracker -------------------------------------------------------------------------------

TEST(TrackerPreparation, EachMeshIsPreparedOncePerSequence) {
  // Half a centimetre per frame, then a 15 cm jump at frame 2 that the search loses: the
  // L-shape starts from the stage 1 at frame 0 (no Reset) and is re-initialised from it at the
  // jump; a second mesh, which no stage 1 names, is tracked (and lost) too.
  SynthOptions so;
  so.target = "lshape";
  so.clutter = 2;
  so.false_positives = 0;
  const std::vector<SynthScene> seq = MakeSynthSequence(so, SynthMotion{5, 0.005, 0.0, 2, 0.15}, 22);
  TrackOptions o;
  o.filter.seed = 5;
  o.filter.threads = 1;
  o.init.num_particles = 200;
  o.init.stop.max_iterations = 10;
  o.init.restarts = 2;
  o.init.threads = 1;
  const std::uint64_t before = ModelLodsPrepared();
  Tracker tracker({seq[0].target, MakeBox(0.05, 0.05, 0.05, "crate")}, o);
  // The searches' models, one per mesh, in the constructor; the initialisations' not yet.
  ASSERT_EQ(tracker.models().size(), 2u);
  EXPECT_EQ(tracker.models()[0]->mesh().name, "lshape");
  EXPECT_EQ(tracker.init_models(), (std::vector<std::shared_ptr<const PreparedModel>>{nullptr, nullptr}));
  EXPECT_EQ(ModelLodsPrepared() - before, 2u);
  tracker.Reset("crate", seq[0].gt[0].T_cam_obj * Eigen::Translation3d(0.3, 0.3, 0.0));

  const std::uint64_t after_construction = ModelLodsPrepared();
  int stage1_calls = 0;
  const Stage1Fn stage1 = [&](const SceneInput&) {
    const SynthScene& s = seq.at(std::size_t(tracker.frames()));
    ++stage1_calls;
    TrackStage1 st;
    st.prior = PriorFromDetections(s.detections, PyramidLayout::Thesis(s.camera.width, s.camera.height, int(s.classes.size())),
                                   s.classes);
    return st;
  };
  std::vector<TrackStatus> lshape;
  for (const SynthScene& s : seq) lshape.push_back(tracker.Track(SceneInput{s.depth, s.camera}, stage1).at(0).status);
  EXPECT_EQ(tracker.frames(), int(seq.size()));
  EXPECT_GE(stage1_calls, 2);
  EXPECT_EQ(lshape[0], TrackStatus::kInitialised) << "the first frame starts the L-shape from the stage 1";
  EXPECT_EQ(lshape[1], TrackStatus::kTracked);
  EXPECT_EQ(lshape[2], TrackStatus::kInitialised) << "the jump frame re-initialises it from the stage 1";
  // Two initialisations of the L-shape, many searches and judgements of both meshes: one more
  // preparation in all, the L-shape's for the initialisations, made by the first of them.
  EXPECT_EQ(ModelLodsPrepared() - after_construction, 1u)
      << "the searches, initialisations and judgements of " << seq.size() << " frames prepared a mesh again";
  // The tracker's own count: the same three preparations; one scored depth per frame, and one
  // prepared frame per stage-1 frame, which its initialisations (and scene pass) share.
  const TrackStats& st = tracker.stats();
  EXPECT_EQ(st.frames, int(seq.size()));
  EXPECT_EQ(st.models_prepared, 3);
  EXPECT_EQ(std::uint64_t(st.models_prepared), ModelLodsPrepared() - before) << "every preparation is the tracker's";
  EXPECT_EQ(st.scenes_prepared, int(seq.size()));
  EXPECT_EQ(st.init_scenes_prepared, stage1_calls);
  EXPECT_GE(st.initialisations, 2);
  EXPECT_GE(st.searches, 2 * int(seq.size()) - 1) << "the crate from frame 0, the L-shape from frame 1";
  EXPECT_GT(st.weighings, 0);
  ASSERT_NE(tracker.init_models()[0], nullptr);
  EXPECT_EQ(tracker.init_models()[1], nullptr) << "no stage 1 names the crate";
  EXPECT_TRUE(tracker.init_models()[0]->Covers(o.init));
}

}  // namespace
}  // namespace posefilter
