#include "filter/online_sorter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "posefilter/rng.h"

namespace posefilter::filter {
namespace {

TEST(OnlineSorterTest, MatchesAStableDescendingSort) {
  Rng rng(5);
  std::vector<RankedWeight> all;
  OnlineSorter s(500);
  for (int i = 0; i < 500; ++i) {
    const double w = std::floor(rng.Uniform() * 50) / 50;  // many ties
    s.Insert(w, i);
    all.push_back({w, i});
  }
  std::stable_sort(all.begin(), all.end(), [](auto& a, auto& b) { return a.weight > b.weight; });
  ASSERT_EQ(s.sorted().size(), all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(s.sorted()[i].index, all[i].index);
    EXPECT_EQ(s.sorted()[i].weight, all[i].weight);
  }
}

}  // namespace
}  // namespace posefilter::filter
