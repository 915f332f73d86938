// Point-pair-feature voting (posefilter/ppf.h): known poses recovered on clean renderings, the
// model cache reused and never trusted when damaged, stale or made otherwise, and bad inputs.
#include "posefilter/ppf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "posefilter/auto_prior.h"
#include "posefilter/metrics.h"
#include "posefilter/render.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::FreshTempPath;

Camera TestCamera() { return testing_util::PinholeCamera(540, 540, 320, 240); }

// `mesh` rendered alone at T (camera frame) on an empty background.
DepthImage Render(const Mesh& mesh, const Eigen::Isometry3d& T) {
  const Camera cam = TestCamera();
  DepthImage depth(cam.width, cam.height);
  RenderDepth(mesh, T, cam, &depth);
  return depth;
}

std::vector<std::uint8_t> ValidPixels(const DepthImage& d) {
  std::vector<std::uint8_t> m(d.data.size());
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = d.data[i] > 0;
  return m;
}

Eigen::Isometry3d PoseAt(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// A box with a smaller block on one corner of its top: no symmetry at all.
Mesh Asymmetric() {
  Mesh m = MakeBox(0.12, 0.08, 0.05, "asymmetric");
  const Mesh block = MakeBox(0.04, 0.03, 0.03);
  const auto base = std::uint32_t(m.vertices.size());
  for (const Eigen::Vector3f& v : block.vertices) m.vertices.push_back(v + Eigen::Vector3f(0.035f, 0.02f, 0.04f));
  for (const auto& f : block.faces) m.faces.push_back({f[0] + base, f[1] + base, f[2] + base});
  return m;
}

// The best of the proposals by ADD-S (symmetric) or ADD, as a fraction of the diameter.
double BestError(const Mesh& mesh, const std::vector<PoseProposal>& proposals, const Eigen::Isometry3d& T_gt,
                 bool symmetric) {
  const std::vector<Eigen::Vector3f> pts = SamplePoints(mesh, 500);
  double best = 1e9;
  for (const PoseProposal& p : proposals) {
    const PoseErrors e = ComputePoseErrors(pts, mesh.Diameter(), p.T_cam_obj, T_gt);
    best = std::min(best, (symmetric ? e.adds : e.add) / mesh.Diameter());
  }
  return best;
}

// Clean renderings: one of the proposals lies on the true pose within 10 % of the diameter, by
// ADD-S for the box (its symmetries make several rotations right), by ADD (every point where
// it belongs) for the mesh without symmetry. The first need not: a face votes for every pose
// that lays a face of its size on it (the box turned 90°, the block turned to the hidden
// side), and only the filter's weight, which renders each pose against the depth, tells
// them apart.
TEST(PpfTest, VotingRecoversAKnownPoseOfABoxAndOfAnAsymmetricMesh) {
  struct Case {
    Mesh mesh;
    bool symmetric;
  };
  const Case cases[] = {{MakeBox(0.12, 0.08, 0.05), true}, {Asymmetric(), false}};
  const Eigen::Isometry3d poses[] = {PoseAt(0.02, -0.01, 0.55, 0.4, -0.3, 0.9), PoseAt(-0.05, 0.03, 0.65, 2.1, 0.5, -1.2)};
  // The filter gets the 4 best of each region and verifies them; here 8, since votes favour
  // the poses that turn the block away (the box's faces vote for all of them).
  PpfOptions opt;
  opt.max_proposals = 8;
  opt.min_relative_votes = 0.1;
  for (const Case& c : cases) {
    const PpfModel model = BuildPpfModel(c.mesh);
    ASSERT_GT(model.points.size(), 50u) << c.mesh.name;
    for (const Eigen::Isometry3d& T : poses) {
      const DepthImage depth = Render(c.mesh, T);
      const std::vector<OrientedPoint> scene = PpfScenePoints(depth, TestCamera(), ValidPixels(depth), model.step);
      ASSERT_GT(scene.size(), 20u) << c.mesh.name;
      const std::vector<PoseProposal> proposals = MatchPpf(model, scene, opt);
      ASSERT_FALSE(proposals.empty()) << c.mesh.name;
      for (std::size_t k = 1; k < proposals.size(); ++k) EXPECT_GE(proposals[k - 1].votes, proposals[k].votes);
      EXPECT_LE(proposals.size(), std::size_t(opt.max_proposals));
      EXPECT_LT(BestError(c.mesh, proposals, T, c.symmetric), 0.1) << c.mesh.name;
    }
  }
}

// Scene points from the image's normals computed once (ComputeSceneNormals) are those the
// mask alone gives (normals of its bounding rectangle); normals of another size are an error.
TEST(PpfTest, ScenePointsFromPrecomputedNormalsAreTheSame) {
  const Mesh mesh = Asymmetric();
  const DepthImage depth = Render(mesh, PoseAt(0.01, 0.02, 0.6, 0.5, 0.3, -0.4));
  const std::vector<std::uint8_t> mask = ValidPixels(depth);
  const std::vector<OrientedPoint> a = PpfScenePoints(depth, TestCamera(), mask, 0.008);
  const std::vector<OrientedPoint> b =
      PpfScenePoints(depth, TestCamera(), ComputeSceneNormals(depth, TestCamera()), mask, 0.008);
  ASSERT_GT(a.size(), 20u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].p, b[k].p);
    EXPECT_EQ(a[k].n, b[k].n);
  }
  testing_util::ExpectError([&] { PpfScenePoints(depth, TestCamera(), std::vector<float>(10), mask, 0.008); },
                            {"normals", "size"});
}

