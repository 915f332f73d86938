// Tests of src/hw/resample.h: selection frequencies vs weights (chi-square), elitism, the
// threshold tracker (same answers as a linear scan, reads counted and saved), the first CDF
// entry (GRIP's base-port bug), all-zero pools, the pool size and the region cap.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "hw/resample.h"
#include "posefilter/rng.h"

namespace posefilter::hw {
namespace {

// Sorted input of the resampler: raw weights (2^-17) sorted descending, with a random
// permutation as the relative indices; samples[i].cell = cell_of[i].
struct Input {
  weight_t w[kMaxParticles];
  particle_index_t idx[kMaxParticles];
  Sample samples[kMaxParticles];
  hypothesis_t hyp[kNumCells];
  std::vector<uint32_t> raw;  // sorted raw weights
};

void Build(std::vector<uint32_t> raw, Input* in, uint64_t seed = 1) {
  std::sort(raw.begin(), raw.end(), std::greater<uint32_t>());
  in->raw = raw;
  Rng rng(seed);
  std::vector<int> perm(kMaxParticles);
  std::iota(perm.begin(), perm.end(), 0);
  for (int i = kMaxParticles - 1; i > 0; --i) std::swap(perm[i], perm[int(rng.UniformInt(i + 1))]);
  for (int k = 0; k < kMaxParticles; ++k) {
    in->w[k] = UFixedFromRaw<18, 1>(ap_uint<18>(k < int(raw.size()) ? raw[k] : 0));
    in->idx[k] = perm[k];
    in->samples[k] = Sample{};
    in->samples[k].cell = 0;
  }
  for (int c = 0; c < kNumCells; ++c) in->hyp[c] = 0;
}

double ChiCritical(int dof) {  // p = 0.001, Wilson–Hilferty
  const double z = 3.09, k = dof;
  return k * std::pow(1 - 2 / (9 * k) + z * std::sqrt(2 / (9 * k)), 3);
}

// Rank (position in the sorted list) of each relative index.
// kMaxParticles raw weights (2^-17) lo + UniformInt(span), drawn from Rng(seed).
std::vector<uint32_t> RandomRaw(uint64_t seed, uint32_t lo, uint64_t span) {
  Rng rng(seed);
  std::vector<uint32_t> raw(kMaxParticles);
  for (auto& r : raw) r = lo + uint32_t(rng.UniformInt(span));
  return raw;
}

std::vector<int> RankOf(const Input& in) {
  std::vector<int> rank(kMaxParticles);
  for (int k = 0; k < kMaxParticles; ++k) rank[in.idx[k].to_int()] = k;
  return rank;
}

TEST(HwRandomResample, SelectionFrequenciesFollowWeights) {
  const std::vector<uint32_t> raw = RandomRaw(21, 13107, 117965);  // weights in [0.1, 1)
  Input in;
  Build(raw, &in);
  const std::vector<int> rank = RankOf(in);
  ResampleParams p;
  p.num_elite = 0;
  Lfsr18 lfsr(4242);
  std::vector<double> count(kMaxParticles, 0);
  const int calls = 200;
  for (int c = 0; c < calls; ++c) {
    particle_index_t out[kMaxParticles];
    Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, nullptr, nullptr, nullptr);
    for (int j = 0; j < kMaxParticles; ++j) count[rank[out[j].to_int()]] += 1;
  }
  const double total_w = std::accumulate(in.raw.begin(), in.raw.end(), 0.0);
  const double draws = double(calls) * kMaxParticles;
  double chi = 0;
  for (int k = 0; k < kMaxParticles; ++k) {
    const double e = draws * in.raw[k] / total_w;
    chi += (count[k] - e) * (count[k] - e) / e;
  }
  EXPECT_LT(chi, ChiCritical(kMaxParticles - 1)) << "chi2 " << chi;
  // And it is not uniform (the test can tell weights apart): the heaviest decile is drawn
  // clearly more often than the lightest.
  double top = 0, bottom = 0;
  for (int k = 0; k < 51; ++k) {
    top += count[k];
    bottom += count[kMaxParticles - 1 - k];
  }
  EXPECT_GT(top, 3 * bottom);
}

TEST(HwRandomResample, EliteIsTheHeadOfTheSortedList) {
  const std::vector<uint32_t> raw = RandomRaw(1, 0, 1u << 17);
  Input in;
  Build(raw, &in);
  ResampleParams p;
  p.num_elite = 10;
  Lfsr18 lfsr(1);
  particle_index_t out[kMaxParticles];
  ResampleCounters cnt;
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, nullptr, nullptr);
  for (int j = 0; j < 10; ++j) EXPECT_EQ(out[j].to_int(), in.idx[j].to_int()) << j;
  EXPECT_EQ(cnt.draws, uint32_t(kMaxParticles - 10));
}

