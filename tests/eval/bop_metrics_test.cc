// BOP 2019 pose errors (VSD, MSSD, MSPD), symmetry sets, the YCB-Video AUC and EvaluateBop's
// recalls on the tiny synthetic BOP dataset (bop_metrics.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <vector>

#include "eval/bop_test_dataset.h"
#include "posefilter/bop_metrics.h"
#include "posefilter/error.h"
#include "posefilter/metrics.h"
#include "posefilter/render.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::At;
using testing_util::ExpectError;
using testing_util::HalfTurn;

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Isometry3d Rotated(const Eigen::Isometry3d& T, const Eigen::Vector3d& axis_obj, double angle) {
  Eigen::Isometry3d R = Eigen::Isometry3d::Identity();
  R.linear() = Eigen::AngleAxisd(angle, axis_obj).toRotationMatrix();
  return T * R;
}

std::vector<Eigen::Vector3f> Vertices(const Mesh& m) { return m.vertices; }

TEST(BopSymmetries, SetsHoldIdentityDiscreteAndDiscretisedContinuous) {
  DatasetModel none;
  EXPECT_EQ(SymmetryTransformations(none).size(), 1u);
  EXPECT_TRUE(SymmetryTransformations(none)[0].isApprox(Eigen::Isometry3d::Identity()));

  DatasetModel box;
  box.symmetries_discrete = {HalfTurn(Eigen::Vector3d::UnitX()), HalfTurn(Eigen::Vector3d::UnitY()),
                             HalfTurn(Eigen::Vector3d::UnitZ())};
  const auto bs = SymmetryTransformations(box);
  ASSERT_EQ(bs.size(), 4u);
  // Every transformation maps the box's vertex set onto itself.
  const Mesh m = MakeBox(0.12, 0.08, 0.16);
  for (const auto& S : bs)
    for (const auto& v : m.vertices) {
      double nearest = kInf;
      for (const auto& w : m.vertices) nearest = std::min(nearest, (S * v.cast<double>() - w.cast<double>()).norm());
      EXPECT_LT(nearest, 1e-6);
    }

  DatasetModel cyl;
  cyl.symmetries_discrete = {HalfTurn(Eigen::Vector3d::UnitX())};
  cyl.symmetries_continuous = {ContinuousSymmetry{Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0.01, 0, 0)}};
  const auto cs = SymmetryTransformations(cyl, 0.01);
  const int n = static_cast<int>(std::ceil(std::numbers::pi / 0.01));  // 315 steps
  ASSERT_EQ(cs.size(), std::size_t(2 * n));
  EXPECT_TRUE(cs[0].isApprox(Eigen::Isometry3d::Identity()));
  // The axis passes through the offset: the point (0.01, 0, z) stays where it is.
  for (const auto& S : cs) {
    if (S.linear()(2, 2) < 0) continue;  // combined with the flip
    EXPECT_LT((S * Eigen::Vector3d(0.01, 0, 0.3) - Eigen::Vector3d(0.01, 0, 0.3)).norm(), 1e-12);
  }
  ExpectError([&] { SymmetryTransformations(cyl, 0); }, {"max_sym_disc_step"});
}

TEST(BopMssdMspd, TranslationGivesItsLengthAndItsProjection) {
  const Mesh box = MakeBox(0.12, 0.08, 0.16);
  const auto pts = Vertices(box);
  const Camera cam = testing_util::PinholeCamera(500, 500);
  const Eigen::Isometry3d gt = At(0, 0, 0.8);
  const double d = 0.03;
  const std::vector<Eigen::Isometry3d> id = {Eigen::Isometry3d::Identity()};
  EXPECT_NEAR(MssdError(pts, At(d, 0, 0.8), gt, id), d, 1e-7);
  // A lateral shift d moves a point at depth z by fx·d/z pixels: largest at the nearest vertex.
  double z_min = kInf;
  for (const auto& p : pts) z_min = std::min(z_min, 0.8 + p.z());
  EXPECT_NEAR(MspdError(pts, At(d, 0, 0.8), gt, id, cam), 500 * d / z_min, 1e-6);
  EXPECT_NEAR(MssdError(pts, gt, gt, id), 0, 1e-12);
  ExpectError([&] { MssdError({}, gt, gt, id); }, {"MSSD", "empty"});
  ExpectError([&] { MspdError(pts, gt, gt, {}, cam); }, {"MSPD", "symmetry"});
}

