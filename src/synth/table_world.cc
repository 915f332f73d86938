// Table-top scenes of real object meshes seen by a structured-light sensor (table_world.h).
//
// Construction, in the table frame W (z up, table top z = 0), then in the camera frame:
//  1. Objects: k distinct classes; each in one of its stable poses (drawn by probability),
//     turned about z by a uniform yaw. Footprints are the 2-D convex hulls of the objects'
//     hull vertices on the table.
//  2. Placement: the first object at the origin; each next one beside a random placed one, in
//     a random direction, moved outwards from it until its footprint is clear of every
//     placed footprint by the gap (0–3 mm when touching, else 1–8 cm).
//  3. Camera: looks at the group's centre (plus a few cm of jitter) from a random azimuth,
//     elevation and distance, with a small roll.
//  4. Table: a rectangle under the whole group, floor 74 cm below; rendered with the objects
//     (z-buffered, render.h RenderDepth) into the clean depth and the instance labels.
//  5. Sensor model (SensorModel): projector shadows, grazing-angle dropouts, edge dropouts,
//     material patches, holes, disparity noise and quantisation, range limits, rounding.
//  6. Prior: targets' jittered boxes and false boxes; targets' noisy instance masks.
// Independent Rng streams (Split) drive each stage, so e.g. changing the sensor does not move
// the objects.
#include "posefilter/table_world.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include "core/option_check.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/scene_io.h"
#include "synth/synth_util.h"
#include "synth/world_parts.h"

