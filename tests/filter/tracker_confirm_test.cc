// The tracker's confirmation (TrackOptions::confirm): a frame whose predicted pose, polished
// alone, weighs as much as the object's reference weight (less confirm_margin) ends its search
// there, without the particle search. On a sliding, turning target it tracks every frame as the
// particle search does, with a fraction of its weighings; the first frame after a Reset and a
// jump beyond the search are never confirmed; confirm = false gives the particle search's
// results; and the stats (TrackStats) count searches, confirmations and weighings.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "posefilter/metrics.h"
#include "posefilter/synth.h"
#include "posefilter/tracker.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::ExpectInvalid;

SynthOptions ConfirmSeqOptions() {
  SynthOptions so;
  so.target = "lshape";
  so.clutter = 2;
  so.false_positives = 0;
  return so;
}

TrackOptions ConfirmTrackOptions(bool confirm) {
  TrackOptions o;
  o.filter.seed = 7;
  o.filter.threads = 1;
  o.confirm = confirm;
  return o;
}

struct ConfirmRun {
  std::vector<TrackResult> results;  // one per frame
  TrackStats stats;
};

// Tracks the L-shape of `seq` from a Reset at frame 0's ground truth, without a stage 1.
ConfirmRun TrackSequence(const std::vector<SynthScene>& seq, const TrackOptions& o) {
  Tracker tracker({seq[0].target}, o);
  tracker.Reset("lshape", seq[0].gt[0].T_cam_obj);
  ConfirmRun run;
  for (const SynthScene& s : seq) run.results.push_back(tracker.Track(SceneInput{s.depth, s.camera}).at(0));
  run.stats = tracker.stats();
  return run;
}

bool FoundInFrame(const SynthScene& s, const TrackResult& r) {
  const PoseErrors e = ComputePoseErrors(SamplePoints(s.target), s.target.Diameter(), r.T_cam_obj, s.gt[0].T_cam_obj);
  return e.adds_ok && r.status != TrackStatus::kLost;
}

class TrackerConfirmTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // 1 cm and 0.05 rad per frame; and 5 mm per frame with a 15 cm jump at frame 3.
    moving_ = new std::vector<SynthScene>(MakeSynthSequence(ConfirmSeqOptions(), SynthMotion{10, 0.01, 0.05}, 31));
    jump_ = new std::vector<SynthScene>(MakeSynthSequence(ConfirmSeqOptions(), SynthMotion{5, 0.005, 0.0, 3, 0.15}, 32));
  }
  static void TearDownTestSuite() {
    delete moving_;
    delete jump_;
    moving_ = jump_ = nullptr;
  }
  inline static std::vector<SynthScene>* moving_ = nullptr;
  inline static std::vector<SynthScene>* jump_ = nullptr;
};

TEST_F(TrackerConfirmTest, ConfirmedFramesTrackAsTheSearchDoesWithFarFewerWeighings) {
  const std::vector<SynthScene>& seq = *moving_;
  const ConfirmRun on = TrackSequence(seq, ConfirmTrackOptions(true));
  const ConfirmRun off = TrackSequence(seq, ConfirmTrackOptions(false));
  int found_on = 0, found_off = 0;
  for (std::size_t t = 0; t < seq.size(); ++t) {
    found_on += FoundInFrame(seq[t], on.results[t]);
    found_off += FoundInFrame(seq[t], off.results[t]);
    EXPECT_EQ(on.results[t].status, TrackStatus::kTracked) << "frame " << t;
    EXPECT_FALSE(off.results[t].confirmed) << "frame " << t;
    if (on.results[t].confirmed) {
      EXPECT_EQ(on.results[t].iterations, 1) << "frame " << t << ": one weighing of the prediction";
      EXPECT_GE(on.results[t].weight, ConfirmTrackOptions(true).refresh_weight) << "frame " << t;
    }
  }
  EXPECT_EQ(found_on, int(seq.size()));
  EXPECT_GE(found_on, found_off);
  EXPECT_FALSE(on.results[0].confirmed) << "no reference weight after a Reset: the first frame is searched";
  EXPECT_EQ(on.stats.searches, int(seq.size()));
  EXPECT_EQ(off.stats.searches, int(seq.size()));
  EXPECT_EQ(off.stats.confirmed, 0);
  EXPECT_GE(on.stats.confirmed, int(seq.size()) / 2) << "most frames of a smooth motion are confirmed";
  int flagged = 0;
  for (const TrackResult& r : on.results) flagged += r.confirmed;
  EXPECT_EQ(flagged, on.stats.confirmed);
  EXPECT_LT(2 * on.stats.weighings, off.stats.weighings) << "the confirmations weigh far less than the searches";
}

