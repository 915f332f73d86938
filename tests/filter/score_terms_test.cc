// Our additions to the score kernel and the filter: the ICP normal equations (one step brings
// a perturbed pose back), the silhouette edge samples (a face laid on a plane is "continued",
// the true object is not), scene normals, and restarts.
#include <gtest/gtest.h>

#include <cmath>

#include "filter/diffusion.h"
#include "filter/driver.h"
#include "filter/scene_prep.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/metrics.h"
#include "posefilter/render.h"
#include "posefilter/synth.h"

namespace posefilter {
namespace {

ScoreKernelParams Params(const Mesh& m, const Eigen::Isometry3d& T, const SynthScene& sc, const std::vector<float>* normals) {
  ScoreKernelParams k = MakeKernelParams(m, T, sc.camera);
  k.depth = sc.depth.data.data();
  k.depth_width = sc.depth.width;
  k.depth_height = sc.depth.height;
  k.scene_normals = normals ? normals->data() : nullptr;
  return k;
}

SynthScene Clean(const std::string& target, std::uint64_t seed) {
  SynthOptions so;
  so.target = target;
  so.noise_sigma_m = 0;
  so.hole_fraction = 0;
  return MakeSynthScene(so, seed);
}

TEST(SceneNormalsTest, PlaneNormalsAreExactAndFaceTheCamera) {
  Camera cam;
  DepthImage d(cam.width, cam.height, 0.f);
  // Plane n·x = 0.8 with n = (0, −sin 30°, −cos 30°) (tilted floor seen from above).
  const Eigen::Vector3d n(0, -0.5, -std::sqrt(3.0) / 2);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray = cam.Backproject(u, v, 1.0);
      d.at(u, v) = float(-0.8 / n.dot(ray));
    }
  const std::vector<float> normals = ComputeSceneNormals(d, cam);
  for (int v = 10; v < cam.height - 10; v += 37)
    for (int u = 10; u < cam.width - 10; u += 41) {
      const float* p = &normals[3 * (std::size_t(v) * cam.width + u)];
      EXPECT_NEAR(p[0], n.x(), 1e-3);
      EXPECT_NEAR(p[1], n.y(), 1e-3);
      EXPECT_NEAR(p[2], n.z(), 1e-3);
    }
  EXPECT_EQ(normals[0], 0.f);  // border: no normal
}

TEST(SceneNormalsTest, TheSameWithAnyThreadCount) {
  const SynthScene sc = Clean("torus", 4);  // a table-top scene with depth steps
  const std::vector<float> all = ComputeSceneNormals(sc.depth, sc.camera);
  EXPECT_EQ(ComputeSceneNormals(sc.depth, sc.camera, 1), all);
  EXPECT_EQ(ComputeSceneNormals(sc.depth, sc.camera, 3), all);
  std::size_t nonzero = 0;
  for (float x : all) nonzero += x != 0.f;
  EXPECT_GT(nonzero, all.size() / 2);  // not an empty image
}

TEST(IcpStepTest, OneStepPullsAPerturbedPoseBack) {
  for (const auto& [target, seed] : std::vector<std::pair<std::string, int>>{{"box", 3}, {"lshape", 7}, {"torus", 4}}) {
    const SynthScene sc = Clean(target, seed);
    const std::vector<float> normals = ComputeSceneNormals(sc.depth, sc.camera);
    const Eigen::Isometry3d T = sc.gt[0].T_cam_obj;
    Eigen::Isometry3d P = T;
    P.translation() += Eigen::Vector3d(0.004, -0.004, 0.004);
    P.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix() * P.linear();
    const auto pts = SamplePoints(sc.target);
    const double before = AddError(pts, P, T);
    for (int it = 0; it < 3; ++it) {
      RenderWorkspace ws;
      const ScoreKernelResult r = ScoreReference(Params(sc.target, P, sc, &normals), &ws);
      std::array<double, 6> step;
      ASSERT_TRUE(filter::SolveIcpStep(r, &step));
      const Eigen::Vector3d w(step[0], step[1], step[2]);
      Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
      if (w.norm() > 0) D.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      D.translation() = Eigen::Vector3d(step[3], step[4], step[5]);
      P = D * P;
    }
    const double after = AddError(pts, P, T);
    EXPECT_GT(before, 0.005) << target;
    EXPECT_LT(after, 0.0015) << target << ": " << 1000 * before << " mm -> " << 1000 * after << " mm";
  }
}

TEST(IcpStepTest, TooFewFragmentsGiveNoStep) {
  ScoreKernelResult r;
  r.icp_count = 5;
  std::array<double, 6> step;
  EXPECT_FALSE(filter::SolveIcpStep(r, &step));
}

TEST(EdgeSamplesTest, AFaceLaidOnAPlaneIsContinuedTheTrueObjectIsNot) {
  Camera cam;
  DepthImage wall(cam.width, cam.height, 1.0f);  // a fronto-parallel wall at 1 m
  const Mesh box = MakeBox(0.1, 0.1, 0.1);
  // (a) the box sunk into the wall: its front face lies exactly on the wall.
  Eigen::Isometry3d sunk = Eigen::Isometry3d::Identity();
  sunk.translation() = Eigen::Vector3d(0, 0, 1.05);
  // (b) a scene with the box standing 20 cm in front of the wall, box at its true pose.
  DepthImage scene = wall;
  Eigen::Isometry3d front = Eigen::Isometry3d::Identity();
  front.translation() = Eigen::Vector3d(0, 0, 0.85);
  RenderDepth(box, front, cam, &scene);
  auto score = [&](const Eigen::Isometry3d& T, const DepthImage& d) {
    ScoreKernelParams k = MakeKernelParams(box, T, cam);
    k.window = PixelRect{220, 124, 200, 200};
    k.depth = d.data.data();
    k.depth_width = d.width;
    k.depth_height = d.height;
    RenderWorkspace ws;
    return ScoreReference(k, &ws);
  };
  const ScoreKernelResult a = score(sunk, wall);
  const ScoreKernelResult b = score(front, scene);
  EXPECT_GT(a.n_edge, 100);
  EXPECT_EQ(a.n_edge_continued, a.n_edge);  // the wall goes on across the whole outline
  EXPECT_GT(b.n_edge, 100);
  EXPECT_EQ(b.n_edge_continued, 0);         // a 15 cm step all around the true box
  EXPECT_NEAR(a.inlier_sum, double(a.n_raster), 1e-9);  // both explain their pixels fully
  EXPECT_NEAR(b.inlier_sum, double(b.n_raster), 1e-9);
}

TEST(RestartsTest, RunsAreIndependentAndTheBestWins) {
  SynthOptions so;
  so.target = "box";
  so.false_positives = 0;
  const SynthScene sc = MakeSynthScene(so, 2);
  const Prior prior = PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes);
  FilterOptions o;
  o.num_particles = 40;
  o.stop.max_iterations = 4;
  o.restarts = 3;
  o.polish.steps = 0;  // the runs' own results only
  const SceneInput in{sc.depth, sc.camera};
  const EstimateResult r = EstimatePose(in, sc.target, prior, prior.ClassIndex("box"), o);
  EXPECT_EQ(r.iterations, 12);
  ASSERT_EQ(r.best_weight_history.size(), 12u);
  // The result is the best of the three runs' final weights.
  const double best_final = std::max({r.best_weight_history[3], r.best_weight_history[7], r.best_weight_history[11]});
  EXPECT_EQ(r.weight, best_final);
  const EstimateResult again = EstimatePose(in, sc.target, prior, prior.ClassIndex("box"), o);
  EXPECT_EQ(again.weight, r.weight);
  EXPECT_TRUE(again.T_cam_obj.isApprox(r.T_cam_obj, 0.0));
}

