// src/filter/host_setup.cc — the host-side set-up every engine shares (host_setup.h): the
// heuristic-volume options, cell windows, hypothesis labels and resampling pool sizes.
#include "filter/host_setup.h"

#include <algorithm>
#include <cmath>

namespace posefilter::filter {

HeuristicOptions VolumeOptions(const FilterOptions& options, double diameter) {
  HeuristicOptions hopt = options.heuristics;
  if (hopt.depth_extension_m == 0) hopt.depth_extension_m = 0.5 * diameter;
  return hopt;
}

double MinWindowSide(const FilterOptions& options, double diameter, const Camera& camera, const Volume* volume) {
  const double z_cam = volume ? (camera.base_to_camera * volume->Centre()).z() : 1.0;
  return options.render.min_window_diameters * diameter * camera.fx / std::max(z_cam, options.render.near_m);
}

PixelRect CellWindow(const Box& box, double min_side, int max_px, int image_w, int image_h) {
  PixelRect r;
  r.width = std::clamp(int(std::lround(std::max(box.w, min_side))), 1, std::min(max_px, image_w));
  r.height = std::clamp(int(std::lround(std::max(box.h, min_side))), 1, std::min(max_px, image_h));
  r.u0 = std::clamp(int(std::lround(box.cx - 0.5 * r.width)), 0, image_w - r.width);
  r.v0 = std::clamp(int(std::lround(box.cy - 0.5 * r.height)), 0, image_h - r.height);
  return r;
}

int HypothesisLabeller::Label(const Box& b) {
  const std::array<long, 4> key = {std::lround(b.cx), std::lround(b.cy), std::lround(b.w), std::lround(b.h)};
  auto it = ids_.find(key);
  if (it == ids_.end()) {
    if (int(ids_.size()) >= max_labels_) return overflow_;
    it = ids_.emplace(key, first_ + int(ids_.size())).first;
  }
  return it->second;
}

int ResamplePoolSize(const FilterOptions& options, int set_size) {
  return std::max(std::max(options.num_elite, 1), int(std::lround(options.resample_pool * set_size)));
}

int NicheCap(double cap_fraction, int pool_size) {
  return std::max(1, int(std::ceil(cap_fraction * pool_size)));
}

}  // namespace posefilter::filter