namespace posefilter {
namespace {

using synth::kDeg;
using synth::kPad;
constexpr double kTableHeightM = 0.74;     // floor below the table top
constexpr double kMaxGroupRadiusM = 0.25;  // objects are placed within this of the first one

using Vec2 = Eigen::Vector2d;
using Polygon = std::vector<Vec2>;

}  // namespace

namespace synth {

// Convex hull of 2-D points (Andrew's monotone chain), counter-clockwise.
Polygon ConvexHull2d(std::vector<Vec2> pts) {
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  if (pts.size() < 3) return pts;
  auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  Polygon hull(2 * pts.size());
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

// True when the convex polygons a and b are at least `gap` apart along one of their edge
// normals (separating axis test; a conservative stand-in for the Euclidean gap).
bool Separated(const Polygon& a, const Polygon& b, double gap) {
  for (const Polygon* p : {&a, &b}) {
    const std::size_t n = p->size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 e = (*p)[(i + 1) % n] - (*p)[i];
      const Vec2 axis = Vec2(e.y(), -e.x()).normalized();
      double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
      for (const Vec2& q : a) amin = std::min(amin, axis.dot(q)), amax = std::max(amax, axis.dot(q));
      for (const Vec2& q : b) bmin = std::min(bmin, axis.dot(q)), bmax = std::max(bmax, axis.dot(q));
      if (amax + gap <= bmin || bmax + gap <= amin) return true;
    }
  }
  return false;
}

Polygon Shifted(const Polygon& p, const Vec2& d) {
  Polygon out = p;
  for (Vec2& q : out) q += d;
  return out;
}

}  // namespace synth

namespace {

using synth::ConvexHull2d;
using synth::Separated;
using synth::Shifted;

struct Placement {
  int model = -1;
  int pose = -1;
  Eigen::Isometry3d T_W_obj = Eigen::Isometry3d::Identity();
  Polygon footprint;  // table frame, at the object's position
  double radius = 0;  // largest footprint distance from the position, metres
};

}  // namespace

namespace synth {

int DrawPose(const std::vector<StablePose>& poses, Rng& rng) {
  const double u = rng.Uniform();
  double acc = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    acc += poses[i].probability;
    if (u < acc) return int(i);
  }
  return int(poses.size()) - 1;
}

// Unit normals of the clean depth (camera frame) by central differences, zero where a
// neighbour is missing or more than jump_m away.
static std::vector<Eigen::Vector3f> DepthNormals(const DepthImage& d, const Camera& cam, double jump_m) {
  const int w = d.width, h = d.height;
  std::vector<Eigen::Vector3f> n(std::size_t(w) * h, Eigen::Vector3f::Zero());
  for (int v = 1; v + 1 < h; ++v)
    for (int u = 1; u + 1 < w; ++u) {
      const float z = d.at(u, v), zl = d.at(u - 1, v), zr = d.at(u + 1, v), zu = d.at(u, v - 1), zd = d.at(u, v + 1);
      if (z <= 0 || zl <= 0 || zr <= 0 || zu <= 0 || zd <= 0) continue;
      if (std::fabs(zl - z) > jump_m || std::fabs(zr - z) > jump_m || std::fabs(zu - z) > jump_m ||
          std::fabs(zd - z) > jump_m)
        continue;
      const Eigen::Vector3d dx = cam.Backproject(u + 1, v, zr) - cam.Backproject(u - 1, v, zl);
      const Eigen::Vector3d dy = cam.Backproject(u, v + 1, zd) - cam.Backproject(u, v - 1, zu);
      const Eigen::Vector3d nn = dx.cross(dy);
      if (nn.norm() > 0) n[std::size_t(v) * w + u] = nn.normalized().cast<float>();
    }
  return n;
}

// Removes disc (centre cu, cv, radius r pixels) from the depth.
static void DropDisc(DepthImage* d, double cu, double cv, double r) {
  const int ir = int(std::ceil(r));
  for (int v = std::max(0, int(cv) - ir); v <= std::min(d->height - 1, int(cv) + ir); ++v)
    for (int u = std::max(0, int(cu) - ir); u <= std::min(d->width - 1, int(cu) + ir); ++u)
      if ((u - cu) * (u - cu) + (v - cv) * (v - cv) <= r * r) d->at(u, v) = 0;
}

// The structured-light sensor model on the clean depth (SensorModel's list, in that order).
// `meshes`/`poses`: every rendered surface (for the projector's view).
DepthImage ApplySensor(const DepthImage& clean, const std::vector<int>& labels, int num_objects,
                       const std::vector<const Mesh*>& meshes, const std::vector<Eigen::Isometry3d>& poses,
                       const Camera& cam, const SensorModel& s, Rng& rng) {
  const int W = clean.width, H = clean.height;
  DepthImage d = clean;
  // Projector shadows: the projector sits baseline_m along the camera's x axis; a point it
  // does not see (something nearer along its ray) gets no pattern, so no depth.
  if (s.baseline_m > 0) {
    // The projector's field of view is wider than the camera's: its image is the camera's
    // padded by kPad pixels on every side.
    Camera pc = cam;
    pc.width = W + 2 * kPad;
    pc.height = H + 2 * kPad;
    pc.cx += kPad;
    pc.cy += kPad;
    DepthImage proj(pc.width, pc.height, 0.f);
    Eigen::Isometry3d T_P_C = Eigen::Isometry3d::Identity();
    T_P_C.translation() = Eigen::Vector3d(-s.baseline_m, 0, 0);
    for (std::size_t i = 0; i < meshes.size(); ++i) RenderDepth(*meshes[i], T_P_C * poses[i], pc, &proj);
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const float z = clean.at(u, v);
        if (z <= 0) continue;
        const Eigen::Vector3d p = T_P_C * cam.Backproject(u, v, z);
        if (p.z() <= 0.05) {
          d.at(u, v) = 0;
          continue;
        }
        const Eigen::Vector2d q = pc.Project(p);
        const int iu = int(std::lround(q.x())), iv = int(std::lround(q.y()));
        if (iu < 0 || iv < 0 || iu >= pc.width || iv >= pc.height) {
          d.at(u, v) = 0;  // outside the projector's field of view
          continue;
        }
        const float zp = proj.at(iu, iv);
        if (zp > 0 && zp < p.z() * (1.0 - s.shadow_tolerance)) d.at(u, v) = 0;
      }
  }
  // Grazing angles: the pattern smears on surfaces seen nearly edge-on.
  const std::vector<Eigen::Vector3f> normals = DepthNormals(clean, cam, s.edge_jump_m);
  const double c0 = std::cos(s.grazing_start_deg * kDeg), c1 = std::cos(s.grazing_end_deg * kDeg);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const Eigen::Vector3f& n = normals[std::size_t(v) * W + u];
      const double draw = rng.Uniform();
      if (n.isZero()) continue;
      const double c = std::fabs(n.cast<double>().dot(cam.Backproject(u, v, 1.0).normalized()));
      const double p = c >= c0 ? 0.0 : c <= c1 ? 1.0 : (c0 - c) / (c0 - c1);
      if (draw < p) d.at(u, v) = 0;
    }
  // Depth edges: the pixels at an occlusion boundary, sometimes a second ring.
  const std::vector<std::uint8_t> edge = synth::DepthEdgePixels(clean, s.edge_jump_m);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      if (!edge[std::size_t(v) * W + u]) continue;
      d.at(u, v) = 0;
      if (rng.Uniform() < s.edge_second_ring_probability) {
        if (u > 0) d.at(u - 1, v) = 0;
        if (u + 1 < W) d.at(u + 1, v) = 0;
        if (v > 0) d.at(u, v - 1) = 0;
        if (v + 1 < H) d.at(u, v + 1) = 0;
      }
    }
  // Material: some objects lose a few patches of their surface (dark print, gloss).
  for (int i = 0; i < num_objects; ++i) {
    const bool patchy = rng.Uniform() < s.object_patch_probability;
    const int patches = 1 + int(rng.UniformInt(3));
    if (!patchy) continue;
    std::vector<int> pix;
    for (int k = 0; k < W * H; ++k)
      if (labels[std::size_t(k)] == i + 1) pix.push_back(k);
    if (pix.empty()) continue;
    for (int p = 0; p < patches; ++p) {
      const int k = pix[rng.UniformInt(pix.size())];
      const int column = k % W, row = k / W;  // the disc's centre pixel
      DropDisc(&d, column, row, rng.Uniform(3.0, 10.0));
    }
  }
  synth::DropHoles(&d, s.hole_fraction, rng);
  // Disparity noise (per pixel and smooth) and quantisation, then range and rounding.
  const double fb = s.focal_px * s.baseline_m;
  constexpr int kCell = 32;  // smooth field: Gaussian values on a 32 px grid, bilinear
  const int gw = W / kCell + 2, gh = H / kCell + 2;
  std::vector<double> field(std::size_t(gw) * gh);
  for (double& f : field) f = s.disparity_smooth_px * rng.Normal();
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const double noise = s.disparity_noise_px * rng.Normal();
      float& z = d.at(u, v);
      if (z <= 0) continue;
      const double gx = double(u) / kCell, gy = double(v) / kCell;
      const int ix = int(gx), iy = int(gy);
      const double fx = gx - ix, fy = gy - iy;
      auto F = [&](int x, int y) { return field[std::size_t(y) * gw + x]; };
      const double smooth = (1 - fy) * ((1 - fx) * F(ix, iy) + fx * F(ix + 1, iy)) +
                            fy * ((1 - fx) * F(ix, iy + 1) + fx * F(ix + 1, iy + 1));
      double disp = (fb > 0 ? fb / z : 0) + noise + smooth;
      if (s.disparity_step_px > 0) disp = std::round(disp / s.disparity_step_px) * s.disparity_step_px;
      double zn = fb > 0 ? (disp > 0 ? fb / disp : 0.0) : double(z);
      if (zn < s.min_range_m || zn > s.max_range_m) zn = 0;
      if (zn > 0 && s.output_step_m > 0) zn = std::round(zn / s.output_step_m) * s.output_step_m;
      z = float(zn);
    }
  return d;
}

