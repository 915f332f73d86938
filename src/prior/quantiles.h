// Exact nearest-rank quantiles of a sample, the robust bounds of the heuristic volumes
// (docs/ALGORITHM.md §3; src/prior/heuristics.cc). Internal: not part of the public API.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace posefilter::prior {

// Reusable buffers of QuantilePair (one per thread).
struct QuantileScratch {
  std::vector<std::uint8_t> bin_of;
  std::vector<double> tmp;
};

// The nearest-rank quantiles p_lo ≤ p_hi of v[0..n) (n ≥ 1, finite values, 0 ≤ p ≤ 1): the
// values of sorted rank lround(p·(n − 1)) (the upper one at least the lower one's rank), exactly
// what sorting v and indexing would give, in O(n).
void QuantilePair(const double* v, std::size_t n, double p_lo, double p_hi, double* lo, double* hi,
                  QuantileScratch& s);

}  // namespace posefilter::prior
