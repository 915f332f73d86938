// The particle filter end to end on synthetic scenes: option checks, scene checks,
// determinism per seed, and recovery of a pose.
#include <gtest/gtest.h>

#include <cmath>
#include <exception>
#include <thread>

#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/metrics.h"
#include "posefilter/synth.h"
#include "filter/driver.h"
#include "filter/easy_case.h"
#include "test_util.h"

namespace posefilter {
namespace {

TEST(FilterOptionsTest, IsValidNamesTheViolatedConstraint) {
  FilterOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  auto expect_bad = [](const FilterOptions& bad, const std::string& needle) {
    std::string w;
    EXPECT_FALSE(bad.IsValid(&w));
    EXPECT_NE(w.find(needle), std::string::npos) << w;
  };
  FilterOptions b = o;
  b.score.alpha = 0.5;  // α + β + γ ≠ 1
  expect_bad(b, "score.alpha + score.beta + score.gamma must equal 1");
  b = o;
  b.num_particles = 1;
  expect_bad(b, "num_particles");
  b = o;
  b.stop.confidence = 0;
  expect_bad(b, "confidence");
  b = o;
  b.num_elite = b.num_particles;
  expect_bad(b, "num_elite");
  b = o;
  b.diffusion.sigma_t0_m = std::nan("");
  expect_bad(b, "sigma_t0_m");
  b = o;
  b.diffusion.move_probabilities.fill(0);
  expect_bad(b, "diffusion.move_probabilities");
  b = o;
  b.engine = "vulkan";
  expect_bad(b, "engine");
  b = o;
  b.cpu_isa = "avx9";
  expect_bad(b, "cpu_isa");
  for (const char* isa : {"auto", "portable"}) {  // every build and x86-64 CPU runs these
    b = o;
    b.cpu_isa = isa;
    EXPECT_TRUE(b.IsValid(nullptr)) << isa;
  }
  b = o;
  b.score.inlier.thr1_m = -1;
  expect_bad(b, "score.inlier.thr1_m");
  b = o;
  b.stop.stall_iterations = -1;
  expect_bad(b, "stop.stall_iterations");
  b = o;
  b.stop.stall_gain = std::nan("");
  expect_bad(b, "stop.stall_gain");
  for (int f : {0, 5, -2}) {
    b = o;
    b.anneal.subsample = f;
    expect_bad(b, "anneal.subsample");
  }
  for (double f : {0.0, 1.5, std::nan("")}) {
    b = o;
    b.fine_particle_fraction = f;
    expect_bad(b, "fine_particle_fraction");
  }
  b = o;
  b.num_particles = 12;  // valid with any fraction: the fine set keeps one more than the elite
  b.fine_particle_fraction = 0.1;
  EXPECT_TRUE(b.IsValid(nullptr));
  EXPECT_EQ(filter::FineParticles(b), 11);
  b.num_particles = 510;
  b.fine_particle_fraction = 2.0 / 3.0;
  EXPECT_EQ(filter::FineParticles(b), 340);
  b.fine_particle_fraction = 1;
  EXPECT_EQ(filter::FineParticles(b), 510);
}

// Pixel (i, j) of the coarse scene is pixel (f·i, f·j) of the full one, and a camera-frame
// point projects to 1/f of its full-resolution pixel coordinates.
TEST(SubsampleSceneTest, KeepsEveryFthPixelAndScalesTheCamera) {
  Camera cam;
  cam.width = 641;
  cam.height = 481;
  cam.cx = 321.7;
  cam.cy = 230.2;
  SceneInput full{DepthImage(cam.width, cam.height), cam};
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) full.depth.at(u, v) = 0.5f + 0.001f * float(u) + 1e-6f * float(v);
  for (int f : {1, 2, 3, 4}) {
    const SceneInput c = SubsampleScene(full, f);
    const int w = (641 + f - 1) / f, h = (481 + f - 1) / f;
    ASSERT_EQ(c.camera.width, w) << f;
    ASSERT_EQ(c.camera.height, h) << f;
    ASSERT_EQ(c.depth.width, w) << f;
    ASSERT_EQ(c.depth.height, h) << f;
    for (int j = 0; j < h; j += 7)
      for (int i = 0; i < w; i += 5) ASSERT_EQ(c.depth.at(i, j), full.depth.at(f * i, f * j)) << f << " " << i << " " << j;
    EXPECT_EQ(c.depth.at(w - 1, h - 1), full.depth.at(f * (w - 1), f * (h - 1))) << f;
    const Eigen::Vector3d p(0.13, -0.07, 0.8);
    EXPECT_TRUE((cam.Project(p) / f).isApprox(c.camera.Project(p), 1e-12)) << f;
    EXPECT_TRUE(c.camera.base_to_camera.isApprox(cam.base_to_camera)) << f;
    std::string why;
    EXPECT_TRUE(c.camera.IsValid(&why)) << why;
  }
  EXPECT_THROW(SubsampleScene(full, 0), Error);
}

TEST(RunEndsTest, StopsOnConfidenceOnAStallAtTheFinalThresholdOrAfterTheLastIteration) {
  FilterOptions o;
  o.stop.max_iterations = 17;
  o.stop.confidence = 0.9;
  o.stop.stall_iterations = 3;
  o.stop.stall_gain = 0.01;
  const int anneal = 8;
  // Flat while annealing (the threshold still changes there: no stall), then slowing gains.
  const std::vector<double> h = {0.1, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.5, 0.52, 0.522, 0.529, 0.529};
  bool converged = false;
  for (int it = 0; it <= 10; ++it) EXPECT_FALSE(filter::RunEnds(o, it, anneal, h, &converged)) << it;
  EXPECT_FALSE(filter::RunEnds(o, 11, anneal, h, &converged));  // 0.529 − 0.5 ≥ 0.01
  EXPECT_TRUE(filter::RunEnds(o, 12, anneal, h, &converged));   // 0.529 − 0.52 < 0.01
  EXPECT_FALSE(converged);
  o.stop.stall_iterations = 0;  // off: only confidence or the last iteration end a run
  EXPECT_FALSE(filter::RunEnds(o, 12, anneal, h, &converged));
  const std::vector<double> flat(17, 0.4);
  EXPECT_FALSE(filter::RunEnds(o, 15, anneal, flat, &converged));
  EXPECT_TRUE(filter::RunEnds(o, 16, anneal, flat, &converged));
  EXPECT_FALSE(converged);
  std::vector<double> high = flat;
  high[5] = 0.95;  // while annealing: not a convergence
  EXPECT_FALSE(filter::RunEnds(o, 5, anneal, high, &converged));
  EXPECT_FALSE(converged);
  high[9] = 0.95;
  EXPECT_TRUE(filter::RunEnds(o, 9, anneal, high, &converged));
  EXPECT_TRUE(converged);
}

// Runs whose k-th result has origin x = xs[k] (metres) and weight weights[k], 10 iterations each.
filter::RunFn ScriptedRuns(const std::vector<double>& xs, const std::vector<double>& weights, int* calls) {
  return [xs, weights, calls](Rng&, const ProgressFn&) {
    EstimateResult r;
    r.pose_base.x = xs[std::size_t(*calls)];
    r.weight = weights[std::size_t(*calls)];
    r.iterations = 10;
    ++*calls;
    return r;
  };
}

TEST(RunRestartsTest, TheRestAreSkippedWhereTheFirstTwoRunsAgree) {
  FilterOptions o;
  o.restarts = 4;
  o.stop.restart_agree_m = 0.01;
  o.stop.restart_agree_weight = 0.02;
  // Agreeing: 5 mm and 0.01 apart. The third and fourth runs (which would win) never run.
  int calls = 0;
  EstimateResult r = filter::RunRestarts(o, nullptr, ScriptedRuns({0.100, 0.105, 0.3, 0.4}, {0.60, 0.61, 0.9, 0.9}, &calls));
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(r.iterations, 20);
  EXPECT_EQ(r.weight, 0.61);
  // 2 cm apart, or weights 0.05 apart: every run.
  const std::vector<std::pair<std::vector<double>, std::vector<double>>> apart = {
      {{0.1, 0.12, 0.3, 0.4}, {0.6, 0.61, 0.7, 0.5}}, {{0.1, 0.105, 0.3, 0.4}, {0.6, 0.65, 0.7, 0.5}}};
  for (const auto& [xs, ws] : apart) {
    calls = 0;
    r = filter::RunRestarts(o, nullptr, ScriptedRuns(xs, ws, &calls));
    EXPECT_EQ(calls, 4);
    EXPECT_EQ(r.iterations, 40);
    EXPECT_EQ(r.weight, 0.7);
    EXPECT_EQ(r.pose_base.x, 0.3);
  }
  // Off (0 m): every run, agreeing or not; and the third run is never compared.
  o.stop.restart_agree_m = 0;
  calls = 0;
  filter::RunRestarts(o, nullptr, ScriptedRuns({0.1, 0.1, 0.1, 0.1}, {0.6, 0.6, 0.6, 0.6}, &calls));
  EXPECT_EQ(calls, 4);
  o.stop.restart_agree_m = 0.01;
  calls = 0;
  filter::RunRestarts(o, nullptr, ScriptedRuns({0.1, 0.3, 0.3, 0.3}, {0.6, 0.6, 0.6, 0.6}, &calls));
  EXPECT_EQ(calls, 4);
}

TEST(ValidateSceneTest, RejectsSizeMismatchNanAndEmptyDepth) {
  SceneInput s{DepthImage(640, 480, 1.0f), Camera{}};
  EXPECT_NO_THROW(ValidateScene(s, "d.png"));
  SceneInput small{DepthImage(320, 240, 1.0f), Camera{}};
  try {
    ValidateScene(small, "d.png");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("320x240"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("d.png"), std::string::npos);
  }
  SceneInput nan = s;
  nan.depth.at(3, 4) = std::nanf("");
  EXPECT_THROW(ValidateScene(nan, "d.png"), Error);
  SceneInput zero{DepthImage(640, 480, 0.0f), Camera{}};
  EXPECT_THROW(ValidateScene(zero, "d.png"), Error);
}

TEST(ParticleFilterTest, SameSeedSamePoseDifferentSeedDifferentRun) {
  const EasyCase box("box", 3);
  FilterOptions o = EasyCase::Small(6);
  o.seed = 5;
  const EstimateResult a = box.Run(o);
  o.threads = 1;  // thread count must not change anything
  const EstimateResult b = box.Run(o);
  EXPECT_EQ(a.weight, b.weight);
  EXPECT_TRUE(a.T_cam_obj.isApprox(b.T_cam_obj, 0.0));
  EXPECT_EQ(a.best_weight_history, b.best_weight_history);
  o.seed = 6;
  const EstimateResult c = box.Run(o);
  EXPECT_NE(a.best_weight_history, c.best_weight_history);
  EXPECT_EQ(a.iterations, 6);
  EXPECT_EQ(int(a.best_weight_history.size()), 6);
  // Elitism: from the first iteration at the final inlier threshold on (iteration
  // anneal = 3 of 6; the weights before it are measured at other thresholds and on the
  // coarse grid, so they are not comparable and may be higher), the best particle is carried
  // unchanged with its weight, so the best weight of each iteration is at least the one
  // before. Checked for both seeds (one run each: restarts = 1).
  const int anneal = filter::AnnealIterations(o);
  ASSERT_EQ(anneal, 3);
  for (const EstimateResult* r : {&a, &c}) {
    for (int it = anneal + 1; it < int(r->best_weight_history.size()); ++it)
      EXPECT_GE(r->best_weight_history[it], r->best_weight_history[it - 1]) << "iteration " << it;
  }
}

// Pose seeds: with a uniform prior and a budget far too small to search the image, a seed
// at the true pose leads the filter to it; seed_start 0 (or no seed) gives exactly the
// unseeded run; a seed that is not finite is an error naming it.
TEST(ParticleFilterTest, PoseSeedsStartParticlesAtThem) {
  const EasyCase box("lshape", 4);
  const Prior uniform = UniformPrior(box.prior.layout, box.prior.classes);
  FilterOptions o = EasyCase::Small(4);
  const std::vector<Eigen::Vector3f> pts = SamplePoints(box.sc.target, 500);
  const double D = box.sc.target.Diameter();
  const Eigen::Isometry3d& T_gt = box.sc.gt[0].T_cam_obj;
  SceneInput seeded = box.in;
  // A decoy first, scored lower: seeds are drawn by score, and the filter weighs them.
  Eigen::Isometry3d decoy = T_gt;
  decoy.translation().x() += 0.3;
  seeded.seeds = {{decoy, 0.5}, {T_gt, 1.0}};
  const EstimateResult with = EstimatePose(seeded, box.sc.target, uniform, box.cls, o);
  EXPECT_LT(ComputePoseErrors(pts, D, with.T_cam_obj, T_gt).adds, 0.1 * D);
  const EstimateResult without = EstimatePose(box.in, box.sc.target, uniform, box.cls, o);
  EXPECT_GT(with.weight, without.weight);
  o.seed_start = 0;
  const EstimateResult off = EstimatePose(seeded, box.sc.target, uniform, box.cls, o);
  const EstimateResult none = EstimatePose(box.in, box.sc.target, uniform, box.cls, o);
  EXPECT_TRUE(off.T_cam_obj.isApprox(none.T_cam_obj, 0.0));
  EXPECT_EQ(off.best_weight_history, none.best_weight_history);
  SceneInput bad = box.in;
  Eigen::Isometry3d nan = T_gt;
  nan.translation().z() = std::nan("");
  bad.seeds = {{T_gt, 1.0}, {nan, 1.0}};
  testing_util::ExpectError([&] { EstimatePose(bad, box.sc.target, uniform, box.cls, o); }, {"pose seed 1"});
  bad.seeds = {{T_gt, 0.0}};
  testing_util::ExpectError([&] { EstimatePose(bad, box.sc.target, uniform, box.cls, o); }, {"pose seed 0", "score"});
}

// No global state: estimates running at once on the caller's threads (each with its own two
// workers), or inside the caller's OpenMP region (where, nested parallelism being off, each
// weighs on its calling thread alone), give exactly the results of one after the other.
TEST(ParticleFilterTest, ConcurrentEstimatesGiveTheSequentialResults) {
  const EasyCase box("box", 3), torus("torus", 4);
  FilterOptions o = EasyCase::Small(6);  // with the final polish (default)
  o.threads = 2;
  const EasyCase* cases[2] = {&box, &torus};
  EstimateResult seq[2];
  for (int i = 0; i < 2; ++i) seq[i] = cases[i]->Run(o);
  auto expect_same = [&](const EstimateResult (&r)[2], const char* how) {
    for (int i = 0; i < 2; ++i) {
      EXPECT_EQ(r[i].weight, seq[i].weight) << how << ", case " << i;
      EXPECT_TRUE(r[i].T_cam_obj.isApprox(seq[i].T_cam_obj, 0.0)) << how << ", case " << i;
      EXPECT_EQ(r[i].best_weight_history, seq[i].best_weight_history) << how << ", case " << i;
      EXPECT_EQ(r[i].stats.fragments, seq[i].stats.fragments) << how << ", case " << i;
    }
  };
  EstimateResult par[2];
  std::exception_ptr err[2];
  std::thread workers[2];
  for (int i = 0; i < 2; ++i)
    workers[i] = std::thread([&, i] {
      try {
        par[i] = cases[i]->Run(o);
      } catch (...) {
        err[i] = std::current_exception();
      }
    });
  for (auto& w : workers) w.join();
  for (const auto& e : err)
    if (e) std::rethrow_exception(e);
  expect_same(par, "two caller threads");
  EstimateResult omp[2];
#pragma omp parallel for num_threads(2) schedule(static, 1)
  for (int i = 0; i < 2; ++i) {
    try {
      omp[i] = cases[i]->Run(o);
    } catch (...) {
      err[i] = std::current_exception();
    }
  }
  for (const auto& e : err)
    if (e) std::rethrow_exception(e);
  expect_same(omp, "inside an OpenMP region");
}

// The default stall stop (3 iterations, gain < 0.01) ends a converged run long before 40
// iterations, at the first iteration the rule allows, the same way for the same seed.
TEST(ParticleFilterTest, AStalledRunEndsEarlyAndTheSameSeedStallsAlike) {
  const EasyCase box("box", 3);
  FilterOptions o = EasyCase::Small(40);
  o.polish.steps = 0;
  o.stop.confidence = 1;  // on this clean scene the weight can reach 0.9: only the stall rule ends the run
  const EstimateResult a = box.Run(o);
  const int anneal = filter::AnnealIterations(o), k = o.stop.stall_iterations;
  ASSERT_EQ(k, 3);
  ASSERT_LT(a.iterations, o.stop.max_iterations);
  ASSERT_EQ(int(a.best_weight_history.size()), a.iterations);
  const std::vector<double>& h = a.best_weight_history;
  const int last = a.iterations - 1;
  ASSERT_GE(last - k, anneal);
  EXPECT_LT(h[last] - h[last - k], o.stop.stall_gain);
  for (int it = anneal + k; it < last; ++it) EXPECT_GE(h[it] - h[it - k], o.stop.stall_gain) << it;  // not earlier
  EXPECT_FALSE(a.converged);
  EXPECT_EQ(box.Run(o).best_weight_history, h);
  o.stop.stall_iterations = 0;
  EXPECT_EQ(box.Run(o).iterations, o.stop.max_iterations);
}

// Coarse pixels while annealing (anneal_subsample): the annealing iterations weigh about a
// quarter of the fragments, every later weighing is at full resolution — the answer's weight
// is what WeighPoses gives its pose — and the same seed gives the same run.
TEST(ParticleFilterTest, CoarseAnnealingWeighsFewerPixelsAndAnswersAtFullResolution) {
  const EasyCase box("box", 3);
  FilterOptions o = EasyCase::Small(6);
  o.polish.steps = 0;
  o.stop.stall_iterations = 0;
  o.anneal.subsample = 1;
  const EstimateResult full = box.Run(o);
  o.anneal.subsample = 2;
  ASSERT_EQ(filter::AnnealIterations(o), 3);  // iterations 0–2 coarse, 3–5 full
  const EstimateResult coarse = box.Run(o);
  EXPECT_EQ(coarse.iterations, 6);
  // ≈ 3/6 · 1/4 + 3/6 · 1 = 0.625 of the fragments (the runs differ after the first weighing).
  EXPECT_LT(double(coarse.stats.fragments), 0.8 * double(full.stats.fragments));
  EXPECT_GT(double(coarse.stats.fragments), 0.45 * double(full.stats.fragments));
  // The last iteration's weights are full-resolution ones at the final threshold.
  const std::vector<double> w = WeighPoses(box.in, box.sc.target, box.prior, box.cls, o, {{coarse.pose_base, coarse.cell}});
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0], coarse.weight);
  EXPECT_EQ(coarse.best_weight_history.back(), coarse.weight);
  const EstimateResult again = box.Run(o);
  EXPECT_EQ(again.best_weight_history, coarse.best_weight_history);
  EXPECT_EQ(again.stats.fragments, coarse.stats.fragments);
  // A one-iteration run is never coarse: its only weighing is the answer.
  o.stop.max_iterations = 1;
  FilterOptions o1 = o;
  o1.anneal.subsample = 1;
  EXPECT_EQ(box.Run(o).stats.fragments, box.Run(o1).stats.fragments);
}

