// Synthetic moving-target sequences (SynthMotion, MakeSynthSequence, WriteSynthSequence): the
// motion's ranges, frame 0 = MakeSynthScene, the target's motion (a turn about the table's
// normal through its footprint centre plus an in-plane slide, and the jump), the sensor noise
// drawn anew per frame, the refusal of an occluder, and the dataset folder a sequence is
// written as.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "posefilter/bop.h"
#include "posefilter/error.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectError;
using testing_util::ExpectInvalid;

SynthOptions Lshape(int clutter = 2) {
  SynthOptions o;
  o.target = "lshape";
  o.clutter = clutter;
  o.false_positives = 0;
  return o;
}

TEST(SynthMotionTest, DefaultsAndRangeEdgesAreValidAndEachBadFieldIsNamed) {
  std::string why;
  EXPECT_TRUE(SynthMotion{}.IsValid(&why)) << why;
  for (const SynthMotion& ok : {SynthMotion{1, 0, 0}, SynthMotion{1000, 0.5, M_PI}, SynthMotion{5, 0.01, -M_PI, 1, 0},
                                SynthMotion{5, 0.01, 0.1, 4, 1.0}, SynthMotion{5, 0.01, 0.1, -1, 0.3}})
    EXPECT_TRUE(ok.IsValid(&why)) << why;
  const double nan = std::nan("");
  ExpectInvalid(SynthMotion{0, 0.01, 0}, "frames");
  ExpectInvalid(SynthMotion{1001, 0.01, 0}, "frames");
  ExpectInvalid(SynthMotion{5, -0.01, 0}, "speed_m");
  ExpectInvalid(SynthMotion{5, 0.51, 0}, "speed_m");
  ExpectInvalid(SynthMotion{5, nan, 0}, "speed_m");
  ExpectInvalid(SynthMotion{5, 0.01, 3.2}, "turn_rad");
  ExpectInvalid(SynthMotion{5, 0.01, -3.2}, "turn_rad");
  ExpectInvalid(SynthMotion{5, 0.01, nan}, "turn_rad");
  ExpectInvalid(SynthMotion{5, 0.01, 0, -2, 0.1}, "jump_frame");
  ExpectInvalid(SynthMotion{5, 0.01, 0, 5, 0.1}, "jump_frame");
  ExpectInvalid(SynthMotion{5, 0.01, 0, 2, -0.1}, "jump_m");
  ExpectInvalid(SynthMotion{5, 0.01, 0, 2, 1.5}, "jump_m");
  ExpectInvalid(SynthMotion{5, 0.01, 0, 2, nan}, "jump_m");
  EXPECT_FALSE((SynthMotion{0, 0, 0}.IsValid(nullptr)));
}

TEST(SynthSequenceTest, RejectsBadMotionBadOptionsAndAnOccluder) {
  ExpectError([] { MakeSynthSequence(Lshape(), SynthMotion{0, 0.01, 0}, 1); }, {"synth motion", "frames"});
  ExpectError([] { MakeSynthSequence(Lshape(), SynthMotion{3, 0.01, 0, 3, 0.1}, 1); }, {"jump_frame"});
  SynthOptions occluded = Lshape();
  occluded.occlusion = 0.3;
  ExpectError([&] { MakeSynthSequence(occluded, SynthMotion{3, 0.01, 0}, 1); }, {"occlusion must be 0"});
  SynthOptions bad = Lshape();
  bad.target = "teapot";
  ExpectError([&] { MakeSynthSequence(bad, SynthMotion{3, 0.01, 0}, 1); }, {"synth options", "teapot"});
}

// Frame 0 of a sequence is MakeSynthScene(opt, seed), bit for bit. The clutter must keep
// clear of the whole path of a sequence's target, while frame 0 must equal a scene that knows
// of no path: checked over several seeds and a long fast path with much clutter.
void ExpectFrameZeroIsTheScene(const SynthOptions& opt, const SynthMotion& motion, std::uint64_t seed) {
  const std::vector<SynthScene> seq = MakeSynthSequence(opt, motion, seed);
  ASSERT_EQ(seq.size(), std::size_t(motion.frames));
  const SynthScene one = MakeSynthScene(opt, seed);
  const SynthScene& f0 = seq[0];
  EXPECT_TRUE(f0.depth.data == one.depth.data) << "seed " << seed << ": depth differs";
  EXPECT_TRUE(f0.labels == one.labels) << "seed " << seed << ": labels differ";
  ASSERT_EQ(f0.gt.size(), 1u);
  EXPECT_TRUE(f0.gt[0].T_cam_obj.matrix() == one.gt[0].T_cam_obj.matrix()) << seed;
  EXPECT_EQ(f0.raw_pyramid, one.raw_pyramid) << seed;
  ASSERT_EQ(f0.detections.size(), one.detections.size()) << seed;
  for (std::size_t i = 0; i < f0.detections.size(); ++i) {
    EXPECT_EQ(f0.detections[i].cls, one.detections[i].cls);
    EXPECT_EQ(f0.detections[i].score, one.detections[i].score);
    EXPECT_EQ(f0.detections[i].x, one.detections[i].x);
    EXPECT_EQ(f0.detections[i].w, one.detections[i].w);
  }
  EXPECT_EQ(f0.distance_m, one.distance_m);
  EXPECT_EQ(f0.table_angle_rad, one.table_angle_rad);
  EXPECT_EQ(f0.occlusion_achieved, one.occlusion_achieved);
}

