// Tracker (posefilter/tracker.h) on synthetic moving-target sequences (MakeSynthSequence):
// it follows a sliding, turning object from a Reset, reports a jump beyond its search and a
// target that leaves the image as lost, (re-)initialises from a stage 1 that it calls only when
// needed (lost, not started, or below refresh_weight), is deterministic per seed and thread
// count, and rejects bad options, meshes, poses and frames with errors that name the problem.
// The sequences are made once per binary run; each tracking step is the cheap default
// (TrackingFilterOptions), and the stage-1 estimates get a small budget.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/metrics.h"
#include "posefilter/prior.h"
#include "posefilter/synth.h"
#include "posefilter/tracker.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectError;
using testing_util::ExpectInvalid;

constexpr int kLabelTargetPixel = 1;  // SynthScene::labels: 1 = target

SynthOptions SeqOptions() {
  SynthOptions so;
  so.target = "lshape";
  so.clutter = 2;
  so.false_positives = 0;
  return so;
}

SceneInput Input(const SynthScene& s) { return SceneInput{s.depth, s.camera}; }

// Tracker options: the default tracking step with `seed` and `threads`, and a small budget for
// the stage-1 (re-)initialisations.
TrackOptions Options(std::uint64_t seed = 5, int threads = 1) {
  TrackOptions o;
  o.filter.seed = seed;
  o.filter.threads = threads;
  o.init.num_particles = 200;
  o.init.stop.max_iterations = 10;
  o.init.restarts = 2;
  o.init.threads = threads;
  return o;
}

// A stage 1 from the synthetic detections of frame *frame of `seq` (the caller sets *frame
// before each Track); records the frame of every call in *calls.
Stage1Fn DetectionStage1(const std::vector<SynthScene>& seq, const int* frame, std::vector<int>* calls) {
  return [&seq, frame, calls](const SceneInput& in) {
    calls->push_back(*frame);
    const SynthScene& s = seq.at(std::size_t(*frame));
    EXPECT_EQ(in.depth.data, s.depth.data) << "the stage 1 got another frame's depth";
    TrackStage1 st;
    st.prior = PriorFromDetections(s.detections, PyramidLayout::Thesis(s.camera.width, s.camera.height, int(s.classes.size())),
                                   s.classes);
    return st;
  };
}

// ADD-S of `T` against frame s's ground truth (10 % of the diameter passes).
PoseErrors Errors(const SynthScene& s, const Eigen::Isometry3d& T) {
  return ComputePoseErrors(SamplePoints(s.target), s.target.Diameter(), T, s.gt[0].T_cam_obj);
}

std::size_t TargetPixels(const SynthScene& s) {
  std::size_t n = 0;
  for (int l : s.labels) n += l == kLabelTargetPixel;
  return n;
}

class TrackerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A slide of 1 cm and a turn of 0.05 rad per frame.
    moving_ = new std::vector<SynthScene>(MakeSynthSequence(SeqOptions(), SynthMotion{6, 0.01, 0.05}, 21));
    // Half a centimetre per frame, then a 15 cm jump at frame 2: far beyond the search.
    jump_ = new std::vector<SynthScene>(MakeSynthSequence(SeqOptions(), SynthMotion{4, 0.005, 0.0, 2, 0.15}, 22));
  }
  static void TearDownTestSuite() {
    delete moving_;
    delete jump_;
    moving_ = jump_ = nullptr;
  }
  static const std::vector<SynthScene>& moving() { return *moving_; }
  static const std::vector<SynthScene>& jump() { return *jump_; }

  // Tracks `seq` from a Reset at frame 0's ground truth; one result per frame.
  static std::vector<TrackResult> TrackFromGt(const std::vector<SynthScene>& seq, const TrackOptions& o,
                                              const Stage1Fn& stage1 = nullptr, int* frame = nullptr) {
    Tracker tracker({seq[0].target}, o);
    tracker.Reset("lshape", seq[0].gt[0].T_cam_obj);
    std::vector<TrackResult> out;
    for (std::size_t t = 0; t < seq.size(); ++t) {
      if (frame) *frame = int(t);
      const std::vector<TrackResult> r = tracker.Track(Input(seq[t]), stage1);
      EXPECT_EQ(r.size(), 1u);
      out.push_back(r.at(0));
    }
    EXPECT_EQ(tracker.frames(), int(seq.size()));
    return out;
  }

  inline static std::vector<SynthScene>* moving_ = nullptr;
  inline static std::vector<SynthScene>* jump_ = nullptr;
};

