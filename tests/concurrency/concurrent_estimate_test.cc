// Many estimates at once from the caller's own std::threads, through the entry point that
// Python's Estimator.estimate calls (EstimatePose with a detection prior and a progress
// callback): on one shared set of inputs (the same scene, meshes, prior and options objects)
// and on separate copies, for the cpu and reference engines. Every result must equal the
// single-threaded result for the same seed, bit for bit.
//
// ctest label `tsan`: scripts/tsan.sh runs this binary under ThreadSanitizer. libgomp is not
// instrumented, so TSan cannot see the happens-before edges of an OpenMP team and reports
// false races between team members; under TSan every estimate therefore runs with threads = 1
// (a team of one: the library's OpenMP regions run on the calling std::thread). Without TSan
// each estimate runs with threads = 2 (nested teams inside the caller's threads).
#include <gtest/gtest.h>

#include <cstdint>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "posefilter/filter.h"
#include "posefilter/prior.h"
#include "posefilter/synth.h"

#if defined(__SANITIZE_THREAD__)
#define POSEFILTER_UNDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define POSEFILTER_UNDER_TSAN 1
#endif
#endif

namespace posefilter {
namespace {

#ifdef POSEFILTER_UNDER_TSAN
constexpr int kWorkerThreads = 1;  // see the file comment
#else
constexpr int kWorkerThreads = 2;
#endif
constexpr int kCallerThreads = 4;

// A synthetic scene turned into what Estimator.estimate(depth, camera, mesh, prior=detections)
// passes to EstimatePose: the scene, the mesh, the detection prior and the target's class.
struct Inputs {
  Inputs(const std::string& target, std::uint64_t seed) {
    SynthOptions so;
    so.target = target;
    so.occlusion = 0.2;
    so.clutter = 1;
    so.false_positives = 1;
    const SynthScene sc = MakeSynthScene(so, seed);
    scene = SceneInput{sc.depth, sc.camera};
    mesh = sc.target;
    prior = PriorFromDetections(sc.detections, sc.layout, sc.classes);
    cls = prior.ClassIndex(mesh.name);
  }
  SceneInput scene;
  Mesh mesh;
  Prior prior;
  int cls = -1;
};

// A small budget with every stage on: annealing on the coarse grid with a simplified mesh,
// two restarts, the final polish.
FilterOptions Options(const std::string& engine, std::uint64_t seed) {
  FilterOptions o;
  o.engine = engine;
  o.num_particles = 48;
  o.stop.max_iterations = 5;
  o.restarts = 2;
  o.polish.steps = 2;
  o.seed = seed;
  o.threads = kWorkerThreads;
  return o;
}

// One estimate to make: which inputs, which engine, which seed.
struct Job {
  int inputs;
  std::string engine;
  std::uint64_t seed;
};

std::vector<Job> Jobs() {
  std::vector<Job> jobs;
  for (int i = 0; i < 2; ++i)
    for (const char* engine : {"cpu", "reference"})
      for (std::uint64_t seed : {7u, 8u}) jobs.push_back({i, engine, seed});
  return jobs;
}

// As Python's binding: a progress callback after every iteration (here it only counts).
EstimateResult Estimate(const Inputs& in, const FilterOptions& o, int* calls) {
  const ProgressFn progress = [calls](int, double) { ++*calls; };
  return EstimatePose(in.scene, in.mesh, in.prior, in.cls, o, progress);
}

void ExpectSame(const EstimateResult& got, const EstimateResult& want, const std::string& how) {
  EXPECT_EQ(got.weight, want.weight) << how;
  EXPECT_TRUE(got.T_cam_obj.isApprox(want.T_cam_obj, 0.0)) << how;
  const Pose6 &g = got.pose_base, &w = want.pose_base;
  EXPECT_TRUE(g.x == w.x && g.y == w.y && g.z == w.z && g.roll == w.roll && g.pitch == w.pitch && g.yaw == w.yaw)
      << how;
  EXPECT_EQ(got.cell, want.cell) << how;
  EXPECT_EQ(got.iterations, want.iterations) << how;
  EXPECT_EQ(got.converged, want.converged) << how;
  EXPECT_EQ(got.best_weight_history, want.best_weight_history) << how;
  EXPECT_EQ(got.stats.fragments, want.stats.fragments) << how;
  EXPECT_EQ(got.stats.weighings, want.stats.weighings) << how;
}

class ConcurrentEstimateTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    inputs_ = new std::vector<Inputs>{Inputs("box", 3), Inputs("torus", 4)};
    serial_ = new std::vector<EstimateResult>;
    for (const Job& j : Jobs()) {
      int calls = 0;
      serial_->push_back(Estimate((*inputs_)[std::size_t(j.inputs)], Options(j.engine, j.seed), &calls));
      ASSERT_EQ(calls, serial_->back().iterations);  // one call per iteration
    }
  }
  static void TearDownTestSuite() {
    delete inputs_;
    delete serial_;
    inputs_ = nullptr;
    serial_ = nullptr;
  }

