// Tests of include/posefilter/metrics.h: ADD, ADD-S (k-d tree vs brute force), rotation and
// translation errors, thresholds, point sampling and the .xyz reader.
#include "posefilter/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/rng.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

constexpr double kDeg = std::numbers::pi / 180.0;

std::vector<Eigen::Vector3f> RandomPoints(Rng& rng, int n, double half_extent) {
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(n);
  // Draws one per statement, the last coordinate first: C++ leaves the order of a call's
  // argument evaluations open (GCC takes the last first, Clang the first), and these are the
  // cases the tests have always run (GCC's order). The same below.
  for (int i = 0; i < n; ++i) {
    const double z = rng.Uniform(-half_extent, half_extent), y = rng.Uniform(-half_extent, half_extent),
                 x = rng.Uniform(-half_extent, half_extent);
    pts.emplace_back(x, y, z);
  }
  return pts;
}

Eigen::Isometry3d RandomPose(Rng& rng, double max_angle_rad, double max_trans_m) {
  const double az = rng.Normal(), ay = rng.Normal(), ax = rng.Normal();
  Eigen::Vector3d axis(ax, ay, az);
  axis.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(rng.Uniform(-max_angle_rad, max_angle_rad), axis).toRotationMatrix();
  const double tz = 0.5 + rng.Uniform(0, max_trans_m), ty = rng.Uniform(-max_trans_m, max_trans_m),
               tx = rng.Uniform(-max_trans_m, max_trans_m);
  T.translation() = Eigen::Vector3d(tx, ty, tz);
  return T;
}

// O(N²) reference of ADD-S: mean over gt points of the distance to the closest estimated point.
// Plain loops over doubles (the sanitizer build compiles tests without optimisation); the
// minimum of the squared distances has the minimum distance's square root, exactly.
double BruteForceAddS(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                      const Eigen::Isometry3d& T_gt) {
  const std::size_t n = pts.size();
  std::vector<double> ex(n), ey(n), ez(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d e = T_est * pts[i].cast<double>();
    ex[i] = e.x(), ey[i] = e.y(), ez[i] = e.z();
  }
  double sum = 0;
  for (const auto& p : pts) {
    const Eigen::Vector3d g = T_gt * p.cast<double>();
    const double gx = g.x(), gy = g.y(), gz = g.z();
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
      const double dx = gx - ex[j], dy = gy - ey[j], dz = gz - ez[j];
      const double d2 = dx * dx + dy * dy + dz * dz;
      if (d2 < best) best = d2;
    }
    sum += std::sqrt(best);
  }
  return sum / n;
}

using testing_util::ExpectError;
using testing_util::ScratchDir;

TEST(AddError, ZeroForIdenticalPoses) {
  Rng rng(1);
  const auto pts = RandomPoints(rng, 500, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Isometry3d T = RandomPose(rng, std::numbers::pi, 0.2);
    EXPECT_NEAR(AddError(pts, T, T), 0.0, 1e-15);
    EXPECT_NEAR(AddSError(pts, T, T), 0.0, 1e-15);
  }
}

TEST(AddError, EqualsNormOfPureTranslation) {
  Rng rng(2);
  const auto pts = RandomPoints(rng, 300, 0.08);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Isometry3d T_gt = RandomPose(rng, std::numbers::pi, 0.2);
    const double dz = rng.Uniform(-0.05, 0.05), dy = rng.Uniform(-0.05, 0.05), dx = rng.Uniform(-0.05, 0.05);
    const Eigen::Vector3d d(dx, dy, dz);
    const Eigen::Isometry3d T_est = Eigen::Translation3d(d) * T_gt;  // every point moved by d
    EXPECT_NEAR(AddError(pts, T_est, T_gt), d.norm(), 1e-12);
    EXPECT_NEAR(TranslationError(T_est.translation(), T_gt.translation()), d.norm(), 1e-12);
  }
}