std::vector<TrackStatus> Statuses(const std::vector<TrackResult>& rs) {
  std::vector<TrackStatus> s;
  for (const auto& r : rs) s.push_back(r.status);
  return s;
}

std::string Describe(const std::vector<TrackResult>& rs) {
  std::string s;
  for (const auto& r : rs) s += std::string(TrackStatusName(r.status)) + "(" + std::to_string(r.weight) + ") ";
  return s;
}

// ---- Following a moving target --------------------------------------------------------------

TEST_F(TrackerTest, FollowsAMovingTargetFromAResetAtTheFirstGroundTruth) {
  const TrackOptions o = Options();
  const std::vector<TrackResult> rs = TrackFromGt(moving(), o);
  ASSERT_EQ(rs.size(), moving().size());
  for (std::size_t t = 0; t < rs.size(); ++t) {
    const TrackResult& r = rs[t];
    EXPECT_EQ(r.obj, "lshape");
    EXPECT_EQ(r.status, TrackStatus::kTracked) << "frame " << t << ": " << Describe(rs);
    EXPECT_GE(r.weight, o.lost_weight) << t;
    EXPECT_LE(r.weight, 1.0) << t;
    EXPECT_GE(r.iterations, 1) << t;
    EXPECT_LE(r.iterations, o.filter.stop.max_iterations * o.filter.restarts) << t;
    EXPECT_GE(r.time_ms, 0.0) << t;
    EXPECT_TRUE(r.T_cam_obj.matrix().allFinite()) << t;
    const PoseErrors e = Errors(moving()[t], r.T_cam_obj);
    EXPECT_TRUE(e.adds_ok) << "frame " << t << ": ADD-S " << e.adds * 1e3 << " mm, diameter " << e.diameter * 1e3 << " mm";
  }
  // The target really moved: the last frame's ground truth is far from the first's, so a
  // tracker that kept the Reset pose would fail the ADD-S check above.
  EXPECT_FALSE(Errors(moving().back(), moving().front().gt[0].T_cam_obj).adds_ok);
}

TEST_F(TrackerTest, WithoutConstantVelocityItStillFollowsTheSlowTarget) {
  TrackOptions o = Options();
  o.constant_velocity = false;
  const std::vector<TrackResult> rs = TrackFromGt(moving(), o);
  for (std::size_t t = 0; t < rs.size(); ++t) {
    EXPECT_EQ(rs[t].status, TrackStatus::kTracked) << "frame " << t << ": " << Describe(rs);
    EXPECT_TRUE(Errors(moving()[t], rs[t].T_cam_obj).adds_ok) << t;
  }
}

TEST_F(TrackerTest, ConstantVelocityFollowsATargetFasterThanTheSearch) {
  // 5 cm per frame, five times the search's σ: the prediction by the last frame-to-frame motion
  // keeps it (without it, seed 21 loses the target from frame 3 on today).
  for (const std::uint64_t seed : {21, 30}) {
    const std::vector<SynthScene> seq = MakeSynthSequence(SeqOptions(), SynthMotion{6, 0.05, 0.0}, seed);
    const std::vector<TrackResult> rs = TrackFromGt(seq, Options());
    for (std::size_t t = 0; t < rs.size(); ++t) {
      EXPECT_EQ(rs[t].status, TrackStatus::kTracked) << "seed " << seed << ", frame " << t << ": " << Describe(rs);
      EXPECT_TRUE(Errors(seq[t], rs[t].T_cam_obj).adds_ok) << "seed " << seed << ", frame " << t;
    }
    // The option is used: the first frame (no motion known yet) is the same without it, later
    // frames are not.
    TrackOptions still = Options();
    still.constant_velocity = false;
    const std::vector<TrackResult> rl = TrackFromGt(seq, still);
    EXPECT_TRUE(rl[0].T_cam_obj.matrix() == rs[0].T_cam_obj.matrix()) << seed;
    bool differs = false;
    for (std::size_t t = 1; t < rs.size(); ++t) differs = differs || !(rl[t].T_cam_obj.matrix() == rs[t].T_cam_obj.matrix());
    EXPECT_TRUE(differs) << "seed " << seed << ": constant_velocity changed nothing";
  }
}

