#include "filter/cdf_sampler.h"

#include <algorithm>
#include <cmath>

#include "posefilter/error.h"

namespace posefilter::filter {

CdfSampler::CdfSampler(const std::vector<double>& weights, int tracker_bins) {
  double total = 0;
  for (double w : weights) {
    if (!(w >= 0) || !std::isfinite(w)) throw Error("CDF sampler: weights must be finite and >= 0");
    total += w;
  }
  if (weights.empty() || !(total > 0)) throw Error("CDF sampler: no probability mass to sample from");
  cdf_.resize(weights.size());
  double acc = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    acc += weights[i];
    cdf_[i] = acc / total;
  }
  cdf_.back() = 1.0;  // saturate the last value (the hw CDF does the same, §7.4)
  const int bins = std::max(1, tracker_bins);
  bin_start_.resize(bins);
  std::size_t i = 0;
  for (int b = 0; b < bins; ++b) {
    const double threshold = double(b) / bins;
    while (i + 1 < cdf_.size() && cdf_[i] < threshold) ++i;
    bin_start_[b] = int(i);
  }
}

int CdfSampler::Sample(double u) {
  const int bins = int(bin_start_.size());
  const int b = std::min(bins - 1, int(u * bins));
  int i = bin_start_[b];
  while (i + 1 < int(cdf_.size()) && cdf_[i] < u) ++i;
  reads_ += i - bin_start_[b] + 1;
  reads_linear_ += i + 1;
  return i;
}

}  // namespace posefilter::filter