TEST(SynthSequenceTest, FrameZeroIsMakeSynthSceneBitForBit) {
  ExpectFrameZeroIsTheScene(Lshape(2), SynthMotion{6, 0.01, 0.05}, 21);
  ExpectFrameZeroIsTheScene(Lshape(0), SynthMotion{3, 0.02, -0.1}, 4);
  SynthOptions box = Lshape(3);
  box.target = "box";
  box.false_positives = 2;
  ExpectFrameZeroIsTheScene(box, SynthMotion{2, 0.0, 0.0}, 7);
}

// Where a clutter placement of the single scene would stand on the target's path, the
// sequence places that object elsewhere, so frame 0 differs from MakeSynthScene there (seeds 4
// and 9 of the lshape with clutter 3 and 10 frames of 1 cm / 0.05 rad); the table, the target's
// pose and the detections stay the scene's.
TEST(SynthSequenceTest, FrameZeroKeepsTheScenesTargetWhenThePathCrossesClutter) {
  SynthOptions o;
  o.target = "lshape";
  for (std::uint64_t seed : {4, 9}) {
    const SynthScene one = MakeSynthScene(o, seed);
    const SynthScene f0 = MakeSynthSequence(o, SynthMotion{10, 0.01, 0.05}, seed).front();
    EXPECT_TRUE(f0.gt[0].T_cam_obj.matrix() == one.gt[0].T_cam_obj.matrix()) << seed;
    EXPECT_EQ(f0.table_angle_rad, one.table_angle_rad) << seed;
    EXPECT_EQ(f0.gt_box.cx, one.gt_box.cx) << seed;
    EXPECT_FALSE(f0.depth.data == one.depth.data) << seed << ": the clutter on the path should have moved";
  }
}

// The table's upward normal u (SynthScene::table_angle_rad α: u = (0, −cos α, −sin α)).
Eigen::Vector3d TableNormal(const SynthScene& s) {
  return Eigen::Vector3d(0, -std::cos(s.table_angle_rad), -std::sin(s.table_angle_rad));
}

// min over the target's vertices of u·(T v): the height of its lowest point along u.
double Lowest(const SynthScene& s, const Eigen::Vector3d& u) {
  double lo = INFINITY;
  for (const auto& v : s.target.vertices) lo = std::min(lo, u.dot(s.gt[0].T_cam_obj * v.cast<double>()));
  return lo;
}

// Checks the motion of `seq` against `m`: per frame, a turn by turn_rad about the table normal
// through the footprint centre, and a slide of speed_m (+ jump_m from jump_frame on) along
// one fixed direction of the table plane; the lowest point stays on the table.
void ExpectTheMotion(const std::vector<SynthScene>& seq, const SynthMotion& m) {
  ASSERT_EQ(seq.size(), std::size_t(m.frames));
  const Eigen::Vector3d u = TableNormal(seq[0]);
  const Eigen::Isometry3d T0 = seq[0].gt[0].T_cam_obj;
  const Eigen::Vector3d centre = T0 * (0.5f * (seq[0].target.Min() + seq[0].target.Max())).cast<double>();
  const double table_k = Lowest(seq[0], u);
  const Eigen::Vector3d foot = centre + u * (table_k - u.dot(centre));  // on the table, below the centre
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();
  for (std::size_t t = 0; t < seq.size(); ++t) {
    const SynthScene& s = seq[t];
    const Eigen::Isometry3d& T = s.gt[0].T_cam_obj;
    // Camera, table and sizes stay.
    EXPECT_EQ(s.table_angle_rad, seq[0].table_angle_rad);
    EXPECT_EQ(s.distance_m, seq[0].distance_m);
    EXPECT_EQ(s.target.vertices, seq[0].target.vertices);
    EXPECT_NEAR(Lowest(s, u), table_k, 1e-9) << "frame " << t << ": the target left the table plane";
    if (t > 0) {
      // The turn between consecutive frames: turn_rad about ±u.
      const Eigen::AngleAxisd step(T.linear() * seq[t - 1].gt[0].T_cam_obj.linear().transpose());
      EXPECT_NEAR(step.angle(), std::fabs(m.turn_rad), 1e-9) << "frame " << t;
      if (std::fabs(m.turn_rad) > 1e-3)
        EXPECT_NEAR(step.axis().dot(u), m.turn_rad > 0 ? 1.0 : -1.0, 1e-9) << "frame " << t << ": not about the table normal";
    }
    // The footprint centre (the turn's pivot) slides along one direction of the table plane.
    const Eigen::Vector3d moved = T * T0.inverse() * foot - foot;
    const double slide = m.speed_m * double(t) + (m.jump_frame >= 0 && int(t) >= m.jump_frame ? m.jump_m : 0.0);
    EXPECT_NEAR(moved.norm(), slide, 1e-9) << "frame " << t;
    EXPECT_NEAR(moved.dot(u), 0.0, 1e-9) << "frame " << t << ": the slide leaves the table plane";
    if (slide > 1e-6 && moved.norm() > 1e-6) {
      if (dir.isZero()) dir = moved.normalized();
      EXPECT_NEAR(moved.normalized().dot(dir), 1.0, 1e-9) << "frame " << t << ": the slide changed direction";
    }
  }
}

