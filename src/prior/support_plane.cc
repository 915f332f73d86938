// prior/support_plane.cc — RANSAC for the dominant (table) plane of a depth image
// (support_plane.h).
#include "posefilter/support_plane.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/option_check.h"
#include "core/plane_fit.h"
#include "posefilter/error.h"
#include "posefilter/rng.h"

namespace posefilter {
namespace {

// One edge of a patch's outline in the plane's (a, b) frame, m: its start a, its direction
// e = b − a and its length |e| > 0.
struct OutlineEdge {
  double ax, ay, ex, ey, len;
};

// True when the foot of p on s (its coordinates in the plane's (a, b) frame) lies within
// margin_m outside of every edge of `edges` (s's outline; counter-clockwise, so outward is to
// the right of each edge).
bool FootWithin(const SupportSurface& s, const std::vector<OutlineEdge>& edges, const Eigen::Vector3d& p, double margin_m) {
  const Eigen::Vector3d q = p - s.origin;
  const double fx = q.dot(s.e1), fy = q.dot(s.e2);
  for (const OutlineEdge& g : edges)
    if ((g.ex * (fy - g.ay) - g.ey * (fx - g.ax)) / -g.len > margin_m) return false;
  return true;
}

// The non-degenerate edges of a counter-clockwise outline, in order.
std::vector<OutlineEdge> EdgesOf(const std::vector<Eigen::Vector2d>& outline) {
  std::vector<OutlineEdge> edges;
  for (std::size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d e = outline[(i + 1) % outline.size()] - a;
    const double len = e.norm();
    if (len > 0) edges.push_back({a.x(), a.y(), e.x(), e.y(), len});
  }
  return edges;
}

constexpr std::uint64_t kRansacSeed = 0x5eed'7ab1e;  // fixed: the same image gives the same plane
constexpr int kMinPoints = 50;
constexpr std::size_t kMaxOutline = 24;  // a patch's outline keeps at most this many vertices

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

// A plane's residual scale at 1 m (σ₁, m) from its inliers' residuals divided by z²: the
// median absolute deviation, scaled to a normal distribution's σ (1.4826).
double ResidualScale(std::vector<double> scaled) {
  const double med = Median(scaled);
  for (double& v : scaled) v = std::fabs(v - med);
  return 1.4826 * Median(scaled);
}

// A support surface's band about its plane at depth z, m: band_sigmas·σ₁·z², at least
// min_band_m, at most max_band_m·max(1, z²) (SupportSurface::Band).
double SurfaceBand(const SupportPlane& plane, double z, const SupportSurfaceOptions& opt) {
  return std::clamp(opt.plane.band_sigmas * plane.sigma_1m * z * z, opt.plane.min_band_m,
                    opt.plane.max_band_m * std::max(1.0, z * z));
}

// Convex hull of 2-D points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> Hull2d(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (pts.size() < 3) return pts;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

// Distance between two convex polygons (counter-clockwise; 0 when they overlap): the least
// distance of a vertex of one to an edge of the other.
double PointSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (a + t * e - p).norm();
}

bool InsideConvex(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly) {
  if (poly.size() < 3) return false;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[(i + 1) % poly.size()];
    if ((b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x()) < 0) return false;
  }
  return true;
}

}  // namespace

double HullDistance(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  if (a.empty() || b.empty()) return 1e30;
  if (InsideConvex(a.front(), b) || InsideConvex(b.front(), a)) return 0;
  double best = 1e30;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& p = pass == 0 ? a : b;
    const auto& q = pass == 0 ? b : a;
    for (const Eigen::Vector2d& v : p)
      for (std::size_t i = 0; i < q.size(); ++i) best = std::min(best, PointSegment(v, q[i], q[(i + 1) % q.size()]));
  }
  return best;
}

