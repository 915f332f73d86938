// prior/ppf.cc — point-pair-feature model, scene points and voting (posefilter/ppf.h).
#include "posefilter/ppf.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include "core/option_check.h"
#include "core/threads.h"
#include "posefilter/error.h"
#include "posefilter/rng.h"
#include "render/scene_normals.h"

namespace posefilter {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Angle between two vectors, radians in [0, π].
float Angle(const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// T_m of ppf.h: moves the point to the origin and turns its normal onto the x axis.
Eigen::Isometry3f ToReferenceFrame(const OrientedPoint& r) {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::Quaternionf::FromTwoVectors(r.n, Eigen::Vector3f::UnitX()).toRotationMatrix();
  T.translation() = -(T.linear() * r.p);
  return T;
}

// α of a point already in a reference frame: the angle about x from the half-plane {y > 0, z = 0}.
float AlphaOf(const Eigen::Vector3f& q) { return std::atan2(q.z(), q.y()); }

// Integer voxel coordinates of p for voxels of side `step`, packed for sorting.
struct VoxelKey {
  std::int64_t x, y, z;
  bool operator<(const VoxelKey& o) const { return std::tie(x, y, z) < std::tie(o.x, o.y, o.z); }
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
VoxelKey KeyOf(const Eigen::Vector3f& p, double step) {
  return {std::int64_t(std::floor(p.x() / step)), std::int64_t(std::floor(p.y() / step)),
          std::int64_t(std::floor(p.z() / step))};
}

// Indices 0..n−1 sorted by voxel (then by index: deterministic).
std::vector<std::size_t> SortedByVoxel(const std::vector<VoxelKey>& keys) {
  std::vector<std::size_t> order(keys.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  return order;
}

// The bounding rectangle [u0, u1) × [v0, v1) of a W × H mask's set pixels (empty: u0 ≥ u1).
struct Rect {
  int u0, v0, u1, v1;
};
Rect MaskBounds(const std::vector<std::uint8_t>& mask, int W, int H) {
  Rect r{W, H, 0, 0};
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u)
      if (mask[std::size_t(v) * W + u]) r = {std::min(r.u0, u), std::min(r.v0, v), std::max(r.u1, u + 1), std::max(r.v1, v + 1)};
  return r;
}

}  // namespace

bool PpfOptions::IsValid(std::string* why) const {
  if (!(distance_step > 0 && distance_step <= 0.5)) return Fail(why, "distance_step must be in (0, 0.5]");
  if (angle_bins < 4 || angle_bins > 64) return Fail(why, "angle_bins must be in [4, 64]");
  if (max_bucket < 1) return Fail(why, "max_bucket must be >= 1");
  if (alpha_bins < 4 || alpha_bins > 256) return Fail(why, "alpha_bins must be in [4, 256]");
  if (reference_stride < 1) return Fail(why, "reference_stride must be >= 1");
  if (!(cluster_translation > 0 && std::isfinite(cluster_translation)))
    return Fail(why, "cluster_translation must be > 0");
  if (!(cluster_rotation_rad > 0 && std::isfinite(cluster_rotation_rad)))
    return Fail(why, "cluster_rotation_rad must be > 0");
  if (max_proposals < 1) return Fail(why, "max_proposals must be >= 1");
  if (threads < 0 || threads > MaxWorkerThreads())
    return Fail(why, "threads must be in [0, " + std::to_string(MaxWorkerThreads()) + "]");
  if (!(min_relative_votes > 0 && min_relative_votes <= 1)) return Fail(why, "min_relative_votes must be in (0, 1]");
  return true;
}

int PpfModel::Key(const OrientedPoint& a, const OrientedPoint& b) const {
  const Eigen::Vector3f d = b.p - a.p;
  const float len = d.norm();
  if (!(len > 1e-9f)) return -1;
  const int dq = int(len / step);
  if (dq >= distance_bins) return -1;
  const float bin = float(angle_bins / kPi);
  auto q = [&](float angle) { return std::min(angle_bins - 1, int(angle * bin)); };
  return ((dq * angle_bins + q(Angle(a.n, d))) * angle_bins + q(Angle(b.n, d))) * angle_bins + q(Angle(a.n, b.n));
}

PpfModel BuildPpfModel(const Mesh& mesh, const PpfOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("ppf: " + why);
  if (!mesh.IsValid(&why)) throw Error("ppf: mesh '" + mesh.name + "': " + why);
  PpfModel m;
  m.mesh_hash = MeshContentHash(mesh);
  m.diameter = mesh.Diameter();
  m.step = opt.distance_step * m.diameter;
  m.angle_bins = opt.angle_bins;
  m.distance_bins = int(std::ceil(1.0 / opt.distance_step)) + 1;

  // Surface samples by area, about 16 per voxel face (step²), at most 400k in all.
  double area = 0;
  for (const auto& f : mesh.faces)
    area += 0.5 * double((mesh.vertices[f[1]] - mesh.vertices[f[0]]).cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]).norm());
  const double density = std::min(16.0 / (m.step * m.step), 400000.0 / std::max(area, 1e-12));  // samples per m²
  // Vertex normals (area-weighted face normals), interpolated across each face: a scanned
  // mesh's bumpy small faces would otherwise split every voxel into several normal groups.
  std::vector<Eigen::Vector3f> vn(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3f cr = (mesh.vertices[f[1]] - mesh.vertices[f[0]]).cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
    for (int k = 0; k < 3; ++k) vn[f[k]] += cr;
  }
  Rng rng(0x5050460001ull);
  std::vector<OrientedPoint> samples;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3f a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], c = mesh.vertices[f[2]];
    const Eigen::Vector3f cr = (b - a).cross(c - a);
    const double fa = 0.5 * double(cr.norm());
    if (!(fa > 0)) continue;
    const int count = int(fa * density + rng.Uniform());
    for (int k = 0; k < count; ++k) {
      double u = rng.Uniform(), v = rng.Uniform();
      if (u + v > 1) u = 1 - u, v = 1 - v;
      Eigen::Vector3f n = float(1 - u - v) * vn[f[0]].normalized() + float(u) * vn[f[1]].normalized() +
                          float(v) * vn[f[2]].normalized();
      // A sharp edge's vertex normal leans across the edge: keep the face's own where they differ by > 45°.
      if (!(n.norm() > 1e-6f) || n.normalized().dot(cr.normalized()) < 0.7f) n = cr;
      samples.push_back({a + float(u) * (b - a) + float(v) * (c - a), n.normalized()});
    }
  }
  // One point per voxel and normal direction: the normals of a voxel are grouped greedily
  // (within 30° of a group's first normal), each group gives its mean point and normal.
  std::vector<VoxelKey> keys(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) keys[i] = KeyOf(samples[i].p, m.step);
  const std::vector<std::size_t> order = SortedByVoxel(keys);
  const float kSameSide = std::cos(float(kPi / 6));
  for (std::size_t s = 0; s < order.size();) {
    std::size_t e = s;
    while (e < order.size() && keys[order[e]] == keys[order[s]]) ++e;
    struct Group {
      Eigen::Vector3f first_n, sum_p, sum_n;
      int count;
    };
    std::vector<Group> groups;
    for (std::size_t k = s; k < e; ++k) {
      const OrientedPoint& q = samples[order[k]];
      auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& g) { return g.first_n.dot(q.n) > kSameSide; });
      if (g == groups.end()) {
        groups.push_back({q.n, q.p, q.n, 1});
      } else {
        g->sum_p += q.p;
        g->sum_n += q.n;
        ++g->count;
      }
    }
    for (const Group& g : groups)
      if (g.sum_n.norm() > 1e-6f) m.points.push_back({g.sum_p / float(g.count), g.sum_n.normalized()});
    s = e;
  }
  // At most kMaxPoints points (a fixed stride through them): the table grows with their square.
  constexpr std::size_t kMaxPoints = PpfModel::kMaxPoints;
  if (m.points.size() > kMaxPoints) {
    std::vector<OrientedPoint> kept;
    for (std::size_t k = 0; k < kMaxPoints; ++k) kept.push_back(m.points[k * m.points.size() / kMaxPoints]);
    m.points = std::move(kept);
  }

  // The table: every ordered pair, counting-sorted by key.
  const std::size_t n = m.points.size();
  std::vector<std::int32_t> pair_key(n * n, -1);
  std::vector<float> pair_alpha(n * n, 0.f);
  m.offsets.assign(std::size_t(m.KeyCount()) + 1, 0);
  for (std::size_t r = 0; r < n; ++r) {
    const Eigen::Isometry3f T = ToReferenceFrame(m.points[r]);
    for (std::size_t i = 0; i < n; ++i) {
      if (i == r) continue;
      const int key = m.Key(m.points[r], m.points[i]);
      if (key < 0) continue;
      pair_key[r * n + i] = key;
      pair_alpha[r * n + i] = AlphaOf(T * m.points[i].p);
      ++m.offsets[std::size_t(key) + 1];
    }
  }
  std::partial_sum(m.offsets.begin(), m.offsets.end(), m.offsets.begin());
  m.entries.resize(m.offsets.back());
  std::vector<std::uint32_t> fill(m.offsets.begin(), m.offsets.end() - 1);
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t i = 0; i < n; ++i) {
      const int key = pair_key[r * n + i];
      if (key < 0) continue;
      const double q = std::floor((double(pair_alpha[r * n + i]) + kPi) * (65536 / (2 * kPi)));
      m.entries[fill[std::size_t(key)]++] = {std::uint16_t(r), std::uint16_t(std::clamp(q, 0.0, 65535.0))};
    }
  // Buckets above max_bucket keep an even stride through their entries.
  std::vector<std::uint32_t> offsets(m.offsets.size(), 0);
  std::vector<PpfEntry> kept;
  for (int k = 0; k < m.KeyCount(); ++k) {
    const std::size_t b = m.offsets[std::size_t(k)], count = m.offsets[std::size_t(k) + 1] - b;
    const std::size_t keep = std::min(count, std::size_t(opt.max_bucket));
    for (std::size_t j = 0; j < keep; ++j) kept.push_back(m.entries[b + j * count / keep]);
    offsets[std::size_t(k) + 1] = std::uint32_t(kept.size());
  }
  m.offsets = std::move(offsets);
  m.entries = std::move(kept);
  return m;
}