TEST(HwRandomResample, TrackerGivesLinearScanAnswersWithFewerReads) {
  const std::vector<uint32_t> raw = RandomRaw(8, 1000, 2000);  // broad: many bins
  Input in;
  Build(raw, &in);
  const std::vector<int> rank = RankOf(in);
  ResampleParams p;
  p.num_elite = 0;
  Lfsr18 lfsr(77), replay(77);
  particle_index_t out[kMaxParticles];
  cdf_t cdf[kMaxParticles];
  ResampleCounters cnt;
  CycleTrace trace;
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, cdf, &trace);
  // CDF: non-decreasing, first entry set to w0/Σ (not 0), last saturated, each within 2 LSB
  // of the exact normalised cumulative sum.
  const double total = std::accumulate(in.raw.begin(), in.raw.end(), 0.0);
  double acc = 0;
  for (int i = 0; i < kMaxParticles; ++i) {
    acc += in.raw[i];
    if (i > 0) { ASSERT_GE(RawOf(cdf[i]).to_uint(), RawOf(cdf[i - 1]).to_uint()); }
    if (i + 1 < kMaxParticles) { ASSERT_NEAR(cdf[i].to_double(), acc / total, 2.0 / 262144) << i; }
  }
  EXPECT_GT(RawOf(cdf[0]).to_uint(), 0u);
  EXPECT_EQ(RawOf(cdf[kMaxParticles - 1]).to_uint(), 0x3FFFFu);
  // Replay the draws with a linear scan from 0 and with our own tracker from the CDF.
  uint64_t reads = 0, linear = 0;
  for (int j = 0; j < kMaxParticles; ++j) {
    const uint32_t u = replay.Draw().to_uint();
    int i = 0;
    while (i < kMaxParticles - 1 && RawOf(cdf[i]).to_uint() < u) ++i;
    ASSERT_EQ(out[j].to_int(), in.idx[i].to_int()) << "draw " << j;
    int start = 0;  // first index whose top 5 CDF bits reach u's
    while (start < kMaxParticles - 1 && (RawOf(cdf[start]).to_uint() >> 13) < (u >> 13)) ++start;
    reads += uint64_t(i - start + 1);
    linear += uint64_t(i + 1);
  }
  EXPECT_EQ(cnt.cdf_reads, reads);
  EXPECT_EQ(cnt.cdf_reads_linear, linear);
  // 510 equally-ish weighted entries over 32 thresholds: ~8 reads instead of ~255.
  EXPECT_GT(double(cnt.cdf_reads_linear) / cnt.cdf_reads, 15.0)
      << cnt.cdf_reads_linear << " vs " << cnt.cdf_reads;
  // The scan loop's trace carries the reads.
  bool found = false;
  for (int r = 0; r < trace.count; ++r)
    if (std::string(trace.records[r].loop) == "RESAMPLE_SCAN") {
      found = true;
      EXPECT_EQ(trace.records[r].trips, uint64_t(cnt.cdf_reads));
    }
  EXPECT_TRUE(found);
}

TEST(HwRandomResample, FirstEntryIsSetAndZeroWeightsAreNeverDrawn) {
  // All mass on the best entry: every draw must return it (a CDF whose first entry is never
  // set — GRIP's base port — would return entry 1 instead).
  std::vector<uint32_t> raw(kMaxParticles, 0);
  raw[0] = 1u << 16;
  Input in;
  Build(raw, &in);
  ResampleParams p;
  p.num_elite = 0;
  Lfsr18 lfsr(3);
  particle_index_t out[kMaxParticles];
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, nullptr, nullptr, nullptr);
  for (int j = 0; j < kMaxParticles; ++j) ASSERT_EQ(out[j].to_int(), in.idx[0].to_int()) << j;
  // Three non-zero weights: nothing else is ever drawn.
  std::vector<uint32_t> raw3(kMaxParticles, 0);
  raw3[0] = 3000;
  raw3[1] = 2000;
  raw3[2] = 1;
  Build(raw3, &in);
  const std::vector<int> rank = RankOf(in);
  for (int c = 0; c < 20; ++c) {
    Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, nullptr, nullptr, nullptr);
    for (int j = 0; j < kMaxParticles; ++j) ASSERT_LT(rank[out[j].to_int()], 3);
  }
}

