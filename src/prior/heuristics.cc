// Per-cell heuristic volumes (thesis §1.1.2, §7.4; docs/ALGORITHM.md §3).
// See include/posefilter/heuristics.h.
#include "posefilter/heuristics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <tuple>
#include <utility>

#include "core/option_check.h"
#include "core/threads.h"
#include "posefilter/error.h"
#include "posefilter/option_rows.h"
#include "prior/quantiles.h"
#include "prior/volume_cache.h"

namespace posefilter {
namespace {

struct Scratch {
  std::vector<double> x, y, z;
  prior::QuantileScratch q;
};

// The centred regular grid of pixels sampled in a box (at most max_samples of them).
struct SampleGrid {
  bool empty = true;  // the box holds no pixel of the image
  int su = 0, sv = 0;  // first sampled pixel
  long step = 1, ku = 0, kv = 0;  // pixel step, samples per row and per column
};

SampleGrid GridOf(const DepthImage& depth, const Box& b, const HeuristicOptions& opt) {
  SampleGrid g;
  const int W = depth.width, H = depth.height;
  // Pixels whose centre lies in [cx − w/2, cx + w/2) × [cy − h/2, cy + h/2), cut to the image.
  // (Edges are clamped to [−1, size] before the int cast so huge boxes cannot overflow.)
  auto edge = [](double e, int size) { return int(std::ceil(std::clamp(e, -1.0, double(size)))); };
  const int u0 = std::max(0, edge(b.cx - b.w / 2, W));
  const int u1 = std::min(W - 1, edge(b.cx + b.w / 2, W) - 1);
  const int v0 = std::max(0, edge(b.cy - b.h / 2, H));
  const int v1 = std::min(H - 1, edge(b.cy + b.h / 2, H) - 1);
  if (u1 < u0 || v1 < v0) return g;
  const long nu = u1 - u0 + 1, nv = v1 - v0 + 1;
  // Grid step so that at most max_samples pixels are read.
  long step = std::max(1L, long(std::ceil(std::sqrt(double(nu * nv) / opt.max_samples))));
  while (((nu - 1) / step + 1) * ((nv - 1) / step + 1) > opt.max_samples) ++step;
  g.empty = false;
  g.step = step;
  g.ku = (nu - 1) / step + 1;
  g.kv = (nv - 1) / step + 1;
  g.su = u0 + int((nu - 1 - (g.ku - 1) * step) / 2);  // centre the grid in the box
  g.sv = v0 + int((nv - 1 - (g.kv - 1) * step) / 2);
  return g;
}

// A sampled depth that enters the volume: present and not too far.
inline bool Usable(double z, const HeuristicOptions& opt) { return z > 0 && z <= opt.max_depth_m; }

// Whether the box has a volume: enough usable samples (OneVolume's `valid`, without the points).
bool HasVolume(const DepthImage& depth, const Box& b, const HeuristicOptions& opt) {
  const SampleGrid g = GridOf(depth, b, opt);
  if (g.empty) return false;
  int count = 0;
  for (long j = 0; j < g.kv; ++j) {
    const float* depth_row = &depth.data[size_t(g.sv + int(j * g.step)) * depth.width];
    for (long i = 0; i < g.ku; ++i) count += Usable(depth_row[g.su + int(i * g.step)], opt);
  }
  return count >= opt.min_valid_pixels;
}

Volume OneVolume(const DepthImage& depth, const Camera& cam, const Eigen::Matrix3d& R,
                 const Eigen::Vector3d& t, const Box& b, const HeuristicOptions& opt,
                 Scratch& s) {
  Volume vol;
  const int W = depth.width;
  const SampleGrid g = GridOf(depth, b, opt);
  if (g.empty) return vol;

  // Per sample: ray direction d = R·((u − cx)/fx, (v − cy)/fy, 1), so the base-frame point is
  // pb = z·d + t (= R·Backproject(u, v, z) + t) and the extended point pe = pb + ext·d/|d|.
  // The column part of d is precomputed per row to keep the inner loop to a few FMAs.
  const double ext = opt.depth_extension_m;
  const size_t cap = size_t(g.ku * g.kv) * (ext > 0 ? 2 : 1);
  s.x.resize(cap);
  s.y.resize(cap);
  s.z.resize(cap);
  size_t m = 0;
  int count = 0;
  const Eigen::Vector3d rx = R.col(0) / cam.fx;
  for (long j = 0; j < g.kv; ++j) {
    const int v = g.sv + int(j * g.step);
    const double bv = (v - cam.cy) / cam.fy;
    const Eigen::Vector3d row = bv * R.col(1) + R.col(2) - cam.cx * rx;  // d at u = 0
    const float* depth_row = &depth.data[size_t(v) * W];
    for (long i = 0; i < g.ku; ++i) {
      const int u = g.su + int(i * g.step);
      const double z = depth_row[u];
      if (!Usable(z, opt)) continue;  // missing or too far
      ++count;
      const Eigen::Vector3d d = row + double(u) * rx;
      s.x[m] = z * d.x() + t.x();
      s.y[m] = z * d.y() + t.y();
      s.z[m] = z * d.z() + t.z();
      ++m;
      if (ext > 0) {
        // The same point pushed `ext` metres further along its viewing ray (|d| = |ray|
        // since R is a rotation).
        const double k = z + ext / d.norm();
        s.x[m] = k * d.x() + t.x();
        s.y[m] = k * d.y() + t.y();
        s.z[m] = k * d.z() + t.z();
        ++m;
      }
    }
  }
  s.x.resize(m);
  s.y.resize(m);
  s.z.resize(m);
  if (count < opt.min_valid_pixels) return vol;
  prior::QuantilePair(s.x.data(), m, opt.percentile_lo, opt.percentile_hi, &vol.min.x(), &vol.max.x(), s.q);
  prior::QuantilePair(s.y.data(), m, opt.percentile_lo, opt.percentile_hi, &vol.min.y(), &vol.max.y(), s.q);
  prior::QuantilePair(s.z.data(), m, opt.percentile_lo, opt.percentile_hi, &vol.min.z(), &vol.max.z(), s.q);
  vol.valid = true;
  return vol;
}

// ComputeHeuristics's input checks (throw Error naming the problem); returns the camera →
// base rotation and translation.
void CheckInputs(const DepthImage& depth, const Camera& camera, const std::vector<Box>& boxes,
                 const HeuristicOptions& opt, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("heuristic options: " + why);
  if (!camera.IsValid(&why)) throw Error("heuristics: invalid camera: " + why);
  if (depth.width != camera.width || depth.height != camera.height ||
      depth.data.size() != size_t(depth.width) * size_t(depth.height)) {
    throw Error("heuristics: depth image is " + std::to_string(depth.width) + "×" +
                std::to_string(depth.height) + " but the camera is " +
                std::to_string(camera.width) + "×" + std::to_string(camera.height));
  }
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    if (!(std::isfinite(b.cx) && std::isfinite(b.cy) && std::isfinite(b.w) &&
          std::isfinite(b.h) && b.w >= 0 && b.h >= 0)) {
      throw Error("heuristics: box " + std::to_string(i) +
                  " is not finite or has a negative size");
    }
  }
  const Eigen::Isometry3d cam_to_base = camera.base_to_camera.inverse();
  *R = cam_to_base.linear();
  *t = cam_to_base.translation();
}

}  // namespace