std::vector<OrientedPoint> PpfScenePoints(const DepthImage& depth, const Camera& camera,
                                          const std::vector<std::uint8_t>& pixel_mask, double step) {
  const int W = depth.width, H = depth.height;
  if (pixel_mask.size() != std::size_t(W) * H) throw Error("ppf: the pixel mask's size differs from the depth image's");
  // Normals only where the mask is (its bounding rectangle).
  const Rect r = MaskBounds(pixel_mask, W, H);
  std::vector<float> normals(std::size_t(W) * H * 3, 0.f);
  if (r.u0 < r.u1) render::NormalsInRect(depth, camera, r.u0, r.v0, r.u1, r.v1, normals.data());
  return PpfScenePoints(depth, camera, normals, pixel_mask, step);
}

std::vector<OrientedPoint> PpfScenePoints(const DepthImage& depth, const Camera& camera,
                                          const std::vector<float>& normals,
                                          const std::vector<std::uint8_t>& pixel_mask, double step) {
  const int W = depth.width, H = depth.height;
  if (pixel_mask.size() != std::size_t(W) * H) throw Error("ppf: the pixel mask's size differs from the depth image's");
  if (normals.size() != 3 * pixel_mask.size()) throw Error("ppf: the normals' size differs from the depth image's");
  if (!(step > 0)) throw Error("ppf: the voxel step must be > 0");
  std::vector<OrientedPoint> pts;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const std::size_t i = std::size_t(v) * W + u;
      const float* nn = &normals[3 * i];
      if (!pixel_mask[i] || (nn[0] == 0 && nn[1] == 0 && nn[2] == 0)) continue;
      pts.push_back({camera.Backproject(u, v, depth.at(u, v)).cast<float>(), Eigen::Vector3f(nn[0], nn[1], nn[2])});
    }
  std::vector<VoxelKey> keys(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) keys[i] = KeyOf(pts[i].p, step);
  const std::vector<std::size_t> order = SortedByVoxel(keys);
  std::vector<OrientedPoint> out;
  for (std::size_t s = 0; s < order.size();) {
    std::size_t e = s;
    Eigen::Vector3f sp = Eigen::Vector3f::Zero(), sn = Eigen::Vector3f::Zero();
    for (; e < order.size() && keys[order[e]] == keys[order[s]]; ++e) {
      sp += pts[order[e]].p;
      sn += pts[order[e]].n;
    }
    const float count = float(e - s);
    if (count >= 3 && sn.norm() >= 0.6f * count) out.push_back({sp / count, sn.normalized()});
    s = e;
  }
  return out;
}

