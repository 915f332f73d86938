// Tests of src/hw/sorter.h: the macro-sorting-cell chain against std::stable_sort (descending,
// ties in arrival order), with many ties, partial fills and the cycle trace.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "hw/fx_math.h"
#include "hw/sorter.h"
#include "posefilter/rng.h"

namespace posefilter::hw {
namespace {

// Runs the network on raw weights (2^-17 units) and compares with std::stable_sort.
void CheckAgainstStableSort(const std::vector<uint32_t>& raw, CycleTrace* trace = nullptr) {
  const int n = int(raw.size());
  hls::stream<weight_t> in;
  for (uint32_t r : raw) in.write(UFixedFromRaw<18, 1>(ap_uint<18>(r)));
  weight_t w[kMaxParticles];
  particle_index_t idx[kMaxParticles];
  SortWeights(in, n, w, idx, trace);
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return raw[a] > raw[b]; });
  for (int k = 0; k < n; ++k) {
    ASSERT_EQ(idx[k].to_int(), order[k]) << "rank " << k << " of " << n;
    ASSERT_EQ(RawOf(w[k]).to_uint(), raw[order[k]]) << "rank " << k;
  }
  EXPECT_TRUE(in.empty());
}

TEST(HwRandomSorter, RandomWeightsFullSet) {
  Rng rng(3);
  for (int rep = 0; rep < 5; ++rep) {
    std::vector<uint32_t> raw(kMaxParticles);
    for (auto& r : raw) r = uint32_t(rng.UniformInt(1u << 17));  // weights in [0, 1)
    CheckAgainstStableSort(raw);
  }
}

TEST(HwRandomSorter, ManyTiesKeepArrivalOrder) {
  Rng rng(5);
  std::vector<uint32_t> raw(kMaxParticles);
  for (auto& r : raw) r = uint32_t(rng.UniformInt(7)) * 1000;  // 7 distinct values
  CheckAgainstStableSort(raw);
  std::vector<uint32_t> same(kMaxParticles, 4242);  // all equal: identity order
  CheckAgainstStableSort(same);
}

TEST(HwRandomSorter, AscendingDescendingAndPartialFills) {
  std::vector<uint32_t> asc(kMaxParticles), desc(kMaxParticles);
  for (int i = 0; i < kMaxParticles; ++i) {
    asc[i] = uint32_t(i) * 100;
    desc[i] = uint32_t(kMaxParticles - i) * 100;
  }
  CheckAgainstStableSort(asc);   // every arrival goes to the head: maximal displacement chain
  CheckAgainstStableSort(desc);  // every arrival passes through every full cell
  Rng rng(9);
  for (int n : {1, 2, 29, 30, 31, 61, 300, 509}) {
    std::vector<uint32_t> raw(n);
    for (auto& r : raw) r = uint32_t(rng.UniformInt(50));
    CheckAgainstStableSort(raw);
  }
  // Weight 1.0 and above (weight_t reaches 2 − 2^-17).
  CheckAgainstStableSort({1u << 17, (1u << 18) - 1, 0, 1u << 17, 5});
}

TEST(HwRandomSorter, TraceCountsArrivalsAndDrain) {
  std::vector<uint32_t> raw(100);
  for (int i = 0; i < 100; ++i) raw[i] = uint32_t((i * 37) % 101);
  CycleTrace trace;
  CheckAgainstStableSort(raw, &trace);
  ASSERT_EQ(trace.count, 2);
  EXPECT_STREQ(trace.records[0].loop, "SORT_INSERT");
  EXPECT_EQ(trace.records[0].trips, 100u);
  EXPECT_EQ(trace.records[0].ii, 1u);
  EXPECT_EQ(int(trace.records[0].depth), kSortCells);
  EXPECT_STREQ(trace.records[1].loop, "SORT_DRAIN");
  EXPECT_EQ(trace.records[1].trips, 100u);
}

}  // namespace
}  // namespace posefilter::hw