  // Runs every job `rounds` times from kCallerThreads threads at once (the k-th estimate on
  // thread k % kCallerThreads); `run(job index, calls)` makes one estimate. Checks each result
  // against the serial one.
  template <typename RunJob>
  static void RunAtOnce(int rounds, const RunJob& run, const std::string& how) {
    const std::vector<Job> jobs = Jobs();
    const std::size_t n = jobs.size() * std::size_t(rounds);
    std::vector<EstimateResult> results(n);
    std::vector<int> calls(n, 0);
    std::vector<std::exception_ptr> errors(kCallerThreads);
    std::vector<std::thread> threads;
    for (int t = 0; t < kCallerThreads; ++t)
      threads.emplace_back([&, t] {
        try {
          for (std::size_t k = std::size_t(t); k < n; k += kCallerThreads)
            results[k] = run(k % jobs.size(), &calls[k]);
        } catch (...) {
          errors[std::size_t(t)] = std::current_exception();
        }
      });
    for (auto& th : threads) th.join();
    for (const auto& e : errors)
      if (e) std::rethrow_exception(e);
    for (std::size_t k = 0; k < n; ++k) {
      const Job& j = jobs[k % jobs.size()];
      const std::string what = how + ": inputs " + std::to_string(j.inputs) + ", engine " + j.engine + ", seed " +
                               std::to_string(j.seed) + ", round " + std::to_string(k / jobs.size());
      ExpectSame(results[k], (*serial_)[k % jobs.size()], what);
      EXPECT_EQ(calls[k], results[k].iterations) << what;
    }
  }

  static std::vector<Inputs>* inputs_;
  static std::vector<EstimateResult>* serial_;
};

std::vector<Inputs>* ConcurrentEstimateTest::inputs_ = nullptr;
std::vector<EstimateResult>* ConcurrentEstimateTest::serial_ = nullptr;

// The serial results are worth comparing with: on the same inputs, different seeds give
// different runs.
TEST_F(ConcurrentEstimateTest, TheSerialResultsDependOnTheSeedOnly) {
  const std::vector<Job> jobs = Jobs();
  ASSERT_EQ(serial_->size(), jobs.size());
  for (std::size_t a = 0; a < jobs.size(); ++a)
    for (std::size_t b = 0; b < jobs.size(); ++b)
      if (jobs[a].inputs == jobs[b].inputs && jobs[a].seed != jobs[b].seed)
        EXPECT_NE((*serial_)[a].best_weight_history, (*serial_)[b].best_weight_history) << a << " " << b;
}

// Every thread reads the same SceneInput, Mesh, Prior and FilterOptions objects.
TEST_F(ConcurrentEstimateTest, SharedInputsGiveTheSerialResults) {
  const std::vector<Job> jobs = Jobs();
  std::vector<FilterOptions> options;
  for (const Job& j : jobs) options.push_back(Options(j.engine, j.seed));
  RunAtOnce(
      2, [&](std::size_t k, int* calls) { return Estimate((*inputs_)[std::size_t(jobs[k].inputs)], options[k], calls); },
      "shared inputs");
}

// Every estimate builds its own inputs (scene, mesh, prior) and options first.
TEST_F(ConcurrentEstimateTest, SeparateInputsGiveTheSerialResults) {
  RunAtOnce(
      1,
      [](std::size_t k, int* calls) {
        const Job j = Jobs()[k];
        const Inputs own = j.inputs == 0 ? Inputs("box", 3) : Inputs("torus", 4);
        return Estimate(own, Options(j.engine, j.seed), calls);
      },
      "separate inputs");
}

// Copies of shared inputs, made while other threads estimate on the originals.
TEST_F(ConcurrentEstimateTest, CopiesMadeDuringEstimatesGiveTheSerialResults) {
  RunAtOnce(
      1,
      [](std::size_t k, int* calls) {
        const Job j = Jobs()[k];
        const Inputs copy = (*inputs_)[std::size_t(j.inputs)];
        return Estimate(copy, Options(j.engine, j.seed), calls);
      },
      "copied inputs");
}

}  // namespace
}  // namespace posefilter
