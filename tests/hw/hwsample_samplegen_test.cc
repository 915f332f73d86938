// Tests of src/hw/sample_gen.h (thesis §7.4 item 5, Listing 7.5 [ALGORITHM.md]) and of the whole
// initialisation chain InitSamples (Fig. 7.5).
#include <gtest/gtest.h>

#include <cmath>

#include "hw/sample_gen.h"
#include "hwsample_test_util.h"

namespace posefilter::hw {
namespace {

using namespace hwsample_test;

constexpr double kXyzLsb = 1.0 / 1024;   // xyz_t
constexpr double kAngleLsb = 1.0 / 256;  // angle_t

xyz_t X(double v) { return xyz_t(v); }

// Random heuristic volumes for every cell (x, y in [−1, 1], z in [0.3, 2.5], min ≤ max).
std::vector<HeuristicVolume> RandomVolumes(std::uint64_t seed) {
  Rng rng(seed);
  std::vector<HeuristicVolume> v(kNumCells);
  for (HeuristicVolume& h : v) {
    const double x0 = rng.Uniform(-1, 1), y0 = rng.Uniform(-1, 1), z0 = rng.Uniform(0.3, 2.0);
    h.x_min = X(x0);
    h.x_max = X(x0 + rng.Uniform(0, 0.5));
    h.y_min = X(y0);
    h.y_max = X(y0 + rng.Uniform(0, 0.5));
    h.z_min = X(z0);
    h.z_max = X(z0 + rng.Uniform(0, 0.5));
  }
  return v;
}

void ExpectSampleInVolume(const Sample& s, const HeuristicVolume& h, const std::string& what) {
  const double cx = 0.5 * (h.x_min.to_double() + h.x_max.to_double());
  const double cy = 0.5 * (h.y_min.to_double() + h.y_max.to_double());
  // x, y: the centre floored to 2^-10.
  EXPECT_NEAR(s.x.to_double(), cx, kXyzLsb) << what;
  EXPECT_LE(s.x.to_double(), cx) << what;
  EXPECT_NEAR(s.y.to_double(), cy, kXyzLsb) << what;
  EXPECT_GE(s.x, h.x_min) << what;
  EXPECT_LE(s.x, h.x_max) << what;
  EXPECT_GE(s.z, h.z_min) << what;
  EXPECT_LE(s.z, h.z_max) << what;
  // Angles within ±π (one angle_t LSB of floor quantization at −π).
  for (const angle_t& a : {s.roll, s.pitch, s.yaw}) {
    EXPECT_GE(a.to_double(), -M_PI - kAngleLsb) << what;
    EXPECT_LT(a.to_double(), M_PI) << what;
  }
}

TEST(HwSampleGen, SamplesSitInTheirVolumes) {
  const std::vector<HeuristicVolume> vols = RandomVolumes(21);
  Rng rng(4);
  hls::stream<cell_index_t> cells;
  hls::stream<unif18_t> z;
  hls::stream<angle_t> roll, pitch, yaw;
  std::vector<int> cell_of(kMaxParticles);
  Lfsr18 zg(0x3A3A3);
  Lfsr15 rg(0x1234), pg(0x2345), yg(0x3456);
  for (int i = 0; i < kMaxParticles; ++i) {
    cell_of[i] = int(rng.UniformInt(kNumCells));
    cells.write(cell_index_t(cell_of[i]));
  }
  UniformGenerate(zg, z, kMaxParticles, true, nullptr);
  AngleGenerate(rg, roll, kMaxParticles, nullptr);
  AngleGenerate(pg, pitch, kMaxParticles, nullptr);
  AngleGenerate(yg, yaw, kMaxParticles, nullptr);
  std::vector<Sample> samples(kMaxParticles);
  auto trace = std::make_unique<CycleTrace>();
  GenSample(cells, z, roll, pitch, yaw, vols.data(), samples.data(), kMaxParticles, trace.get());
  EXPECT_TRUE(cells.empty() && z.empty() && roll.empty() && pitch.empty() && yaw.empty());
  double roll_min = 10, roll_max = -10;
  for (int i = 0; i < kMaxParticles; ++i) {
    ASSERT_EQ(samples[i].cell.to_int(), cell_of[i]);
    ExpectSampleInVolume(samples[i], vols[cell_of[i]], "sample " + std::to_string(i));
    roll_min = std::min(roll_min, samples[i].roll.to_double());
    roll_max = std::max(roll_max, samples[i].roll.to_double());
  }
  // The angles cover ±π.
  EXPECT_LT(roll_min, -2.9);
  EXPECT_GT(roll_max, 2.9);
  ASSERT_EQ(trace->count, 2);  // the volumes' on-chip copy, then the samples
  EXPECT_STREQ(trace->records[0].loop, "GEN_LOAD_VOLUMES");
  EXPECT_EQ(trace->records[0].trips, uint64_t(kNumCells));
  EXPECT_EQ(trace->records[1].trips, uint64_t(kMaxParticles));
}

TEST(HwSampleGen, DepthIsUniformInTheInterval) {
  std::vector<HeuristicVolume> vols(kNumCells);
  for (HeuristicVolume& h : vols) {
    h.x_min = X(0.1);
    h.x_max = X(0.3);
    h.y_min = X(-0.2);
    h.y_max = X(-0.1);
    h.z_min = X(0.5);
    h.z_max = X(1.5);
  }
  hls::stream<cell_index_t> cells;
  hls::stream<unif18_t> z;
  hls::stream<angle_t> roll, pitch, yaw;
  Lfsr18 zg(0x15A5A);
  Lfsr15 rg(0x0111), pg(0x0222), yg(0x0333);
  for (int i = 0; i < kMaxParticles; ++i) cells.write(cell_index_t(7));
  UniformGenerate(zg, z, kMaxParticles, true, nullptr);
  AngleGenerate(rg, roll, kMaxParticles, nullptr);
  AngleGenerate(pg, pitch, kMaxParticles, nullptr);
  AngleGenerate(yg, yaw, kMaxParticles, nullptr);
  std::vector<Sample> samples(kMaxParticles);
  GenSample(cells, z, roll, pitch, yaw, vols.data(), samples.data(), kMaxParticles, nullptr);
  // x: (x_min + x_max)/2 at full precision, floored to 2^-10.
  const double want_x = std::floor((X(0.1).to_double() + X(0.3).to_double()) / 2 * 1024) / 1024;
  double mean = 0;
  int below = 0;
  for (const Sample& s : samples) {
    mean += s.z.to_double();
    below += s.z.to_double() < 1.0;
    EXPECT_EQ(s.x.to_double(), want_x);
  }
  mean /= kMaxParticles;
  // Uniform on [0.5, 1.5]: mean 1 ± 3σ/√n (σ = 1/√12), half the draws below 1 ± 3·0.5/√n.
  EXPECT_NEAR(mean, 1.0, 3 * 0.2887 / std::sqrt(double(kMaxParticles)));
  EXPECT_NEAR(below / double(kMaxParticles), 0.5, 3 * 0.5 / std::sqrt(double(kMaxParticles)));
}

TEST(HwSampleGen, ListingArithmeticTestVector) {
  // shared/hls/test_vectors.md §F: z_min 0.5, z_max 1.5, rand01 raw 200000 → 1.262939453 at
  // full precision; truncated to xyz_t: floor(1.262939453·1024)/1024 = 1293/1024.
  std::vector<HeuristicVolume> vols(kNumCells);
  vols[42].x_min = X(-0.5);
  vols[42].x_max = X(0.25);
  vols[42].y_min = X(0.0);
  vols[42].y_max = X(kXyzLsb);
  vols[42].z_min = X(0.5);
  vols[42].z_max = X(1.5);
  hls::stream<cell_index_t> cells;
  hls::stream<unif18_t> z;
  hls::stream<angle_t> roll, pitch, yaw;
  cells.write(cell_index_t(42));
  unif18_t u;
  u.range(17, 0) = ap_uint<18>(200000);
  z.write(u);
  roll.write(angle_t(1.5));
  pitch.write(angle_t(-3.140625));
  yaw.write(angle_t(0.25));
  std::vector<Sample> samples(kMaxParticles);
  GenSample(cells, z, roll, pitch, yaw, vols.data(), samples.data(), 1, nullptr);
  EXPECT_EQ(samples[0].z.to_double(), 1293.0 / 1024);
  EXPECT_EQ(samples[0].x.to_double(), -0.125);
  EXPECT_EQ(samples[0].y.to_double(), 0.0);  // (0 + 2^-10)/2 floors to 0
  EXPECT_EQ(samples[0].roll.to_double(), 1.5);
  EXPECT_EQ(samples[0].pitch.to_double(), -3.140625);
  EXPECT_EQ(samples[0].cell.to_int(), 42);
}

TEST(HwSampleGen, ParticleCountIsClamped) {
  std::vector<HeuristicVolume> vols = RandomVolumes(3);
  hls::stream<cell_index_t> cells;
  hls::stream<unif18_t> z;
  hls::stream<angle_t> roll, pitch, yaw;
  const int n = kMaxParticles + 40;
  Lfsr18 zg(1);
  Lfsr15 rg(2), pg(3), yg(4);
  for (int i = 0; i < n; ++i) cells.write(cell_index_t(i % kNumCells));
  UniformGenerate(zg, z, n, true, nullptr);
  AngleGenerate(rg, roll, n, nullptr);
  AngleGenerate(pg, pitch, n, nullptr);
  AngleGenerate(yg, yaw, n, nullptr);
  std::vector<Sample> samples(kMaxParticles + 40);  // guard region after the sample memory
  for (int i = kMaxParticles; i < n; ++i) samples[i].cell = 8000;
  GenSample(cells, z, roll, pitch, yaw, vols.data(), samples.data(), n, nullptr);
  for (int i = kMaxParticles; i < n; ++i) EXPECT_EQ(samples[i].cell.to_int(), 8000) << "wrote past kMaxParticles";
  EXPECT_EQ(cells.size(), 40u);  // the rest is left in the stream
  while (!cells.empty()) cells.read();
  while (!z.empty()) z.read();
  while (!roll.empty()) roll.read();
  while (!pitch.empty()) pitch.read();
  while (!yaw.empty()) yaw.read();
}

TEST(HwSampleInit, ChainDrawsFromThePriorIntoTheVolumes) {
  HwPrior<21> prior = RunPostProcess<21>(SceneRaw(), ThesisPostProcessParams());
  const int cls = 9;  // banana
  const std::vector<HeuristicVolume> vols = RandomVolumes(8);
  auto cdf_mem = std::make_unique<cdf_t[]>(kNumCells);
  std::vector<Sample> a(kMaxParticles), b(kMaxParticles);
  InitGenerators gen_a, gen_b;
  InitReport rep_a, rep_b;
  InitOptions tracker_on;
  InitOptions tracker_off;
  tracker_off.use_tracker = false;
  auto trace = std::make_unique<CycleTrace>();
  InitSamples<21>(prior.prob.get(), cls, prior.class_sum[cls], vols.data(), cdf_mem.get(), gen_a, tracker_on,
                  a.data(), kMaxParticles, rep_a, trace.get());
  InitSamples<21>(prior.prob.get(), cls, prior.class_sum[cls], vols.data(), cdf_mem.get(), gen_b, tracker_off,
                  b.data(), kMaxParticles, rep_b, nullptr);
  EXPECT_FALSE(rep_a.uniform_fallback);
  // The tracker changes the reads, never the result.
  for (int i = 0; i < kMaxParticles; ++i) {
    ASSERT_EQ(a[i].cell, b[i].cell) << i;
    ASSERT_EQ(a[i].z, b[i].z) << i;
  }
  EXPECT_EQ(rep_b.counters.reads, rep_b.counters.reads_linear);
  EXPECT_LT(rep_a.counters.reads, rep_b.counters.reads);
  // Every sample comes from a cell with banana probability, inside its volume; most of the
  // draws land on the detection's cells (the class's mass there dominates).
  const std::vector<cdf_t> cdf(cdf_mem.get(), cdf_mem.get() + kNumCells);
  double mass_drawn = 0;
  for (int i = 0; i < kMaxParticles; ++i) {
    const int c = a[i].cell.to_int();
    ASSERT_GT(D(prior.prob[c][cls]), 0.0) << "sample " << i << " drawn from an empty cell " << c;
    ExpectSampleInVolume(a[i], vols[c], "sample " + std::to_string(i));
    mass_drawn += D(prior.prob[c][cls]);
  }
  EXPECT_GT(mass_drawn / kMaxParticles, 0.1);
  // Distinct generators: the three angles of a sample are not copies of each other.
  int equal = 0;
  for (const Sample& s : a) equal += (s.roll == s.pitch) + (s.pitch == s.yaw);
  EXPECT_LT(equal, 20);
  // The trace holds every module of the chain.
  for (const char* loop : {"CDF_NORM", "THR_TRACK", "BOUND_GEN", "SAMPLE_SCAN", "GEN_SAMPLE", "ANGLE_GEN"}) {
    bool seen = false;
    for (int i = 0; i < trace->count; ++i) seen |= std::string(trace->records[i].loop) == loop;
    EXPECT_TRUE(seen) << loop;
  }
  std::printf("[init] reads: %u with the tracker, %u without (%.1f×)\n", rep_a.counters.reads.to_uint(),
              rep_b.counters.reads.to_uint(),
              double(rep_b.counters.reads.to_uint()) / double(rep_a.counters.reads.to_uint()));
}

TEST(HwSampleInit, ZeroMassClassIsDrawnUniformlyAndFlagged) {
  auto prob = std::make_unique<prob_t[][1]>(kNumCells);
  for (int i = 0; i < kNumCells; ++i) prob[i][0] = 0;
  const std::vector<HeuristicVolume> vols = RandomVolumes(9);
  auto cdf_mem = std::make_unique<cdf_t[]>(kNumCells);
  std::vector<Sample> s(kMaxParticles);
  InitGenerators gen;
  InitReport rep;
  InitSamples<1>(prob.get(), 0, class_sum_t(0), vols.data(), cdf_mem.get(), gen, InitOptions{}, s.data(),
                 kMaxParticles, rep, nullptr);
  EXPECT_TRUE(rep.uniform_fallback);
  // Spread over the cells: all three pyramid levels are hit.
  int per_level[3] = {0, 0, 0};
  for (const Sample& x : s) {
    const int c = x.cell.to_int();
    ++per_level[c < 300 ? 0 : (c < 1500 ? 1 : 2)];
  }
  EXPECT_GT(per_level[0], 5);
  EXPECT_GT(per_level[1], 40);
  EXPECT_GT(per_level[2], 250);
}

}  // namespace
}  // namespace posefilter::hw
