// posefilter/rng.h — the float engines' random numbers: seeded, portable, reproducible.
//
// xoshiro256** seeded through splitmix64; uniform and Gaussian draws are computed here (not
// with <random> distributions, whose output differs between standard libraries), so the
// same seed gives the same poses on every platform. (The `hw` engine uses the thesis's LFSRs.)
#pragma once

#include <cstdint>

namespace posefilter {

class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  std::uint64_t NextU64();
  // Uniform in [0, 1) with 53 random bits.
  double Uniform();
  // Uniform in [lo, hi).
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [0, n), n > 0 (unbiased).
  std::uint64_t UniformInt(std::uint64_t n);
  // Standard normal N(0, 1) by Box–Muller (eq. 5.1 [ALGORITHM.md]); both outputs of a pair are used.
  double Normal();
  // A new independent stream derived from this one (for per-object or per-worker streams).
  Rng Split();

 private:
  std::uint64_t s_[4];
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace posefilter
