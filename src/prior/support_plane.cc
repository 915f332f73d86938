// prior/support_plane.cc — RANSAC for the dominant (table) plane of a depth image
// (support_plane.h).
#include "posefilter/support_plane.h"

#include <algorithm>
#include <cmath>

#include "core/plane_fit.h"
#include "posefilter/error.h"
#include "posefilter/rng.h"

namespace posefilter {
namespace {

constexpr std::uint64_t kRansacSeed = 0x5eed'7ab1e;  // fixed: the same image gives the same plane
constexpr int kMinPoints = 50;

// Least-squares plane through `pts` (smallest eigenvector of the scatter matrix), its normal
// turned towards the camera (the origin).
bool FitPlane(const std::vector<Eigen::Vector3d>& pts, Eigen::Vector3d* n, double* d) {
  if (pts.size() < 3) return false;
  const LeastSquaresPlane fit = FitLeastSquaresPlane(pts);
  *n = fit.normal;
  *d = -n->dot(fit.centroid);
  if (*d < 0) *n = -*n, *d = -*d;
  return n->allFinite();
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

bool SupportPlaneOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (samples < kMinPoints) return fail("samples must be >= 50");
  if (iterations < 1) return fail("iterations must be >= 1");
  if (!(ransac_band_m > 0 && std::isfinite(ransac_band_m))) return fail("ransac_band_m must be > 0");
  if (!(min_fraction > 0 && min_fraction <= 1)) return fail("min_fraction must be in (0, 1]");
  if (!(band_sigmas > 0 && std::isfinite(band_sigmas))) return fail("band_sigmas must be > 0");
  if (!(min_band_m > 0 && max_band_m >= min_band_m && std::isfinite(max_band_m)))
    return fail("the band clamp must satisfy 0 < min_band_m <= max_band_m");
  return true;
}

double SupportPlane::Band(double z, const SupportPlaneOptions& opt) const {
  return std::clamp(opt.band_sigmas * sigma_1m * z * z, opt.min_band_m, opt.max_band_m);
}

SupportPlane FindSupportPlane(const DepthImage& depth, const Camera& camera, const SupportPlaneOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("support plane: " + why);
  if (depth.width != camera.width || depth.height != camera.height)
    throw Error("support plane: the depth image's size differs from the camera's");
  // A regular grid of the valid pixels: stride chosen so that about `samples` remain.
  const std::size_t valid = depth.CountValid();
  SupportPlane plane;
  if (valid < std::size_t(kMinPoints)) return plane;
  const int stride = std::max(1, int(std::floor(std::sqrt(double(valid) / opt.samples))));
  std::vector<Eigen::Vector3d> pts;
  for (int v = stride / 2; v < depth.height; v += stride)
    for (int u = stride / 2; u < depth.width; u += stride) {
      const float z = depth.at(u, v);
      if (z > 0) pts.push_back(camera.Backproject(u, v, z));
    }
  if (pts.size() < std::size_t(kMinPoints)) return plane;

  Rng rng(kRansacSeed);
  const std::size_t n = pts.size();
  int best_count = 0;
  Eigen::Vector3d best_n = Eigen::Vector3d::Zero();
  double best_d = 0;
  for (int it = 0; it < opt.iterations; ++it) {
    const std::size_t a = rng.UniformInt(n), b = rng.UniformInt(n), c = rng.UniformInt(n);
    Eigen::Vector3d nn = (pts[b] - pts[a]).cross(pts[c] - pts[a]);
    const double len = nn.norm();
    if (!(len > 1e-9)) continue;
    nn /= len;
    double d = -nn.dot(pts[a]);
    if (d < 0) nn = -nn, d = -d;
    int count = 0;
    for (const auto& p : pts) count += std::fabs(nn.dot(p) + d) <= opt.ransac_band_m * p.z() * p.z();
    if (count > best_count) best_count = count, best_n = nn, best_d = d;
  }
  if (best_count < 3) return plane;
  // Refit on the inliers twice (the second with the refined plane's inliers).
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector3d> in;
    for (const auto& p : pts)
      if (std::fabs(best_n.dot(p) + best_d) <= opt.ransac_band_m * p.z() * p.z()) in.push_back(p);
    if (!FitPlane(in, &best_n, &best_d)) return plane;
  }
  std::vector<double> scaled;  // residual / z² of the inliers: σ at 1 m
  for (const auto& p : pts) {
    const double r = best_n.dot(p) + best_d;
    if (std::fabs(r) <= opt.ransac_band_m * p.z() * p.z()) scaled.push_back(r / (p.z() * p.z()));
  }
  const double med = Median(scaled);
  for (double& s : scaled) s = std::fabs(s - med);
  plane.normal = best_n;
  plane.offset = best_d;
  plane.sigma_1m = 1.4826 * Median(scaled);
  int on = 0;
  for (const auto& p : pts) on += std::fabs(plane.Height(p)) <= plane.Band(p.z(), opt);
  plane.fraction = double(on) / double(n);
  plane.found = plane.fraction >= opt.min_fraction;
  return plane;
}

std::vector<std::uint8_t> SupportPlanePixels(const DepthImage& depth, const Camera& camera, const SupportPlane& plane,
                                             const SupportPlaneOptions& opt) {
  std::vector<std::uint8_t> on(std::size_t(depth.width) * depth.height, 0);
  if (!plane.found) return on;
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u) {
      const float z = depth.at(u, v);
      if (z > 0 && std::fabs(plane.Height(camera.Backproject(u, v, z))) <= plane.Band(z, opt))
        on[std::size_t(v) * depth.width + u] = 1;
    }
  return on;
}

}  // namespace posefilter