// ---- Loss and (re-)initialisation ----------------------------------------------------------

TEST_F(TrackerTest, AJumpBeyondTheSearchIsLostFromTheJumpOnWithoutAStage1) {
  const std::vector<TrackResult> rs = TrackFromGt(jump(), Options());
  EXPECT_EQ(Statuses(rs), (std::vector<TrackStatus>{TrackStatus::kTracked, TrackStatus::kTracked, TrackStatus::kLost,
                                                    TrackStatus::kLost}))
      << Describe(rs);
  for (std::size_t t = 2; t < rs.size(); ++t) EXPECT_LT(rs[t].weight, Options().lost_weight) << t;
}

TEST_F(TrackerTest, AStage1ReinitialisesAtTheJumpAndIsCalledOnlyThere) {
  int frame = 0;
  std::vector<int> calls;
  const std::vector<TrackResult> rs = TrackFromGt(jump(), Options(), DetectionStage1(jump(), &frame, &calls), &frame);
  EXPECT_EQ(Statuses(rs), (std::vector<TrackStatus>{TrackStatus::kTracked, TrackStatus::kTracked,
                                                    TrackStatus::kInitialised, TrackStatus::kTracked}))
      << Describe(rs);
  // Once, for the jump frame: never while the object is tracked with a weight above
  // refresh_weight (checked, so that a low weight cannot explain a call).
  EXPECT_EQ(calls, std::vector<int>{2});
  for (std::size_t t : {0u, 1u, 3u}) EXPECT_GE(rs[t].weight, Options().refresh_weight) << t << ": " << Describe(rs);
  for (std::size_t t = 2; t < rs.size(); ++t)
    EXPECT_TRUE(Errors(jump()[t], rs[t].T_cam_obj).adds_ok) << "frame " << t << " after the restart";
}

TEST_F(TrackerTest, AnObjectWithoutAStartIsNotStartedUntilAStage1Initialises) {
  Tracker tracker({moving()[0].target}, Options());
  std::vector<TrackResult> r = tracker.Track(Input(moving()[0]));
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].obj, "lshape");
  EXPECT_EQ(r[0].status, TrackStatus::kNotStarted);
  EXPECT_TRUE(r[0].T_cam_obj.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(r[0].weight, 0.0);
  // Still not started on the next frame (nothing started it), then initialised by a stage 1.
  r = tracker.Track(Input(moving()[1]), nullptr);
  EXPECT_EQ(r.at(0).status, TrackStatus::kNotStarted);
  int frame = 2;
  std::vector<int> calls;
  r = tracker.Track(Input(moving()[2]), DetectionStage1(moving(), &frame, &calls));
  EXPECT_EQ(r.at(0).status, TrackStatus::kInitialised) << r.at(0).weight;
  EXPECT_EQ(calls, std::vector<int>{2});
  EXPECT_TRUE(Errors(moving()[2], r.at(0).T_cam_obj).adds_ok);
  EXPECT_GE(r.at(0).weight, Options().lost_weight);
  // From there it is tracked.
  r = tracker.Track(Input(moving()[3]));
  EXPECT_EQ(r.at(0).status, TrackStatus::kTracked) << r.at(0).weight;
  EXPECT_TRUE(Errors(moving()[3], r.at(0).T_cam_obj).adds_ok);
  EXPECT_EQ(tracker.frames(), 4);
}