// The voting does not depend on the number of workers.
TEST(PpfTest, ProposalsDoNotDependOnThreads) {
  const Mesh mesh = MakeLShape(0.12, 0.03, 0.05);
  const PpfModel model = BuildPpfModel(mesh);
  const DepthImage depth = Render(mesh, PoseAt(0.0, 0.0, 0.6, 0.3, 0.2, 0.1));
  const auto scene = PpfScenePoints(depth, TestCamera(), ValidPixels(depth), model.step);
  PpfOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const auto a = MatchPpf(model, scene, one), b = MatchPpf(model, scene, two);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].votes, b[k].votes);
    EXPECT_TRUE(a[k].T_cam_obj.isApprox(b[k].T_cam_obj));
  }
}

// The cache: built and written once, loaded the next time with the same table; a damaged,
// cut, foreign or other-options file is rebuilt (and rewritten), never trusted.
TEST(PpfTest, TheCacheIsReusedAndABadFileIsRebuilt) {
  const fs::path dir = FreshTempPath("ppf_cache");
  const Mesh mesh = MakeBox(0.1, 0.06, 0.04);
  // A coarse model (a tenth of the diameter per voxel): the cache does not depend on its size.
  PpfOptions base;
  base.distance_step = 0.1;
  std::string status;
  const PpfModel built = LoadOrBuildPpfModel(mesh, base, dir.string(), &status);
  EXPECT_EQ(status, "built");
  const fs::path file = PpfCachePath(mesh, base, dir.string());
  ASSERT_TRUE(fs::exists(file));
  const PpfModel loaded = LoadOrBuildPpfModel(mesh, base, dir.string(), &status);
  EXPECT_EQ(status, "loaded");
  ASSERT_EQ(loaded.points.size(), built.points.size());
  ASSERT_EQ(loaded.entries.size(), built.entries.size());
  EXPECT_EQ(loaded.offsets, built.offsets);
  for (std::size_t k = 0; k < built.entries.size(); k += 97) {
    EXPECT_EQ(loaded.entries[k].reference, built.entries[k].reference);
    EXPECT_EQ(loaded.entries[k].alpha, built.entries[k].alpha);
  }
  const std::string good = testing_util::ReadFile(file);

  auto expect_rebuilt = [&](const std::string& bytes, const std::string& why) {
    testing_util::WriteFile(file, bytes);
    const PpfModel m = LoadOrBuildPpfModel(mesh, base, dir.string(), &status);
    EXPECT_NE(status.find("rebuilt"), std::string::npos) << why << ": " << status;
    EXPECT_NE(status.find(why), std::string::npos) << status;
    EXPECT_EQ(m.entries.size(), built.entries.size());
    EXPECT_EQ(testing_util::ReadFile(file), good) << "the rebuilt model is written back";
  };
  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x5a;
  expect_rebuilt(flipped, "checksum");
  expect_rebuilt(good.substr(0, good.size() / 3), "checksum");
  expect_rebuilt("", "not a posefilter PPF cache file");

  // A file of another mesh under this mesh's name (a stale cache after an edit in place).
  const Mesh other = MakeBox(0.1, 0.06, 0.05);
  LoadOrBuildPpfModel(other, base, dir.string(), &status);
  expect_rebuilt(testing_util::ReadFile(PpfCachePath(other, base, dir.string())), "another mesh");

  // Other options give another file; a file of other options under this name is rebuilt.
  PpfOptions coarse = base;
  coarse.angle_bins = 10;
  EXPECT_NE(PpfCachePath(mesh, coarse, dir.string()), file.string());
  LoadOrBuildPpfModel(mesh, coarse, dir.string(), &status);
  EXPECT_EQ(status, "built");
  expect_rebuilt(testing_util::ReadFile(PpfCachePath(mesh, coarse, dir.string())), "other options");
  fs::remove_all(dir);
}

