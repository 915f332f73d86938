// tests/hw/hwsample_test_util.h — helpers of the HwSample* tests (post-process, CDF, threshold
// tracker, sampling, sample generation): running the kernels on host data, random and
// synthetic pyramids, and the double-precision references written for the tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "hw/cdf.h"
#include "hw/postprocess.h"
#include "posefilter/prior.h"
#include "posefilter/rng.h"

namespace posefilter::hw::hwsample_test {

// Output of one PostProcess<NC> run.
template <int NC>
struct HwPrior {
  std::unique_ptr<prob_t[][NC]> prob = std::make_unique<prob_t[][NC]>(kNumCells);
  std::vector<CellBox> boxes = std::vector<CellBox>(kNumCells);
  std::vector<Window> windows = std::vector<Window>(kNumCells);
  std::vector<class_sum_t> class_sum = std::vector<class_sum_t>(NC);
  std::unique_ptr<CycleTrace> trace = std::make_unique<CycleTrace>();
};

template <int NC>
HwPrior<NC> RunPostProcess(const std::vector<float>& raw, const PostProcessParams& prm) {
  HwPrior<NC> out;
  hls::stream<raw_t> in;
  RawPyramidToStream(raw, NC, in);
  CycleTrace* trace = out.trace.get();
  PostProcess<NC>(in, prm, out.prob.get(), out.boxes.data(), out.windows.data(), out.class_sum.data()
                      HW_TRACE_ARG);
  EXPECT_TRUE(in.empty()) << "post-process left raw values unread";
  return out;
}

// Random raw pyramid: logits uniform in [−9, 9], a few far out (±25, saturating the exp
// range), confidence c in [−7, 7], box offsets in [−0.8, 0.8], log sizes in [−2.5, 1.5].
inline std::vector<float> RandomRaw(int nc, std::uint64_t seed) {
  Rng rng(seed);
  const int per = nc + 5;
  std::vector<float> raw(size_t(kNumCells) * per);
  for (int cell = 0; cell < kNumCells; ++cell) {
    float* r = &raw[size_t(cell) * per];
    for (int j = 0; j < nc; ++j) {
      r[j] = float(rng.Uniform(-9, 9));
      if (rng.Uniform() < 0.01) r[j] = rng.Uniform() < 0.5 ? -25.f : 25.f;
    }
    r[nc + 0] = float(rng.Uniform(-0.8, 0.8));
    r[nc + 1] = float(rng.Uniform(-0.8, 0.8));
    r[nc + 2] = float(rng.Uniform(-2.5, 1.5));
    r[nc + 3] = float(rng.Uniform(-2.5, 1.5));
    r[nc + 4] = float(rng.Uniform(-7, 7));
  }
  return raw;
}

// A synthetic stage-1 output like the thesis's scene (§7.4 results, banana): detections
// converted to a raw pyramid by the library (DetectionsToRawPyramid).
inline std::vector<Detection> SceneDetections() {
  std::vector<Detection> d;
  d.push_back({"011_banana", 0.92, 300, 210, 90, 60});
  d.push_back({"025_mug", 0.75, 80, 300, 70, 80});
  d.push_back({"004_sugar_box", 0.6, 450, 120, 80, 150});
  d.push_back({"011_banana", 0.2, 520, 380, 60, 40});
  return d;
}

inline std::vector<float> SceneRaw() {
  return DetectionsToRawPyramid(SceneDetections(), PyramidLayout::Thesis(), YcbVideoClassNames());
}

inline double D(const prob_t& p) { return p.to_double(); }
inline double D(const cdf_t& p) { return p.to_double(); }

// Runs CdfNormalise<NC> for class cls; returns the kNumCells values.
template <int NC>
std::vector<cdf_t> RunCdf(const prob_t prob[kNumCells][NC], int cls, class_sum_t sum, bool* fallback,
                          CycleTrace* trace = nullptr) {
  hls::stream<cdf_t> s;
  bool fb = false;
  CdfNormalise<NC>(prob, cls, sum, s, fb HW_TRACE_ARG);
  std::vector<cdf_t> out;
  while (!s.empty()) out.push_back(s.read());
  if (fallback) *fallback = fb;
  return out;
}

// The exact sum of one class's prob_t values, as class_sum_t.
template <int NC>
class_sum_t ClassSum(const prob_t prob[kNumCells][NC], int cls) {
  class_sum_t s = 0;
  for (int i = 0; i < kNumCells; ++i) s = s + prob[i][cls];
  return s;
}

// Double-precision reference of eq. 7.3 [ALGORITHM.md] over the given (quantized) weights, no saturation.
inline std::vector<double> DoubleCdf(const std::vector<double>& w) {
  double total = 0;
  for (double x : w) total += x;
  std::vector<double> c(w.size());
  double acc = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    acc += w[i];
    c[i] = acc / total;
  }
  return c;
}

// Linear-scan reference of the sampling: the first index with cdf ≥ u.
inline int LinearPick(const std::vector<cdf_t>& cdf, const ap_ufixed<18, 0>& u) {
  for (size_t i = 0; i < cdf.size(); ++i)
    if (cdf[i] >= u) return int(i);
  return int(cdf.size()) - 1;
}

}  // namespace posefilter::hw::hwsample_test