// The heuristic options' rows: their ranges and help are written here only (the filter's
// heuristics-* options take them from these rows).
std::span<const OptionInfo> HeuristicOptionTable() {
  using O = HeuristicOptions;
  const char* g = "Heuristic volumes";
  static const std::vector<OptionInfo> rows = [&] {
    std::vector<OptionInfo> r = {
        MakeOptionRow("percentile-lo", POSEFILTER_OPTION_FIELD(O, percentile_lo), g, kFractionRange,
                      "volume bounds: lower quantile of the cell's points, per axis"),
        MakeOptionRow("percentile-hi", POSEFILTER_OPTION_FIELD(O, percentile_hi), g, kFractionRange,
                      "volume bounds: upper quantile (>= the lower)"),
        MakeOptionRow("depth-extension", POSEFILTER_OPTION_FIELD(O, depth_extension_m), g, AtLeastRange(0),
                      "points also moved this far along their ray (m; 0 = the surface points only)"),
        MakeOptionRow("max-samples", POSEFILTER_OPTION_FIELD(O, max_samples), g, AtLeastRange(1),
                      "depth pixels sampled per box"),
        MakeOptionRow("max-depth", POSEFILTER_OPTION_FIELD(O, max_depth_m), g, kPositiveRange,
                      "depth beyond this is ignored (m)"),
        MakeOptionRow("min-valid-pixels", POSEFILTER_OPTION_FIELD(O, min_valid_pixels), g, AtLeastRange(1),
                      "a box with fewer valid sampled pixels has no volume"),
    };
    // The thesis clips the depth at 4 m (Table 7.1 [HARDWARE.md]); a thesis configuration keeps the caller's.
    r[4].thesis = "4";
    r[4].thesis_kept = true;
    return r;
  }();
  return rows;
}

