// The hw design under hardware semantics (src/hw/hls_types/hls_sim.h, src/hw/dataflow.h):
// bounded streams and concurrent dataflow processes in C simulation. ctest LABEL hw_bounded
// (tests/CMakeLists.txt), suites HwBounded*.
//
//   HwBoundedSim    — the simulation itself: a producer and a consumer called in sequence
//                     through a shallow stream deadlock and the report names the stream; the
//                     same pair as a dataflow region runs; a stream holds its declared depth;
//                     an empty read nobody serves is a deadlock; test-bench streams stay
//                     unbounded; a deadlock report is the same on every run.
//   HwBoundedTops   — every top (HwInitTop, HwWeighTop5, the engine's HwWeighTop<10>,
//                     HwUpdateTop) with bounded streams and concurrent processes gives the
//                     sequential model's outputs bit for bit: HwWeighTop5 directly on the
//                     2048-face torus with 510 particles (and the same cycle trace); the whole
//                     hw engine (every top, each iteration) on the torus with 96 particles;
//                     with every FIFO one deep, the same results.
//   HwBoundedLong   — the whole hw engine with 510 particles on the torus and on a real
//                     YCB-Video frame, with its mesh at the engine's level of detail and the
//                     windows the frame's box gives (ctest LABEL long: outside scripts/test.sh).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hw/cycle_model.h"
#include "hw/dataflow.h"
#include "hw/top.h"
#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/filter.h"
#include "posefilter/hw_engine.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/scene_io.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using namespace posefilter::hw;
using hls::sim::Deadlock;
using hls::sim::Mode;
using hls::sim::ScopedMode;

// ---------------------------------------------------------------------------------------------
// The simulation.

void Produce(int n, hls::stream<int>& out) {
  for (int i = 0; i < n; ++i) out.write(i);
}
void Consume(int n, hls::stream<int>& in, long* sum) {
  for (int i = 0; i < n; ++i) *sum += in.read();
}

// The negative control: a producer and its consumer called one after the other inside one
// process, through a stream of depth 2 — what a process that calls two stages without a
// DATAFLOW region between them builds.
void InSequence(int n, long* sum) {
  hls::stream<int> shallow;
  HW_STREAM(shallow, 2);
  Produce(n, shallow);
  Consume(n, shallow, sum);
}
void InSequenceRegion(int n, long* sum) {
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, nullptr);
  HW_PROCESS(df, InSequence(n, sum));
  HW_DATAFLOW_END(df);
}

// The same two as a dataflow region.
void Concurrent(int n, long* sum) {
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, nullptr);
  hls::stream<int> pipe;
  HW_STREAM(pipe, 2);
  HW_PROCESS(df, Produce(n, pipe));
  HW_PROCESS(df, Consume(n, pipe, sum));
  HW_DATAFLOW_END(df);
}

std::string DeadlockMessage(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const Deadlock& e) {
    return e.what();
  }
  return "";
}

TEST(HwBoundedSim, ProducerThenConsumerThroughAShallowStreamIsADeadlockNamingTheStream) {
  const ScopedMode bounded(Mode::kBounded);
  long sum = 0;
  const std::string msg = DeadlockMessage([&] { InSequenceRegion(3, &sum); });
  ASSERT_FALSE(msg.empty()) << "three writes into a depth-2 stream nobody reads yet did not deadlock";
  EXPECT_NE(msg.find("InSequence: write to 'shallow', full (2 of 2)"), std::string::npos) << msg;
  // Two elements fit: the same sequence with n = 2 completes.
  sum = 0;
  InSequenceRegion(2, &sum);
  EXPECT_EQ(sum, 1);
  // Sequential C simulation (the vendor's model) cannot see it.
  const ScopedMode sequential(Mode::kSequential);
  sum = 0;
  InSequenceRegion(1000, &sum);
  EXPECT_EQ(sum, 999L * 1000 / 2);
}