TEST(AddError, EmptyPointSetThrows) {
  const std::vector<Eigen::Vector3f> none;
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_THROW(AddError(none, T, T), Error);
  EXPECT_THROW(AddSError(none, T, T), Error);
}

TEST(AddSError, NeverExceedsAdd) {
  Rng rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const auto pts = RandomPoints(rng, 400, 0.06);
    const Eigen::Isometry3d T_gt = RandomPose(rng, std::numbers::pi, 0.2);
    const Eigen::Isometry3d T_est = RandomPose(rng, std::numbers::pi, 0.2);
    const double add = AddError(pts, T_est, T_gt);
    const double adds = AddSError(pts, T_est, T_gt);
    EXPECT_GT(add, 0.0);
    EXPECT_LE(adds, add + 1e-12) << "trial " << trial;
  }
}

TEST(AddSError, ZeroForCubeRotatedQuarterTurnWhileAddIsNot) {
  // A 5×5×5 lattice filling a cube of half-side a maps onto itself under 90° about z.
  const double a = 0.04;
  std::vector<Eigen::Vector3f> lattice;
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j)
      for (int k = -2; k <= 2; ++k) lattice.emplace_back(a * i / 2, a * j / 2, a * k / 2);
  Eigen::Isometry3d T_gt = Eigen::Isometry3d::Identity();
  T_gt.translation() = Eigen::Vector3d(0.1, -0.05, 0.7);
  T_gt.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Isometry3d T_est = T_gt;
  T_est.linear() = T_gt.linear() * Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();

  EXPECT_NEAR(AddSError(lattice, T_est, T_gt), 0.0, 1e-7);
  // Each point moves by √2·r_xy (chord of a quarter turn), r_xy = its distance from the z axis.
  double expected_add = 0;
  for (const auto& p : lattice) expected_add += std::sqrt(2.0) * std::hypot(p.x(), p.y());
  expected_add /= lattice.size();
  EXPECT_NEAR(AddError(lattice, T_est, T_gt), expected_add, 1e-7);
  EXPECT_GT(AddError(lattice, T_est, T_gt), 0.02);

  // The 8 corners alone: every corner moves by 2a.
  std::vector<Eigen::Vector3f> corners;
  for (int s = 0; s < 8; ++s) corners.emplace_back(s & 1 ? a : -a, s & 2 ? a : -a, s & 4 ? a : -a);
  EXPECT_NEAR(AddError(corners, T_est, T_gt), 2 * a, 1e-7);
  EXPECT_NEAR(AddSError(corners, T_est, T_gt), 0.0, 1e-7);
}

TEST(AddSError, MatchesBruteForce) {
  Rng rng(4);
  // Uniform cloud, a flat (degenerate) cloud, a cloud with many duplicates, tiny sets.
  std::vector<std::vector<Eigen::Vector3f>> clouds;
  clouds.push_back(RandomPoints(rng, 2500, 0.1));
  auto flat = RandomPoints(rng, 1500, 0.05);
  for (auto& p : flat) p.z() = 0;
  clouds.push_back(flat);
  auto dup = RandomPoints(rng, 200, 0.03);
  const auto copy = dup;
  for (int r = 0; r < 4; ++r) dup.insert(dup.end(), copy.begin(), copy.end());
  clouds.push_back(dup);
  clouds.push_back(RandomPoints(rng, 1, 0.05));
  clouds.push_back(RandomPoints(rng, 9, 0.05));
  for (std::size_t c = 0; c < clouds.size(); ++c) {
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::Isometry3d T_gt = RandomPose(rng, std::numbers::pi, 0.2);
      // Small to large perturbations: near-exact matches and far-away estimates.
      const double scale = trial == 0 ? 0.002 : trial == 1 ? 0.03 : 0.5;
      Eigen::Isometry3d T_est = T_gt;
      const double dz = rng.Uniform(-scale, scale), dy = rng.Uniform(-scale, scale), dx = rng.Uniform(-scale, scale);
      T_est.translation() += Eigen::Vector3d(dx, dy, dz);
      const double az = rng.Normal(), ay = rng.Normal(), ax = rng.Normal();
      T_est.linear() = T_est.linear() * Eigen::AngleAxisd(scale * 3, Eigen::Vector3d(ax, ay, az).normalized()).toRotationMatrix();
      const double fast = AddSError(clouds[c], T_est, T_gt);
      const double ref = BruteForceAddS(clouds[c], T_est, T_gt);
      EXPECT_NEAR(fast, ref, 1e-12 * std::max(1.0, ref)) << "cloud " << c << " trial " << trial;
    }
  }
}