TEST(BopMssdMspd, SymmetricPosesScoreZero) {
  const Camera cam = testing_util::PinholeCamera(500, 500);
  const Eigen::Isometry3d gt = Rotated(At(0.05, -0.02, 0.8), Eigen::Vector3d(1, 2, 3).normalized(), 0.7);

  // Box: turned 180° about its z axis (a listed symmetry).
  const Mesh box = MakeBox(0.12, 0.08, 0.16);
  DatasetModel bm;
  bm.symmetries_discrete = {HalfTurn(Eigen::Vector3d::UnitZ())};
  const Eigen::Isometry3d flipped = Rotated(gt, Eigen::Vector3d::UnitZ(), std::numbers::pi);
  const auto syms = SymmetryTransformations(bm);
  EXPECT_LT(MssdError(box.vertices, flipped, gt, syms), 1e-9);
  EXPECT_LT(MspdError(box.vertices, flipped, gt, syms, cam), 1e-6);
  // Without the symmetry it is the distance between opposite corners in x–y: √(0.12² + 0.08²).
  const std::vector<Eigen::Isometry3d> id = {Eigen::Isometry3d::Identity()};
  EXPECT_NEAR(MssdError(box.vertices, flipped, gt, id), std::hypot(0.12, 0.08), 1e-7);
  EXPECT_GT(MspdError(box.vertices, flipped, gt, id, cam), 50);

  // Cylinder: any turn about z is within the discretisation (≤ π/315 rad of arc).
  const Mesh cyl = MakeCylinder(0.04, 0.14, 32);
  DatasetModel cm;
  cm.symmetries_continuous = {ContinuousSymmetry{}};
  const Eigen::Isometry3d turned = Rotated(gt, Eigen::Vector3d::UnitZ(), 0.7);
  const auto csyms = SymmetryTransformations(cm);
  EXPECT_LT(MssdError(cyl.vertices, turned, gt, csyms), 0.04 * std::numbers::pi / 315 + 1e-9);
  EXPECT_GT(MssdError(cyl.vertices, turned, gt, id), 0.02);
}

// Camera 640×480, a box 0.8 m in front; the test depth is the box rendered alone.
struct VsdSetup {
  Mesh box = MakeBox(0.12, 0.08, 0.16);
  Camera cam = testing_util::PinholeCamera(540, 540);
  Eigen::Isometry3d gt = Rotated(At(0.0, 0.0, 0.8), Eigen::Vector3d(1, 1, 0).normalized(), 0.5);
  DepthImage depth;
  VsdSetup() {
    depth = DepthImage(cam.width, cam.height, 0.f);
    RenderDepth(box, gt, cam, &depth);
  }
};

TEST(BopVsd, IdenticalPoseIsZeroFarPoseIsOne) {
  VsdSetup s;
  const std::vector<double> taus = Multiples(0.05, 10);
  const double diam = s.box.Diameter();
  for (double e : VsdErrors(s.box, s.gt, s.gt, s.depth, s.cam, 0.015, taus, diam)) EXPECT_DOUBLE_EQ(e, 0);
  Eigen::Isometry3d away = s.gt;
  away.translation().x() += 2.0;  // out of the image
  for (double e : VsdErrors(s.box, away, s.gt, s.depth, s.cam, 0.015, taus, diam)) EXPECT_DOUBLE_EQ(e, 1);
  // Missing test depth: a pose far in front of the box is still visible there (D_I = 0 counts).
  DepthImage empty(s.cam.width, s.cam.height, 0.f);
  for (double e : VsdErrors(s.box, away, s.gt, empty, s.cam, 0.015, taus, diam)) EXPECT_DOUBLE_EQ(e, 1);
}

TEST(BopVsd, DepthShiftFailsBelowAndPassesAboveItsTau) {
  VsdSetup s;
  const std::vector<double> taus = Multiples(0.05, 10);
  const double diam = s.box.Diameter();  // ≈ 216 mm: a 30 mm shift ≈ 0.14 of it
  Eigen::Isometry3d back = s.gt;
  back.translation().z() += 0.03;
  const std::vector<double> e = VsdErrors(s.box, back, s.gt, s.depth, s.cam, 0.015, taus, diam);
  ASSERT_EQ(e.size(), 10u);
  for (std::size_t k = 1; k < e.size(); ++k) EXPECT_LE(e[k], e[k - 1] + 1e-12);
  EXPECT_GT(e[0], 0.9);   // τ = 5 % (11 mm) < 30 mm: almost every pixel misaligned
  EXPECT_GT(e[1], 0.9);   // τ = 10 % (22 mm)
  EXPECT_LT(e[3], 0.25);  // τ = 20 % (43 mm): only the silhouette difference remains
  ExpectError([&] { VsdErrors(s.box, back, s.gt, DepthImage(10, 10), s.cam, 0.015, taus, diam); }, {"VSD", "10x10"});
  ExpectError([&] { VsdErrors(s.box, back, s.gt, s.depth, s.cam, 0.015, taus, 0); }, {"VSD", "diameter"});
}