TEST_F(TrackerTest, AStage1WithoutTheObjectsClassLeavesItNotStarted) {
  Tracker tracker({moving()[0].target}, Options());
  int calls = 0;
  const auto r = tracker.Track(Input(moving()[0]), [&](const SceneInput& in) {
    ++calls;
    TrackStage1 st;
    std::vector<Detection> dets = moving()[0].detections;
    for (auto& d : dets) d.cls = "box";
    st.prior = PriorFromDetections(dets, PyramidLayout::Thesis(in.camera.width, in.camera.height, 1), {"box"});
    return st;
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(r.at(0).status, TrackStatus::kNotStarted);
}

TEST_F(TrackerTest, RefreshWeightOneAsksTheStage1EveryFrameAndZeroNever) {
  // refresh_weight 1: every tracked weight is below it, so every frame asks the stage 1 (and the
  // object is still followed: the heavier of the two poses wins).
  TrackOptions o = Options();
  o.refresh_weight = 1.0;
  const std::size_t n = 4;
  const std::vector<SynthScene> seq(moving().begin(), moving().begin() + n);
  int frame = 0;
  std::vector<int> calls;
  std::vector<TrackResult> rs = TrackFromGt(seq, o, DetectionStage1(seq, &frame, &calls), &frame);
  EXPECT_EQ(calls, (std::vector<int>{0, 1, 2, 3}));
  for (std::size_t t = 0; t < n; ++t) {
    EXPECT_TRUE(rs[t].status == TrackStatus::kTracked || rs[t].status == TrackStatus::kInitialised) << Describe(rs);
    EXPECT_TRUE(Errors(seq[t], rs[t].T_cam_obj).adds_ok) << t;
  }

  // refresh_weight 0: a tracked object never asks.
  o.refresh_weight = 0;
  calls.clear();
  rs = TrackFromGt(seq, o, DetectionStage1(seq, &frame, &calls), &frame);
  EXPECT_TRUE(calls.empty()) << calls.size() << " call(s), first for frame " << calls.front();
  for (std::size_t t = 0; t < n; ++t) EXPECT_EQ(rs[t].status, TrackStatus::kTracked) << Describe(rs);
}

TEST_F(TrackerTest, ATrackedObjectAsksTheStage1ExactlyWhenItsWeightIsBelowRefreshWeight) {
  // Frame 0's tracked weight w (a run without stage 1; the search does not depend on it):
  // refresh_weight just above w asks the stage 1 for frame 0, refresh_weight = w does not.
  const std::vector<SynthScene> seq(moving().begin(), moving().begin() + 1);
  const double w = TrackFromGt(seq, Options()).at(0).weight;
  ASSERT_GT(w, 0.0);
  ASSERT_LT(w, 1.0);
  TrackOptions o = Options();
  int frame = 0;
  std::vector<int> calls;
  o.refresh_weight = std::nextafter(w, 2.0);
  TrackFromGt(seq, o, DetectionStage1(seq, &frame, &calls), &frame);
  EXPECT_EQ(calls, std::vector<int>{0}) << "weight " << w << ", refresh_weight just above it";
  o.refresh_weight = w;
  calls.clear();
  const std::vector<TrackResult> rs = TrackFromGt(seq, o, DetectionStage1(seq, &frame, &calls), &frame);
  EXPECT_TRUE(calls.empty()) << "weight " << w << " = refresh_weight asked the stage 1";
  EXPECT_EQ(rs.at(0).weight, w);
}

// ---- Determinism ----------------------------------------------------------------------------

void ExpectSameResults(const std::vector<TrackResult>& a, const std::vector<TrackResult>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t t = 0; t < a.size(); ++t) {
    EXPECT_EQ(a[t].status, b[t].status) << what << " frame " << t;
    EXPECT_EQ(a[t].weight, b[t].weight) << what << " frame " << t;
    EXPECT_EQ(a[t].iterations, b[t].iterations) << what << " frame " << t;
    EXPECT_TRUE(a[t].T_cam_obj.matrix() == b[t].T_cam_obj.matrix())
        << what << " frame " << t << ":\n" << a[t].T_cam_obj.matrix() << "\nvs\n" << b[t].T_cam_obj.matrix();
  }
}

TEST_F(TrackerTest, TheSameSeedGivesBitIdenticalPosesAndAnotherSeedStillTracks) {
  const std::vector<SynthScene> seq(moving().begin(), moving().begin() + 4);
  const std::vector<TrackResult> a = TrackFromGt(seq, Options(9));
  const std::vector<TrackResult> b = TrackFromGt(seq, Options(9));
  ExpectSameResults(a, b, "seed 9 twice");
  const std::vector<TrackResult> c = TrackFromGt(seq, Options(10));
  bool differs = false;
  for (std::size_t t = 0; t < seq.size(); ++t) {
    EXPECT_EQ(c[t].status, TrackStatus::kTracked) << "seed 10, frame " << t << ": " << Describe(c);
    EXPECT_TRUE(Errors(seq[t], c[t].T_cam_obj).adds_ok) << "seed 10, frame " << t;
    differs = differs || !(c[t].T_cam_obj.matrix() == a[t].T_cam_obj.matrix());
  }
  EXPECT_TRUE(differs) << "seed 10 gave seed 9's poses: the seed is not used";
}

TEST_F(TrackerTest, TheThreadCountDoesNotChangeTheResult) {
  const std::vector<SynthScene> seq(moving().begin(), moving().begin() + 4);
  ExpectSameResults(TrackFromGt(seq, Options(5, 1)), TrackFromGt(seq, Options(5, 2)), "threads 1 vs 2");
  // Also through a (re-)initialisation from the stage 1.
  int frame = 0;
  std::vector<int> calls;
  const std::vector<TrackResult> one = TrackFromGt(jump(), Options(5, 1), DetectionStage1(jump(), &frame, &calls), &frame);
  const std::vector<TrackResult> two = TrackFromGt(jump(), Options(5, 2), DetectionStage1(jump(), &frame, &calls), &frame);
  ExpectSameResults(one, two, "jump, threads 1 vs 2");
}

TEST_F(TrackerTest, TwoObjectsSearchedOnSeveralThreadsGiveTheResultsOfOneThread) {
  // The lshape at its ground truth and a box (not in the scene) Reset 25 cm beside it: both are
  // searched every frame, in parallel when there are threads for it.
  const std::vector<SynthScene> seq(moving().begin(), moving().begin() + 3);
  auto run = [&](int threads) {
    TrackOptions o = Options(5, threads);
    o.refresh_weight = 0;
    Tracker tracker({MakeShape("box"), seq[0].target}, o);
    Eigen::Isometry3d beside = seq[0].gt[0].T_cam_obj;
    beside.translation().x() += 0.25;
    tracker.Reset("box", beside);
    tracker.Reset("lshape", seq[0].gt[0].T_cam_obj);
    std::vector<TrackResult> all;
    for (const SynthScene& s : seq) {
      const std::vector<TrackResult> r = tracker.Track(Input(s));
      EXPECT_EQ(r.size(), 2u);
      all.insert(all.end(), r.begin(), r.end());
    }
    return all;
  };
  const std::vector<TrackResult> one = run(1), two = run(2);
  ExpectSameResults(one, two, "two objects, threads 1 vs 2");
  for (std::size_t t = 0; t < seq.size(); ++t) {
    EXPECT_EQ(one[2 * t].obj, "box");
    EXPECT_EQ(one[2 * t + 1].obj, "lshape");
    EXPECT_EQ(one[2 * t + 1].status, TrackStatus::kTracked) << t;
    EXPECT_TRUE(Errors(seq[t], one[2 * t + 1].T_cam_obj).adds_ok) << t;
  }
}

// ---- A target that leaves the image ---------------------------------------------------------

TEST_F(TrackerTest, ATargetThatLeavesTheImageIsReportedLostNeverACrash) {
  SynthOptions so = SeqOptions();
  so.clutter = 0;  // nothing else for the search to lock onto
  const std::vector<SynthScene> seq = MakeSynthSequence(so, SynthMotion{8, 0.12, 0.0}, 23);
  std::size_t out_of_view = 0;
  for (const auto& s : seq) out_of_view += TargetPixels(s) == 0;
  ASSERT_GE(out_of_view, 2u) << "the target should leave the image";
  for (const bool with_stage1 : {false, true}) {
    int frame = 0;
    std::vector<int> calls;
    std::vector<TrackResult> rs;
    ASSERT_NO_THROW(rs = TrackFromGt(seq, Options(), with_stage1 ? DetectionStage1(seq, &frame, &calls) : Stage1Fn(), &frame));
    for (std::size_t t = 0; t < seq.size(); ++t) {
      EXPECT_TRUE(rs[t].T_cam_obj.matrix().allFinite()) << t;
      if (TargetPixels(seq[t]) == 0)
        EXPECT_EQ(rs[t].status, TrackStatus::kLost)
            << (with_stage1 ? "with" : "without") << " stage 1, frame " << t << " (out of view): " << Describe(rs);
    }
  }
}

// ---- Errors ---------------------------------------------------------------------------------

TEST(TrackOptionsTest, DefaultsAreValidAndIsValidNamesEachBadField) {
  std::string why;
  EXPECT_TRUE(TrackOptions{}.IsValid(&why)) << why;
  EXPECT_TRUE(TrackOptions{}.IsValid(nullptr));
  EXPECT_TRUE(TrackingFilterOptions().IsValid(&why)) << why;
  auto bad = [](auto change, const std::string& needle) {
    TrackOptions o;
    change(o);
    ExpectInvalid(o, needle);
    EXPECT_FALSE(o.IsValid(nullptr)) << needle;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bad([](TrackOptions& o) { o.lost_weight = 2; }, "lost_weight must be in [0, 1] (got 2)");
  bad([](TrackOptions& o) { o.lost_weight = -0.1; }, "lost_weight");
  bad([](TrackOptions& o) { o.refresh_weight = -1; }, "refresh_weight must be in [0, 1] (got -1)");
  bad([&](TrackOptions& o) { o.search_t_m = nan; }, "search_t_m");
  bad([](TrackOptions& o) { o.search_t_m = -0.01; }, "search_t_m");
  bad([](TrackOptions& o) { o.search_r_rad = 4; }, "search_r_rad must be in [0, pi] (got 4)");
  bad([](TrackOptions& o) { o.window_margin = 0; }, "window_margin must be in (0, 2]");
  bad([](TrackOptions& o) { o.window_margin = 2.5; }, "window_margin");
  bad([](TrackOptions& o) { o.filter.num_particles = 0; }, "filter.num_particles");
  bad([](TrackOptions& o) { o.init.num_particles = 0; }, "init.num_particles");
  bad([](TrackOptions& o) { o.filter.engine = "hw"; }, "filter.engine");
  bad([](TrackOptions& o) { o.filter.engine = "rtl"; }, "filter.engine");
  // The edges of each range are valid.
  TrackOptions o;
  o.lost_weight = 0;
  o.refresh_weight = 1;
  o.search_t_m = 0;
  o.search_r_rad = M_PI;
  o.window_margin = 2;
  EXPECT_TRUE(o.IsValid(&why)) << why;
}

TEST(TrackStatusTest, Names) {
  EXPECT_STREQ(TrackStatusName(TrackStatus::kTracked), "tracked");
  EXPECT_STREQ(TrackStatusName(TrackStatus::kInitialised), "initialised");
  EXPECT_STREQ(TrackStatusName(TrackStatus::kLost), "lost");
  EXPECT_STREQ(TrackStatusName(TrackStatus::kNotStarted), "not-started");
}

TEST(TrackerErrorsTest, TheConstructorRejectsBadOptionsNoMeshAnInvalidMeshAndARepeatedName) {
  const Mesh l = MakeShape("lshape");
  TrackOptions bad;
  bad.lost_weight = 2;
  ExpectError([&] { Tracker({l}, bad); }, {"lost_weight"});
  ExpectError([&] { Tracker({}, TrackOptions{}); }, {"no mesh"});
  Mesh empty;
  empty.name = "empty";
  ExpectError([&] { Tracker({l, empty}); }, {"'empty'"});
  Mesh broken = MakeShape("box");
  broken.faces.push_back({0, 1, 99});  // a face index past the vertices
  ExpectError([&] { Tracker({broken}); }, {"'box'"});
  ExpectError([&] { Tracker({l, MakeShape("box"), l}); }, {"'lshape'", "twice"});
  EXPECT_NO_THROW(Tracker({l, MakeShape("box")}));
}

TEST_F(TrackerTest, ResetRejectsAnUnknownObjectAndANonFinitePose) {
  Tracker tracker({moving()[0].target}, Options());
  ExpectError([&] { tracker.Reset("cup", Eigen::Isometry3d::Identity()); }, {"unknown object 'cup'"});
  Eigen::Isometry3d T = moving()[0].gt[0].T_cam_obj;
  T.translation().x() = std::nan("");
  ExpectError([&] { tracker.Reset("lshape", T); }, {"'lshape'", "not finite"});
  // The failed Reset left the object without a pose.
  EXPECT_EQ(tracker.Track(Input(moving()[0])).at(0).status, TrackStatus::kNotStarted);
}

TEST_F(TrackerTest, TrackRejectsAFrameOfAnotherSizeAndNanDepth) {
  Tracker tracker({moving()[0].target}, Options());
  tracker.Reset("lshape", moving()[0].gt[0].T_cam_obj);
  // NaN depth: invalid, named by the frame; nothing was processed.
  SceneInput nan = Input(moving()[0]);
  nan.depth.at(10, 20) = std::numeric_limits<float>::quiet_NaN();
  ExpectError([&] { tracker.Track(nan); }, {"frame 0", "NaN"});
  EXPECT_EQ(tracker.frames(), 0);
  // Depth and camera of different sizes.
  SceneInput mismatch = Input(moving()[0]);
  mismatch.depth = DepthImage(320, 240, 0.8f);
  ExpectError([&] { tracker.Track(mismatch); }, {"frame 0", "320x240", "640x480"});
  EXPECT_EQ(tracker.frames(), 0);

  ASSERT_EQ(tracker.Track(Input(moving()[0])).at(0).status, TrackStatus::kTracked);
  // A consistent frame of another size than the first.
  SceneInput half;
  half.camera = moving()[0].camera;
  half.camera.width = 320;
  half.camera.height = 240;
  half.camera.cx /= 2;
  half.camera.cy /= 2;
  half.depth = DepthImage(320, 240, 0.8f);
  ExpectError([&] { tracker.Track(half); }, {"frame 1", "320x240", "640x480"});
  EXPECT_EQ(tracker.frames(), 1);
  // NaN depth on a later frame, too.
  SceneInput nan1 = Input(moving()[1]);
  nan1.depth.at(5, 5) = std::numeric_limits<float>::quiet_NaN();
  ExpectError([&] { tracker.Track(nan1); }, {"frame 1", "NaN"});
  // The tracker goes on after the rejected frames.
  const auto r = tracker.Track(Input(moving()[1]));
  EXPECT_EQ(r.at(0).status, TrackStatus::kTracked);
  EXPECT_TRUE(Errors(moving()[1], r.at(0).T_cam_obj).adds_ok);
  EXPECT_EQ(tracker.frames(), 2);
}

TEST_F(TrackerTest, TwoObjectsGetOneResultEachInTheMeshesOrder) {
  // A second mesh that is not in the scene: the lshape is still tracked; the box, never
  // started, stays not started and the stage 1 (whose classes do not hold it) cannot start it.
  Mesh box = MakeShape("box");
  TrackOptions o = Options();
  o.refresh_weight = 0;  // only the box asks the stage 1
  Tracker tracker({box, moving()[0].target}, o);
  tracker.Reset("lshape", moving()[0].gt[0].T_cam_obj);
  int frame = 0;
  std::vector<int> calls;
  std::vector<SynthScene> seq(moving().begin(), moving().begin() + 2);
  for (auto& s : seq) s.classes = {"lshape"};
  for (auto& s : seq) {
    std::vector<Detection> keep;
    for (const auto& d : s.detections)
      if (d.cls == "lshape") keep.push_back(d);
    s.detections = keep;
  }
  const Stage1Fn stage1 = DetectionStage1(seq, &frame, &calls);
  for (frame = 0; frame < 2; ++frame) {
    const auto r = tracker.Track(Input(seq[std::size_t(frame)]), stage1);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(r[0].obj, "box");
    EXPECT_EQ(r[0].status, TrackStatus::kNotStarted);
    EXPECT_EQ(r[1].obj, "lshape");
    EXPECT_EQ(r[1].status, TrackStatus::kTracked) << r[1].weight;
    EXPECT_TRUE(Errors(seq[std::size_t(frame)], r[1].T_cam_obj).adds_ok) << frame;
  }
  // The box needs a start every frame: the stage 1 is asked once per frame, not per object.
  EXPECT_EQ(calls, (std::vector<int>{0, 1}));
}

}  // namespace
}  // namespace posefilter