// The mask a segmentation network would give for `label`: the visible pixels with the
// outline moved by `shift` pixels (> 0 out, < 0 in) and then ragged: each outline pixel
// flips with probability 0.3.
std::vector<std::uint8_t> NoisyMask(const std::vector<int>& labels, int label, int W, int H, int shift, Rng& rng) {
  std::vector<std::uint8_t> m(std::size_t(W) * H);
  for (std::size_t k = 0; k < m.size(); ++k) m[k] = labels[k] == label;
  auto step = [&](bool grow) {
    std::vector<std::uint8_t> out = m;
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        const std::size_t k = std::size_t(v) * W + u;
        if (m[k] == grow) continue;  // growing: only outside pixels change; shrinking: inside
        const bool n = (u > 0 && m[k - 1] == grow) || (u + 1 < W && m[k + 1] == grow) ||
                       (v > 0 && m[k - W] == grow) || (v + 1 < H && m[k + W] == grow);
        if (n) out[k] = grow;
      }
    m = std::move(out);
  };
  for (int i = 0; i < std::abs(shift); ++i) step(shift > 0);
  std::vector<std::uint8_t> out = m;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const std::size_t k = std::size_t(v) * W + u;
      const bool boundary = (u > 0 && m[k - 1] != m[k]) || (u + 1 < W && m[k + 1] != m[k]) ||
                            (v > 0 && m[k - W] != m[k]) || (v + 1 < H && m[k + W] != m[k]);
      if (boundary && rng.Uniform() < 0.3) out[k] = !m[k];
    }
  return out;
}

Box JitterBox(const Box& b0, double sigma, double scale, Rng& rng) {
  const double jx = rng.Normal(), jy = rng.Normal(), jw = rng.Normal(), jh = rng.Normal();
  Box b = b0;
  b.cx += std::clamp(sigma * jx, -0.25 * b0.w, 0.25 * b0.w);
  b.cy += std::clamp(sigma * jy, -0.25 * b0.h, 0.25 * b0.h);
  b.w = std::max(4.0, scale * b0.w + sigma * jw);
  b.h = std::max(4.0, scale * b0.h + sigma * jh);
  return b;
}

Detection ToDetection(const std::string& cls, double score, const Box& b) {
  return {cls, score, b.cx - b.w / 2, b.cy - b.h / 2, b.w, b.h};
}

}  // namespace synth

namespace {

using synth::ApplySensor;
using synth::DrawPose;
using synth::JitterBox;
using synth::NoisyMask;
using synth::ToDetection;

using synth::InRange;

}  // namespace