TEST(BopVsd, DistanceImageIsDepthAlongTheRay) {
  const Camera cam = testing_util::PinholeCamera(100, 200, 320, 240);
  DepthImage d(640, 480, 0.f);
  d.at(420, 240) = 2.0f;   // x/z = 1: distance 2·√2
  d.at(320, 440) = 1.0f;   // y/z = 1: distance √2
  const DepthImage r = DepthToDistance(d, cam);
  EXPECT_NEAR(r.at(420, 240), 2 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(r.at(320, 440), std::sqrt(2.0), 1e-6);
  EXPECT_EQ(r.at(0, 0), 0.f);
}

TEST(YcbvAucTest, MatchesHandComputedArea) {
  // Errors 2 cm, 5 cm, none, 20 cm (n = 4): steps of 1/4 at 2 cm and 2/4 at 5 cm, held to 10 cm:
  // (0.02·1/4 + 0.03·2/4 + 0.05·2/4) / 0.1 = 0.45.
  EXPECT_NEAR(YcbvAuc({0.02, 0.05, kInf, 0.2}), 0.45, 1e-12);
  EXPECT_NEAR(YcbvAuc({0.0, 0.0}), 1.0, 1e-12);
  EXPECT_EQ(YcbvAuc({}), 0.0);
  EXPECT_EQ(YcbvAuc({kInf, 0.5}), 0.0);
  // PoseCNN's right-endpoint steps: a single error below the cap gives area 1, and with a missing
  // second estimate 1/2.
  EXPECT_NEAR(YcbvAuc({0.05}), 1.0, 1e-12);
  EXPECT_NEAR(YcbvAuc({0.05, kInf}), 0.5, 1e-12);
  ExpectError([&] { YcbvAuc({0.1}, 0); }, {"max"});
}

TEST(BopEvalOptionsTest, InvalidFieldsAreNamed) {
  BopEvalOptions o;
  EXPECT_TRUE(o.IsValid(nullptr));
  o.vsd_taus.clear();
  testing_util::ExpectInvalid(o, "vsd_taus");
  o = {};
  o.vsd_thresholds = {1.5};
  testing_util::ExpectInvalid(o, "vsd_thresholds");
  o = {};
  o.vsd_delta_m = -1;
  testing_util::ExpectInvalid(o, "vsd_delta_m");
  o = {};
  o.mspd_thresholds_px = {5, NAN};
  testing_util::ExpectInvalid(o, "mspd_thresholds_px");
  o = {};
  o.max_points = 0;
  testing_util::ExpectInvalid(o, "max_points");
}

// ---- EvaluateBop on the tiny dataset ------------------------------------------------------------

class BopEvalTest : public testing_util::ScratchDirTest {
 protected:
  BopEvalTest() : ScratchDirTest("bop_eval") {}
  static void SetUpTestSuite() {
    base_dir_ = new fs::path(testing_util::FreshTempPath("bop_eval_base"));
    tiny_ = new testing_util::TinyBop(testing_util::MakeTinyBop(*base_dir_, 3));
    ds_ = new Dataset(ReadBopDataset(tiny_->root, "test"));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*base_dir_, ec);
    delete ds_;
    delete tiny_;
    delete base_dir_;
  }
  static fs::path* base_dir_;
  static testing_util::TinyBop* tiny_;
  static Dataset* ds_;
};
fs::path* BopEvalTest::base_dir_ = nullptr;
testing_util::TinyBop* BopEvalTest::tiny_ = nullptr;
Dataset* BopEvalTest::ds_ = nullptr;