// fine_particle_fraction: once annealing is over each set has round(f·N) particles. Counted:
// every particle of an annealing iteration (the threshold changes each time), the whole fine
// set at the first final-threshold iteration, then its children (the 10 elite keep their weights).
TEST(ParticleFilterTest, FineSetsHaveTheFineFractionOfTheParticles) {
  const EasyCase box("box", 3);
  FilterOptions o = EasyCase::Countable(6);  // N = 64, 10 elite, iterations 0–2 annealing
  ASSERT_EQ(filter::AnnealIterations(o), 3);
  o.fine_particle_fraction = 1;
  EXPECT_EQ(box.Run(o).stats.weighings, 3 * 64 + 64 + 2 * (64 - 10));
  o.fine_particle_fraction = 0.5;
  ASSERT_EQ(filter::FineParticles(o), 32);
  const EstimateResult half = box.Run(o);
  EXPECT_EQ(half.stats.weighings, 3 * 64 + 32 + 2 * (32 - 10));
  EXPECT_EQ(half.iterations, 6);
  EXPECT_EQ(box.Run(o).best_weight_history, half.best_weight_history);  // same seed, same run
  o.anneal.start_m = 0;  // no annealing: every set has N particles (the thesis)
  EXPECT_EQ(box.Run(o).stats.weighings, 64 + 5 * (64 - 10));
}

