// src/eval/metrics.cc — ADD, ADD-S, rotation/translation errors, model point sets
// (docs/DATASETS.md, "Metrics").
#include "posefilter/metrics.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <string_view>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/file_io.h"

namespace posefilter {
namespace {

// Exact nearest-neighbour queries over a fixed 3-D point set: a balanced k-d tree split at the
// median of the widest axis, leaves of ≤ kLeafSize points, pruned by each node's bounding box. Points are stored reordered so that
// each node covers a contiguous range [lo, hi).
class KdTree {
 public:
  explicit KdTree(std::vector<Eigen::Vector3d> pts) : pts_(std::move(pts)) {
    if (!pts_.empty()) Build(0, static_cast<int>(pts_.size()));
  }

  // Squared distance from q to the closest stored point (the set must be non-empty).
  double NearestSquared(const Eigen::Vector3d& q) const {
    double best = std::numeric_limits<double>::infinity();
    Search(0, q, &best);
    return best;
  }

 private:
  static constexpr int kLeafSize = 8;

  struct Node {
    int lo = 0, hi = 0;          // point range [lo, hi)
    int left = -1, right = -1;   // children (−1: leaf)
    Eigen::Vector3d min, max;    // bounding box of the node's points
  };

  // Squared distance from q to the node's bounding box (0 inside).
  static double BoxDistSquared(const Node& n, const Eigen::Vector3d& q) {
    return ((n.min - q).cwiseMax(q - n.max)).cwiseMax(0.0).squaredNorm();
  }

  int Build(int lo, int hi) {
    const int id = static_cast<int>(nodes_.size());
    Eigen::Vector3d mn = pts_[lo], mx = pts_[lo];
    for (int i = lo + 1; i < hi; ++i) {
      mn = mn.cwiseMin(pts_[i]);
      mx = mx.cwiseMax(pts_[i]);
    }
    nodes_.push_back(Node{lo, hi, -1, -1, mn, mx});
    if (hi - lo <= kLeafSize) return id;
    int dim = 0;
    (mx - mn).maxCoeff(&dim);
    const int mid = lo + (hi - lo) / 2;
    std::nth_element(pts_.begin() + lo, pts_.begin() + mid, pts_.begin() + hi,
                     [dim](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a[dim] < b[dim]; });
    const int left = Build(lo, mid);
    const int right = Build(mid, hi);
    nodes_[id].left = left;  // indexed again: push_back may have reallocated
    nodes_[id].right = right;
    return id;
  }

  void Search(int id, const Eigen::Vector3d& q, double* best) const {
    const Node& n = nodes_[id];
    if (n.left < 0) {
      for (int i = n.lo; i < n.hi; ++i) *best = std::min(*best, (pts_[i] - q).squaredNorm());
      return;
    }
    // Visit the closer child box first; skip a box farther than the best point so far.
    double dl = BoxDistSquared(nodes_[n.left], q), dr = BoxDistSquared(nodes_[n.right], q);
    int first = n.left, second = n.right;
    if (dr < dl) {
      std::swap(first, second);
      std::swap(dl, dr);
    }
    if (dl < *best) Search(first, q, best);
    if (dr < *best) Search(second, q, best);
  }

  std::vector<Eigen::Vector3d> pts_;
  std::vector<Node> nodes_;
};

void RequirePoints(const std::vector<Eigen::Vector3f>& pts, const char* what) {
  if (pts.empty()) throw Error(std::string(what) + ": empty model point set");
}

bool IsFinite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

}  // namespace

double AddError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                const Eigen::Isometry3d& T_gt) {
  RequirePoints(pts, "ADD");
  double sum = 0;
  for (const auto& p : pts) {
    const Eigen::Vector3d pd = p.cast<double>();
    sum += (T_est * pd - T_gt * pd).norm();
  }
  return sum / static_cast<double>(pts.size());
}

double AddSError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                 const Eigen::Isometry3d& T_gt) {
  RequirePoints(pts, "ADD-S");
  std::vector<Eigen::Vector3d> est;
  est.reserve(pts.size());
  for (const auto& p : pts) est.push_back(T_est * p.cast<double>());
  const KdTree tree(std::move(est));
  double sum = 0;
  for (const auto& p : pts) sum += std::sqrt(tree.NearestSquared(T_gt * p.cast<double>()));
  return sum / static_cast<double>(pts.size());
}