TEST(HwBoundedSim, TheSamePairAsADataflowRegionStreamsThroughTwoSlots) {
  const ScopedMode bounded(Mode::kBounded);
  long sum = 0;
  Concurrent(100000, &sum);
  EXPECT_EQ(sum, 99999L * 100000 / 2);
}

// A process that fills a stream with write_nb until it is refused, and one that then drains it.
void FillUntilFull(hls::stream<int>& s, int* accepted) {
  *accepted = 0;
  while (s.write_nb(*accepted)) ++*accepted;
}
void Drain(hls::stream<int>& s, const int* accepted, long* sum) {
  for (int i = 0; i < *accepted; ++i) *sum += s.read();
}
void DepthProbe(int* deep, int* dflt, long* sum) {
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, nullptr);
  hls::stream<int> deep_s, default_s;
  HW_STREAM(deep_s, 24);
  HW_PROCESS(df, FillUntilFull(deep_s, deep));
  HW_PROCESS(df, FillUntilFull(default_s, dflt));
  HW_PROCESS_AFTER(df, "FillUntilFull", Drain(deep_s, deep, sum));
  HW_PROCESS_AFTER(df, "FillUntilFull#1", Drain(default_s, dflt, sum));
  HW_DATAFLOW_END(df);
}

TEST(HwBoundedSim, AStreamHoldsItsDeclaredDepthAndTwoWhenUndeclared) {
  const ScopedMode bounded(Mode::kBounded);
  int deep = 0, dflt = 0;
  long sum = 0;
  DepthProbe(&deep, &dflt, &sum);
  EXPECT_EQ(deep, 24);
  EXPECT_EQ(dflt, 2);  // Vitis's default FIFO depth
  EXPECT_EQ(sum, 23L * 24 / 2 + 1);
}

void ReadNobodyWrites(hls::stream<int>& in, long* sum) { *sum += in.read(); }
void StarvedRegion(long* sum) {
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, nullptr);
  hls::stream<int> never;
  HW_STREAM(never, 2);
  HW_PROCESS(df, Produce(0, never));
  HW_PROCESS(df, ReadNobodyWrites(never, sum));
  HW_DATAFLOW_END(df);
}

TEST(HwBoundedSim, AReadNobodyServesIsADeadlockNamingTheEmptyStream) {
  const ScopedMode bounded(Mode::kBounded);
  long sum = 0;
  const std::string first = DeadlockMessage([&] { StarvedRegion(&sum); });
  EXPECT_NE(first.find("ReadNobodyWrites: read from 'never', empty (0 of 2)"), std::string::npos) << first;
  // Cooperative scheduling: the same report on every run.
  EXPECT_EQ(DeadlockMessage([&] { StarvedRegion(&sum); }), first);
}

TEST(HwBoundedSim, StreamsOutsideARegionStayUnbounded) {
  const ScopedMode bounded(Mode::kBounded);
  hls::stream<int> bench;  // a test bench's stream
  HW_STREAM(bench, 2);
  for (int i = 0; i < 100; ++i) bench.write(i);
  EXPECT_FALSE(bench.bounded());
  long sum = 0;
  Consume(100, bench, &sum);
  EXPECT_EQ(sum, 99L * 100 / 2);
}

// ---------------------------------------------------------------------------------------------
// The weigh tops on the torus, directly.

struct WeighProblem {
  std::unique_ptr<depth_t[]> depth{new depth_t[kImageHeight * kImageWidth]};
  xyz_t vmem[3][kMaxVertices];
  face_t tri_mem[kMaxFaces];
  Window cell_windows[kNumCells];
  prob_t class_prob[kNumCells];
  Sample samples[kMaxParticles];
  WeighConfig cfg{};
  int n = 0;
};