TEST(AddSError, TenThousandPoints) {
  // A large cloud (the timing of this case is bench/metrics_bench.cc's BM_AddSError).
  Rng rng(5);
  const auto pts = RandomPoints(rng, 10000, 0.1);
  const Eigen::Isometry3d T_gt = RandomPose(rng, std::numbers::pi, 0.2);
  const Eigen::Isometry3d T_est = RandomPose(rng, std::numbers::pi, 0.2);
  const double adds = AddSError(pts, T_est, T_gt);
  EXPECT_GT(adds, 0.0);
  EXPECT_LE(adds, AddError(pts, T_est, T_gt));
}

TEST(RotationErrorDeg, KnownRotations) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_NEAR(RotationErrorDeg(I, I), 0.0, 1e-12);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -1.0, 0.5).normalized();
  const Eigen::Matrix3d base = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  for (double deg : {1e-5, 0.5, 30.0, 90.0, 179.0, 180.0}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(deg * kDeg, axis).toRotationMatrix();
    EXPECT_NEAR(RotationErrorDeg(base * R, base), deg, 1e-9) << deg;  // right-multiplied
    EXPECT_NEAR(RotationErrorDeg(R * base, base), deg, 1e-9) << deg;  // left-multiplied
    EXPECT_NEAR(RotationErrorDeg(base, base * R), deg, 1e-9) << deg;  // symmetric
  }
  // Rx(30°) then Rx(−20°): 50° apart.
  EXPECT_NEAR(RotationErrorDeg(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                               Eigen::AngleAxisd(-20 * kDeg, Eigen::Vector3d::UnitX()).toRotationMatrix()),
              50.0, 1e-9);
}

TEST(TranslationError, EuclideanDistance) {
  EXPECT_DOUBLE_EQ(TranslationError(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 6, 3)), 5.0);
  EXPECT_DOUBLE_EQ(TranslationError(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3)), 0.0);
}