// anneal_simplify: the coarse iterations weigh the mesh simplified to max(256, F / s²) faces,
// every later one the full mesh — FilterStats::faces_total counts the faces of every weighing.
TEST(ParticleFilterTest, CoarseIterationsWeighTheSimplifiedMesh) {
  const EasyCase torus("torus", 4);
  const int F = int(torus.sc.target.faces.size());
  ASSERT_GT(F, 1024);
  FilterOptions o = EasyCase::Countable(6);  // N = 64; iterations 0–2 coarse; fine sets of 43
  o.render.lod_face_px = 0;                  // the full mesh at every size in the image
  ASSERT_EQ(filter::CoarseMeshFaces(F, 3), std::max(256, F / 9));
  const std::int64_t Fc = std::int64_t(SimplifyMesh(torus.sc.target, filter::CoarseMeshFaces(F, 3)).faces.size());
  ASSERT_LT(Fc, F);
  const std::int64_t coarse_weighings = 3 * 64, fine_weighings = 43 + 2 * (43 - 10);
  const EstimateResult r = torus.Run(o);
  EXPECT_EQ(r.stats.weighings, coarse_weighings + fine_weighings);
  EXPECT_EQ(r.stats.faces_total, coarse_weighings * Fc + fine_weighings * F);
  o.anneal.simplify = false;
  EXPECT_EQ(torus.Run(o).stats.faces_total, (coarse_weighings + fine_weighings) * F);
  // Meshes at or below the floor are weighed as they are.
  EXPECT_EQ(filter::CoarseMeshFaces(12, 3), filter::kCoarseMinFaces);
}