// The synthetic torus scene (2048 faces) and n particles spread around its pose, in cells whose
// windows cover the object (up to 200 × 200 px, grown per particle).
void MakeTorusProblem(WeighProblem* wp, int n) {
  SynthOptions so;
  so.target = "torus";
  const SynthScene scene = MakeSynthScene(so, 3);
  const Mesh& mesh = scene.target;
  ASSERT_EQ(mesh.faces.size(), 2048u);
  ASSERT_LE(mesh.vertices.size(), std::size_t(kMaxVertices));
  for (int v = 0; v < kImageHeight; ++v)
    for (int u = 0; u < kImageWidth; ++u)
      wp->depth[v * kImageWidth + u] =
          depth_t(ap_ufixed<12, 2, AP_RND, AP_SAT>(std::min(4.0, double(scene.depth.at(u, v)))));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) wp->vmem[k][i] = xyz_t(ap_fixed<13, 3, AP_RND>(double(mesh.vertices[i][k])));
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    wp->tri_mem[f] = PackFace(mesh.faces[f][0], mesh.faces[f][1], mesh.faces[f][2]);
  const Eigen::Vector2d c = scene.camera.Project(scene.gt[0].T_cam_obj.translation());
  for (int cell = 0; cell < kNumCells; ++cell) {
    wp->cell_windows[cell] = SaturatedWindow(int(c.x()) - 60 + (cell % 11) * 4, int(c.y()) - 60 + (cell % 7) * 4,
                                             110 + cell % 90, 100 + cell % 100, kImageWidth, kImageHeight);
    wp->class_prob[cell] = prob_t(ap_ufixed<8, 0, AP_RND>((cell % 10) / 10.0));
  }
  const Pose6 gt = TransformToPose(scene.gt[0].T_cam_obj);  // base = camera
  for (int p = 0; p < n; ++p) {
    Sample& s = wp->samples[p];
    const double d = ((p * 7) % 9 - 4) * 0.006, a = ((p * 5) % 7 - 3) * 0.15;
    s.x = xyz_t(ap_fixed<13, 3, AP_RND>(gt.x + d));
    s.y = xyz_t(ap_fixed<13, 3, AP_RND>(gt.y - 0.5 * d));
    s.z = xyz_t(ap_fixed<13, 3, AP_RND>(gt.z + d));
    s.roll = angle_t(ap_fixed<12, 4, AP_RND>(gt.roll + a));
    s.pitch = angle_t(ap_fixed<12, 4, AP_RND>(gt.pitch - 0.5 * a));
    s.yaw = angle_t(ap_fixed<12, 4, AP_RND>(gt.yaw + a));
    s.cell = (p * 37) % kNumCells;
  }
  wp->n = n;
  WeighConfig& cfg = wp->cfg;
  cfg.num_faces = int(mesh.faces.size());
  cfg.img_width = kImageWidth;
  cfg.img_height = kImageHeight;
  cfg.cam.fx = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.fx));
  cfg.cam.fy = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.fy));
  cfg.cam.cx = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.cx));
  cfg.cam.cy = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.cy));
  for (int k = 0; k < 9; ++k) cfg.cam.rot[k] = trig_t(k % 4 == 0 ? 1.0 : 0.0);
  for (int k = 0; k < 3; ++k) cfg.cam.trans[k] = ctrans_t(0.0);
  cfg.raster = DefaultRasterParams();
  cfg.weight = DefaultWeightParams();
  cfg.grow_window = 1;
  cfg.max_window = kMaxWindow;
  Eigen::Vector3f lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 3; ++j) cfg.bbox[k][j] = xyz_t(ap_fixed<13, 3, AP_RND>(double((k >> j) & 1 ? hi[j] : lo[j])));
}

// Every output word of one weigh-top call, and its trace.
struct WeighWords {
  std::vector<std::uint64_t> words;
  std::unique_ptr<CycleTrace> trace{new CycleTrace};
};

template <typename T>
void Push(std::vector<std::uint64_t>* w, const T& x) {
  w->push_back(ap_uint<64>(x.range()).to_uint64());
}