TEST(ComputePoseErrors, ThresholdIsFractionOfDiameter) {
  Rng rng(6);
  const auto pts = RandomPoints(rng, 200, 0.05);
  const Eigen::Isometry3d T_gt = RandomPose(rng, std::numbers::pi, 0.1);
  const double diameter = 0.2;  // limit at 10 %: 20 mm
  const auto shifted = [&](double d) { return Eigen::Isometry3d(Eigen::Translation3d(d, 0, 0) * T_gt); };

  const PoseErrors near = ComputePoseErrors(pts, diameter, shifted(0.019), T_gt);
  EXPECT_NEAR(near.add, 0.019, 1e-12);
  EXPECT_NEAR(near.trans_m, 0.019, 1e-12);
  EXPECT_NEAR(near.rot_deg, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(near.diameter, diameter);
  EXPECT_LE(near.adds, near.add);
  EXPECT_TRUE(near.add_ok);
  EXPECT_TRUE(near.adds_ok);

  const PoseErrors far = ComputePoseErrors(pts, diameter, shifted(0.021), T_gt);
  EXPECT_FALSE(far.add_ok);
  EXPECT_NEAR(far.add, 0.021, 1e-12);

  // A tighter threshold rejects the same 19 mm estimate; a looser one accepts the 21 mm one.
  EXPECT_FALSE(ComputePoseErrors(pts, diameter, shifted(0.019), T_gt, 0.05).add_ok);
  EXPECT_TRUE(ComputePoseErrors(pts, diameter, shifted(0.021), T_gt, 0.2).add_ok);

  // ADD-S accepts what ADD rejects for a symmetric ambiguity: the cube corners, quarter turn.
  std::vector<Eigen::Vector3f> corners;
  for (int s = 0; s < 8; ++s) corners.emplace_back(s & 1 ? 0.05f : -0.05f, s & 2 ? 0.05f : -0.05f, s & 4 ? 0.05f : -0.05f);
  Eigen::Isometry3d T_rot = T_gt;
  T_rot.linear() = T_gt.linear() * Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const PoseErrors sym = ComputePoseErrors(corners, 0.1 * std::sqrt(3.0), T_rot, T_gt);
  EXPECT_FALSE(sym.add_ok);
  EXPECT_TRUE(sym.adds_ok);
  EXPECT_NEAR(sym.rot_deg, 90.0, 1e-9);
  EXPECT_NEAR(sym.trans_m, 0.0, 1e-12);
}

TEST(ComputePoseErrors, RejectsBadArguments) {
  Rng rng(7);
  const auto pts = RandomPoints(rng, 10, 0.05);
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ExpectError([&] { ComputePoseErrors(pts, 0.0, T, T); }, {"diameter"});
  ExpectError([&] { ComputePoseErrors(pts, -1.0, T, T); }, {"diameter"});
  ExpectError([&] { ComputePoseErrors(pts, nan, T, T); }, {"diameter"});
  ExpectError([&] { ComputePoseErrors(pts, 0.1, T, T, 0.0); }, {"threshold"});
  ExpectError([&] { ComputePoseErrors(pts, 0.1, T, T, -0.1); }, {"threshold"});
  ExpectError([&] { ComputePoseErrors(pts, 0.1, T, T, nan); }, {"threshold"});
  Eigen::Isometry3d bad = T;
  bad.translation().x() = nan;
  ExpectError([&] { ComputePoseErrors(pts, 0.1, bad, T); }, {"estimated"});
  ExpectError([&] { ComputePoseErrors(pts, 0.1, T, bad); }, {"ground-truth"});
  ExpectError([&] { ComputePoseErrors({}, 0.1, T, T); }, {"empty"});
}

TEST(SamplePoints, EvenStrideOverVertices) {
  Mesh mesh;
  mesh.name = "ten";
  for (int i = 0; i < 10; ++i) mesh.vertices.emplace_back(static_cast<float>(i), 0.f, 0.f);
  mesh.faces.push_back({0, 1, 2});

  const auto all = SamplePoints(mesh, 20);
  ASSERT_EQ(all.size(), 10u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(all[i].x(), static_cast<float>(i));
  EXPECT_EQ(SamplePoints(mesh, 10).size(), 10u);

  const auto half = SamplePoints(mesh, 5);  // stride 2
  ASSERT_EQ(half.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(half[i].x(), static_cast<float>(2 * i));

  const auto three = SamplePoints(mesh, 3);  // stride ⌈10/3⌉ = 4 → 0, 4, 8
  ASSERT_EQ(three.size(), 3u);
  EXPECT_EQ(three[0].x(), 0.f);
  EXPECT_EQ(three[1].x(), 4.f);
  EXPECT_EQ(three[2].x(), 8.f);

  const auto one = SamplePoints(mesh, 1);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].x(), 0.f);

  // Deterministic and the default cap holds on a large mesh.
  Mesh big;
  big.name = "big";
  for (int i = 0; i < 4999; ++i) big.vertices.emplace_back(static_cast<float>(i), 1.f, 2.f);
  const auto a = SamplePoints(big);
  EXPECT_LE(a.size(), 2000u);
  EXPECT_GE(a.size(), 1000u);
  EXPECT_EQ(a, SamplePoints(big));
}

TEST(SamplePoints, RejectsEmptyMeshAndBadCap) {
  Mesh empty;
  empty.name = "hollow_thing";
  ExpectError([&] { SamplePoints(empty); }, {"hollow_thing"});
  Mesh one;
  one.name = "one";
  one.vertices.emplace_back(0.f, 0.f, 0.f);
  ExpectError([&] { SamplePoints(one, 0); }, {"max_points"});
  ExpectError([&] { SamplePoints(one, -5); }, {"max_points"});
}

TEST(ReadXyzPoints, ReadsValidFile) {
  const ScratchDir dir("metrics");
  const std::string path =
      dir.Write("ok.xyz", "0.1 0.2 0.3\n\n  -1e-3\t2.5e-2 -0.000001\r\n4 5 6");  // blank, CRLF, no final \n
  const auto pts = ReadXyzPoints(path);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_FLOAT_EQ(pts[0].x(), 0.1f);
  EXPECT_FLOAT_EQ(pts[0].z(), 0.3f);
  EXPECT_FLOAT_EQ(pts[1].x(), -1e-3f);
  EXPECT_FLOAT_EQ(pts[1].y(), 2.5e-2f);
  EXPECT_FLOAT_EQ(pts[1].z(), -1e-6f);
  EXPECT_FLOAT_EQ(pts[2].y(), 5.f);
}

TEST(ReadXyzPoints, BadInputNamesFileAndLine) {
  const ScratchDir dir("metrics");
  struct Case {
    const char* name;
    const char* text;
    const char* where;  // expected "<file>:<line>" suffix in the message
  };
  const Case cases[] = {
      {"garbage.xyz", "0 0 0\n1 two 3\n", ":2:"},
      {"nan.xyz", "0 0 0\n0 0 0\nnan 0 0\n", ":3:"},
      {"inf.xyz", "inf 0 0\n", ":1:"},
      {"overflow.xyz", "1e300 0 0\n", ":1:"},
      {"two_fields.xyz", "0 0 0\n\n1 2\n", ":3:"},
      {"four_fields.xyz", "1 2 3 4\n", ":1:"},
      {"suffix.xyz", "1 2 3m\n", ":1:"},
      {"comma.xyz", "1,2,3\n", ":1:"},
  };
  for (const auto& c : cases) {
    const std::string path = dir.Write(c.name, c.text);
    ExpectError([&] { ReadXyzPoints(path); }, {path + c.where});
  }
  const std::string empty = dir.Write("empty.xyz", "");
  ExpectError([&] { ReadXyzPoints(empty); }, {empty, "no points"});
  const std::string blank = dir.Write("blank.xyz", "\n  \n\t\n");
  ExpectError([&] { ReadXyzPoints(blank); }, {blank, "no points"});
  const std::string missing = dir.Path("does_not_exist.xyz");
  ExpectError([&] { ReadXyzPoints(missing); }, {missing});
}

TEST(ReadXyzPoints, OfficialYcbvPointSets) {
  const fs::path dir = testing_util::YcbvDataDir() / "models" / "points";
  if (!fs::exists(dir)) GTEST_SKIP() << dir << " not present";
  const auto pts = ReadXyzPoints((dir / "002_master_chef_can.xyz").string());
  EXPECT_EQ(pts.size(), 2620u);  // the dataset's official count (data/ycbv/README.md)
  Eigen::Vector3f mn = pts[0], mx = pts[0];
  for (const auto& p : pts) {
    mn = mn.cwiseMin(p);
    mx = mx.cwiseMax(p);
  }
  // Metres: the can is ~10 cm wide and ~14 cm tall, centred near the origin.
  EXPECT_GT((mx - mn).maxCoeff(), 0.08f);
  EXPECT_LT((mx - mn).maxCoeff(), 0.25f);
  // ADD-S of the identity pose vs itself and a translated copy on a real model.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0, 0, 0.8);
  Eigen::Isometry3d T2 = Eigen::Translation3d(0.01, 0, 0) * T;
  EXPECT_NEAR(AddSError(pts, T, T), 0.0, 1e-12);
  EXPECT_NEAR(AddSError(pts, T2, T), BruteForceAddS(pts, T2, T), 1e-12);
}

}  // namespace
}  // namespace posefilter