double RotationErrorDeg(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_gt) {
  const Eigen::Matrix3d R = R_est.transpose() * R_gt;
  const double c = 0.5 * (R.trace() - 1.0);
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double s = 0.5 * v.norm();
  return std::atan2(s, c) * 180.0 / std::numbers::pi;
}

double TranslationError(const Eigen::Vector3d& t_est, const Eigen::Vector3d& t_gt) {
  return (t_est - t_gt).norm();
}

PoseErrors ComputePoseErrors(const std::vector<Eigen::Vector3f>& pts, double diameter,
                             const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_gt,
                             double threshold) {
  if (!std::isfinite(diameter) || diameter <= 0)
    throw Error("pose errors: diameter must be finite and > 0 (got " + std::to_string(diameter) + ")");
  if (!std::isfinite(threshold) || threshold <= 0)
    throw Error("pose errors: threshold must be finite and > 0 (got " + std::to_string(threshold) + ")");
  if (!IsFinite(T_est)) throw Error("pose errors: estimated pose has a NaN/inf entry");
  if (!IsFinite(T_gt)) throw Error("pose errors: ground-truth pose has a NaN/inf entry");
  PoseErrors e;
  e.add = AddError(pts, T_est, T_gt);
  e.adds = AddSError(pts, T_est, T_gt);
  e.rot_deg = RotationErrorDeg(T_est.linear(), T_gt.linear());
  e.trans_m = TranslationError(T_est.translation(), T_gt.translation());
  e.diameter = diameter;
  const double limit = threshold * diameter;
  e.add_ok = e.add < limit;
  e.adds_ok = e.adds < limit;
  return e;
}

std::vector<Eigen::Vector3f> SamplePoints(const Mesh& mesh, int max_points) {
  if (max_points < 1)
    throw Error("SamplePoints: max_points must be ≥ 1 (got " + std::to_string(max_points) + ")");
  if (mesh.vertices.empty()) throw Error("SamplePoints: mesh '" + mesh.name + "' has no vertices");
  const std::size_t n = mesh.vertices.size();
  const std::size_t m = static_cast<std::size_t>(max_points);
  const std::size_t stride = (n + m - 1) / m;  // ⌈n / m⌉ ≥ 1
  std::vector<Eigen::Vector3f> out;
  out.reserve((n + stride - 1) / stride);
  for (std::size_t i = 0; i < n; i += stride) out.push_back(mesh.vertices[i]);
  return out;
}

std::vector<Eigen::Vector3f> ReadXyzPoints(const std::string& path) {
  CheckInputFile(path, kMaxSmallFileBytes, "point file");
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open point file");
  std::vector<Eigen::Vector3f> pts;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto where = [&] { return path + ":" + std::to_string(line_no) + ": "; };
    std::vector<std::string_view> tok;
    std::string_view rest(line);
    constexpr std::string_view kSpace = " \t\r\f\v";
    while (true) {
      const auto b = rest.find_first_not_of(kSpace);
      if (b == std::string_view::npos) break;
      rest.remove_prefix(b);
      const auto e = std::min(rest.find_first_of(kSpace), rest.size());
      tok.push_back(rest.substr(0, e));
      rest.remove_prefix(e);
    }
    if (tok.empty()) continue;  // blank line
    if (tok.size() != 3)
      throw Error(where() + "expected 3 numbers \"x y z\", got " + std::to_string(tok.size()) + " fields");
    Eigen::Vector3f p;
    for (int k = 0; k < 3; ++k) {
      double v = 0;
      const char* first = tok[k].data();
      const char* last = first + tok[k].size();
      const auto [ptr, ec] = std::from_chars(first, last, v);
      if (ec != std::errc() || ptr != last)
        throw Error(where() + "not a number: '" + std::string(tok[k]) + "'");
      p[k] = static_cast<float>(v);
      if (!std::isfinite(v) || !std::isfinite(p[k]))
        throw Error(where() + "non-finite value '" + std::string(tok[k]) + "'");
    }
    pts.push_back(p);
  }
  if (in.bad()) throw Error(path + ": read error");
  if (pts.empty()) throw Error(path + ": no points in file");
  return pts;
}

}  // namespace posefilter
