// Tests of the hw engine's top functions (src/hw/top.h), cycle model (src/hw/cycle_model.h),
// driver (EstimatePose with engine "hw", ProfileHw: src/filter/hw_driver.cc) and its input errors. Suites HwTop*.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "hw/cycle_model.h"
#include "hw/top.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/hw_engine.h"
#include "posefilter/metrics.h"
#include "posefilter/synth.h"
#include "test_util.h"

namespace posefilter {
namespace {

using namespace posefilter::hw;

// ---------------------------------------------------------------------------------------------
// Cycle model: the formulas on hand-made traces.

TEST(HwTopCycleModel, LoopAndModuleCyclesFollowTripsTimesIiPlusDepth) {
  auto t = std::make_unique<CycleTrace>();
  t->Add("a", "L1", 100, 1, 5);  // 105
  t->Add("b", "L2", 10, 3, 7);   // 37
  t->Add("a", "L3", 0, 1, 50);   // ran no trip: 0
  t->Add("a", "L4", 4, 2, 1);    // 9
  EXPECT_EQ(LoopCycles(t->records[0]), 105u);
  EXPECT_EQ(LoopCycles(t->records[2]), 0u);
  const auto mods = ModuleCycles(*t);
  ASSERT_EQ(mods.size(), 2u);
  EXPECT_EQ(mods[0].first, "a");
  EXPECT_EQ(mods[0].second, 114u);
  EXPECT_EQ(mods[1].second, 37u);
  EXPECT_EQ(ModuleTotal(*t, ""), 151u);
  EXPECT_EQ(ModuleDepth(*t, "a"), 6u);  // L3 ran no trip: no fill
  EXPECT_EQ(LoopTrips(*t, "a", "L4"), 4u);
  // Dataflow: the slowest module (a: 114) + every fill (5 + 1 + 7).
  EXPECT_EQ(DataflowLatency(*t), 114u + 13u);
}

// ---------------------------------------------------------------------------------------------
// The weigh top on a small synthetic problem loaded by hand.

struct SmallProblem {
  std::unique_ptr<depth_t[]> depth{new depth_t[kImageHeight * kImageWidth]};
  xyz_t vmem[3][kMaxVertices];
  face_t tri_mem[kMaxFaces];
  Window cell_windows[kNumCells];
  prob_t class_prob[kNumCells];
  Sample samples[kMaxParticles];
  WeighConfig cfg{};
  int n = 0;
};

// A synthetic box scene; particles around the ground-truth pose (some exact, some off).
void MakeSmallProblem(SmallProblem* sp, int n) {
  SynthOptions so;
  so.target = "box";
  so.clutter = 0;
  const SynthScene scene = MakeSynthScene(so, 5);
  for (int v = 0; v < kImageHeight; ++v)
    for (int u = 0; u < kImageWidth; ++u)
      sp->depth[v * kImageWidth + u] = depth_t(ap_ufixed<12, 2, AP_RND, AP_SAT>(std::min(4.0, double(scene.depth.at(u, v)))));
  const Mesh& mesh = scene.target;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) sp->vmem[k][i] = xyz_t(ap_fixed<13, 3, AP_RND>(double(mesh.vertices[i][k])));
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    sp->tri_mem[f] = PackFace(mesh.faces[f][0], mesh.faces[f][1], mesh.faces[f][2]);
  const Eigen::Vector2d c = scene.camera.Project(scene.gt[0].T_cam_obj.translation());
  for (int cell = 0; cell < kNumCells; ++cell) {
    sp->cell_windows[cell] = SaturatedWindow(int(c.x()) + (cell % 7) * 9 - 27, int(c.y()) + (cell % 5) * 7 - 14,
                                             80 + cell % 60, 70 + cell % 90, kImageWidth, kImageHeight);
    sp->class_prob[cell] = prob_t(ap_ufixed<8, 0, AP_RND>((cell % 10) / 10.0));
  }
  const Pose6 gt = TransformToPose(scene.gt[0].T_cam_obj);  // base = camera (identity C)
  for (int p = 0; p < n; ++p) {
    Sample& s = sp->samples[p];
    const double d = (p % 4) * 0.004, a = (p % 3) * 0.05;
    s.x = xyz_t(ap_fixed<13, 3, AP_RND>(gt.x + d));
    s.y = xyz_t(ap_fixed<13, 3, AP_RND>(gt.y - d));
    s.z = xyz_t(ap_fixed<13, 3, AP_RND>(gt.z + 0.5 * d));
    s.roll = angle_t(ap_fixed<12, 4, AP_RND>(gt.roll + a));
    s.pitch = angle_t(ap_fixed<12, 4, AP_RND>(gt.pitch));
    s.yaw = angle_t(ap_fixed<12, 4, AP_RND>(gt.yaw - a));
    s.cell = (p * 37) % kNumCells;
  }
  sp->n = n;
  WeighConfig& cfg = sp->cfg;
  cfg.num_faces = int(mesh.faces.size());
  cfg.img_width = kImageWidth;
  cfg.cam.fx = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.fx));
  cfg.cam.fy = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.fy));
  cfg.cam.cx = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.cx));
  cfg.cam.cy = intr_t(ap_ufixed<28, 12, AP_RND>(scene.camera.cy));
  for (int k = 0; k < 9; ++k) cfg.cam.rot[k] = trig_t(k % 4 == 0 ? 1.0 : 0.0);
  for (int k = 0; k < 3; ++k) cfg.cam.trans[k] = ctrans_t(0.0);
  cfg.raster = DefaultRasterParams();
  cfg.weight = DefaultWeightParams();
}

