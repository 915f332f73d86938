// Tests of src/hw/threshold_tracker.h and src/hw/sampling.h (thesis §7.4 items 2–4): the
// tracker's (level, first index) list, the bound generator + sampling giving the same cell
// as a linear scan for every draw with fewer reads, and sampling frequencies (chi-square).
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "hw/sampling.h"
#include "hw/threshold_tracker.h"
#include "hwsample_test_util.h"

namespace posefilter::hw {
namespace {

using namespace hwsample_test;

constexpr int kIB = 13;
constexpr int kP = kThrBits;
typedef ap_uint<kP + kIB> thr_word_t;

// Runs the tracker over a CDF; returns the threshold words, checks the copy-through.
std::vector<thr_word_t> RunTracker(const std::vector<cdf_t>& cdf) {
  hls::stream<cdf_t> in, copy;
  hls::stream<thr_word_t> thr;
  for (const cdf_t& c : cdf) in.write(c);
  ThresholdTracker<kNumCells, kP, kIB, 18>(in, copy, thr, int(cdf.size()), nullptr);
  for (size_t i = 0; i < cdf.size(); ++i) EXPECT_EQ(D(copy.read()), D(cdf[i])) << i;
  EXPECT_TRUE(copy.empty());
  std::vector<thr_word_t> out;
  while (!thr.empty()) out.push_back(thr.read());
  return out;
}

struct SampleRun {
  std::vector<int> picks;
  SamplingCounters counters{};
};

// Tracker → bound generator → sampling for the given draws.
SampleRun RunSampling(const std::vector<cdf_t>& cdf, const std::vector<unif18_t>& draws, bool use_tracker,
                      CycleTrace* trace = nullptr) {
  hls::stream<cdf_t> in, copy;
  hls::stream<thr_word_t> thr;
  hls::stream<unif18_t> u;
  hls::stream<SampleBounds<kIB, 18> > bounds;
  hls::stream<ap_uint<kIB> > idx;
  for (const cdf_t& c : cdf) in.write(c);
  for (const unif18_t& d : draws) u.write(d);
  const int n = int(cdf.size()), nd = int(draws.size());
  auto mem = std::make_unique<cdf_t[]>(kNumCells);
  SampleRun run;
  ThresholdTracker<kNumCells, kP, kIB, 18>(in, copy, thr, n HW_TRACE_ARG);
  BoundGenerate<kNumCells, kP, kIB, 18>(thr, u, bounds, n, nd, use_tracker HW_TRACE_ARG);
  SampleIndices<kNumCells, kIB, 18>(copy, bounds, mem.get(), idx, n, nd, run.counters HW_TRACE_ARG);
  while (!idx.empty()) run.picks.push_back(idx.read().to_int());
  EXPECT_EQ(int(run.picks.size()), nd);
  EXPECT_TRUE(thr.empty() && u.empty() && bounds.empty());
  return run;
}

std::vector<unif18_t> LfsrDraws(unsigned seed, int n, bool leap) {
  Lfsr18 g(seed);
  hls::stream<unif18_t> s;
  UniformGenerate(g, s, n, leap, nullptr);
  std::vector<unif18_t> out;
  while (!s.empty()) out.push_back(s.read());
  return out;
}

unsigned Bits(const unif18_t& u, int hi, int lo) {
  const ap_uint<18> r = u.range(17, 0);
  return unsigned(r.to_uint() >> lo) & ((1u << (hi - lo + 1)) - 1);
}

unif18_t U18(unsigned raw) {
  unif18_t u;
  u.range(17, 0) = ap_uint<18>(raw);
  return u;
}

// The banana class of the synthetic scene (realistic, peaked prior) as a CDF.
std::vector<cdf_t> SceneCdf(int cls) {
  HwPrior<21> p = RunPostProcess<21>(SceneRaw(), ThesisPostProcessParams());
  bool fb = false;
  return RunCdf<21>(p.prob.get(), cls, ClassSum<21>(p.prob.get(), cls), &fb);
}

TEST(HwSampleTracker, RecordsFirstIndexOfEachLevel) {
  for (int cls : {9, 0}) {
    const std::vector<cdf_t> cdf = SceneCdf(cls);
    const std::vector<thr_word_t> thr = RunTracker(cdf);
    ASSERT_EQ(int(thr.size()), 1 << kP) << "exactly 2^P words";
    int last_level = 0, entries = 0;
    for (const thr_word_t& w : thr) {
      const int level = ThrLevel<kP, kIB>(w).to_int(), index = ThrIndex<kP, kIB>(w).to_int();
      if (level == 0) {
        EXPECT_EQ(index, 0) << "padding must be all zeros";
        continue;
      }
      ++entries;
      EXPECT_GT(level, last_level) << "levels strictly increase";
      // index = the first CDF entry whose top 5 bits reach `level`, and it jumps past last_level.
      for (int i = 0; i < index; ++i) ASSERT_LT(D(cdf[i]) * 32, level) << "level " << level;
      EXPECT_GE(D(cdf[index]) * 32, level);
      EXPECT_LT(std::floor(D(index > 0 ? cdf[index - 1] : cdf_t(0)) * 32), level);
      last_level = level;
    }
    EXPECT_EQ(last_level, 31) << "the saturated last value reaches the top level";
    // Zero words only after the real entries.
    for (int i = entries; i < int(thr.size()); ++i) EXPECT_EQ(thr[i].to_uint64(), 0u) << i;
  }
}

TEST(HwSampleSampling, TrackerPicksTheLinearScanCellForEveryDraw) {
  const std::vector<cdf_t> cdf = SceneCdf(9);
  std::vector<unif18_t> draws = LfsrDraws(0x2ABCD, 5000, true);
  // Edge draws: the smallest and largest u, each level boundary k/32 and one LSB below, and
  // u equal to CDF values (≥ picks the entry itself).
  draws.push_back(U18(1));
  draws.push_back(U18(0x3FFFF));
  for (unsigned k = 1; k < 32; ++k) {
    draws.push_back(U18(k << 13));
    draws.push_back(U18((k << 13) - 1));
  }
  for (int i = 0; i < kNumCells; i += 97) {
    unif18_t u;
    u.range(17, 0) = cdf[i].range(17, 0);
    if (u != 0) draws.push_back(u);
  }
  const SampleRun with = RunSampling(cdf, draws, true);
  const SampleRun without = RunSampling(cdf, draws, false);
  uint64_t linear = 0;
  for (size_t d = 0; d < draws.size(); ++d) {
    const int want = LinearPick(cdf, draws[d]);
    ASSERT_EQ(with.picks[d], want) << "draw " << d << " u = " << draws[d].to_double();
    ASSERT_EQ(without.picks[d], want) << "draw " << d;
    linear += want + 1;
  }
  EXPECT_EQ(uint64_t(with.counters.reads_linear.to_uint64()), linear);
  EXPECT_EQ(uint64_t(without.counters.reads.to_uint64()), linear) << "no tracker = linear scan";
  EXPECT_LT(with.counters.reads.to_uint64() * 10, linear);
  EXPECT_EQ(with.counters.draws.to_int(), int(draws.size()));
}

TEST(HwSampleSampling, TrackerReadRatioOnRealisticPrior) {
  // Thesis §7.4 results (banana, scene 1.6): 2520.27 reads per draw without the tracker,
  // 61.51 with it (41×). Ours: the synthetic scene's banana class, N = 510 thesis draws (one
  // LFSR step per draw, as the thesis).
  const std::vector<cdf_t> cdf = SceneCdf(9);
  const std::vector<unif18_t> draws = LfsrDraws(0x2ABCD, kMaxParticles, false);
  auto trace = std::make_unique<CycleTrace>();
  const SampleRun run = RunSampling(cdf, draws, true, trace.get());
  const double with = double(run.counters.reads.to_uint64()) / kMaxParticles;
  const double without = double(run.counters.reads_linear.to_uint64()) / kMaxParticles;
  std::printf("[tracker] reads per draw: %.2f linear vs %.2f with the tracker → %.1f× fewer\n", without,
              with, without / with);
  ::testing::Test::RecordProperty("reads_per_draw_linear", std::to_string(without));
  ::testing::Test::RecordProperty("reads_per_draw_tracker", std::to_string(with));
  EXPECT_GT(without / with, 10.0);
  // The trace's SAMPLE_SCAN trips are the reads.
  uint64_t scan = 0;
  for (int i = 0; i < trace->count; ++i)
    if (std::string(trace->records[i].loop) == "SAMPLE_SCAN") scan += trace->records[i].trips;
  EXPECT_EQ(scan, run.counters.reads.to_uint64());
}

// Upper α-quantile of χ²(df) (Wilson–Hilferty; z = 3.09 for α = 0.001).
double ChiSquareCritical(int df) {
  const double z = 3.090232;
  const double a = 2.0 / (9.0 * df);
  return df * std::pow(1 - a + z * std::sqrt(a), 3);
}

// Probability of each index under the hw CDF for u uniform over the 2^18 − 1 LFSR values:
// #{u : cdf[j−1] < u ≤ cdf[j]} / (2^18 − 1).
std::vector<double> HwIndexProbabilities(const std::vector<cdf_t>& cdf) {
  std::vector<double> p(cdf.size());
  long prev = 0;  // raw of cdf[j−1], u ≥ 1
  for (size_t j = 0; j < cdf.size(); ++j) {
    const long raw = long(std::lround(D(cdf[j]) * 262144));
    p[j] = double(std::max(0L, raw - std::max(prev, 0L))) / 262143;
    prev = std::max(prev, raw);
  }
  return p;
}

double ChiSquare(const std::vector<int>& picks, const std::vector<double>& p, int* df) {
  std::vector<long> count(p.size(), 0);
  for (int j : picks) ++count[j];
  const double n = double(picks.size());
  double chi = 0, rest_p = 0;
  long rest_c = 0;
  int bins = 0;
  for (size_t j = 0; j < p.size(); ++j) {
    if (n * p[j] >= 5) {
      chi += (count[j] - n * p[j]) * (count[j] - n * p[j]) / (n * p[j]);
      ++bins;
    } else {
      rest_p += p[j];
      rest_c += count[j];
    }
  }
  if (n * rest_p >= 5) {
    chi += (rest_c - n * rest_p) * (rest_c - n * rest_p) / (n * rest_p);
    ++bins;
  }
  *df = bins - 1;
  return chi;
}

TEST(HwSampleSampling, FrequenciesFollowTheProbabilities) {
  // 40 cells with distinct probabilities (the rest 0), 30 000 draws with LFSR leaps.
  auto prob = std::make_unique<prob_t[][1]>(kNumCells);
  for (int i = 0; i < kNumCells; ++i) prob[i][0] = 0;
  for (int k = 0; k < 40; ++k) prob[100 + 151 * k][0].range(7, 0) = 5 + 6 * k;
  bool fb = false;
  const std::vector<cdf_t> cdf = RunCdf<1>(prob.get(), 0, ClassSum<1>(prob.get(), 0), &fb);
  const std::vector<double> p_hw = HwIndexProbabilities(cdf);
  // The hw's index probabilities are the normalised prob_t values within 2^-17.
  double total = 0;
  for (int k = 0; k < 40; ++k) total += D(prob[100 + 151 * k][0]);
  for (int i = 0; i < kNumCells; ++i) ASSERT_NEAR(p_hw[i], D(prob[i][0]) / total, 2.0 / 131072) << i;

  const SampleRun run = RunSampling(cdf, LfsrDraws(0x1F00D, 30000, true), true);
  for (int j : run.picks) ASSERT_GT(D(prob[j][0]), 0.0) << "a zero-probability cell was drawn";
  int df = 0;
  const double chi = ChiSquare(run.picks, p_hw, &df);
  std::printf("[chi-square] %.1f with %d degrees of freedom (critical at 0.001: %.1f)\n", chi, df,
              ChiSquareCritical(df));
  EXPECT_EQ(df, 39);
  EXPECT_LT(chi, ChiSquareCritical(df));
  // Power: the same counts against a wrong distribution (probabilities moved one cell over
  // among the 40) are rejected.
  std::vector<double> wrong(p_hw.size(), 0);
  for (int k = 0; k < 40; ++k) wrong[100 + 151 * k] = p_hw[100 + 151 * ((k + 1) % 40)];
  int df2 = 0;
  const double chi_wrong = ChiSquare(run.picks, wrong, &df2);
  EXPECT_EQ(df2, 39);
  EXPECT_GT(chi_wrong, ChiSquareCritical(df2));
}

TEST(HwSampleSampling, FullLfsrPeriodHitsExactCounts) {
  // Over one full period of the thesis LFSR18 (one step per draw) every u ∈ [1, 2^18 − 1]
  // occurs once, so each cell is drawn exactly #{u : cdf[j−1] < u ≤ cdf[j]} times.
  const std::vector<cdf_t> cdf = SceneCdf(9);
  const std::vector<unif18_t> draws = LfsrDraws(0x2ABCD, int(kLfsr18Period), false);
  const SampleRun run = RunSampling(cdf, draws, true);
  std::vector<long> count(kNumCells, 0);
  for (int j : run.picks) ++count[j];
  const std::vector<double> p = HwIndexProbabilities(cdf);
  for (int j = 0; j < kNumCells; ++j) ASSERT_EQ(count[j], std::lround(p[j] * 262143)) << "cell " << j;
}

TEST(HwSampleSampling, UniformSourceRange) {
  const std::vector<unif18_t> thesis = LfsrDraws(0, 1000, false);  // zero seed → default
  const std::vector<unif18_t> leap = LfsrDraws(0, 1000, true);
  for (size_t i = 0; i < thesis.size(); ++i) {
    EXPECT_NE(D(thesis[i]), 0.0);
    EXPECT_NE(D(leap[i]), 0.0);
  }
  // One step per draw: u[t+1] = u[t]/2 + bit/2 (the top 17 bits are the previous top 17).
  for (size_t i = 1; i < thesis.size(); ++i)
    ASSERT_EQ(Bits(thesis[i], 16, 0), Bits(thesis[i - 1], 17, 1)) << i;
  // Leaps: consecutive draws are not shifted copies.
  int shifted = 0;
  for (size_t i = 1; i < leap.size(); ++i) shifted += Bits(leap[i], 16, 0) == Bits(leap[i - 1], 17, 1);
  EXPECT_LT(shifted, 20);
}

}  // namespace
}  // namespace posefilter::hw