// render.lod_face_px: an object that covers fewer than lod_face_px pixels of D² per face is
// weighed with the mesh of stride m = 4 (max(256, F / 16) faces: the coarse level's too, as the
// torus's 2048 faces are under 9 · 256) at both pixel levels; at 0
// the fine level weighs the full mesh. FilterStats::faces_total counts the faces weighed.
TEST(ParticleFilterTest, AnObjectSmallInTheImageWeighsAMeshOfFewerFaces) {
  const EasyCase torus("torus", 4);
  const int F = int(torus.sc.target.faces.size());
  FilterOptions o = EasyCase::Countable(6);  // N = 64; iterations 0–2 coarse; fine sets of 43
  const std::int64_t F4 = std::int64_t(SimplifyMesh(torus.sc.target, filter::CoarseMeshFaces(F, 4)).faces.size());
  const std::int64_t Fc = std::int64_t(SimplifyMesh(torus.sc.target, filter::CoarseMeshFaces(F, 3)).faces.size());
  ASSERT_LT(F4, F);
  const std::int64_t coarse_weighings = 3 * 64, fine_weighings = 43 + 2 * (43 - 10);
  o.render.lod_face_px = 1e6;  // D² / 1e6 faces: stride 4 for any object under 8000 px across
  const EstimateResult small = torus.Run(o);
  EXPECT_EQ(small.stats.weighings, coarse_weighings + fine_weighings);
  EXPECT_EQ(small.stats.faces_total, (coarse_weighings + fine_weighings) * F4);
  o.render.lod_face_px = 0;
  EXPECT_EQ(torus.Run(o).stats.faces_total, coarse_weighings * Fc + fine_weighings * F);
}