struct WeighOutput {
  std::vector<double> sorted_w;
  std::vector<int> sorted_idx;
  std::vector<long> n_raster, n_depth;
  std::vector<double> offsets;  // side-band, particle order
  DepthDistributionCounts dd;
  std::unique_ptr<CycleTrace> trace{new CycleTrace};
};

void Weigh(SmallProblem& sp, int cores, WeighOutput* out) {
  sp.cfg.num_cores = cores;
  weight_t w[kMaxParticles];
  particle_index_t idx[kMaxParticles];
  RasterCoreOutput stats[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  HwWeighTopCores(cores, sp.n, sp.cfg, sp.samples, sp.cell_windows, sp.class_prob, sp.depth.get(), sp.vmem, sp.tri_mem, w,
                  idx, stats, offsets, &out->dd, out->trace.get());
  for (int p = 0; p < sp.n; ++p) {
    // The side-band: each particle's mean z_s − z_r, to depth_off_t's LSB (2^-15 m) + rounding.
    const long cnt = long(stats[p].depth_diff_count.to_uint64());
    const double mean = cnt > 0 ? stats[p].depth_diff_sum.to_double() / double(cnt) : 0.0;
    EXPECT_NEAR(offsets[p].to_double(), mean, 1.0 / 32768) << p;
    out->offsets.push_back(offsets[p].to_double());
    out->sorted_w.push_back(w[p].to_double());
    out->sorted_idx.push_back(idx[p].to_int());
    out->n_raster.push_back(long(stats[p].n_raster.to_uint64()));
    out->n_depth.push_back(long(stats[p].n_depth.to_uint64()));
  }
}

TEST(HwTopWeigh, ResultsDoNotDependOnTheCoreCountAndTheSetIsSorted) {
  auto sp = std::make_unique<SmallProblem>();
  MakeSmallProblem(sp.get(), 23);
  WeighOutput one, five, ten;
  Weigh(*sp, 1, &one);
  Weigh(*sp, 5, &five);
  Weigh(*sp, 10, &ten);
  EXPECT_EQ(one.sorted_w, five.sorted_w);
  EXPECT_EQ(one.sorted_w, ten.sorted_w);
  EXPECT_EQ(one.sorted_idx, ten.sorted_idx);
  EXPECT_EQ(one.n_raster, ten.n_raster);
  EXPECT_EQ(one.offsets, ten.offsets);
  int nonzero_offsets = 0;
  for (double d : one.offsets) nonzero_offsets += d != 0;
  EXPECT_GT(nonzero_offsets, 0);  // particles that render the object measure a misalignment
  for (int p = 1; p < sp->n; ++p) EXPECT_GE(one.sorted_w[p - 1], one.sorted_w[p]);
  // Particles near the truth render the object: some weight well above the ρ-only floor.
  EXPECT_GT(one.sorted_w[0], 0.5);
  // N_depth of a particle = valid pixels of its cell's window (stats in particle order).
  for (int p = 0; p < sp->n; ++p) {
    const Window& w = sp->cell_windows[sp->samples[p].cell.to_int()];
    long valid = 0;
    for (int v = w.v0.to_int(); v < w.v0.to_int() + w.height.to_int(); ++v)
      for (int u = w.u0.to_int(); u < w.u0.to_int() + w.width.to_int(); ++u) valid += sp->depth[v * kImageWidth + u] != 0;
    EXPECT_EQ(one.n_depth[p], valid) << p;
  }
  // Window sharing: one core never shares, ten cores read fewer pixels than they receive.
  EXPECT_EQ(one.dd.reads_shared.to_uint64(), one.dd.reads_unshared.to_uint64());
  EXPECT_LT(ten.dd.reads_shared.to_uint64(), ten.dd.reads_unshared.to_uint64());
  EXPECT_EQ(ten.dd.reads_unshared.to_uint64(), one.dd.reads_unshared.to_uint64());
  // The trace holds every module of the region, the cores' records merged in.
  for (const char* mod : {"sample_info", "ft_chain", "ft_distributor", "vertex_multiplier", "depth_distributor",
                          "raster_core", "weight_merger", "weight_split", "stats", "sorter"})
    EXPECT_GT(ModuleTotal(*ten.trace, mod), 0u) << mod;
  EXPECT_EQ(LoopTrips(*ten.trace, "raster_core", "RC_FT_READ"), 12u * sp->n);
  EXPECT_EQ(LoopTrips(*one.trace, "vertex_multiplier", "VM_VERTICES"), 3u * sp->cfg.num_faces * sp->n);
  EXPECT_EQ(LoopTrips(*ten.trace, "vertex_multiplier", "VM_VERTICES"), 3u * sp->cfg.num_faces * 3);  // 3 rounds
}

// ---------------------------------------------------------------------------------------------
// The driver.

struct SceneFixture {
  SynthScene scene;
  Prior prior;
  int cls = 0;
  SceneInput input() const { return SceneInput{scene.depth, scene.camera}; }
};

SceneFixture MakeScene(const std::string& target, std::uint64_t seed) {
  SceneFixture f;
  SynthOptions so;
  so.target = target;
  f.scene = MakeSynthScene(so, seed);
  f.prior = PostProcessPyramid(f.scene.raw_pyramid, f.scene.layout, f.scene.classes);
  f.cls = f.prior.ClassIndex(f.scene.target.name);
  return f;
}

FilterOptions SmallHwOptions() {
  FilterOptions o;
  o.engine = "hw";
  o.num_particles = 96;
  o.stop.max_iterations = 3;
  o.restarts = 1;
  o.polish.steps = 0;  // the hardware's own answer (no host-side float polish)
  return o;
}

TEST(HwTopEngine, DispatchIsDeterministicAndTheWeightMatchesTheFloatWeighing) {
  const SceneFixture f = MakeScene("box", 2);
  FilterOptions o = SmallHwOptions();
  const EstimateResult a = EstimatePose(f.input(), f.scene.target, f.prior, f.cls, o);
  const EstimateResult b = EstimatePose(f.input(), f.scene.target, f.prior, f.cls, o);
  EXPECT_EQ(a.weight, b.weight);
  EXPECT_EQ(a.pose_base.x, b.pose_base.x);
  EXPECT_EQ(a.iterations, 3);
  ASSERT_EQ(a.best_weight_history.size(), 3u);
  EXPECT_EQ(a.stats.weighings, 3 * 96);
  EXPECT_GT(a.stats.init_cdf_reads_linear, a.stats.init_cdf_reads);  // tracker saves reads
  EXPECT_GT(a.stats.faces_front, 0);
  EXPECT_LE(a.stats.faces_front, a.stats.faces_total);
  // The same pose and cell weighed by the float reference (full-precision mesh, depth and
  // camera): the hw weight differs by the quantization only. Budget: the xyz_t model grid
  // (≤ 0.85 mm per vertex ≈ 0.6 px at 0.7 m) and 2^-16 sines move the outline by < 1 px, i.e.
  // ≈ perimeter/area ≈ 2–3 % of the rendered pixels of a 100 px object; depth_t (2^-11 m
  // rounding) shifts χ by ≤ 0.13 on the ramp (1/thr1 = 256/m); prob_t rounding ≤ 2^-9·γ.
  o.engine = "reference";
  const std::vector<double> ref = WeighPoses(f.input(), f.scene.target, f.prior, f.cls, o, {{a.pose_base, a.cell}});
  EXPECT_NEAR(a.weight, ref[0], 0.05);
  EXPECT_GT(a.weight, 0.3);
}

TEST(HwTopEngine, HostPolishStartsFromTheRunsBestAndReportsTheFloatWeight) {
  const SceneFixture f = MakeScene("box", 2);
  FilterOptions o = SmallHwOptions();
  const EstimateResult raw = EstimatePose(f.input(), f.scene.target, f.prior, f.cls, o);
  o.polish.steps = 4;
  o.polish.climbers = 2;
  const EstimateResult pol = EstimatePose(f.input(), f.scene.target, f.prior, f.cls, o);
  // The same hardware runs (the polish draws no random numbers), then more weighings.
  EXPECT_EQ(pol.best_weight_history, raw.best_weight_history);
  EXPECT_GT(pol.stats.weighings, raw.stats.weighings);
  // The answer's weight is the float weighing of the answer, and no worse than the float
  // weighing of the hardware's own answer (the polish weighs its seed too).
  FilterOptions f_opt = o;
  f_opt.engine = "cpu";
  const std::vector<double> w = WeighPoses(f.input(), f.scene.target, f.prior, f.cls, f_opt,
                                           {{pol.pose_base, pol.cell}, {raw.pose_base, raw.cell}});
  EXPECT_NEAR(pol.weight, w[0], 1e-9);
  EXPECT_GE(pol.weight, w[1] - 1e-9);
  const EstimateResult again = EstimatePose(f.input(), f.scene.target, f.prior, f.cls, o);
  EXPECT_EQ(again.weight, pol.weight);
  EXPECT_EQ(again.pose_base.yaw, pol.pose_base.yaw);
}

TEST(HwTopEngine, LargeMeshIsReducedToTheHardwareBound) {
  SceneFixture f = MakeScene("torus", 4);
  const Mesh big = MakeTorus(0.06, 0.025, 64, 48, f.scene.target.name);  // 3072 vertices
  ASSERT_GT(big.vertices.size(), 1024u);
  FilterOptions o = SmallHwOptions();
  o.stop.max_iterations = 1;
  o.num_particles = 20;
  HwProfileOptions p;
  p.cores = {2};
  const HwProfile prof = ProfileHw(f.input(), big, f.prior, f.cls, o, p);
  EXPECT_LE(prof.num_vertices, 1024);
  EXPECT_LE(prof.num_faces, 2048);
  EXPECT_GT(prof.num_faces, 1000);  // reduced to the budget, not to a handful of faces
}

TEST(HwTopEngine, ProfileIsConsistent) {
  const SceneFixture f = MakeScene("lshape", 3);
  FilterOptions o = SmallHwOptions();
  o.num_particles = 60;
  o.stop.max_iterations = 2;
  o.render.min_window_diameters = 4;  // 200×200 windows, as the thesis
  HwProfileOptions p;
  p.raw_pyramid = f.scene.raw_pyramid;
  const HwProfile prof = ProfileHw(f.input(), f.scene.target, f.prior, f.cls, o, p);
  ASSERT_EQ(prof.models.size(), 3u);
  EXPECT_EQ(prof.iterations, 2);
  EXPECT_EQ(prof.modelled_iterations, 2);
  EXPECT_NEAR(prof.mean_window_area, 40000, 1);
  EXPECT_GT(prof.postprocess_cycles, 6300.0 * 26);  // ≥ one cycle per raw value
  const HwCoreModel& m1 = prof.models[0];
  const HwCoreModel& m5 = prof.models[1];
  const HwCoreModel& m10 = prof.models[2];
  EXPECT_EQ(m1.cores, 1);
  // One core: no sharing, the distributor reads every window pixel (N × 200 × 200).
  EXPECT_DOUBLE_EQ(m1.depth_reads_shared, m1.depth_reads_unshared);
  EXPECT_DOUBLE_EQ(m1.depth_reads_unshared, 60.0 * 40000);
  EXPECT_LT(m10.depth_reads_shared, m5.depth_reads_shared + 1);
  EXPECT_LE(m5.depth_reads_shared, m5.depth_reads_unshared);
  EXPECT_GE(m1.depth_distribution_cycles, m1.depth_reads_shared);  // ≥ one cycle per pixel
  EXPECT_GT(m1.weigh_cycles, m5.weigh_cycles);
  EXPECT_GT(m5.weigh_cycles, m10.weigh_cycles);
  // The weigh region is at least its slowest stage: the distributor's fill plus the busiest
  // core's compute cannot overlap (one fragment memory per core).
  for (const HwCoreModel& m : prof.models) {
    EXPECT_GE(m.weigh_cycles, m.depth_distribution_cycles);
    EXPECT_NEAR(m.iteration_cycles, m.weigh_cycles + m.update_cycles, 1e-6 * m.iteration_cycles);
    EXPECT_GT(m.first_iteration_cycles, prof.postprocess_cycles + prof.init_cycles);
  }
  EXPECT_GT(prof.init_reads_linear, prof.init_reads);
  EXPECT_GE(prof.faces_total, prof.faces_front);
}

// ---------------------------------------------------------------------------------------------
// Input errors: each names the offending option or input.

TEST(HwTopEngineErrors, InputsTheHardwareCannotTake) {
  const SceneFixture f = MakeScene("box", 1);
  auto expect_error = [&](const FilterOptions& o, const std::string& words) {
    try {
      EstimatePose(f.input(), f.scene.target, f.prior, f.cls, o);
      ADD_FAILURE() << "no error for " << words;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  FilterOptions o = SmallHwOptions();
  o.num_particles = 511;
  expect_error(o, "num_particles");
  o = SmallHwOptions();
  o.render.max_window_px = 256;
  expect_error(o, "max_window_px");
  o = SmallHwOptions();
  o.render.near_m = 0.01;
  expect_error(o, "near_m");
  o = SmallHwOptions();
  o.diffusion.sigma_t0_m = 5;
  expect_error(o, "sigma_t0_m");
  o = SmallHwOptions();
  o.engine = "fpga";
  expect_error(o, "engine");
  // A move set with only the float-only move (ICP) has nothing to model.
  o = SmallHwOptions();
  o.diffusion.move_probabilities.fill(0.0);
  o.diffusion.move_probabilities[int(Move::kIcpStep)] = 1;
  expect_error(o, "move probabilities");

  // An image larger than the hardware's depth memory.
  SceneFixture big = f;
  big.scene.camera.width = 800;
  big.scene.depth = DepthImage(800, 480);
  big.scene.depth.data.assign(800 * 480, 1.0f);
  try {
    EstimatePose(SceneInput{big.scene.depth, big.scene.camera}, f.scene.target, f.prior, f.cls, SmallHwOptions());
    ADD_FAILURE() << "no error for an 800-pixel-wide image";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
  }
  // A prior that is not the thesis pyramid.
  Prior small = f.prior;
  small.layout.levels.pop_back();
  try {
    EstimatePose(f.input(), f.scene.target, small, f.cls, SmallHwOptions());
    ADD_FAILURE() << "no error for a 2-level pyramid";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("thesis pyramid"), std::string::npos) << e.what();
  }
  // A class without any mass where there is depth.
  Prior empty = f.prior;
  for (int c = 0; c < kNumCells; ++c) empty.prob[std::size_t(c) * empty.layout.num_classes + f.cls] = 0;
  try {
    EstimatePose(f.input(), f.scene.target, empty, f.cls, SmallHwOptions());
    ADD_FAILURE() << "no error for a class without mass";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("probability mass"), std::string::npos) << e.what();
  }
  // Profile options.
  HwProfileOptions p;
  p.cores = {11};
  try {
    ProfileHw(f.input(), f.scene.target, f.prior, f.cls, SmallHwOptions(), p);
    ADD_FAILURE() << "no error for 11 cores";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cores"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace posefilter