void WeighTop(WeighProblem& wp, int cores, WeighWords* out) {
  auto w = std::make_unique<weight_t[]>(kMaxParticles);
  auto idx = std::make_unique<particle_index_t[]>(kMaxParticles);
  auto stats = std::make_unique<RasterCoreOutput[]>(kMaxParticles);
  auto offsets = std::make_unique<depth_off_t[]>(kMaxParticles);
  DepthDistributionCounts dd;
  wp.cfg.num_cores = cores;
  const ScopedTopTrace traced(out->trace.get());
  if (cores == 5)
    HwWeighTop5(wp.n, wp.cfg, wp.samples, wp.cell_windows, wp.class_prob, wp.depth.get(), wp.vmem, wp.tri_mem, w.get(),
                idx.get(), stats.get(), offsets.get(), &dd);
  else
    HwWeighTop10(wp.n, wp.cfg, wp.samples, wp.cell_windows, wp.class_prob, wp.depth.get(), wp.vmem, wp.tri_mem, w.get(),
                 idx.get(), stats.get(), offsets.get(), &dd);
  for (int p = 0; p < wp.n; ++p) {
    Push(&out->words, w[p]);
    Push(&out->words, idx[p]);
    Push(&out->words, offsets[p]);
    const RasterCoreOutput& o = stats[p];
    Push(&out->words, o.inlier_sum);
    Push(&out->words, o.n_raster);
    Push(&out->words, o.n_occluded);
    Push(&out->words, o.n_depth);
    Push(&out->words, o.depth_diff_sum);
    Push(&out->words, o.depth_diff_count);
    Push(&out->words, o.n_edge);
    Push(&out->words, o.n_edge_continued);
    Push(&out->words, o.faces_front);
    Push(&out->words, o.faces_total);
  }
  Push(&out->words, dd.reads_shared);
  Push(&out->words, dd.reads_unshared);
}

void ExpectSameTrace(const CycleTrace& a, const CycleTrace& b) {
  ASSERT_EQ(a.count, b.count);
  EXPECT_FALSE(a.overflowed);
  for (int r = 0; r < a.count; ++r) {
    EXPECT_STREQ(a.records[r].module, b.records[r].module) << r;
    EXPECT_STREQ(a.records[r].loop, b.records[r].loop) << r;
    EXPECT_EQ(a.records[r].trips, b.records[r].trips) << r;
    EXPECT_EQ(a.records[r].ii, b.records[r].ii) << r;
    EXPECT_EQ(a.records[r].depth, b.records[r].depth) << r;
  }
}

// HwWeighTop5 here; HwWeighTop<10> (the engine's) in the engine runs below.
TEST(HwBoundedTops, TheWeighTopOnTheTorusWith510ParticlesIsBitIdenticalToTheSequentialModel) {
  auto wp = std::make_unique<WeighProblem>();
  MakeTorusProblem(wp.get(), kMaxParticles);
  for (int cores : {5}) {
    WeighWords seq, bounded;
    {
      const ScopedMode mode(Mode::kSequential);
      WeighTop(*wp, cores, &seq);
    }
    {
      const ScopedMode mode(Mode::kBounded);
      WeighTop(*wp, cores, &bounded);
    }
    ASSERT_EQ(seq.words.size(), bounded.words.size());
    EXPECT_TRUE(seq.words == bounded.words) << cores << " cores: the bounded simulation's outputs differ";
    ExpectSameTrace(*seq.trace, *bounded.trace);
    // A real workload: most particles draw faces, and the cores' triangle FIFOs see more
    // than their 16 entries' worth of front faces per particle.
    const std::uint64_t front = LoopTrips(*seq.trace, "raster_core", "RC_VERTICES");
    EXPECT_EQ(front, 3u * 2048u * kMaxParticles);
  }
}