Camera YcbVideoCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = 1066.778;
  c.fy = 1067.487;
  c.cx = 312.9869;
  c.cy = 241.3109;
  return c;
}

bool SensorModel::IsValid(std::string* why) const {
  if (!InRange(baseline_m, 0, 1)) return Fail(why, "sensor.baseline_m must be in [0, 1] m");
  if (!InRange(focal_px, 1, 1e5)) return Fail(why, "sensor.focal_px must be in [1, 1e5] px");
  if (!InRange(disparity_noise_px, 0, 10) || !InRange(disparity_smooth_px, 0, 10))
    return Fail(why, "sensor disparity noise must be in [0, 10] px");
  if (!InRange(disparity_step_px, 0, 10)) return Fail(why, "sensor.disparity_step_px must be in [0, 10] px");
  if (!(InRange(min_range_m, 0, 100) && InRange(max_range_m, min_range_m, 100)))
    return Fail(why, "sensor range must satisfy 0 <= min_range_m <= max_range_m <= 100");
  if (!InRange(shadow_tolerance, 0, 1)) return Fail(why, "sensor.shadow_tolerance must be in [0, 1]");
  if (!(InRange(grazing_start_deg, 0, 90) && InRange(grazing_end_deg, grazing_start_deg, 90)))
    return Fail(why, "sensor grazing angles must satisfy 0 <= start <= end <= 90 degrees");
  if (!InRange(edge_jump_m, 1e-4, 10)) return Fail(why, "sensor.edge_jump_m must be in [1e-4, 10] m");
  if (!InRange(edge_second_ring_probability, 0, 1))
    return Fail(why, "sensor.edge_second_ring_probability must be in [0, 1]");
  if (!InRange(hole_fraction, 0, 0.5)) return Fail(why, "sensor.hole_fraction must be in [0, 0.5]");
  if (!InRange(object_patch_probability, 0, 1)) return Fail(why, "sensor.object_patch_probability must be in [0, 1]");
  if (!InRange(output_step_m, 0, 0.1)) return Fail(why, "sensor.output_step_m must be in [0, 0.1] m");
  return true;
}

bool TableSceneOptions::IsValid(std::string* why) const {
  std::string sub;
  if (!camera.IsValid(&sub)) return Fail(why, "camera: " + sub);
  if (camera.width < 80 || camera.height < 60) return Fail(why, "camera: image must be at least 80×60 pixels");
  if (!(depth_scale > 0 && std::isfinite(depth_scale))) return Fail(why, "depth_scale must be finite and > 0");
  if (min_objects < 1 || max_objects < min_objects || max_objects > 50)
    return Fail(why, "objects per scene must satisfy 1 <= min_objects <= max_objects <= 50");
  if (!(InRange(min_distance_m, 0.3, 5) && InRange(max_distance_m, min_distance_m, 5)))
    return Fail(why, "distances must satisfy 0.3 <= min_distance_m <= max_distance_m <= 5 m");
  if (!(InRange(min_elevation_deg, 5, 90) && InRange(max_elevation_deg, min_elevation_deg, 90)))
    return Fail(why, "elevations must satisfy 5 <= min_elevation_deg <= max_elevation_deg <= 90");
  if (!InRange(touch_probability, 0, 1)) return Fail(why, "touch_probability must be in [0, 1]");
  if (!InRange(min_visible_fraction, 0, 1)) return Fail(why, "min_visible_fraction must be in [0, 1]");
  if (min_visible_px < 1) return Fail(why, "min_visible_px must be >= 1");
  if (!sensor.IsValid(&sub)) return Fail(why, sub);
  if (!InRange(box_jitter_px, 0, 100)) return Fail(why, "box_jitter_px must be in [0, 100] px");
  if (!(InRange(box_scale_min, 0.2, 5) && InRange(box_scale_max, box_scale_min, 5)))
    return Fail(why, "box scales must satisfy 0.2 <= box_scale_min <= box_scale_max <= 5");
  if (false_positives < 0 || false_positives > 100) return Fail(why, "false_positives must be in [0, 100]");
  if (!InRange(mask_boundary_px, 0, 20)) return Fail(why, "mask_boundary_px must be in [0, 20] px");
  return true;
}

TableWorld::TableWorld(std::vector<Mesh> meshes) {
  std::set<std::string> names;
  for (Mesh& m : meshes) {
    if (m.name.empty()) throw Error("table world: a mesh has no name (its class)");
    if (!names.insert(m.name).second) throw Error("table world: mesh '" + m.name + "' given twice");
    TableModel model;
    StablePoseOptions so;
    so.min_probability = 0.005;  // poses below 0.5 % are left out
    model.poses = ComputeStablePoses(m, so);
    model.diameter = m.Diameter();
    model.mesh = std::move(m);
    models_.push_back(std::move(model));
  }
  if (models_.empty()) throw Error("table world: no meshes");
}