// The final polish starts from the runs' results, so it can only raise the weight; with the
// same seed the runs are identical, so the polished result is at least as good, it costs
// weighings, and it is deterministic.
TEST(PolishTest, NeverLowersTheWeightAndIsDeterministic) {
  SynthOptions so;
  so.target = "lshape";
  so.false_positives = 0;
  const SynthScene sc = MakeSynthScene(so, 3);
  const Prior prior = PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes);
  FilterOptions o;
  o.num_particles = 60;
  o.stop.max_iterations = 4;
  o.restarts = 2;
  o.polish.steps = 0;
  const SceneInput in{sc.depth, sc.camera};
  const int cls = prior.ClassIndex("lshape");
  const EstimateResult plain = EstimatePose(in, sc.target, prior, cls, o);
  o.polish.steps = 3;
  o.polish.climbers = 2;
  const EstimateResult polished = EstimatePose(in, sc.target, prior, cls, o);
  EXPECT_GE(polished.weight, plain.weight);
  EXPECT_GT(polished.stats.weighings, plain.stats.weighings + 2 * 24 * 3);  // 2 seeds × 24 turns × 3 steps
  EXPECT_EQ(polished.iterations, plain.iterations);  // polish is not a filter iteration
  // The result's weight is the weight of its pose: weighing it again gives the same number.
  const std::vector<double> w = WeighPoses(in, sc.target, prior, cls, o, {{polished.pose_base, polished.cell}});
  EXPECT_NEAR(w[0], polished.weight, 1e-12);
  const EstimateResult again = EstimatePose(in, sc.target, prior, cls, o);
  EXPECT_EQ(again.weight, polished.weight);
  EXPECT_TRUE(again.T_cam_obj.isApprox(polished.T_cam_obj, 0.0));
}

