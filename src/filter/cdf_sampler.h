// src/filter/cdf_sampler.h — importance sampling from a normalised CDF with a threshold
// tracker (thesis §7.4 steps 1–4, reused by the resampling of §7.5.4).
#pragma once

#include <cstdint>
#include <vector>

namespace posefilter::filter {

class CdfSampler {
 public:
  // weights ≥ 0, not all zero; tracker_bins ≥ 1 entries of the threshold tracker.
  // CDF (eq. 7.3 [ALGORITHM.md]): c_i = Σ_{q≤i} w_q / Σ_k w_k, the last entry set to exactly 1.
  CdfSampler(const std::vector<double>& weights, int tracker_bins);

  // The first index i whose c_i ≥ u, u in (0, 1] (so zero-weight entries are never picked).
  // The tracker gives the first index whose
  // CDF reaches the bin floor(u·B)/B, so the scan starts there instead of at 0.
  int Sample(double u);

  const std::vector<double>& cdf() const { return cdf_; }
  // CDF entries read by Sample() so far, and what a scan from index 0 would have read.
  std::int64_t reads() const { return reads_; }
  std::int64_t reads_linear() const { return reads_linear_; }

 private:
  std::vector<double> cdf_;
  std::vector<int> bin_start_;  // threshold tracker: (bin value b/B) → first index with c ≥ b/B
  std::int64_t reads_ = 0, reads_linear_ = 0;
};

}  // namespace posefilter::filter