// Every FIFO of the weigh region one deep: the region only stalls more, it cannot deadlock
// (each process reads its streams in the order their producers write them), so the declared
// depths are a matter of throughput, not of correctness.
TEST(HwBoundedTops, WithEveryFifoOneDeepTheWeighTopsStillGiveTheSameResults) {
  auto wp = std::make_unique<WeighProblem>();
  MakeTorusProblem(wp.get(), 36);
  for (int cores : {5, 10}) {
    WeighWords seq, shallow;
    {
      const ScopedMode mode(Mode::kSequential);
      WeighTop(*wp, cores, &seq);
    }
    {
      const ScopedMode mode(Mode::kBounded);
      const hls::sim::ScopedDepthLimit one(1);
      WeighTop(*wp, cores, &shallow);
    }
    EXPECT_TRUE(seq.words == shallow.words) << cores << " cores";
  }
}

// ---------------------------------------------------------------------------------------------
// The whole hw engine: every top, every iteration.

FilterOptions BoundedRunOptions() {
  FilterOptions o;
  o.engine = "hw";
  o.num_particles = kHwMaxParticles;
  o.stop.max_iterations = 2;  // init, weigh, update, weigh
  o.restarts = 1;
  o.polish.steps = 0;  // the hardware's own answer
  o.seed = 7;
  return o;
}

void ExpectSameRun(const EstimateResult& a, const EstimateResult& b) {
  EXPECT_EQ(a.pose_base.x, b.pose_base.x);
  EXPECT_EQ(a.pose_base.y, b.pose_base.y);
  EXPECT_EQ(a.pose_base.z, b.pose_base.z);
  EXPECT_EQ(a.pose_base.roll, b.pose_base.roll);
  EXPECT_EQ(a.pose_base.pitch, b.pose_base.pitch);
  EXPECT_EQ(a.pose_base.yaw, b.pose_base.yaw);
  EXPECT_EQ(a.weight, b.weight);
  EXPECT_EQ(a.cell, b.cell);
  EXPECT_EQ(a.best_weight_history, b.best_weight_history);
  EXPECT_EQ(a.stats.fragments, b.stats.fragments);
  EXPECT_EQ(a.stats.weighings, b.stats.weighings);
  EXPECT_EQ(a.stats.faces_front, b.stats.faces_front);
  EXPECT_EQ(a.stats.init_cdf_reads, b.stats.init_cdf_reads);
  EXPECT_EQ(a.stats.resample_cdf_reads, b.stats.resample_cdf_reads);
}

EstimateResult RunIn(Mode mode, const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                     int particles) {
  const ScopedMode m(mode);
  FilterOptions o = BoundedRunOptions();
  o.num_particles = particles;
  return EstimatePose(scene, mesh, prior, cls, o);
}

// Every top of the engine (HwInitTop, HwWeighTop<10>, HwUpdateTop) on the torus scene with 96
// particles, and again with every FIFO one deep; the 510-particle runs are HwBoundedLong's.
// The synthetic torus scene (seed 3, 2048 faces) with its stage-1 prior: the engine runs' scene.
struct TorusEngineScene {
  SynthScene scene = MakeSynthScene(TorusOptions(), 3);
  Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
  int cls = prior.ClassIndex(scene.target.name);
  SceneInput in{scene.depth, scene.camera};
  static SynthOptions TorusOptions() {
    SynthOptions so;
    so.target = "torus";
    return so;
  }
};

TEST(HwBoundedTops, EveryTopOfTheEngineOnTheTorusIsBitIdenticalToTheSequentialModel) {
  const TorusEngineScene t;
  const SynthScene& scene = t.scene;
  const Prior& prior = t.prior;
  const int cls = t.cls;
  const SceneInput& in = t.in;
  ASSERT_EQ(scene.target.faces.size(), 2048u);
  const EstimateResult seq = RunIn(Mode::kSequential, in, scene.target, prior, cls, 96);
  const EstimateResult bounded = RunIn(Mode::kBounded, in, scene.target, prior, cls, 96);
  EXPECT_EQ(seq.stats.weighings, 2 * 96);
  ExpectSameRun(seq, bounded);
  EstimateResult shallow;
  {
    const hls::sim::ScopedDepthLimit one(1);
    shallow = RunIn(Mode::kBounded, in, scene.target, prior, cls, 96);
  }
  ExpectSameRun(seq, shallow);
}

