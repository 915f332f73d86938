// src/filter/host_setup.h — host-side set-up every engine shares (internal): timing, the
// heuristic-volume options, the per-cell windows, the hypothesis labels of the niching, the
// resampling pool and its caps, and the hard inlier threshold's annealing. The float engines
// (src/filter/particle_filter.cc) and the hw engine's host side (src/filter/hw_driver.cc) both call
// these, so the two compute them the same way; where the hw engine must differ (hardware bit
// widths, its registers' encodings) the difference is a parameter or stays at its call site,
// with a comment there.
#pragma once

#include <array>
#include <chrono>
#include <climits>
#include <map>

#include "posefilter/camera.h"
#include "posefilter/filter.h"
#include "posefilter/heuristics.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"

namespace posefilter::filter {

// The drivers' wall clock (EstimateResult::time_ms, iteration_ms) and the milliseconds since t0.
using Clock = std::chrono::steady_clock;
inline double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The heuristic-volume options for an object of the given diameter (metres):
// options.heuristics, with depth_extension_m = 0 (unset) replaced by half the diameter (the
// object's centre lies about its radius behind the visible surface).
HeuristicOptions VolumeOptions(const FilterOptions& options, double diameter);

// The least side of a cell's window (pixels; thesis §7.5.3, docs/ALGORITHM.md §5):
// min_window_diameters × the object's diameter (metres) projected with fx at the depth of the
// cell's volume centre (camera frame; 1 m when `volume` is null: the cell has no volume),
// a depth nearer than near_m counting as near_m.
double MinWindowSide(const FilterOptions& options, double diameter, const Camera& camera, const Volume* volume);

// The cell's window (thesis §7.5.3; docs/ALGORITHM.md §5): the cell's box centred on the box
// centre, each side at least min_side (the object's projected diameter, so a box smaller than
// the object cannot truncate its rendering) and at most max_px, then shifted ("saturated") to
// lie inside the image.
PixelRect CellWindow(const Box& box, double min_side, int max_px, int image_w, int image_h);

// Hypothesis labels for niching (docs/ALGORITHM.md §7): cells whose decoded boxes agree to the
// pixel (centre and size rounded to whole pixels) share one label — all the cells a detection
// covers carry its box. Labels are handed out in order of first appearance: first, first + 1,
// …; once max_labels boxes have one, a new box gets `overflow`. The float engines label every
// cell, unbounded; the hw engine only cells with mass, in 8 bits (labels 1 … 255, 0 = none).
class HypothesisLabeller {
 public:
  explicit HypothesisLabeller(int first = 0, int max_labels = INT_MAX, int overflow = -1)
      : first_(first), max_labels_(max_labels), overflow_(overflow) {}
  // The label of a cell with this decoded box.
  int Label(const Box& box);
  // Distinct boxes labelled so far.
  int count() const { return int(ids_.size()); }

 private:
  int first_, max_labels_, overflow_;
  std::map<std::array<long, 4>, int> ids_;
};

// The resampling pool of a set of set_size particles (docs/ALGORITHM.md §7): the best
// resample_pool of it, at least num_elite and at least 1.
int ResamplePoolSize(const FilterOptions& options, int set_size);

// The most pool places one niche may take (region_cap, rotation_cap): cap_fraction of the
// pool, rounded up, at least 1.
int NicheCap(double cap_fraction, int pool_size);

// The hard inlier threshold (FilterOptions::score.inlier.hard_thr_m, metres) that goes with the
// annealed threshold thr1 = thr: scaled by thr / inlier.thr1_m, so it anneals with thr1. The
// arithmetic is T's: the float engines pass their float thr1 (float arithmetic, the kernels'
// InlierParams precision), the hw engine its double thr1 (double, rounded to dist_t after).
template <typename T>
T ScaledHardThreshold(const InlierParams& inlier, T thr) {
  return inlier.hard_thr_m * thr / inlier.thr1_m;
}

}  // namespace posefilter::filter