TEST(SynthSequenceTest, TheTargetTurnsAboutTheTableNormalAndSlidesAlongTheTable) {
  const SynthMotion m = SynthMotion{6, 0.01, 0.05};
  const std::vector<SynthScene> seq = MakeSynthSequence(Lshape(), m, 21);
  ExpectTheMotion(seq, m);
  // The target's silhouette, box and detection follow it.
  const Box& b0 = seq.front().gt_box;
  const Box& b5 = seq.back().gt_box;
  EXPECT_TRUE(b0.cx != b5.cx || b0.cy != b5.cy || b0.w != b5.w || b0.h != b5.h) << "the gt box did not move";
  for (std::size_t t = 1; t < seq.size(); ++t) {
    EXPECT_FALSE(seq[t].labels == seq[t - 1].labels) << t;
    ASSERT_FALSE(seq[t].detections.empty());
    EXPECT_EQ(seq[t].detections[0].cls, "lshape");
    const double dcx = seq[t].detections[0].x + 0.5 * seq[t].detections[0].w - seq[t].gt_box.cx;
    EXPECT_LT(std::fabs(dcx), 0.3 * seq[t].gt_box.w) << t;  // centre noise ≤ a quarter of the box (+ size noise)
    std::size_t target_px = 0;
    for (int l : seq[t].labels) target_px += l == 1;
    EXPECT_GT(target_px, 100u) << t;
    EXPECT_GE(seq[t].occlusion_achieved, 0.0);
    EXPECT_LE(seq[t].occlusion_achieved, 1.0);
  }
  // A negative turn, no slide.
  const SynthMotion back = SynthMotion{4, 0.0, -0.2};
  ExpectTheMotion(MakeSynthSequence(Lshape(0), back, 8), back);
}

TEST(SynthSequenceTest, TheJumpDisplacesTheTargetFromTheJumpFrameOn) {
  const SynthMotion m = SynthMotion{5, 0.005, 0.0, 2, 0.15};
  const std::vector<SynthScene> seq = MakeSynthSequence(Lshape(), m, 22);
  ExpectTheMotion(seq, m);
  const double step01 = (seq[1].gt[0].T_cam_obj.translation() - seq[0].gt[0].T_cam_obj.translation()).norm();
  const double step12 = (seq[2].gt[0].T_cam_obj.translation() - seq[1].gt[0].T_cam_obj.translation()).norm();
  const double step23 = (seq[3].gt[0].T_cam_obj.translation() - seq[2].gt[0].T_cam_obj.translation()).norm();
  EXPECT_NEAR(step01, 0.005, 1e-9);  // no turn: the whole object slides
  EXPECT_NEAR(step12, 0.155, 1e-9);
  EXPECT_NEAR(step23, 0.005, 1e-9);
}

// Frame 0 is the scene as the seed makes it, so a jump starts at frame 1 at the earliest.
TEST(SynthSequenceTest, AJumpAtFrameZeroIsRefused) {
  ExpectInvalid(SynthMotion{3, 0.01, 0.0, 0, 0.05}, "jump_frame");
}