TableWorld TableWorld::LoadYcbVideo(const std::string& models_dir) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(models_dir))
    throw Error(models_dir + ": not a folder (the YCB-Video meshes: <class>.ply in metres, or BOP's obj_000001.ply "
                "... in millimetres; scripts/get_data.sh ycbv fetches them)");
  std::vector<Mesh> meshes;
  const std::vector<std::string> classes = YcbVideoClassNames();
  for (std::size_t i = 0; i < classes.size(); ++i) {
    // A YCB-Video folder names the mesh by class (metres); BOP's ycbv models folder by the
    // class's 1-based id in the same order (millimetres).
    const std::string named = (fs::path(models_dir) / (classes[i] + ".ply")).string();
    char bop_name[32];
    std::snprintf(bop_name, sizeof bop_name, "obj_%06zu.ply", i + 1);
    const std::string bop = (fs::path(models_dir) / bop_name).string();
    if (fs::exists(named)) {
      meshes.push_back(LoadMesh(named));
    } else if (fs::exists(bop)) {
      meshes.push_back(LoadMesh(bop, 0.001));
    } else {
      throw Error(named + ": missing YCB-Video mesh (nor " + bop_name + " of a BOP models folder)");
    }
    meshes.back().name = classes[i];
  }
  return TableWorld(std::move(meshes));
}

std::vector<std::string> TableWorld::ClassNames() const {
  std::vector<std::string> out;
  for (const auto& m : models_) out.push_back(m.mesh.name);
  return out;
}