std::vector<PoseProposal> MatchPpf(const PpfModel& model, const std::vector<OrientedPoint>& scene,
                                   const PpfOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("ppf: " + why);
  if (scene.size() < 3 || model.points.empty()) return {};
  const int A = opt.alpha_bins;
  const std::size_t Nm = model.points.size();
  // At most 256 reference points: large regions get a larger stride.
  const std::size_t stride = std::max<std::size_t>(std::size_t(opt.reference_stride), (scene.size() + 255) / 256);
  const float max_d2 = float(model.diameter * model.diameter);
  struct Vote {
    Eigen::Isometry3d T;
    std::uint32_t votes;
  };
  std::vector<std::size_t> refs;
  for (std::size_t r = 0; r < scene.size(); r += stride) refs.push_back(r);
  std::vector<Vote> per_ref(refs.size(), Vote{Eigen::Isometry3d::Identity(), 0});
  // References in parallel, each worker with its own accumulator (allocated by its first
  // reference); per_ref keeps their order.
  const int workers = WorkerThreads(opt.threads);
  std::vector<std::vector<std::uint32_t>> accumulators(std::size_t(std::max(workers, 1)));
  ParallelFor(workers, int(refs.size()), 4, [&](int worker, int ji) {
    const std::size_t j = std::size_t(ji);
    std::vector<std::uint32_t>& acc = accumulators[std::size_t(worker)];
    if (acc.empty()) acc.resize(Nm * std::size_t(A));
    const std::size_t r = refs[j];
    std::fill(acc.begin(), acc.end(), 0u);
    const Eigen::Isometry3f Ts = ToReferenceFrame(scene[r]);
    for (std::size_t i = 0; i < scene.size(); ++i) {
      if (i == r || (scene[i].p - scene[r].p).squaredNorm() > max_d2) continue;
      const int key = model.Key(scene[r], scene[i]);
      if (key < 0) continue;
      // α = α_m − α_s on the 16-bit circle of the entries (2π / 65536 per unit): the entry holds
      // α_m + π, so the wrapped difference is α + π in [0, 2π), and its bin is (diff · A) >> 16.
      const float alpha_s = AlphaOf(Ts * scene[i].p);
      const std::uint16_t s16 = std::uint16_t(std::int32_t(std::lround(alpha_s * float(65536 / (2 * kPi)))));
      for (std::uint32_t k = model.offsets[std::size_t(key)]; k < model.offsets[std::size_t(key) + 1]; ++k) {
        const PpfEntry& e = model.entries[k];
        const std::uint32_t diff = std::uint16_t(e.alpha - s16);
        ++acc[std::size_t(e.reference) * A + ((diff * std::uint32_t(A)) >> 16)];
      }
    }
    const auto peak = std::max_element(acc.begin(), acc.end());
    if (*peak == 0) return;
    const std::size_t at = std::size_t(peak - acc.begin());
    const double alpha = -kPi + (double(at % A) + 0.5) * 2 * kPi / A;
    const Eigen::Isometry3d Tm = ToReferenceFrame(model.points[at / A]).cast<double>();
    per_ref[j] = {Ts.cast<double>().inverse() * Eigen::AngleAxisd(-alpha, Eigen::Vector3d::UnitX()) * Tm, *peak};
  });
  std::vector<Vote> poses;
  for (const Vote& v : per_ref)
    if (v.votes > 0) poses.push_back(v);
  // Greedy clustering, most votes first.
  std::stable_sort(poses.begin(), poses.end(), [](const Vote& a, const Vote& b) { return a.votes > b.votes; });
  const double max_t = opt.cluster_translation * model.diameter;
  const double min_cos = std::cos(opt.cluster_rotation_rad);
  std::vector<PoseProposal> clusters;
  for (const Vote& v : poses) {
    bool joined = false;
    for (PoseProposal& c : clusters) {
      if ((c.T_cam_obj.translation() - v.T.translation()).norm() > max_t) continue;
      const double cos_angle = 0.5 * ((c.T_cam_obj.linear().transpose() * v.T.linear()).trace() - 1);
      if (cos_angle < min_cos) continue;
      c.votes += v.votes;
      joined = true;
      break;
    }
    if (!joined) clusters.push_back({v.T, double(v.votes)});
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const PoseProposal& a, const PoseProposal& b) { return a.votes > b.votes; });
  std::vector<PoseProposal> out;
  for (const PoseProposal& c : clusters) {
    if (int(out.size()) >= opt.max_proposals || c.votes < opt.min_relative_votes * clusters[0].votes) break;
    out.push_back(c);
  }
  return out;
}

}  // namespace posefilter