TEST_F(TrackerConfirmTest, ASearchAfterAFailedConfirmationEndsAtTheReferenceWeight) {
  // Confirmations that never pass (a floor of 0.999): every frame is searched, and each search
  // after the first has a reference to end at. With the filter's own confidence stop off
  // (1.0), it finds every frame with fewer weighings than the searches without the
  // confirmation, which run to their last iteration or stall, and each of its searches that
  // ended early (before the stall rule could end it: 2 iterations without gain) reached the
  // reference.
  const std::vector<SynthScene>& seq = *moving_;
  TrackOptions failing = ConfirmTrackOptions(true);
  failing.refresh_weight = 0.999;
  failing.filter.stop.confidence = 1.0;
  const ConfirmRun on = TrackSequence(seq, failing);
  TrackOptions off_options = ConfirmTrackOptions(false);
  off_options.refresh_weight = 0.999;
  off_options.filter.stop.confidence = 1.0;
  const ConfirmRun off = TrackSequence(seq, off_options);
  EXPECT_EQ(on.stats.confirmed, 0);
  double reference = on.results[0].weight;
  int ended_at_reference = 0;
  for (std::size_t t = 0; t < seq.size(); ++t) {
    EXPECT_TRUE(FoundInFrame(seq[t], on.results[t])) << "frame " << t;
    if (t > 0 && on.results[t].iterations < failing.filter.stop.stall_iterations + 1) {
      EXPECT_GE(on.results[t].weight, reference) << "frame " << t << " ended before its stall rule could end it";
      ++ended_at_reference;
    }
    reference = on.results[t].weight;
  }
  EXPECT_GT(ended_at_reference, 0);
  EXPECT_LT(on.stats.weighings, off.stats.weighings);
}

TEST_F(TrackerConfirmTest, AJumpIsNotConfirmedAndConfirmOffGivesTheParticleSearchAlone) {
  const std::vector<SynthScene>& seq = *jump_;
  const ConfirmRun on = TrackSequence(seq, ConfirmTrackOptions(true));
  ASSERT_EQ(on.results.size(), seq.size());
  EXPECT_FALSE(on.results[3].confirmed) << "the prediction does not explain the jumped object's depth";
  EXPECT_EQ(on.results[3].status, TrackStatus::kLost);
  for (std::size_t t = 0; t < 3; ++t) EXPECT_TRUE(FoundInFrame(seq[t], on.results[t])) << "frame " << t;

  // Without the confirmation every frame is the particle search of the same stream: two
  // trackers agree bit for bit, and the first frame (never confirmed) equals the run above.
  const ConfirmRun off = TrackSequence(seq, ConfirmTrackOptions(false));
  const ConfirmRun off_again = TrackSequence(seq, ConfirmTrackOptions(false));
  for (std::size_t t = 0; t < seq.size(); ++t) {
    EXPECT_TRUE(off.results[t].T_cam_obj.matrix() == off_again.results[t].T_cam_obj.matrix()) << t;
    EXPECT_EQ(off.results[t].weight, off_again.results[t].weight) << t;
  }
  EXPECT_TRUE(off.results[0].T_cam_obj.matrix() == on.results[0].T_cam_obj.matrix());
  EXPECT_EQ(off.results[0].weight, on.results[0].weight);
}

TEST(TrackConfirmOptionsTest, ConfirmMarginIsCheckedAndItsEdgesAreValid) {
  TrackOptions o;
  o.confirm_margin = -0.01;
  ExpectInvalid(o, "confirm_margin must be in [0, 1] (got -0.01)");
  o.confirm_margin = 1.5;
  ExpectInvalid(o, "confirm_margin");
  std::string why;
  for (double edge : {0.0, 1.0}) {
    o.confirm_margin = edge;
    EXPECT_TRUE(o.IsValid(&why)) << edge << ": " << why;
  }
}

}  // namespace
}  // namespace posefilter