TableScene TableWorld::MakeScene(const TableSceneOptions& opt, std::uint64_t seed) const {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("table scene options: " + why);
  if (opt.max_objects > int(models_.size()))
    throw Error("table scene options: max_objects (" + std::to_string(opt.max_objects) + ") exceeds the world's " +
                std::to_string(models_.size()) + " classes");
  Rng root(seed);
  Rng rng_objects = root.Split(), rng_place = root.Split(), rng_camera = root.Split(), rng_sensor = root.Split(),
      rng_prior = root.Split(), rng_mask = root.Split();
  const Camera& cam = opt.camera;
  const int W = cam.width, H = cam.height;

  // 1. Classes and stable poses.
  const int object_choices = opt.max_objects - opt.min_objects + 1;
  const int k = opt.min_objects + int(rng_objects.UniformInt(std::uint64_t(object_choices)));
  std::vector<int> order(models_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  for (std::size_t i = 0; i + 1 < order.size(); ++i)  // Fisher–Yates
    std::swap(order[i], order[i + rng_objects.UniformInt(order.size() - i)]);
  std::vector<Placement> placed;
  for (int i = 0; i < k; ++i) {
    Placement p;
    p.model = order[std::size_t(i)];
    const TableModel& m = models_[std::size_t(p.model)];
    p.pose = DrawPose(m.poses, rng_objects);
    const double yaw = rng_objects.Uniform(-M_PI, M_PI);
    p.T_W_obj = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * m.poses[std::size_t(p.pose)].T_table_obj;
    std::vector<Vec2> xy;
    for (const auto& v : m.mesh.vertices) xy.push_back((p.T_W_obj * v.cast<double>()).head<2>());
    p.footprint = ConvexHull2d(std::move(xy));
    for (const Vec2& q : p.footprint) p.radius = std::max(p.radius, q.norm());
    placed.push_back(std::move(p));
  }

  // 2. Placement: each object beside a random earlier one, pushed out until clear.
  std::vector<Placement> scene_objects;
  std::vector<Polygon> footprints;
  for (int i = 0; i < k; ++i) {
    Placement p = placed[std::size_t(i)];
    if (scene_objects.empty()) {
      scene_objects.push_back(p);
      footprints.push_back(p.footprint);
      continue;
    }
    bool ok = false;
    for (int attempt = 0; attempt < 40 && !ok; ++attempt) {
      const Placement& anchor = scene_objects[rng_place.UniformInt(scene_objects.size())];
      const double theta = rng_place.Uniform(0, 2 * M_PI);
      const bool touch = rng_place.Uniform() < opt.touch_probability;
      const double gap = touch ? rng_place.Uniform(0.0, 0.003) : rng_place.Uniform(0.01, 0.08);
      const Vec2 dir(std::cos(theta), std::sin(theta));
      const Vec2 base = anchor.T_W_obj.translation().head<2>();
      auto clear = [&](double s) {
        const Polygon fp = Shifted(p.footprint, base + s * dir);
        for (const Polygon& q : footprints)
          if (!Separated(fp, q, gap)) return false;
        return true;
      };
      // March out in 5 mm steps to the first clear spot, then bisect back to contact.
      double lo = 0, hi = -1;
      const double limit = anchor.radius + p.radius + 0.2;
      for (double s = 0.005; s <= limit; s += 0.005) {
        if (clear(s)) {
          hi = s;
          break;
        }
        lo = s;
      }
      if (hi < 0) continue;
      for (int it = 0; it < 12; ++it) {
        const double mid = 0.5 * (lo + hi);
        (clear(mid) ? hi : lo) = mid;
      }
      const Vec2 pos = base + hi * dir;
      if (pos.norm() > kMaxGroupRadiusM) continue;
      p.T_W_obj.translation().head<2>() += pos;
      p.footprint = Shifted(p.footprint, pos);
      ok = true;
    }
    if (!ok) continue;  // no room: the scene has one object fewer
    scene_objects.push_back(p);
    footprints.push_back(p.footprint);
  }

  // 3. Camera.
  Vec2 centre = Vec2::Zero();
  double group_radius = 0;
  for (const auto& p : scene_objects) centre += p.T_W_obj.translation().head<2>();
  centre /= double(scene_objects.size());
  for (const auto& p : scene_objects)
    for (const Vec2& q : p.footprint) group_radius = std::max(group_radius, (q - centre).norm());

  TableScene s;
  s.camera = cam;
  s.depth_scale = opt.depth_scale;
  Eigen::Isometry3d T_C_W = Eigen::Isometry3d::Identity();
  std::vector<TableObject> objects;
  std::vector<std::vector<int>> alone;  // per object: its pixels rendered alone (indices)
  double table_view = 0;                // fraction of the image the table covers, seen
  for (int attempt = 0; attempt < 30; ++attempt) {
    const double jx = rng_camera.Uniform(-0.05, 0.05), jy = rng_camera.Uniform(-0.05, 0.05);
    const double lift = rng_camera.Uniform(0.02, 0.08);
    const Eigen::Vector3d look(centre.x() + jx, centre.y() + jy, lift);
    const double elev = rng_camera.Uniform(opt.min_elevation_deg, opt.max_elevation_deg) * kDeg;
    const double az = rng_camera.Uniform(0, 2 * M_PI);
    const double dist = rng_camera.Uniform(opt.min_distance_m, opt.max_distance_m);
    const double roll = rng_camera.Uniform(-8, 8) * kDeg;
    const Eigen::Vector3d C = look + dist * Eigen::Vector3d(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
    const Eigen::Vector3d zf = (look - C).normalized();
    Eigen::Vector3d x = zf.cross(Eigen::Vector3d::UnitZ()).normalized();
    Eigen::Vector3d y = zf.cross(x);
    const Eigen::Vector3d xr = std::cos(roll) * x + std::sin(roll) * y, yr = zf.cross(xr);
    Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
    T_W_C.linear() << xr, yr, zf;
    T_W_C.translation() = C;
    T_C_W = T_W_C.inverse();
    s.distance_m = dist;
    s.elevation_deg = elev / kDeg;

    objects.clear();
    alone.clear();
    int targets = 0;
    for (const auto& p : scene_objects) {
      TableObject o;
      o.model = p.model;
      o.cls = models_[std::size_t(p.model)].mesh.name;
      o.stable_pose = p.pose;
      o.T_cam_obj = T_C_W * p.T_W_obj;
      // Rendered alone on a canvas padded by kPad pixels on every side, so that the part the
      // image border cuts off counts as hidden: (W + 2·kPad) × (H + 2·kPad), principal point
      // shifted by kPad.
      Camera big = cam;
      big.width = W + 2 * kPad;
      big.height = H + 2 * kPad;
      big.cx += kPad;
      big.cy += kPad;
      DepthImage d(big.width, big.height, 0.f);
      std::vector<int> lab(std::size_t(big.width) * big.height, 0);
      RenderDepth(models_[std::size_t(p.model)].mesh, o.T_cam_obj, big, &d, &lab, 1);
      std::vector<int> pix;
      int u0 = W, u1 = -1, v0 = H, v1 = -1;
      for (int q = 0; q < big.width * big.height; ++q) {
        if (!lab[std::size_t(q)]) continue;
        pix.push_back(q);
        const int u = q % big.width - kPad, v = q / big.width - kPad;
        if (u < 0 || v < 0 || u >= W || v >= H) continue;
        u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
      }
      // The box of the silhouette's pixels in the image (ProjectedBox's convention).
      if (u1 >= 0) o.box = Box{0.5 * (u0 + u1), 0.5 * (v0 + v1), double(u1 - u0 + 1), double(v1 - v0 + 1)};
      alone.push_back(std::move(pix));
      objects.push_back(o);
    }
    // 4. Table, floor and objects, z-buffered.
    const double tyaw = rng_camera.Uniform(-M_PI, M_PI);
    const Eigen::Vector3d ex(std::cos(tyaw), std::sin(tyaw), 0), ey(-std::sin(tyaw), std::cos(tyaw), 0);
    const double half_a = std::max(rng_camera.Uniform(0.45, 0.8), group_radius + 0.05);
    const double half_b = std::max(rng_camera.Uniform(0.35, 0.6), group_radius + 0.05);
    const double room_a = half_a - group_radius - 0.03, room_b = half_b - group_radius - 0.03;
    const double oa = rng_camera.Uniform(-1, 1) * std::max(0.0, room_a), ob = rng_camera.Uniform(-1, 1) * std::max(0.0, room_b);
    const Eigen::Vector3d tc(centre.x(), centre.y(), 0);
    const Eigen::Vector3d table_centre = tc - oa * ex - ob * ey;
    const Mesh table = synth::PlaneGridMesh(table_centre, ex, ey, -half_a, half_a, -half_b, half_b, 0.1, T_C_W, 0.1);
    const Mesh floor = synth::PlaneGridMesh(Eigen::Vector3d(centre.x(), centre.y(), -kTableHeightM), Eigen::Vector3d::UnitX(),
                                            Eigen::Vector3d::UnitY(), -4, 4, -4, 4, 0.25, T_C_W, 0.1);
    s.clean_depth = DepthImage(W, H, 0.f);
    s.labels.assign(std::size_t(W) * H, 0);
    RenderDepth(floor, T_C_W, cam, &s.clean_depth, &s.labels, 0);
    RenderDepth(table, T_C_W, cam, &s.clean_depth, &s.labels, -1);  // -1 while counted, then 0
    for (std::size_t i = 0; i < objects.size(); ++i)
      RenderDepth(models_[std::size_t(objects[i].model)].mesh, objects[i].T_cam_obj, cam, &s.clean_depth, &s.labels, int(i) + 1);
    table_view = double(std::count(s.labels.begin(), s.labels.end(), -1)) / double(W * H);
    std::replace(s.labels.begin(), s.labels.end(), -1, 0);
    for (std::size_t i = 0; i < objects.size(); ++i) {
      TableObject& o = objects[i];
      o.visible_px = int(synth::CountLabel(s.labels, int(i) + 1));
      o.visible_fraction = alone[i].empty() ? 0.0 : double(o.visible_px) / double(alone[i].size());
      o.target = o.visible_fraction >= opt.min_visible_fraction && o.visible_px >= opt.min_visible_px;
      targets += o.target;
    }
    if (targets > 0) {
      // The meshes the projector sees, for the sensor model.
      std::vector<const Mesh*> meshes = {&floor, &table};
      std::vector<Eigen::Isometry3d> poses = {T_C_W, T_C_W};
      for (const auto& o : objects) {
        meshes.push_back(&models_[std::size_t(o.model)].mesh);
        poses.push_back(o.T_cam_obj);
      }
      s.depth = ApplySensor(s.clean_depth, s.labels, int(objects.size()), meshes, poses, cam, opt.sensor, rng_sensor);
      break;
    }
  }
  if (s.depth.empty()) throw Error("table scene " + std::to_string(seed) + ": no view shows an object well enough");
  s.objects = objects;
  s.classes = ClassNames();
  const Eigen::Vector3d n = T_C_W.linear() * Eigen::Vector3d::UnitZ();
  s.table_plane << n, -n.dot(T_C_W.translation());
  s.supports = {s.table_plane};
  s.floor_plane << n, s.table_plane[3] + kTableHeightM;
  s.support_view_fractions = {table_view};

  // 6. Prior: targets' boxes, false boxes; targets' masks.
  const std::vector<std::string> classes = ClassNames();
  for (const TableObject& o : s.objects) {
    if (!o.target) continue;
    const double scale = rng_prior.Uniform(opt.box_scale_min, opt.box_scale_max);
    const double score = rng_prior.Uniform(0.6, 0.99);
    s.detections.push_back(ToDetection(o.cls, score, JitterBox(o.box, opt.box_jitter_px, scale, rng_prior)));
  }
  for (int i = 0; i < opt.false_positives; ++i) {
    const std::string& cls = classes[rng_prior.UniformInt(classes.size())];
    const double score = rng_prior.Uniform(0.05, 0.9);
    const bool on_object = i % 2 == 0;
    const TableObject& other = s.objects[rng_prior.UniformInt(s.objects.size())];
    Box b;
    if (on_object && other.cls != cls && other.box.w > 0) {
      b = JitterBox(other.box, opt.box_jitter_px, 1.0, rng_prior);
    } else {
      b.w = rng_prior.Uniform(40.0, 240.0);
      b.h = rng_prior.Uniform(40.0, 240.0);
      b.cx = rng_prior.Uniform(b.w / 2, std::max(b.w / 2, W - b.w / 2));
      b.cy = rng_prior.Uniform(b.h / 2, std::max(b.h / 2, H - b.h / 2));
    }
    s.detections.push_back(ToDetection(cls, score, b));
  }
  s.masks.assign(std::size_t(W) * H, 0);
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    if (!s.objects[i].target) continue;
    const int shift = int(std::lround(rng_mask.Uniform(-opt.mask_boundary_px, opt.mask_boundary_px)));
    const std::vector<std::uint8_t> m = NoisyMask(s.labels, int(i) + 1, W, H, shift, rng_mask);
    for (std::size_t q = 0; q < m.size(); ++q)
      if (m[q] && s.masks[q] == 0) s.masks[q] = std::uint16_t(i + 1);
  }
  return s;
}

void WriteTableScene(const TableScene& s, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw Error(dir + ": cannot create directory" + (ec ? ": " + ec.message() : ""));
  const fs::path d(dir);
  SaveDepthPng(s.depth, (d / "depth.png").string(), s.depth_scale);
  CameraFile cf;
  cf.camera = s.camera;
  cf.depth_scale = s.depth_scale;
  WriteCameraJson(cf, (d / "camera.json").string());
  std::vector<GtObject> gt;
  for (const auto& o : s.objects) gt.push_back({o.cls, o.T_cam_obj});
  WriteGtJson(gt, (d / "gt.json").string());
  WriteDetectionsJson(s.detections, (d / "detections.json").string());
  const int W = s.depth.width, H = s.depth.height;
  // The same detections as a raw pyramid over every class of the world (`estimate --prior
  // prior.pyr --classes classes.txt`).
  {
    const PyramidLayout layout = PyramidLayout::Thesis(W, H, int(s.classes.size()));
    WriteRawPyramid(DetectionsToRawPyramid(s.detections, layout, s.classes), layout, (d / "prior.pyr").string());
    const std::string path = (d / "classes.txt").string();
    WriteFileAtomically(path, [&](std::ostream& os) {
      for (const auto& c : s.classes) os << c << "\n";
    });
  }
  SaveLabelPng(LabelImage{W, H, s.masks}, (d / "mask.png").string());
  std::vector<std::uint8_t> lab(s.labels.size());
  for (std::size_t q = 0; q < lab.size(); ++q) lab[q] = std::uint8_t(std::clamp(s.labels[q], 0, 255));
  SaveGray8Png(lab, W, H, (d / "label.png").string());
  // Shaded depth for humans: brighter = nearer, missing black.
  RgbImage img(W, H);
  float zmin = std::numeric_limits<float>::infinity(), zmax = 0;
  for (float z : s.depth.data)
    if (z > 0) zmin = std::min(zmin, z), zmax = std::max(zmax, z);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const float z = s.depth.at(u, v);
      if (z <= 0) continue;
      const auto g = std::uint8_t(40 + 215 * (1 - (z - zmin) / std::max(1e-3f, zmax - zmin)));
      std::uint8_t* p = img.px(u, v);
      p[0] = p[1] = p[2] = g;
    }
  SaveRgbPng(img, (d / "rgb.png").string());
  auto write_json = [&](const nlohmann::ordered_json& j, const std::string& name) {
    const std::string path = (d / name).string();
    WriteFileAtomically(path, [&](std::ostream& os) { os << j.dump(1) << "\n"; });
  };
  nlohmann::ordered_json classes = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < s.objects.size(); ++i)
    if (s.objects[i].target) classes[std::to_string(i + 1)] = s.objects[i].cls;
  write_json(classes, "mask_classes.json");
  nlohmann::ordered_json j;
  j["distance_m"] = s.distance_m;
  j["elevation_deg"] = s.elevation_deg;
  j["table_plane"] = {s.table_plane[0], s.table_plane[1], s.table_plane[2], s.table_plane[3]};
  j["floor_plane"] = {s.floor_plane[0], s.floor_plane[1], s.floor_plane[2], s.floor_plane[3]};
  j["supports"] = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < s.supports.size(); ++k)
    j["supports"].push_back({{"plane", {s.supports[k][0], s.supports[k][1], s.supports[k][2], s.supports[k][3]}},
                             {"view_fraction", k < s.support_view_fractions.size() ? s.support_view_fractions[k] : 0.0}});
  j["objects"] = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const TableObject& o = s.objects[i];
    j["objects"].push_back({{"obj", o.cls}, {"instance", i + 1}, {"target", o.target},
                            {"visible_fraction", o.visible_fraction}, {"visible_px", o.visible_px},
                            {"stable_pose", o.stable_pose}, {"support", o.support},
                            {"bbox", {o.box.cx - o.box.w / 2, o.box.cy - o.box.h / 2, o.box.w, o.box.h}}});
  }
  write_json(j, "scene.json");
}

}  // namespace posefilter
