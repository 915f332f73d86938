// src/filter/online_sorter.h — the sorting network of §7.5.4 in software form.
//
// Weights arrive one particle at a time; each is inserted into an always-sorted array
// (descending), exactly what a chain of macro sorting cells (shift registers with conditional
// insertion) does. Only (weight, relative index) pairs move, never whole samples.
#pragma once

#include <vector>

namespace posefilter::filter {

struct RankedWeight {
  double weight;
  int index;  // relative index into the sample memory
};

class OnlineSorter {
 public:
  explicit OnlineSorter(int capacity) { sorted_.reserve(capacity); }
  // Insert after every equal weight (stable: earlier arrivals rank first among ties).
  void Insert(double weight, int index) {
    auto it = sorted_.end();
    while (it != sorted_.begin() && (it - 1)->weight < weight) --it;
    sorted_.insert(it, RankedWeight{weight, index});
  }
  const std::vector<RankedWeight>& sorted() const { return sorted_; }

 private:
  std::vector<RankedWeight> sorted_;
};

}  // namespace posefilter::filter