// A cache folder that cannot be made is no error: the model is built and the status says so.
TEST(PpfTest, AnUnwritableCacheStillGivesTheModel) {
  const fs::path dir = FreshTempPath("ppf_cache_file");
  testing_util::WriteFile(dir, "a file where the folder should be");
  std::string status;
  const PpfModel m = LoadOrBuildPpfModel(MakeBox(0.1, 0.06, 0.04), {}, (dir / "sub").string(), &status);
  EXPECT_FALSE(m.entries.empty());
  EXPECT_NE(status.find("cache not written"), std::string::npos) << status;
  fs::remove(dir);
}

// A changed mesh gets another content hash; the same mesh the same one.
TEST(PpfTest, TheContentHashFollowsTheMesh) {
  Mesh a = MakeBox(0.1, 0.06, 0.04), b = a;
  EXPECT_EQ(MeshContentHash(a), MeshContentHash(b));
  b.name = "renamed";
  EXPECT_EQ(MeshContentHash(a), MeshContentHash(b));
  b.vertices[3].x() += 1e-6f;
  EXPECT_NE(MeshContentHash(a), MeshContentHash(b));
}

// Bad inputs are errors naming what is wrong; too few scene points give no proposal.
TEST(PpfTest, BadInputsAreErrors) {
  PpfOptions bad;
  bad.angle_bins = 2;
  testing_util::ExpectError([&] { BuildPpfModel(MakeBox(0.1, 0.1, 0.1), bad); }, {"angle_bins"});
  Mesh broken = MakeBox(0.1, 0.1, 0.1);
  broken.faces[0][0] = 999;
  testing_util::ExpectError([&] { BuildPpfModel(broken); }, {"ppf", "mesh"});
  const DepthImage depth(640, 480);
  testing_util::ExpectError([&] { PpfScenePoints(depth, TestCamera(), std::vector<std::uint8_t>(10), 0.01); },
                            {"mask", "size"});
  const PpfModel model = BuildPpfModel(MakeBox(0.1, 0.1, 0.1));
  EXPECT_TRUE(MatchPpf(model, {}).empty());
}

// The auto stage 1 with PPF: the object's seeds include its pose, and its detections a box
// on it; without a model (regions only) there are no seeds.
TEST(PpfTest, TheAutoStageProposesTheObjectsPose) {
  SynthOptions so;
  so.target = "lshape";
  so.clutter = 0;
  const SynthScene sc = MakeSynthScene(so, 7);
  const PpfModel model = BuildPpfModel(sc.target);
  const AutoProposals with = ProposeAuto(sc.depth, sc.camera, {{sc.target.name, sc.target.Diameter(), &model}});
  ASSERT_EQ(with.seeds.size(), 1u);
  ASSERT_FALSE(with.seeds[0].empty());
  std::vector<PoseProposal> as_proposals;
  for (const PoseSeed& s : with.seeds[0]) as_proposals.push_back({s.T_cam_obj, s.score});
  EXPECT_LT(BestError(sc.target, as_proposals, sc.gt[0].T_cam_obj, true), 0.1);
  const AutoProposals without = ProposeAuto(sc.depth, sc.camera, {{sc.target.name, sc.target.Diameter(), nullptr}});
  EXPECT_TRUE(without.seeds[0].empty());
  EXPECT_GT(with.detections.size(), without.detections.size());
}

}  // namespace
}  // namespace posefilter