// A clean box scene with its post-processed prior, ready for EstimatePose / PolishPoses.
struct CleanBox {
  explicit CleanBox(std::uint64_t seed)
      : sc(Clean("box", seed)), prior(PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes)),
        cls(prior.ClassIndex("box")), in{sc.depth, sc.camera} {}
  SynthScene sc;
  Prior prior;
  int cls;
  SceneInput in;
};

// The ICP move is solved lazily: a child that drew it waits while its parent is weighed once
// more with the ICP sums. With the ICP move alone, every child after the first iteration is
// moved (hence weighed: a child left unmoved would keep its parent's weight unweighed) and
// each parent with such children is weighed twice; the run stays deterministic.
TEST(LazyIcpTest, IcpOnlyDiffusionReweighsParentsAndMovesChildren) {
  const auto& [sc, prior, cls, in] = CleanBox(6);
  FilterOptions o;
  o.num_particles = 60;
  o.stop.max_iterations = 5;
  o.restarts = 1;
  o.polish.steps = 0;
  o.anneal.start_m = 0;
  o.stop.confidence = 1;
  o.stop.stall_iterations = 0;  // all max_iterations iterations (the counts below assume them)
  o.diffusion.move_probabilities.fill(0.0);
  o.diffusion.move_probabilities[int(Move::kIcpStep)] = 1;
  // Every cell keeps a volume (the table's pixels too), so that the 60 particles spread over
  // many hypotheses, the resampling pool holds num_elite particles and the children below
  // are N − num_elite per iteration.
  o.support.plane = false;
  const EstimateResult a = EstimatePose(in, sc.target, prior, cls, o);
  const int children = (o.stop.max_iterations - 1) * (o.num_particles - o.num_elite);
  EXPECT_GT(a.stats.weighings, o.num_particles + children);  // + the parents weighed again
  const EstimateResult b = EstimatePose(in, sc.target, prior, cls, o);
  EXPECT_EQ(a.best_weight_history, b.best_weight_history);
  EXPECT_EQ(a.stats.weighings, b.stats.weighings);
  // Without any ICP move nothing is weighed twice: exactly N + children weighings.
  o.diffusion.move_probabilities.fill(0.0);
  o.diffusion.move_probabilities[int(Move::kTranslateAll)] = 1;
  const EstimateResult c = EstimatePose(in, sc.target, prior, cls, o);
  EXPECT_EQ(c.stats.weighings, o.num_particles + children);
}

// PolishPoses (the polish the hw engine's host side runs on the hardware's answers): a seed
// tipped a quarter turn about the box's edge and shifted 1 cm comes back to the true pose;
// bad seed lists are errors.
TEST(PolishTest, PolishPosesBringsATippedSeedBack) {
  const auto& [sc, prior, cls, in] = CleanBox(5);
  FilterOptions o;
  o.engine = "reference";  // PolishPoses weighs with the cpu engine whatever this says
  const Eigen::Isometry3d T_gt = sc.gt[0].T_cam_obj;
  Eigen::Isometry3d tip = Eigen::Isometry3d::Identity();
  tip.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d T_seed = T_gt * tip;
  T_seed.translation() += Eigen::Vector3d(0.01, 0, 0);
  const Pose6 seed = TransformToPose(sc.camera.base_to_camera.inverse() * T_seed);
  // The cell whose box the detection decoded: the most probable one.
  int cell = 0;
  for (int c = 0; c < prior.layout.CellCount(); ++c)
    if (prior.Prob(c, cls) > prior.Prob(cell, cls)) cell = c;
  ASSERT_FALSE(ComputePoseErrors(SamplePoints(sc.target), sc.target.Diameter(), T_seed, T_gt).adds_ok);
  const std::vector<double> w0 = WeighPoses(in, sc.target, prior, cls, o, {{seed, cell}});
  FilterStats stats;
  const filter::PreparedScene prep = filter::PrepareScene(in, o);
  const filter::PolishResult r = filter::PolishPoses(prep, sc.target, prior, cls, o, {{seed, cell}}, &stats);
  EXPECT_GT(r.weight, w0[0]);
  EXPECT_GT(stats.weighings, 24);
  const Eigen::Isometry3d T = sc.camera.base_to_camera * PoseToTransform(r.pose);
  const PoseErrors e = ComputePoseErrors(SamplePoints(sc.target), sc.target.Diameter(), T, T_gt);
  EXPECT_TRUE(e.adds_ok) << "ADD-S " << 1000 * e.adds << " mm";
  EXPECT_THROW(filter::PolishPoses(prep, sc.target, prior, cls, o, {}, &stats), Error);
  EXPECT_THROW(filter::PolishPoses(prep, sc.target, prior, cls, o, {{seed, -1}}, &stats), Error);
  EXPECT_THROW(filter::PolishPoses(prep, sc.target, prior, cls, o, {{seed, prior.layout.CellCount()}}, &stats), Error);
}

}  // namespace
}  // namespace posefilter