TEST_F(BopEvalTest, GroundTruthScoresOne) {
  const BopEvalReport r = EvaluateBop(*ds_, testing_util::GtResults(*tiny_));
  EXPECT_EQ(r.overall.n_instances, 3);
  EXPECT_EQ(r.overall.n_estimated, 3);
  for (const BopScores& s : r.objects) {
    EXPECT_DOUBLE_EQ(s.add_recall, 1) << s.name;
    EXPECT_DOUBLE_EQ(s.vsd_recall, 1) << s.name;
    EXPECT_DOUBLE_EQ(s.mssd_recall, 1) << s.name;
    EXPECT_DOUBLE_EQ(s.mspd_recall, 1) << s.name;
    EXPECT_DOUBLE_EQ(s.ar, 1) << s.name;
    EXPECT_NEAR(s.auc_adds, 1, 1e-9) << s.name;
  }
  EXPECT_DOUBLE_EQ(r.overall.ar, 1);
  EXPECT_DOUBLE_EQ(r.mean_time_s, 0.5);
  for (const auto& i : r.instances) {
    EXPECT_LT(i.add_m, 1e-6);
    EXPECT_EQ(i.vsd.size(), 10u);
  }
}

TEST_F(BopEvalTest, ShiftedPoseFailsExactlyThatTarget) {
  std::vector<BopResult> res = testing_util::GtResults(*tiny_);
  // Box (image 1): shifted sideways by 22 % of its diameter.
  const double d = ds_->Model(1)->diameter_m;
  res[0].T_cam_obj.translation().x() += 0.22 * d;
  const BopEvalReport r = EvaluateBop(*ds_, res);
  ASSERT_EQ(r.objects.size(), 3u);
  const BopScores& box = r.objects[0];
  EXPECT_DOUBLE_EQ(box.add_recall, 0);
  // ADD-S over the 8 corners: corners are ≥ 80 mm apart, so each one's nearest shifted corner is
  // ≥ 80 − 47 mm away, above 10 % of the diameter (22 mm).
  EXPECT_DOUBLE_EQ(box.adds_recall, 0);
  EXPECT_NEAR(r.instances[0].add_m, 0.22 * d, 1e-6);
  EXPECT_NEAR(r.instances[0].mssd_m, 0.22 * d, 1e-6);
  EXPECT_DOUBLE_EQ(box.mssd_recall, 0.6);  // correct for thresholds 0.25 … 0.5
  EXPECT_LT(box.mspd_recall, 1);
  EXPECT_LT(box.vsd_recall, 1);
  EXPECT_LT(box.ar, 1);
  for (int k = 1; k < 3; ++k) EXPECT_DOUBLE_EQ(r.objects[k].ar, 1) << r.objects[k].name;
  EXPECT_NEAR(r.overall.add_recall, 2.0 / 3, 1e-12);
  EXPECT_NEAR(r.overall.mssd_recall, 26.0 / 30, 1e-12);
  // AUC of ADD: the box's 0.22·d ≈ 47 mm error against two zeros.
  EXPECT_NEAR(r.overall.auc_add, YcbvAuc({0.22 * d, 0, 0}), 1e-6);
}

TEST_F(BopEvalTest, MissingEstimatesFailAndExtraOnesAreIgnored) {
  std::vector<BopResult> res = testing_util::GtResults(*tiny_);
  res.erase(res.begin() + 1);  // no estimate for the cylinder
  BopResult extra = res[0];    // a second, worse box estimate: only the top 1 (by score) counts
  extra.score = 0.1;
  extra.T_cam_obj.translation().z() += 1;
  res.push_back(extra);
  const BopEvalReport r = EvaluateBop(*ds_, res);
  EXPECT_EQ(r.n_results, 3);
  EXPECT_EQ(r.n_results_used, 2);
  EXPECT_EQ(r.overall.n_estimated, 2);
  EXPECT_NEAR(r.overall.ar, 2.0 / 3, 1e-12);
  EXPECT_DOUBLE_EQ(r.objects[1].ar, 0);
  EXPECT_FALSE(r.instances[1].estimated);
  EXPECT_EQ(r.instances[1].add_m, kInf);
  EXPECT_DOUBLE_EQ(r.objects[0].ar, 1);

  BopResult alien = res[0];
  alien.obj_id = 42;
  ExpectError([&] { EvaluateBop(*ds_, {alien}); }, {"obj_id 42"});
  BopEvalOptions bad;
  bad.add_threshold = 0;
  ExpectError([&] { EvaluateBop(*ds_, res, bad); }, {"add_threshold"});
}

}  // namespace
}  // namespace posefilter