bool HeuristicOptions::IsValid(std::string* why) const {
  if (!ValidateOptionRows(HeuristicOptionTable(), *this, OptionNaming::kField, why)) return false;
  if (percentile_lo > percentile_hi) return Fail(why, "percentile_lo must be <= percentile_hi");
  return true;
}

std::vector<Volume> ComputeHeuristics(const DepthImage& depth, const Camera& camera,
                                      const std::vector<Box>& boxes,
                                      const HeuristicOptions& opt, int threads) {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  CheckInputs(depth, camera, boxes, opt, &R, &t);
  // Identical boxes share one volume (a detection prior gives every cell overlapping a
  // detection the detection's box): compute each distinct box once.
  std::vector<int> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](int i) { return std::tie(boxes[i].cx, boxes[i].cy, boxes[i].w, boxes[i].h); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  std::vector<int> uniq;  // first index (in `order`) of each run of equal boxes
  for (size_t k = 0; k < order.size(); ++k)
    if (k == 0 || key(order[k]) != key(order[k - 1])) uniq.push_back(int(k));

  std::vector<Volume> out(boxes.size());
  const long n = long(uniq.size());
  // A few boxes on the calling thread; more on the workers, each with its own scratch
  // (reserved by its first box). Each box writes only its own volumes: any split, same result.
  const int nt = n > 256 ? WorkerThreads(threads) : 1;
  std::vector<Scratch> scratch(std::size_t(std::max(nt, 1)));
  ParallelFor(nt, int(n), 32, [&](int worker, int ui) {
    const long u = ui;
    Scratch& s = scratch[std::size_t(worker)];
    if (s.x.capacity() == 0) {
      s.x.reserve(2 * size_t(opt.max_samples));
      s.y.reserve(2 * size_t(opt.max_samples));
      s.z.reserve(2 * size_t(opt.max_samples));
    }
    const size_t begin = uniq[u], end = u + 1 < n ? size_t(uniq[u + 1]) : order.size();
    const Volume v = OneVolume(depth, camera, R, t, boxes[order[begin]], opt, s);
    for (size_t k = begin; k < end; ++k) out[order[k]] = v;
  });
  return out;
}

namespace prior {

VolumeCache::VolumeCache(const DepthImage& depth, const Camera& camera, const std::vector<Box>& boxes,
                         const HeuristicOptions& opt, int threads)
    : depth_(&depth), camera_(&camera), boxes_(&boxes), opt_(opt) {
  CheckInputs(depth, camera, boxes, opt, &R_, &t_);
  const long n = long(boxes.size());
  valid_.assign(std::size_t(n), 0);
  computed_->volumes.assign(std::size_t(n), Volume{});
  computed_->done.assign(std::size_t(n), 0);
  const int nt = n > 256 ? WorkerThreads(threads) : 1;
  ParallelFor(nt, int(n), 64,
              [&](int, int i) { valid_[std::size_t(i)] = HasVolume(depth, boxes[std::size_t(i)], opt) ? 1 : 0; });
}

VolumeCache::VolumeCache(std::vector<Volume> volumes) : valid_(volumes.size()) {
  for (std::size_t i = 0; i < volumes.size(); ++i) valid_[i] = volumes[i].valid ? 1 : 0;
  computed_->done.assign(volumes.size(), 1);
  computed_->count = int(volumes.size());
  computed_->volumes = std::move(volumes);
}

const Volume& VolumeCache::Get(int i) const {
  const std::size_t k = std::size_t(i);
  Computed& c = *computed_;
  const std::lock_guard<std::mutex> hold(c.lock);
  if (!c.done[k]) {
    if (valid_[k]) {
      Scratch s;
      c.volumes[k] = OneVolume(*depth_, *camera_, R_, t_, (*boxes_)[k], opt_, s);
    }
    c.done[k] = 1;
    ++c.count;
  }
  return c.volumes[k];
}

int VolumeCache::computed() const {
  const std::lock_guard<std::mutex> hold(computed_->lock);
  return computed_->count;
}

}  // namespace prior
}  // namespace posefilter