bool SupportPlaneOptions::IsValid(std::string* why) const {
  if (samples < kMinPoints) return Fail(why, "samples must be >= 50");
  if (iterations < 1) return Fail(why, "iterations must be >= 1");
  if (!(ransac_band_m > 0 && std::isfinite(ransac_band_m))) return Fail(why, "ransac_band_m must be > 0");
  if (!(min_fraction > 0 && min_fraction <= 1)) return Fail(why, "min_fraction must be in (0, 1]");
  if (!(band_sigmas > 0 && std::isfinite(band_sigmas))) return Fail(why, "band_sigmas must be > 0");
  if (!(min_band_m > 0 && max_band_m >= min_band_m && std::isfinite(max_band_m)))
    return Fail(why, "the band clamp must satisfy 0 < min_band_m <= max_band_m");
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
  plane.normal = best_n;
  plane.offset = best_d;
  plane.sigma_1m = ResidualScale(std::move(scaled));
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

bool SupportSurfaceOptions::IsValid(std::string* why) const {
  std::string p;
  if (!plane.IsValid(&p)) return Fail(why, "plane: " + p);
  if (max_planes < 1) return Fail(why, "max_planes must be >= 1");
  if (!(min_fraction > 0 && min_fraction <= 1)) return Fail(why, "min_fraction must be in (0, 1]");
  if (neighbourhood < 1) return Fail(why, "neighbourhood must be >= 1");
  if (!(min_area_m2 > 0 && std::isfinite(min_area_m2))) return Fail(why, "min_area_m2 must be > 0");
  if (!(max_tilt_deg > 0 && max_tilt_deg < 90)) return Fail(why, "max_tilt_deg must be in (0, 90)");
  if (!(large_area_m2 > 0 && std::isfinite(large_area_m2))) return Fail(why, "large_area_m2 must be > 0");
  if (!(margin_m >= 0 && std::isfinite(margin_m))) return Fail(why, "margin_m must be >= 0");
  if (!(min_rise_m >= 0 && std::isfinite(min_rise_m))) return Fail(why, "min_rise_m must be >= 0");
  if (!(merge_gap_m >= 0 && std::isfinite(merge_gap_m))) return Fail(why, "merge_gap_m must be >= 0");
  return true;
}

bool SupportSurface::Over(const Eigen::Vector3d& p, double margin_m) const {
  if (outline.size() < 3) return false;
  return FootWithin(*this, EdgesOf(outline), p, margin_m);
}

double SupportSurface::Band(double z, const SupportSurfaceOptions& opt) const { return SurfaceBand(plane, z, opt); }

int SupportSurfaces::Below(const Eigen::Vector3d& p, const SupportSurfaceOptions& opt, double max_height_m) const {
  int best = -1;
  double best_h = 0;
  for (int i = 0; i < supports; ++i) {
    const SupportSurface& s = patches[std::size_t(i)];
    const double h = s.plane.Height(p);
    if (h < -s.Band(p.z(), opt)) continue;
    if (h > max_height_m || (best >= 0 && h >= best_h)) continue;
    if (!s.Over(p, opt.margin_m)) continue;
    best = i, best_h = h;
  }
  return best;
}

SupportSurfaces FindSupportSurfaces(const DepthImage& depth, const Camera& camera, const SupportSurfaceOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("support surfaces: " + why);
  if (depth.width != camera.width || depth.height != camera.height)
    throw Error("support surfaces: the depth image's size differs from the camera's");
  SupportSurfaces out;
  const std::size_t valid = depth.CountValid();
  if (valid < std::size_t(kMinPoints)) return out;
  // The grid of samples (as FindSupportPlane): cell (gx, gy) holds pixel (gx·stride + stride/2, …).
  const int stride = std::max(1, int(std::floor(std::sqrt(double(valid) / opt.plane.samples))));
  const int gw = (depth.width - stride / 2 + stride - 1) / stride, gh = (depth.height - stride / 2 + stride - 1) / stride;
  std::vector<Eigen::Vector3d> pts;
  std::vector<int> cell_of;                               // sample → grid cell
  std::vector<int> at(std::size_t(gw) * std::size_t(gh), -1);  // grid cell → sample, −1 none
  for (int gy = 0; gy < gh; ++gy)
    for (int gx = 0; gx < gw; ++gx) {
      const int u = gx * stride + stride / 2, v = gy * stride + stride / 2;
      const float z = depth.at(u, v);
      if (!(z > 0)) continue;
      at[std::size_t(gy) * gw + gx] = int(pts.size());
      cell_of.push_back(gy * gw + gx);
      pts.push_back(camera.Backproject(u, v, z));
    }
  const std::size_t n = pts.size();
  if (n < std::size_t(kMinPoints)) return out;
  // Each sample's normal from its grid neighbours two cells away (zero where one is missing or
  // across a depth step of more than 5 % of the depth): an inlier's normal must agree with the
  // plane's, or a plane grazing the far field (whose band grows with z²) would collect the
  // noise of every distant surface it cuts.
  std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    const int gx = cell_of[i] % gw, gy = cell_of[i] / gw;
    auto sample = [&](int x, int y) { return x < 0 || y < 0 || x >= gw || y >= gh ? -1 : at[std::size_t(y) * gw + x]; };
    const int l = sample(gx - 2, gy), r = sample(gx + 2, gy), u = sample(gx, gy - 2), dn = sample(gx, gy + 2);
    if (l < 0 || r < 0 || u < 0 || dn < 0) continue;
    const double z = pts[i].z();
    bool smooth = true;
    for (int q : {l, r, u, dn}) smooth = smooth && std::fabs(pts[std::size_t(q)].z() - z) <= 0.05 * z;
    if (!smooth) continue;
    const Eigen::Vector3d nn = (pts[std::size_t(r)] - pts[std::size_t(l)]).cross(pts[std::size_t(dn)] - pts[std::size_t(u)]);
    if (nn.norm() > 0) normal[i] = nn.normalized();
  }
  constexpr double kMaxBandM = 0.03;           // the RANSAC band's cap (far points), metres
  const double cos_normal = std::cos(30 * M_PI / 180.0);  // an inlier's normal within 30° of the plane's
  const double band = opt.plane.ransac_band_m;
  auto inlier_at = [&](const Eigen::Vector3d& nn, double d, std::size_t i) {
    const Eigen::Vector3d& p = pts[i];
    if (std::fabs(nn.dot(p) + d) > std::min(kMaxBandM, band * p.z() * p.z())) return false;
    return normal[i].isZero() || std::fabs(normal[i].dot(nn)) >= cos_normal;
  };
  std::vector<std::uint8_t> used(n, 0);
  std::vector<int> pool(n);
  std::iota(pool.begin(), pool.end(), 0);
  Rng rng(kRansacSeed);
  const int R = opt.neighbourhood;
  const std::uint64_t side = 2 * std::uint64_t(R) + 1;  // the neighbourhood's cells per row and column
  std::vector<SupportSurface> patches;
  std::vector<std::vector<int>> patch_samples;  // per patch: its samples
  for (int plane_index = 0; plane_index < opt.max_planes; ++plane_index) {
    pool.erase(std::remove_if(pool.begin(), pool.end(), [&](int i) { return used[std::size_t(i)] != 0; }), pool.end());
    if (double(pool.size()) < opt.min_fraction * double(n) || pool.size() < 3) break;
    int best_count = 0;
    Eigen::Vector3d best_n = Eigen::Vector3d::Zero();
    double best_d = 0;
    for (int it = 0; it < opt.plane.iterations; ++it) {
      const int a = pool[rng.UniformInt(pool.size())];
      const int ax = cell_of[std::size_t(a)] % gw, ay = cell_of[std::size_t(a)] / gw;
      int b = -1, c = -1;
      for (int t = 0; t < 20 && (b < 0 || c < 0); ++t) {
        const int x = ax + int(rng.UniformInt(side)) - R;
        const int y = ay + int(rng.UniformInt(side)) - R;
        if (x < 0 || y < 0 || x >= gw || y >= gh) continue;
        const int q = at[std::size_t(y) * gw + x];
        if (q < 0 || q == a || q == b || used[std::size_t(q)]) continue;
        (b < 0 ? b : c) = q;
      }
      if (b < 0 || c < 0) continue;
      Eigen::Vector3d nn = (pts[std::size_t(b)] - pts[std::size_t(a)]).cross(pts[std::size_t(c)] - pts[std::size_t(a)]);
      const double len = nn.norm();
      if (!(len > 1e-12)) continue;
      nn /= len;
      double d = -nn.dot(pts[std::size_t(a)]);
      if (d < 0) nn = -nn, d = -d;
      int count = 0;
      for (int i : pool) count += inlier_at(nn, d, std::size_t(i));
      if (count > best_count) best_count = count, best_n = nn, best_d = d;
    }
    if (double(best_count) < opt.min_fraction * double(n) || best_count < 3) break;
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<Eigen::Vector3d> in;
      for (int i : pool)
        if (inlier_at(best_n, best_d, std::size_t(i))) in.push_back(pts[std::size_t(i)]);
      if (in.size() < 3 || !FitPlane(in, &best_n, &best_d)) break;
    }
    std::vector<int> members;
    for (int i : pool)
      if (inlier_at(best_n, best_d, std::size_t(i))) members.push_back(i);
    if (double(members.size()) < opt.min_fraction * double(n) || members.size() < 3) {
      // The refit moved off the hypothesis' inliers: take those out so the peeling goes on.
      for (int i : pool) used[std::size_t(i)] |= inlier_at(best_n, best_d, std::size_t(i));
      continue;
    }
    // The plane's residual scale (as FindSupportPlane), then twice: the members within the
    // band that scale gives (k·σ₁·z², clamped as SupportSurface::Band), a refit and the scale
    // again on them. On a small surface the tops of thin objects lying on it are a good part
    // of the RANSAC band's inliers; they would tilt the plane and widen its band until the
    // band swallows them. Two surfaces a few centimetres apart (a tablet before a desk) are
    // one RANSAC plane at 2 m; the band splits them, and the lesser goes on to be peeled.
    SupportPlane plane;
    auto residual_scale = [&](const std::vector<int>& set, const Eigen::Vector3d& nn, double d) {
      std::vector<double> scaled;
      for (int i : set) {
        const Eigen::Vector3d& p = pts[std::size_t(i)];
        scaled.push_back((nn.dot(p) + d) / (p.z() * p.z()));
      }
      return ResidualScale(std::move(scaled));
    };
    plane.sigma_1m = residual_scale(members, best_n, best_d);
    for (int round = 0; round < 2; ++round) {
      std::vector<int> tight;
      for (int i : members) {
        const Eigen::Vector3d& p = pts[std::size_t(i)];
        if (std::fabs(best_n.dot(p) + best_d) <= SurfaceBand(plane, p.z(), opt)) tight.push_back(i);
      }
      if (tight.size() < 3 || tight.size() == members.size()) break;
      std::vector<Eigen::Vector3d> in;
      for (int i : tight) in.push_back(pts[std::size_t(i)]);
      Eigen::Vector3d nn = best_n;
      double dd = best_d;
      if (!FitPlane(in, &nn, &dd)) break;
      best_n = nn, best_d = dd;
      members = std::move(tight);
      plane.sigma_1m = residual_scale(members, best_n, best_d);
    }
    plane.normal = best_n;
    plane.offset = best_d;
    std::vector<std::uint8_t> member_cell(std::size_t(gw) * gh, 0);
    for (int i : members) member_cell[std::size_t(cell_of[std::size_t(i)])] = 1;
    // The members leave the pool, and with them the band's tails of the same surface: a sample
    // within the RANSAC band next to a member (8-neighbourhood on the grid) is that surface's
    // noise beyond the tight band. Left in the pool, a large table's tails make a plane of
    // their own that grazes it, whose footprint area (1/cos of a grazing view) outvotes the
    // table for up. The band's samples away from the members stay: another surface.
    for (int i : pool) {
      if (member_cell[std::size_t(cell_of[std::size_t(i)])] || !inlier_at(best_n, best_d, std::size_t(i))) continue;
      const int cx = cell_of[std::size_t(i)] % gw, cy = cell_of[std::size_t(i)] / gw;
      bool next_to_member = false;
      for (int dy = -1; dy <= 1 && !next_to_member; ++dy)
        for (int dx = -1; dx <= 1 && !next_to_member; ++dx) {
          const int x = cx + dx, y = cy + dy;
          next_to_member = x >= 0 && y >= 0 && x < gw && y < gh && member_cell[std::size_t(y) * gw + x];
        }
      if (next_to_member) used[std::size_t(i)] = 1;
    }
    for (int i : members) used[std::size_t(i)] = 1;
    plane.fraction = double(members.size()) / double(n);
    plane.found = true;
    // Patches: 8-connected members on the grid, bridging one missing sample.
    std::vector<int> comp(std::size_t(gw) * gh, -1);
    const Eigen::Vector3d e1 = best_n.unitOrthogonal(), e2 = best_n.cross(e1);
    const Eigen::Vector3d origin = -best_d * best_n;
    struct Piece {
      double area = 0;
      std::vector<Eigen::Vector2d> ab, hull;
      std::vector<int> samples;
      std::size_t cells = 0;
    };
    std::vector<Piece> pieces;
    int next = 0;
    std::vector<int> stack, cells;
    for (int i : members) {
      const int start = cell_of[std::size_t(i)];
      if (comp[std::size_t(start)] >= 0) continue;
      cells.clear();
      stack.assign(1, start);
      comp[std::size_t(start)] = next;
      while (!stack.empty()) {
        const int cidx = stack.back();
        stack.pop_back();
        cells.push_back(cidx);
        const int cx = cidx % gw, cy = cidx / gw;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int x = cx + dx, y = cy + dy;
            if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= gw || y >= gh) continue;
            const int q = y * gw + x;
            if (!member_cell[std::size_t(q)] || comp[std::size_t(q)] >= 0) continue;
            comp[std::size_t(q)] = next;
            stack.push_back(q);
          }
      }
      ++next;
      // Area: each sample stands for stride² pixels, a pixel for (z/fx)·(z/fy) / |cos| of the plane.
      Piece piece;
      for (int cidx : cells) {
        const Eigen::Vector3d& p = pts[std::size_t(at[std::size_t(cidx)])];
        const double cosine = std::max(0.05, std::fabs(best_n.dot(p.normalized())));
        piece.area += double(stride) * stride * (p.z() / camera.fx) * (p.z() / camera.fy) / cosine;
        const Eigen::Vector3d q = p - origin;
        piece.ab.push_back(Eigen::Vector2d(q.dot(e1), q.dot(e2)));
        piece.samples.push_back(at[std::size_t(cidx)]);
      }
      piece.cells = cells.size();
      if (piece.cells < 3) continue;  // noise: never joins nor makes a patch
      piece.hull = Hull2d(piece.ab);
      pieces.push_back(std::move(piece));
    }
    // Pieces of one plane whose outlines lie within merge_gap_m of each other are one surface
    // that the objects standing on it cut apart in the image (a tablet seen around its
    // objects): one patch, its area the pieces' sum, its outline their hull.
    std::vector<int> group(pieces.size());
    std::iota(group.begin(), group.end(), 0);
    auto root = [&](int g) {
      while (group[std::size_t(g)] != g) g = group[std::size_t(g)] = group[std::size_t(group[std::size_t(g)])];
      return g;
    };
    for (std::size_t a = 0; a < pieces.size(); ++a)
      for (std::size_t b = a + 1; b < pieces.size(); ++b)
        if (root(int(a)) != root(int(b)) && HullDistance(pieces[a].hull, pieces[b].hull) <= opt.merge_gap_m)
          group[std::size_t(root(int(a)))] = root(int(b));
    for (std::size_t g = 0; g < pieces.size(); ++g) {
      if (root(int(g)) != int(g)) continue;
      double area = 0;
      std::size_t ncells = 0;
      std::vector<Eigen::Vector2d> ab;
      std::vector<int> samples;
      for (std::size_t k = 0; k < pieces.size(); ++k)
        if (root(int(k)) == int(g)) {
          area += pieces[k].area;
          ncells += pieces[k].cells;
          ab.insert(ab.end(), pieces[k].hull.begin(), pieces[k].hull.end());
          samples.insert(samples.end(), pieces[k].samples.begin(), pieces[k].samples.end());
        }
      if (area < opt.min_area_m2) continue;
      SupportSurface patch;
      patch.plane = plane;
      patch.plane.fraction = double(ncells) / double(n);
      patch.origin = origin;
      patch.e1 = e1;
      patch.e2 = e2;
      patch.outline = Hull2d(std::move(ab));
      if (patch.outline.size() > kMaxOutline) {  // evenly spaced vertices: a convex polygon inside it
        std::vector<Eigen::Vector2d> fewer;
        for (std::size_t k = 0; k < kMaxOutline; ++k) fewer.push_back(patch.outline[k * patch.outline.size() / kMaxOutline]);
        patch.outline = std::move(fewer);
      }
      patch.area_m2 = area;
      if (patch.outline.size() >= 3) {
        patches.push_back(std::move(patch));
        patch_samples.push_back(std::move(samples));
      }
    }
  }
  if (patches.empty()) return out;
  // Up: the normal (not pointing down the image) whose parallel patches have the most area.
  const double cos_tilt = std::cos(opt.max_tilt_deg * M_PI / 180.0);
  double best_area = 0;
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const SupportSurface& c : patches) {
    if (c.plane.normal.y() >= 0.1) continue;
    double area = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const SupportSurface& o : patches)
      if (o.plane.normal.dot(c.plane.normal) >= cos_tilt) area += o.area_m2, sum += o.area_m2 * o.plane.normal;
    if (area > best_area) best_area = area, up = sum.normalized();
  }
  // Walls stand upright: when the largest patch nearly square to up (within max_tilt_deg) is
  // structure-sized and at least as large as the area that gave up, up is made square to it.
  // Without a floor in view, up is a small surface's normal, tilted by degrees (below); a
  // large wall's normal is not.
  if (!up.isZero()) {
    const double sin_tilt = std::sin(opt.max_tilt_deg * M_PI / 180.0);
    const SupportSurface* wall = nullptr;
    for (const SupportSurface& p : patches)
      if (std::fabs(p.plane.normal.dot(up)) <= sin_tilt && p.area_m2 >= opt.large_area_m2 && (!wall || p.area_m2 > wall->area_m2))
        wall = &p;
    if (wall && wall->area_m2 >= best_area)
      up = (up - up.dot(wall->plane.normal) * wall->plane.normal).normalized();
  }
  for (SupportSurface& p : patches) p.support = !up.isZero() && p.plane.normal.dot(up) >= cos_tilt;
  // Supports are level: each takes up as its normal and, as its offset, the height of up that
  // most of its samples share (a small patch's least-squares fit tilts by degrees under the
  // sensor's correlated noise and the tops of thin objects lying on it), its σ₁ from the
  // samples around that height. A patch that the camera sees from below, or whose samples
  // do not agree on one height, keeps its fit.
  for (std::size_t k = 0; k < patches.size(); ++k) {
    SupportSurface& p = patches[k];
    if (!p.support) continue;
    const std::vector<int>& idx = patch_samples[k];
    std::vector<double> h(idx.size()), tol(idx.size());
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const Eigen::Vector3d& q = pts[std::size_t(idx[i])];
      h[i] = up.dot(q);
      tol[i] = std::clamp(0.5 * band * q.z() * q.z(), opt.plane.min_band_m, kMaxBandM);
    }
    const std::size_t step = std::max<std::size_t>(1, idx.size() / 64);
    std::size_t best_count = 0;
    double best_h = 0;
    for (std::size_t c = 0; c < idx.size(); c += step) {
      std::size_t count = 0;
      for (std::size_t i = 0; i < idx.size(); ++i) count += std::fabs(h[i] - h[c]) <= tol[i];
      if (count > best_count) best_count = count, best_h = h[c];
    }
    if (best_count < 3 || double(best_count) < 0.5 * double(idx.size())) continue;
    std::vector<double> near, scaled;
    for (std::size_t i = 0; i < idx.size(); ++i)
      if (std::fabs(h[i] - best_h) <= tol[i]) near.push_back(h[i]);
    const double level = Median(near);
    if (!(-level > 0)) continue;  // seen from below: the camera must lie above (n·0 + d > 0)
    for (std::size_t i = 0; i < idx.size(); ++i)
      if (std::fabs(h[i] - level) <= tol[i]) {
        const double z = pts[std::size_t(idx[i])].z();
        scaled.push_back((h[i] - level) / (z * z));
      }
    // The outline's vertices, dropped onto the level plane, in its own coordinates.
    std::vector<Eigen::Vector3d> corners;
    for (const Eigen::Vector2d& a : p.outline) corners.push_back(p.origin + a.x() * p.e1 + a.y() * p.e2);
    p.plane.normal = up;
    p.plane.offset = -level;
    p.plane.sigma_1m = ResidualScale(std::move(scaled));
    p.origin = level * up;
    p.e1 = up.unitOrthogonal();
    p.e2 = up.cross(p.e1);
    std::vector<Eigen::Vector2d> ab;
    for (const Eigen::Vector3d& c : corners) ab.push_back(Eigen::Vector2d((c - p.origin).dot(p.e1), (c - p.origin).dot(p.e2)));
    p.outline = Hull2d(std::move(ab));
  }
  // An object's top: a horizontal patch less than min_rise_m above another it lies over.
  auto centroid = [](const SupportSurface& p) {
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& q : p.outline) m += q;
    m /= double(p.outline.size());
    return Eigen::Vector3d(p.origin + m.x() * p.e1 + m.y() * p.e2);
  };
  std::vector<std::uint8_t> object_top(patches.size(), 0);
  for (std::size_t i = 0; i < patches.size(); ++i)
    for (std::size_t j = 0; j < patches.size() && patches[i].support; ++j) {
      if (j == i || !patches[j].support) continue;
      const Eigen::Vector3d c = centroid(patches[i]);
      const double rise = patches[j].plane.Height(c);
      if (rise > patches[j].plane.Band(c.z(), opt.plane) && rise < opt.min_rise_m && patches[j].Over(c, opt.margin_m)) object_top[i] = 1;
    }
  std::vector<SupportSurface> supports, structure;
  for (std::size_t i = 0; i < patches.size(); ++i) {
    SupportSurface& p = patches[i];
    if (object_top[i]) continue;
    if (p.support)
      supports.push_back(std::move(p));
    else if (p.area_m2 >= opt.large_area_m2)
      structure.push_back(std::move(p));
  }
  auto larger = [](const SupportSurface& a, const SupportSurface& b) { return a.area_m2 > b.area_m2; };
  std::stable_sort(supports.begin(), supports.end(), larger);
  std::stable_sort(structure.begin(), structure.end(), larger);
  out.supports = int(supports.size());
  out.up = up;
  out.patches = std::move(supports);
  for (SupportSurface& p : structure) out.patches.push_back(std::move(p));
  return out;
}

std::vector<int> SupportSurfacePixels(const DepthImage& depth, const Camera& camera, const SupportSurfaces& surfaces,
                                      const SupportSurfaceOptions& opt) {
  std::vector<int> on(std::size_t(depth.width) * depth.height, 0);
  if (surfaces.patches.empty()) return on;
  // SupportSurface::Over per pixel with each outline's edges made once (the same arithmetic).
  std::vector<std::vector<OutlineEdge>> edges;
  for (const SupportSurface& s : surfaces.patches) edges.push_back(EdgesOf(s.outline));
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u) {
      const float z = depth.at(u, v);
      if (!(z > 0)) continue;
      const Eigen::Vector3d p = camera.Backproject(u, v, z);
      for (std::size_t k = 0; k < surfaces.patches.size(); ++k) {
        const SupportSurface& s = surfaces.patches[k];
        if (std::fabs(s.plane.Height(p)) > s.Band(z, opt)) continue;
        if (s.outline.size() < 3 || !FootWithin(s, edges[k], p, opt.margin_m)) continue;
        on[std::size_t(v) * depth.width + u] = int(k) + 1;
        break;
      }
    }
  return on;
}

}  // namespace posefilter
