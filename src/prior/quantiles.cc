// Exact nearest-rank quantiles in O(n). See quantiles.h.
#include "prior/quantiles.h"

#include <algorithm>
#include <cmath>

namespace posefilter::prior {

// A 256-bin histogram over [min, max] finds the bins holding the two ranks, and
// std::nth_element runs only on those bins' values (about 3× faster than nth_element on the
// whole array, which mispredicts a branch per comparison). Measured with bench/prior_bench.cc
// and not used: four interleaved sub-histograms, one collecting pass for both ranks, a
// branch-free collection — none was faster.
void QuantilePair(const double* v, std::size_t n, double p_lo, double p_hi, double* lo, double* hi,
                  QuantileScratch& s) {
  const std::size_t r_lo = std::size_t(std::lround(p_lo * double(n - 1)));
  const std::size_t r_hi = std::max(r_lo, std::size_t(std::lround(p_hi * double(n - 1))));
  // Min/max with four independent accumulators (breaks the minsd dependency chain).
  double mn4[4] = {v[0], v[0], v[0], v[0]}, mx4[4] = {v[0], v[0], v[0], v[0]};
  std::size_t i4 = 0;
  for (; i4 + 4 <= n; i4 += 4) {
    for (int k = 0; k < 4; ++k) {
      mn4[k] = std::min(mn4[k], v[i4 + k]);
      mx4[k] = std::max(mx4[k], v[i4 + k]);
    }
  }
  for (; i4 < n; ++i4) {
    mn4[0] = std::min(mn4[0], v[i4]);
    mx4[0] = std::max(mx4[0], v[i4]);
  }
  const double mn = std::min(std::min(mn4[0], mn4[1]), std::min(mn4[2], mn4[3]));
  const double mx = std::max(std::max(mx4[0], mx4[1]), std::max(mx4[2], mx4[3]));
  if (!(mx > mn)) {
    *lo = *hi = mn;
    return;
  }
  constexpr int kBins = 256;
  const double scale = kBins / (mx - mn);
  int count[kBins] = {};
  s.bin_of.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int b = std::min(kBins - 1, int((v[i] - mn) * scale));
    s.bin_of[i] = std::uint8_t(b);
    ++count[b];
  }
  auto select = [&](std::size_t rank) {
    std::size_t before = 0;
    int b = 0;
    while (before + std::size_t(count[b]) <= rank) before += std::size_t(count[b++]);
    s.tmp.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (s.bin_of[i] == b) s.tmp.push_back(v[i]);
    std::nth_element(s.tmp.begin(), s.tmp.begin() + std::ptrdiff_t(rank - before), s.tmp.end());
    return s.tmp[rank - before];
  };
  *lo = select(r_lo);
  *hi = select(r_hi);
}

}  // namespace posefilter::prior