// render.lod_face_px's stride at a depth: the smallest m in [1, 4] with faces / m² ≤ D² / K,
// D = diameter · max(fx, fy) / z. A 4096-face mesh of 0.1 m at f = 1000 px with K = 16
// (sqrt(4096 · 16) = 256 px): D = 256.4 px → 1, 200 → 2, 100 → 3, 50 → 4, and 4 beyond.
TEST(MeshFactorTest, TheStrideFollowsTheProjectedDiameter) {
  FilterOptions o;
  Camera cam;
  cam.fx = cam.fy = 1000;
  o.render.lod_face_px = 16;
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 4096, 0.39), 1);
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 4096, 0.5), 2);
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 4096, 1.0), 3);
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 4096, 2.0), 4);
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 4096, 20.0), 4);
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 256, 1.5), 1);  // 256 faces ≤ 66.7² / 16
  o.render.lod_face_px = 0;  // off: the mesh itself at every size
  EXPECT_EQ(filter::MeshFactorAt(o, cam, 0.1, 4096, 2.0), 1);
}

TEST(ParticleFilterTest, CountsTheThesisQuantities) {
  const SynthScene sc = EasyScene("lshape", 4);
  const Prior prior = PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes);
  FilterOptions o;
  o.num_particles = 100;
  o.stop.max_iterations = 3;
  o.restarts = 1;
  o.anneal.start_m = 0;
  o.polish.steps = 0;  // the filter's own weighings only
  const EstimateResult r =
      EstimatePose(SceneInput{sc.depth, sc.camera}, sc.target, prior, prior.ClassIndex(sc.target.name), o);
  EXPECT_GT(r.stats.init_cdf_reads_linear, 0);
  EXPECT_LT(r.stats.init_cdf_reads, r.stats.init_cdf_reads_linear);  // the tracker saves reads
  EXPECT_LT(r.stats.resample_cdf_reads, r.stats.resample_cdf_reads_linear);
  // Back-face culling removes roughly half of a closed mesh's faces (thesis: 2.06×).
  const double ratio = double(r.stats.faces_total) / double(r.stats.faces_front);
  EXPECT_GT(ratio, 1.5);
  EXPECT_LT(ratio, 3.0);
  // Elite particles are not weighed again: fewer weighings than N × iterations.
  EXPECT_LT(r.stats.weighings, 300);
  EXPECT_GE(r.stats.weighings, 100 + 2 * (100 - o.num_elite));
}