TEST(HwRandomResample, AllZeroPoolIsSampledUniformly) {
  std::vector<uint32_t> raw(kMaxParticles, 0);
  Input in;
  Build(raw, &in);
  const std::vector<int> rank = RankOf(in);
  ResampleParams p;
  p.num_elite = 0;
  p.pool_size = 64;
  Lfsr18 lfsr(5);
  std::vector<double> count(64, 0);
  for (int c = 0; c < 40; ++c) {
    particle_index_t out[kMaxParticles];
    Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, nullptr, nullptr, nullptr);
    for (int j = 0; j < kMaxParticles; ++j) {
      const int r = rank[out[j].to_int()];
      ASSERT_LT(r, 64);
      count[r] += 1;
    }
  }
  const double e = 40.0 * kMaxParticles / 64;
  double chi = 0;
  for (double c : count) chi += (c - e) * (c - e) / e;
  EXPECT_LT(chi, ChiCritical(63));
}

TEST(HwRandomResample, PoolSizeAndRegionCap) {
  const std::vector<uint32_t> raw = RandomRaw(12, 100, 100000);
  Input in;
  Build(raw, &in);
  const std::vector<int> rank = RankOf(in);
  // Pool of the best 50: nothing outside it is drawn.
  ResampleParams p;
  p.num_elite = 5;
  p.pool_size = 50;
  Lfsr18 lfsr(9);
  particle_index_t out[kMaxParticles];
  ResampleCounters cnt;
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, nullptr, nullptr);
  EXPECT_EQ(cnt.pool, 50u);
  for (int j = 0; j < kMaxParticles; ++j) ASSERT_LT(rank[out[j].to_int()], 50);
  // Region cap: the particles at ranks 0..19 and at even ranks sit in cell 7 (hypothesis 1),
  // the others in cell 8 (hypothesis 2). With a cap of 10 per hypothesis the pool of 20 holds
  // ranks 0..9 (hypothesis 1) and the odd ranks 21..39 (hypothesis 2).
  for (int k = 0; k < kMaxParticles; ++k) in.samples[in.idx[k].to_int()].cell = (k < 20 || k % 2 == 0) ? 7 : 8;
  in.hyp[7] = 1;
  in.hyp[8] = 2;
  p.pool_size = 20;
  p.region_cap = 10;
  cnt = ResampleCounters{};
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, nullptr, nullptr);
  EXPECT_EQ(cnt.pool, 20u);
  int h1 = 0, h2 = 0;
  for (int j = 0; j < kMaxParticles; ++j) {
    const int r = rank[out[j].to_int()];
    const int h = in.hyp[in.samples[out[j].to_int()].cell.to_int()].to_int();
    if (h == 1) {
      ++h1;
      ASSERT_LT(r, 10) << "hypothesis-1 particle beyond the cap";
    } else {
      ++h2;
      ASSERT_EQ(h, 2);
      ASSERT_TRUE(r >= 21 && r <= 39 && r % 2 == 1) << r;
    }
  }
  EXPECT_GT(h1, 0);
  EXPECT_GT(h2, 0);
  for (int j = 0; j < 5; ++j) EXPECT_EQ(out[j].to_int(), in.idx[j].to_int());  // elite: ranks 0..4
  // Without the cap the pool is the best 20 again, all of hypothesis 1.
  p.region_cap = 0;
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, nullptr, nullptr);
  for (int j = 0; j < kMaxParticles; ++j) ASSERT_LT(rank[out[j].to_int()], 20);
}

TEST(HwRandomResample, ParamsValidationNamesTheConstraint) {
  ResampleParams p;
  std::string why;
  EXPECT_TRUE(p.IsValid(&why));
  p.pool_size = 0;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("pool_size"), std::string::npos);
  p = ResampleParams{};
  p.num_elite = p.pool_size + 1;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("num_elite"), std::string::npos);
  p = ResampleParams{};
  p.num_particles = kMaxParticles + 1;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("num_particles"), std::string::npos);
  p = ResampleParams{};
  p.region_cap = -1;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("region_cap"), std::string::npos);
}

}  // namespace
}  // namespace posefilter::hw