// The full particle set (510) through every top, on the torus. ctest LABEL long (outside
// scripts/test.sh: about 30 s).
TEST(HwBoundedLong, EveryTopOfTheEngineOnTheTorusWith510ParticlesIsBitIdenticalToTheSequentialModel) {
  const TorusEngineScene t;
  const SynthScene& scene = t.scene;
  const Prior& prior = t.prior;
  const int cls = t.cls;
  const SceneInput& in = t.in;
  const EstimateResult seq = RunIn(Mode::kSequential, in, scene.target, prior, cls, kHwMaxParticles);
  const EstimateResult bounded = RunIn(Mode::kBounded, in, scene.target, prior, cls, kHwMaxParticles);
  EXPECT_EQ(seq.stats.weighings, 2 * kHwMaxParticles);
  ExpectSameRun(seq, bounded);
}

// A real YCB-Video frame: its depth, camera, one object's mesh (reduced by the engine to its
// level of detail) and a detection box around the object's ground-truth silhouette.
// ctest LABEL long (outside scripts/test.sh: about 30 s).
TEST(HwBoundedLong, EveryTopOfTheEngineOnARealYcbVideoFrameIsBitIdenticalToTheSequentialModel) {
  namespace fs = std::filesystem;
  const fs::path frame = testing_util::YcbvDataDir() / "scenes" / "ycbv_0000_000001";
  const fs::path models = testing_util::YcbvDataDir() / "models";
  if (!fs::exists(frame / "depth.png")) GTEST_SKIP() << "no shared YCB-Video frame at " << frame;
  const CameraFile cam = ReadCameraJson((frame / "camera.json").string());
  SceneInput in;
  in.camera = cam.camera;
  in.depth = LoadDepthPng((frame / "depth.png").string(), cam.depth_scale);
  const std::vector<GtObject> gt = ReadGtJson((frame / "gt.json").string());
  ASSERT_FALSE(gt.empty());
  const GtObject& obj = gt[0];
  const Mesh mesh = LoadMesh((models / (obj.obj + ".ply")).string());
  ASSERT_GT(mesh.faces.size(), std::size_t(kMaxFaces)) << "the engine's level of detail should reduce this mesh";
  // The box of the ground-truth projection, 10 % larger.
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector2d p = in.camera.Project(obj.T_cam_obj * v.cast<double>());
    u0 = std::min(u0, p.x()), v0 = std::min(v0, p.y()), u1 = std::max(u1, p.x()), v1 = std::max(v1, p.y());
  }
  Detection d;
  d.cls = obj.obj;
  d.score = 0.9;
  d.x = u0 - 0.05 * (u1 - u0);
  d.y = v0 - 0.05 * (v1 - v0);
  d.w = 1.1 * (u1 - u0);
  d.h = 1.1 * (v1 - v0);
  const std::vector<std::string> classes = YcbVideoClassNames();
  const Prior prior = PriorFromDetections({d}, PyramidLayout::Thesis(), classes);
  const int cls = prior.ClassIndex(obj.obj);
  ASSERT_GE(cls, 0);
  const EstimateResult seq = RunIn(Mode::kSequential, in, mesh, prior, cls, kHwMaxParticles);
  const EstimateResult bounded = RunIn(Mode::kBounded, in, mesh, prior, cls, kHwMaxParticles);
  EXPECT_EQ(seq.stats.weighings, 2 * kHwMaxParticles);
  EXPECT_GT(seq.stats.faces_front, 0);
  ExpectSameRun(seq, bounded);
}

}  // namespace
}  // namespace posefilter