TEST(ParticleFilterTest, RejectsAClassWithoutMassAndAPriorOfAnotherSize) {
  const SynthScene sc = EasyScene("box", 1);
  FilterOptions o;
  o.num_particles = 16;
  o.stop.max_iterations = 1;
  const SceneInput in{sc.depth, sc.camera};
  Prior prior = PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes);
  std::fill(prior.prob.begin(), prior.prob.end(), 0.0f);
  EXPECT_THROW(EstimatePose(in, sc.target, prior, 0, o), Error);
  const Prior other = UniformPrior(PyramidLayout::Thesis(320, 240, 4), sc.classes);
  EXPECT_THROW(EstimatePose(in, sc.target, other, 0, o), Error);
  EXPECT_THROW(EstimatePose(in, sc.target, other, 99, o), Error);
}

TEST(ParticleFilterTest, RecoversThePoseOnCleanScenes) {
  // Default options, unoccluded targets with a correct detection: ADD-S below 10% of the
  // diameter. (The 20-scene suite with occlusion and false positives is `posefilter suite`.)
  int found = 0;
  for (const auto& [target, seed] : std::vector<std::pair<std::string, int>>{{"box", 21}, {"cylinder", 22}}) {
    const SynthScene sc = EasyScene(target, seed);
    const Prior prior = PostProcessPyramid(sc.raw_pyramid, sc.layout, sc.classes);
    FilterOptions o;
    o.seed = 1;
    const EstimateResult r =
        EstimatePose(SceneInput{sc.depth, sc.camera}, sc.target, prior, prior.ClassIndex(sc.target.name), o);
    const PoseErrors e = ComputePoseErrors(SamplePoints(sc.target), sc.target.Diameter(), r.T_cam_obj, sc.gt[0].T_cam_obj);
    EXPECT_TRUE(e.adds_ok) << target << ": ADD-S " << 1000 * e.adds << " mm, diameter " << 1000 * e.diameter << " mm";
    found += e.adds_ok;
  }
  EXPECT_EQ(found, 2);
}

}  // namespace
}  // namespace posefilter