// ---- Ours: the rotation cap (an accuracy addition, not in the thesis) ----
namespace posefilter::hw {
namespace {

constexpr int kHalfPiRawForTest = 402;  // round(π/2·256), angle_t raw

// The reference's RotationBin (src/filter/particle_filter.cc), in double, on R = Rz·Ry·Rx.
// *margin: the smallest gap of the decisions (argmax and sign) — near-ties are skipped, where
// the 2^-16 SinCos error may legitimately pick the other bin.
int FloatRotationBin(double roll, double pitch, double yaw, double* margin) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  const double col0[3] = {cy * cp, sy * cp, -sp};
  const double col2[3] = {cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr};
  auto signed_axis = [&](const double* v, int exclude, int* axis, int* sign) {
    int best = exclude == 0 ? 1 : 0;
    for (int a = 0; a < 3; ++a)
      if (a != exclude && std::fabs(v[a]) > std::fabs(v[best])) best = a;
    for (int a = 0; a < 3; ++a)
      if (a != exclude && a != best) *margin = std::min(*margin, std::fabs(v[best]) - std::fabs(v[a]));
    *margin = std::min(*margin, std::fabs(v[best]));
    *axis = best;
    *sign = v[best] < 0 ? 1 : 0;
  };
  *margin = 1e9;
  int za, zs, xa, xs;
  signed_axis(col2, -1, &za, &zs);
  signed_axis(col0, za, &xa, &xs);
  const int slot = xa > za ? xa - 1 : xa;
  return (za * 2 + zs) * 4 + slot * 2 + xs;
}

TEST(HwRandomResample, RotationBinMatchesTheReferenceBins) {
  Rng rng(31);
  int compared = 0;
  bool seen[kRotationBins] = {};
  for (int i = 0; i < 4000; ++i) {
    Sample s{};
    s.roll = FixedFromRaw<12, 4>(ap_int<12>(int(rng.UniformInt(1608)) - 803));
    s.pitch = FixedFromRaw<12, 4>(ap_int<12>(int(rng.UniformInt(1608)) - 803));
    s.yaw = FixedFromRaw<12, 4>(ap_int<12>(int(rng.UniformInt(1608)) - 803));
    double margin;
    const int ref = FloatRotationBin(s.roll.to_double(), s.pitch.to_double(), s.yaw.to_double(), &margin);
    if (margin < 1e-3) continue;  // SinCos error ≤ 2^-16 per factor: ≤ 1e-4 per entry
    ++compared;
    const int hw = RotationBinHw(s);
    ASSERT_EQ(hw, ref) << "angles " << s.roll.to_double() << " " << s.pitch.to_double() << " " << s.yaw.to_double();
    seen[hw] = true;
  }
  EXPECT_GT(compared, 3500);
  for (int b = 0; b < kRotationBins; ++b) EXPECT_TRUE(seen[b]) << "bin " << b << " never reached";
}

// Three orientations (identity, yaw +π/2, pitch +π/2 — three different bins) in rank blocks
// 0..14, 15..29, 30..; one hypothesis. A rotation cap of 5 admits ranks 0..4, 15..19, 30..34.
TEST(HwRandomResample, RotationCapLimitsEachOrientationNiche) {
  const std::vector<uint32_t> raw = RandomRaw(13, 100, 100000);
  Input in;
  Build(raw, &in);
  const std::vector<int> rank = RankOf(in);
  for (int k = 0; k < kMaxParticles; ++k) {
    Sample& s = in.samples[in.idx[k].to_int()];
    s.cell = 5;
    if (k >= 15 && k < 30) s.yaw = FixedFromRaw<12, 4>(ap_int<12>(kHalfPiRawForTest));
    if (k >= 30) s.pitch = FixedFromRaw<12, 4>(ap_int<12>(kHalfPiRawForTest));
  }
  in.hyp[5] = 3;
  const int b0 = RotationBinHw(in.samples[in.idx[0].to_int()]), b1 = RotationBinHw(in.samples[in.idx[15].to_int()]),
            b2 = RotationBinHw(in.samples[in.idx[30].to_int()]);
  ASSERT_TRUE(b0 != b1 && b1 != b2 && b0 != b2);
  ResampleParams p;
  p.pool_size = 20;
  p.num_elite = 15;
  p.rotation_cap = 5;
  Lfsr18 lfsr(4);
  particle_index_t out[kMaxParticles];
  ResampleCounters cnt;
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, nullptr, nullptr);
  EXPECT_EQ(cnt.pool, 15u);
  const int expect_ranks[15] = {0, 1, 2, 3, 4, 15, 16, 17, 18, 19, 30, 31, 32, 33, 34};
  for (int j = 0; j < 15; ++j) EXPECT_EQ(rank[out[j].to_int()], expect_ranks[j]) << j;  // the elite = the pool
  for (int j = 0; j < kMaxParticles; ++j) {
    const int r = rank[out[j].to_int()];
    ASSERT_TRUE(r < 5 || (r >= 15 && r < 20) || (r >= 30 && r < 35)) << r;
  }
  // Off (0): the pool is the best 20 again.
  p.rotation_cap = 0;
  cnt = ResampleCounters{};
  Resample(in.w, in.idx, in.samples, in.hyp, p, lfsr, out, &cnt, nullptr, nullptr);
  EXPECT_EQ(cnt.pool, 20u);
  for (int j = 0; j < kMaxParticles; ++j) ASSERT_LT(rank[out[j].to_int()], 20);
  // Validation names the option.
  p.rotation_cap = -1;
  std::string why;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("rotation_cap"), std::string::npos);
}

}  // namespace
}  // namespace posefilter::hw