TEST(SynthSequenceTest, TheSensorNoiseIsDrawnAnewPerFrameAndTheWorldStays) {
  // No motion: every frame shows the same world; only the noise (and holes and jitter) differ.
  SynthOptions noise_only = Lshape();
  noise_only.hole_fraction = 0;
  const std::vector<SynthScene> noisy = MakeSynthSequence(noise_only, SynthMotion{3, 0, 0}, 5);
  EXPECT_TRUE(noisy[1].gt[0].T_cam_obj.matrix() == noisy[0].gt[0].T_cam_obj.matrix());
  EXPECT_TRUE(noisy[1].labels == noisy[0].labels);
  EXPECT_FALSE(noisy[1].depth.data == noisy[0].depth.data);
  EXPECT_FALSE(noisy[2].depth.data == noisy[1].depth.data);
  // Without noise, holes and box jitter the frames are identical.
  SynthOptions clean = Lshape();
  clean.noise_sigma_m = 0;
  clean.hole_fraction = 0;
  clean.box_jitter_px = 0;
  const std::vector<SynthScene> still = MakeSynthSequence(clean, SynthMotion{3, 0, 0}, 5);
  for (std::size_t t = 1; t < still.size(); ++t) {
    EXPECT_TRUE(still[t].depth.data == still[0].depth.data) << t;
    EXPECT_TRUE(still[t].labels == still[0].labels) << t;
    ASSERT_EQ(still[t].detections.size(), still[0].detections.size());
    EXPECT_EQ(still[t].detections[0].x, still[0].detections[0].x) << t;
  }
  // Deterministic per seed.
  const std::vector<SynthScene> again = MakeSynthSequence(noise_only, SynthMotion{3, 0, 0}, 5);
  for (std::size_t t = 0; t < again.size(); ++t) EXPECT_TRUE(again[t].depth.data == noisy[t].depth.data) << t;
}

TEST(SynthSequenceTest, ATargetThatLeavesTheImageIsStillMadeWithItsGroundTruth) {
  SynthOptions o = Lshape(0);
  const SynthMotion m = SynthMotion{8, 0.15, 0.1};
  std::vector<SynthScene> seq;
  ASSERT_NO_THROW(seq = MakeSynthSequence(o, m, 23));
  ExpectTheMotion(seq, m);
  std::size_t gone = 0;
  for (const SynthScene& s : seq) {
    std::size_t target_px = 0;
    for (int l : s.labels) target_px += l == 1;
    gone += target_px == 0;
    EXPECT_TRUE(s.gt[0].T_cam_obj.matrix().allFinite());
    EXPECT_GE(s.occlusion_achieved, 0.0);
    EXPECT_LE(s.occlusion_achieved, 1.0);
  }
  EXPECT_GE(gone, 1u) << "the target should have left the image";
}

TEST(SynthSequenceTest, WriteSynthSequenceWritesADatasetFolderThatReadsBack) {
  testing_util::ScratchDir dir("synth_sequence");
  const std::vector<SynthScene> seq = MakeSynthSequence(Lshape(), SynthMotion{3, 0.01, 0.05}, 21);
  const std::string root = dir.Path("seq");
  WriteSynthSequence(seq, root, "walk");
  EXPECT_TRUE(fs::exists(fs::path(root) / "models" / "lshape.ply"));
  for (const char* f : {"walk_0000_000001", "walk_0000_000002", "walk_0000_000003"})
    for (const char* file : {"depth.png", "camera.json", "gt.json", "detections.json", "label.png"})
      EXPECT_TRUE(fs::exists(fs::path(root) / "scenes" / f / file)) << f << "/" << file;
  EXPECT_FALSE(fs::exists(fs::path(root) / "scenes" / "walk_0000_000004"));

  const Dataset ds = OpenDataset(root, "test");
  ASSERT_EQ(ds.images.size(), 3u);
  ASSERT_EQ(ds.models.size(), 1u);
  EXPECT_EQ(ds.models[0].name, "lshape");
  for (std::size_t t = 0; t < 3; ++t) {
    const DatasetImage& im = ds.images[t];
    EXPECT_EQ(im.scene_id, 0);
    EXPECT_EQ(im.im_id, int(t) + 1);
    ASSERT_EQ(im.gt.size(), 1u);
    EXPECT_TRUE(im.gt[0].T_cam_obj.isApprox(seq[t].gt[0].T_cam_obj, 1e-6)) << t;
    const SceneInput in = LoadDatasetScene(im);
    ASSERT_EQ(in.depth.data.size(), seq[t].depth.data.size());
    for (std::size_t i = 0; i < in.depth.data.size(); i += 97)
      ASSERT_NEAR(in.depth.data[i], seq[t].depth.data[i], 1e-6) << t << " " << i;
  }
  // The default name is "synth".
  WriteSynthSequence({seq[0]}, dir.Path("one"));
  EXPECT_TRUE(fs::exists(fs::path(dir.Path("one")) / "scenes" / "synth_0000_000001" / "depth.png"));

  ExpectError([&] { WriteSynthSequence({}, dir.Path("none")); }, {"no frames"});
  ExpectError([&] { WriteSynthSequence(seq, dir.Path("bad"), "a/b"); }, {"'a/b'", "plain file-name stem"});
  ExpectError([&] { WriteSynthSequence(seq, dir.Path("bad"), ""); }, {"plain file-name stem"});
}

}  // namespace
}  // namespace posefilter
