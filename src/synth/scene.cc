// Synthetic table-top scenes with ground truth (synth.h).
//
// Construction (all in the camera frame, metres):
//  1. The table: a plane whose "up" normal is u = (0, −cos α, −sin α), α ∈ [30°, 50°] the angle
//     between the optical axis and the table (the camera looks down at α).
//  2. The target: its bounding-box centre at c = d·r̂, d ∈ [min_distance_m, max_distance_m],
//     r̂ the ray of a random pixel in the central part of the image; a uniformly random full
//     rotation; the table plane is then put through the target's lowest vertex along u, so
//     the target rests on it.
//  3. For occlusion > 0: an upright panel (a thin box) on the table between the camera and
//     the target, wide and tall enough to hide it completely; its lateral offset is bisected
//     until the visible fraction of the target (pixels labelled target / pixels of the target
//     rendered alone) is 1 − occlusion.
//  4. Clutter: upright boxes and cylinders of random sizes at random places around the target,
//     never overlapping another object's footprint circle on the table and rejected when they
//     would hide more than 0.5 % of the target.
//  5. Rendering (render.h RenderDepth, z-buffered): table (label 0), target (1), occluder (2),
//     clutter (3..); then the sensor model on the depth: missing edges, noise, quantisation,
//     holes.
//  6. The stage-1 prior: the target's detection from its full silhouette's bbox, jittered;
//     false positives elsewhere; both as a list and as a raw pyramid (prior.h).
// Independent Rng streams (Split) drive geometry, occluder, clutter, sensor and prior, so e.g.
// changing the noise does not move the objects.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/option_check.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/projection.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/synth.h"
#include "synth/synth_util.h"
#include "synth/world_parts.h"

namespace posefilter {
namespace {

constexpr int kLabelBackground = 0;
constexpr int kLabelTarget = 1;
constexpr int kLabelOccluder = 2;
constexpr int kLabelClutterFirst = 3;

using synth::kDeg;
constexpr double kEdgeJumpM = 0.02;            // missing-edge threshold |Δz|, metres
constexpr double kClutterMaxHiddenFrac = 0.005;  // clutter may hide ≤ 0.5 % of the target
constexpr int kMinTargetPixels = 20;

// ---------------------------------------------------------------------------------------------
// Geometry helpers.

Eigen::Vector3d BoxCentre(const Mesh& m) { return (0.5f * (m.Min() + m.Max())).cast<double>(); }

// min over vertices of u·(T v): the height of the lowest point along u.
double MinAlong(const Mesh& m, const Eigen::Isometry3d& T, const Eigen::Vector3d& u) {
  double lo = std::numeric_limits<double>::infinity();
  for (const auto& v : m.vertices) lo = std::min(lo, u.dot(T * v.cast<double>()));
  return lo;
}

// The table plane {p : u·p = k} with in-plane axes ex (= camera x), ey = u × ex (forward,
// away from the camera); (ex, ey, u) is right-handed.
struct Table {
  Eigen::Vector3d u, ex, ey;
  double k = 0;  // plane offset, metres (< 0: the camera is above the table)

  Eigen::Vector3d Project(const Eigen::Vector3d& p) const { return p + u * (k - u.dot(p)); }
  Eigen::Matrix3d Frame() const {
    Eigen::Matrix3d R;
    R << ex, ey, u;
    return R;
  }
};

// An object placed in the scene, with its footprint circle on the table (for overlap tests).
struct Placed {
  Mesh mesh;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();  // object → camera
  int label = 0;
  Eigen::Vector3d foot = Eigen::Vector3d::Zero();  // footprint centre, on the table plane
  double radius = 0;                                // footprint radius, metres
};

// Radius of the object's footprint around `foot`: the largest distance of a vertex from the
// vertical (u) line through foot.
double FootprintRadius(const Mesh& m, const Eigen::Isometry3d& T, const Table& t,
                       const Eigen::Vector3d& foot) {
  double r = 0;
  for (const auto& v : m.vertices) {
    Eigen::Vector3d d = T * v.cast<double>() - foot;
    d -= t.u * t.u.dot(d);
    r = std::max(r, d.norm());
  }
  return r;
}

// Pose that stands `m` upright on the table (object z along u), rotated by yaw about u, with
// its bounding-box centre above `foot` and its lowest vertex on the plane.
Eigen::Isometry3d StandOnTable(const Mesh& m, const Table& t, double yaw, const Eigen::Vector3d& foot) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = t.Frame() * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = foot - T.linear() * BoxCentre(m);
  T.translation() += t.u * (t.k - MinAlong(m, T, t.u));
  return T;
}

// The table as a grid of 10 cm quads around `centre` (faces towards the camera); quads with a
// vertex closer than 0.1 m to the camera plane are left out (the renderer skips them anyway).
Mesh MakeTableMesh(const Table& t, const Eigen::Vector3d& centre) {
  Mesh m = synth::PlaneGridMesh(centre, t.ex, t.ey, -1.5, 1.5, -1.5, 2.0, 0.1, Eigen::Isometry3d::Identity(), 0.1);
  m.name = "table";
  return m;
}

// Pixel bbox of the projected vertices (z > 0.05 m only); false when none is in front.
bool ProjectedBounds(const Mesh& m, const Eigen::Isometry3d& T, const Camera& cam, double* u0,
                     double* v0, double* u1, double* v1) {
  *u0 = *v0 = std::numeric_limits<double>::infinity();
  *u1 = *v1 = -std::numeric_limits<double>::infinity();
  bool any = false;
  for (const auto& v : m.vertices) {
    const Eigen::Vector3d p = T * v.cast<double>();
    if (p.z() < 0.05) continue;
    const Eigen::Vector2d q = cam.Project(p);
    *u0 = std::min(*u0, q.x());
    *v0 = std::min(*v0, q.y());
    *u1 = std::max(*u1, q.x());
    *v1 = std::max(*v1, q.y());
    any = true;
  }
  return any;
}

// ---------------------------------------------------------------------------------------------
// Sensor model.

// Drops pixels with a valid 4-neighbour more than kEdgeJumpM away in depth (flying pixels and
// shadowed edges of real depth sensors), computed on the clean depth.
void DropEdges(DepthImage* depth) {
  const std::vector<std::uint8_t> edge = synth::DepthEdgePixels(*depth, kEdgeJumpM);
  for (std::size_t i = 0; i < edge.size(); ++i)
    if (edge[i]) depth->data[i] = 0;
}

// z += N(0, σ²), σ = noise_sigma_m·(z/1 m)²; then quantised to depth_scale; values that do
// not fit the 16-bit PNG (> 65535·depth_scale) become missing, as out-of-range readings.
void AddNoiseAndQuantise(DepthImage* depth, double sigma_1m, double depth_scale, Rng& rng) {
  const double max_z = 65535.0 * depth_scale;
  for (float& z : depth->data) {
    if (z <= 0) continue;
    double zn = z;
    if (sigma_1m > 0) zn += sigma_1m * zn * zn * rng.Normal();
    const double q = std::round(zn / depth_scale);
    z = (q <= 0 || q * depth_scale > max_z) ? 0.f : float(q * depth_scale);
  }
}

// ---------------------------------------------------------------------------------------------
// Stage-1 prior.

using synth::ToDetection;

// The detection list: the target's (jittered, unless missed) first, then false positives of
// random classes with random boxes that barely overlap the target (IoU ≤ 0.1 when possible).
std::vector<Detection> MakeDetections(const SynthOptions& opt, const Box& gt_box,
                                      const std::string& target_cls,
                                      const std::vector<std::string>& classes, Rng& rng,
                                      bool* detected) {
  std::vector<Detection> dets;
  const double W = opt.camera.width, H = opt.camera.height;
  // Always draw the jitter (so miss_probability does not shift the false positives' stream).
  const double jx = rng.Normal(), jy = rng.Normal(), jw = rng.Normal(), jh = rng.Normal();
  const double score = rng.Uniform(0.6, 0.99);
  const bool missed = rng.Uniform() < opt.miss_probability;
  *detected = !missed;
  if (!missed) {
    const double s = opt.box_jitter_px;
    Box b = gt_box;
    // Centre noise is clamped to a quarter of the box, so the box still covers the object.
    b.cx += std::clamp(s * jx, -0.25 * gt_box.w, 0.25 * gt_box.w);
    b.cy += std::clamp(s * jy, -0.25 * gt_box.h, 0.25 * gt_box.h);
    b.w = std::max(4.0, b.w + s * jw);
    b.h = std::max(4.0, b.h + s * jh);
    dets.push_back(ToDetection(target_cls, score, b));
  }
  for (int i = 0; i < opt.false_positives; ++i) {
    const std::string& cls = classes[rng.UniformInt(classes.size())];
    const double sc = rng.Uniform(0.05, 0.9);
    Box b;
    for (int attempt = 0; attempt < 20; ++attempt) {
      b.w = std::min(rng.Uniform(30.0, 160.0), W);
      b.h = std::min(rng.Uniform(30.0, 160.0), H);
      b.cx = rng.Uniform(b.w / 2 - 0.5, W - 0.5 - b.w / 2);
      b.cy = rng.Uniform(b.h / 2 - 0.5, H - 0.5 - b.h / 2);
      if (BoxIoU(b, gt_box) <= 0.1) break;
    }
    dets.push_back(ToDetection(cls, sc, b));
  }
  return dets;
}

// ---------------------------------------------------------------------------------------------
// Output helpers.

// The label image as 8-bit gray (labels clamped to [0, 255]).
void SaveLabelsGray8(const std::vector<int>& labels, int w, int h, const std::string& path) {
  std::vector<std::uint8_t> pix(std::size_t(w) * h);
  for (std::size_t i = 0; i < pix.size(); ++i) pix[i] = std::uint8_t(std::clamp(labels[i], 0, 255));
  SaveGray8Png(pix, w, h, path);
}

// Depth shaded for humans: brighter = nearer; target green, occluder red, clutter blue tint;
// missing depth black.
RgbImage PreviewImage(const SynthScene& s) {
  RgbImage img(s.depth.width, s.depth.height);
  float zmin = std::numeric_limits<float>::infinity(), zmax = 0;
  for (float z : s.depth.data)
    if (z > 0) zmin = std::min(zmin, z), zmax = std::max(zmax, z);
  const float span = std::max(1e-3f, zmax - zmin);
  for (int v = 0; v < img.height; ++v)
    for (int u = 0; u < img.width; ++u) {
      const float z = s.depth.at(u, v);
      if (z <= 0) continue;
      const double g = 40 + 215 * (1 - (z - zmin) / span);
      const int l = s.labels[std::size_t(v) * img.width + u];
      double r = g, gr = g, b = g;
      if (l == kLabelTarget) r *= 0.45, b *= 0.45;
      else if (l == kLabelOccluder) gr *= 0.55, b *= 0.55;
      else if (l >= kLabelClutterFirst) r *= 0.6, gr *= 0.7;
      std::uint8_t* p = img.px(u, v);
      p[0] = std::uint8_t(r);
      p[1] = std::uint8_t(gr);
      p[2] = std::uint8_t(b);
    }
  return img;
}

using synth::InRange;

// The scene of MakeSynthScene, or each frame of MakeSynthSequence (motion != nullptr): the world
// (table, target at frame 0, occluder, clutter) is built once; then per frame the target is
// moved (target_at) and everything rendered, with the sensor model and the prior drawn from
// streams that run on from frame to frame. Frame 0 is MakeSynthScene(opt, seed) but for clutter
// that would stand on the target's path, which is placed elsewhere.
std::vector<SynthScene> BuildScenes(const SynthOptions& opt, std::uint64_t seed, const SynthMotion* motion) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("synth options: " + why);
  if (motion && !motion->IsValid(&why)) throw Error("synth motion: " + why);
  if (motion && opt.occlusion > 0) throw Error("synth motion: a sequence has no occluder panel (occlusion must be 0)");
  Rng root(seed);
  Rng rng_geom = root.Split(), rng_occ = root.Split(), rng_clutter = root.Split(),
      rng_sensor = root.Split(), rng_prior = root.Split(), rng_motion = root.Split();
  const Camera& cam = opt.camera;
  const int W = cam.width, H = cam.height;

  SynthScene s;
  s.camera = cam;
  s.depth_scale = opt.depth_scale;
  s.target = opt.target_mesh ? *opt.target_mesh : MakeShape(opt.target);
  s.classes = SynthClassNames();
  if (std::find(s.classes.begin(), s.classes.end(), s.target.name) == s.classes.end())
    s.classes.push_back(s.target.name);

  // 1–2. Table angle, target position and rotation, then the table through its lowest point.
  const double alpha = rng_geom.Uniform(30 * kDeg, 50 * kDeg);
  const double d = rng_geom.Uniform(opt.min_distance_m, opt.max_distance_m);
  const double pu = rng_geom.Uniform(0.35 * W, 0.65 * W), pv = rng_geom.Uniform(0.4 * H, 0.6 * H);
  const Eigen::Vector3d c = d * cam.Backproject(pu, pv, 1.0).normalized();
  Placed target;
  target.mesh = s.target;
  target.label = kLabelTarget;
  target.T.linear() = synth::RandomRotation(rng_geom);
  target.T.translation() = c - target.T.linear() * BoxCentre(s.target);
  Table table;
  table.u = Eigen::Vector3d(0, -std::cos(alpha), -std::sin(alpha));
  table.ex = Eigen::Vector3d::UnitX();
  table.ey = table.u.cross(table.ex);
  table.k = MinAlong(s.target, target.T, table.u);
  if (table.k >= -0.05) throw Error("synth: the target does not fit below the camera (distance too small)");
  target.foot = table.Project(c);
  target.radius = FootprintRadius(s.target, target.T, table, target.foot);
  s.distance_m = d;
  s.table_angle_rad = alpha;
  s.gt.push_back({s.target.name, target.T});
  // The motion (sequences): the target slides along a random direction of the table plane and
  // turns about the table's normal through its footprint centre; feet[t] is frame t's footprint
  // centre (clutter keeps clear of all of them).
  const int n_frames = motion ? motion->frames : 1;
  Eigen::Vector3d slide_dir = table.ex;
  if (motion) {
    const double a = rng_motion.Uniform(0, 2 * M_PI);
    slide_dir = std::cos(a) * table.ex + std::sin(a) * table.ey;
  }
  auto slide_at = [&](int t) {
    if (!motion) return 0.0;
    return motion->speed_m * t + (motion->jump_frame >= 0 && t >= motion->jump_frame ? motion->jump_m : 0.0);
  };
  auto target_at = [&](int t) {
    if (t == 0) return target.T;
    Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
    M.linear() = Eigen::AngleAxisd(motion->turn_rad * t, table.u).toRotationMatrix();
    M.translation() = target.foot + slide_dir * slide_at(t) - M.linear() * target.foot;
    return Eigen::Isometry3d(M * target.T);
  };
  std::vector<Eigen::Vector3d> feet;
  for (int t = 1; t < n_frames; ++t) feet.push_back(target.foot + slide_dir * slide_at(t));

  // The target alone: its full silhouette.
  DepthImage alone_depth(W, H, 0.f);
  std::vector<int> alone_labels(std::size_t(W) * H, kLabelBackground);
  RenderDepth(s.target, target.T, cam, &alone_depth, &alone_labels, kLabelTarget);
  const std::size_t n_alone = synth::CountLabel(alone_labels, kLabelTarget);
  std::size_t n_alone_t = n_alone;  // the target's pixels rendered alone in the frame being made
  if (n_alone < std::size_t(kMinTargetPixels))
    throw Error("synth: the target covers only " + std::to_string(n_alone) +
                " pixels (camera or target size unsuitable)");
  s.gt_box = ProjectedBox(s.target, target.T, cam);  // the box of exactly alone_labels' target pixels

  std::vector<Placed> placed;  // besides the target
  DepthImage comp_depth = alone_depth;  // target + occluder + accepted clutter (no table)
  std::vector<int> comp_labels = alone_labels;

  // 3. Occluder panel, lateral offset by bisection on the visible fraction.
  if (opt.occlusion > 0) {
    const Eigen::Vector3d cam_foot = table.u * table.k;
    Eigen::Vector3d dir = target.foot - cam_foot;
    dir -= table.u * table.u.dot(dir);
    dir = dir.norm() > 1e-9 ? dir.normalized() : table.ey;
    const Eigen::Vector3d lat = dir.cross(table.u);
    const double side = rng_occ.Uniform() < 0.5 ? -1.0 : 1.0;
    const double thick = 0.01, rt = target.radius;
    // Gap between panel and target: 3–8 cm, less when the target is close to the camera (the
    // panel's front must stay ≥ 10 cm in front of the camera, horizontally).
    const double room = dir.dot(target.foot) - rt - thick - 0.1;
    if (room < 0.005)
      throw Error("synth: no room for the occluder between the camera and the target at " +
                  std::to_string(d) + " m (use a larger min_distance_m, or occlusion 0)");
    const double gap = std::min(rng_occ.Uniform(0.03, 0.08), room);
    // The smallest panel (+1 cm margins) that hides the whole target when centred: where the
    // rays to the target's vertices cross the panel's front plane {q : dir·q = dir·front}.
    const Eigen::Vector3d front = target.foot - dir * (rt + gap + thick);
    const double front_dist = dir.dot(front);  // horizontal camera → panel distance, metres
    double height = 0, half_width = 0;
    for (const auto& v : s.target.vertices) {
      const Eigen::Vector3d p = target.T * v.cast<double>();
      const Eigen::Vector3d q = p * (front_dist / dir.dot(p));
      height = std::max(height, table.u.dot(q) - table.k);
      half_width = std::max(half_width, std::fabs(lat.dot(q - front)));
    }
    height += 0.01;
    const double width = 2 * (half_width + 0.01);
    Placed panel;
    panel.mesh = MakeBox(width, thick, height, "occluder");
    panel.label = kLabelOccluder;
    Eigen::Matrix3d Rp;
    Rp << lat, dir, table.u;
    const Eigen::Vector3d base = target.foot - dir * (rt + gap + thick / 2) + table.u * (height / 2);
    const double goal = 1.0 - opt.occlusion;
    auto pose_at = [&](double off) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = Rp;
      T.translation() = base + lat * (side * off);
      return T;
    };
    auto visible = [&](double off) {
      DepthImage dd = alone_depth;
      std::vector<int> ll = alone_labels;
      RenderDepth(panel.mesh, pose_at(off), cam, &dd, &ll, kLabelOccluder);
      return double(synth::CountLabel(ll, kLabelTarget)) / double(n_alone);
    };
    double lo = 0, hi = width + 0.02;
    double best_off = 0, best_vis = visible(0);
    for (int i = 0; i < 8 && visible(hi) < goal; ++i) hi *= 1.5;
    for (int it = 0; it < 20 && best_vis != goal; ++it) {
      const double mid = 0.5 * (lo + hi), vis = visible(mid);
      if (std::fabs(vis - goal) < std::fabs(best_vis - goal)) best_off = mid, best_vis = vis;
      if (vis < goal) lo = mid;
      else hi = mid;
      if (std::fabs(vis - goal) < 0.005) break;
    }
    panel.T = pose_at(best_off);
    panel.foot = table.Project(panel.T.translation());
    panel.radius = std::hypot(width / 2, thick / 2);
    RenderDepth(panel.mesh, panel.T, cam, &comp_depth, &comp_labels, kLabelOccluder);
    placed.push_back(std::move(panel));
  }

  // 4. Clutter around the target: no footprint overlap, and (nearly) never hiding it.
  std::size_t hidden_budget = std::size_t(kClutterMaxHiddenFrac * double(n_alone));
  for (int i = 0; i < opt.clutter; ++i) {
    const bool is_box = rng_clutter.Uniform() < 0.5;
    Mesh m;
    if (is_box) {  // sizes drawn one per statement, last first (see RandomRotation)
      const double sz = rng_clutter.Uniform(0.04, 0.18), sy = rng_clutter.Uniform(0.04, 0.12),
                   sx = rng_clutter.Uniform(0.04, 0.12);
      m = MakeBox(sx, sy, sz, "clutter_box");
    } else {
      const double height = rng_clutter.Uniform(0.05, 0.2), radius = rng_clutter.Uniform(0.025, 0.06);
      m = MakeCylinder(radius, height, 24, "clutter_cylinder");
    }
    const double rc = 0.5 * std::hypot(m.Max().x() - m.Min().x(), m.Max().y() - m.Min().y());
    for (int attempt = 0; attempt < 40; ++attempt) {
      const double ang = rng_clutter.Uniform(0, 2 * M_PI);
      const double rho = target.radius + rc + rng_clutter.Uniform(0.02, 0.35);
      const double yaw = rng_clutter.Uniform(0, 2 * M_PI);
      const Eigen::Vector3d foot = target.foot + rho * (std::cos(ang) * table.ex + std::sin(ang) * table.ey);
      if (foot.z() < 0.3) continue;
      bool overlap = false;
      for (const auto& p : placed) overlap = overlap || (p.foot - foot).norm() < p.radius + rc + 0.01;
      for (const auto& f : feet) overlap = overlap || (f - foot).norm() < target.radius + rc + 0.01;
      if (overlap) continue;
      const Eigen::Isometry3d T = StandOnTable(m, table, yaw, foot);
      // Would it hide the target? Only a render tells, but a disjoint image bbox is enough.
      double u0, v0, u1, v1;
      if (!ProjectedBounds(m, T, cam, &u0, &v0, &u1, &v1)) continue;
      const Box& g = s.gt_box;
      const bool disjoint = u1 < g.cx - g.w / 2 - 1 || u0 > g.cx + g.w / 2 + 1 ||
                            v1 < g.cy - g.h / 2 - 1 || v0 > g.cy + g.h / 2 + 1;
      const int label = kLabelClutterFirst + int(placed.size()) - (opt.occlusion > 0 ? 1 : 0);
      if (!disjoint) {
        DepthImage dd = comp_depth;
        std::vector<int> ll = comp_labels;
        RenderDepth(m, T, cam, &dd, &ll, label);
        const std::size_t lost = synth::CountLabel(comp_labels, kLabelTarget) - synth::CountLabel(ll, kLabelTarget);
        if (lost > hidden_budget) continue;
        hidden_budget -= lost;
        comp_depth = std::move(dd);
        comp_labels = std::move(ll);
      } else {
        RenderDepth(m, T, cam, &comp_depth, &comp_labels, label);
      }
      Placed p;
      p.mesh = std::move(m);
      p.T = T;
      p.label = label;
      p.foot = foot;
      p.radius = rc;
      placed.push_back(std::move(p));
      break;
    }
  }

  // 5. Render everything, measure occlusion, apply the sensor model (per frame).
  const Mesh table_mesh = MakeTableMesh(table, target.foot);
  std::vector<SynthScene> frames;
  for (int t = 0; t < n_frames; ++t) {
    SynthScene f = s;
    const Eigen::Isometry3d T = target_at(t);
    if (t > 0) {
      f.gt[0].T_cam_obj = T;
      DepthImage dd(W, H, 0.f);
      std::vector<int> ll(std::size_t(W) * H, kLabelBackground);
      RenderDepth(f.target, T, cam, &dd, &ll, kLabelTarget);
      n_alone_t = synth::CountLabel(ll, kLabelTarget);
      f.gt_box = ProjectedBox(f.target, T, cam);
    }
    f.depth = DepthImage(W, H, 0.f);
    f.labels.assign(std::size_t(W) * H, kLabelBackground);
    RenderDepth(table_mesh, Eigen::Isometry3d::Identity(), cam, &f.depth, &f.labels, kLabelBackground);
    RenderDepth(f.target, T, cam, &f.depth, &f.labels, kLabelTarget);
    for (const auto& p : placed) RenderDepth(p.mesh, p.T, cam, &f.depth, &f.labels, p.label);
    f.occlusion_achieved =
        n_alone_t > 0 ? 1.0 - double(synth::CountLabel(f.labels, kLabelTarget)) / double(n_alone_t) : 1.0;

    if (opt.missing_edges) DropEdges(&f.depth);
    AddNoiseAndQuantise(&f.depth, opt.noise_sigma_m, opt.depth_scale, rng_sensor);
    synth::DropHoles(&f.depth, opt.hole_fraction, rng_sensor);

    // 6. Stage-1 prior.
    f.detections = MakeDetections(opt, f.gt_box, f.target.name, f.classes, rng_prior, &f.target_detected);
    f.layout = PyramidLayout::Thesis(W, H, int(f.classes.size()));
    f.raw_pyramid = DetectionsToRawPyramid(f.detections, f.layout, f.classes);
    frames.push_back(std::move(f));
  }
  return frames;
}

}  // namespace

bool SynthMotion::IsValid(std::string* why) const {
  if (frames < 1 || frames > 1000) return Fail(why, "frames must be in [1, 1000]");
  if (!InRange(speed_m, 0.0, 0.5)) return Fail(why, "speed_m must be in [0, 0.5] m per frame");
  if (!InRange(turn_rad, -M_PI, M_PI)) return Fail(why, "turn_rad must be in [-pi, pi] rad per frame");
  if (jump_frame != -1 && (jump_frame < 1 || jump_frame >= frames))
    return Fail(why, "jump_frame must be -1 (none) or a frame in [1, frames) (frame 0 is the seed's scene)");
  if (!InRange(jump_m, 0.0, 1.0)) return Fail(why, "jump_m must be in [0, 1] m");
  return true;
}

SynthScene MakeSynthScene(const SynthOptions& opt, std::uint64_t seed) {
  return std::move(BuildScenes(opt, seed, nullptr).front());
}

std::vector<SynthScene> MakeSynthSequence(const SynthOptions& opt, const SynthMotion& motion, std::uint64_t seed) {
  return BuildScenes(opt, seed, &motion);
}

void WriteSynthScene(const SynthScene& s, const std::string& dir) {
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
  WriteGtJson(s.gt, (d / "gt.json").string());
  SaveMeshPly(s.target, (d / (s.target.name + ".ply")).string());
  WriteDetectionsJson(s.detections, (d / "detections.json").string());
  WriteRawPyramid(s.raw_pyramid, s.layout, (d / "prior.pyr").string());
  {
    const std::string path = (d / "classes.txt").string();
    WriteFileAtomically(path, [&](std::ostream& os) {
      for (const auto& c : s.classes) os << c << "\n";
    });
  }
  SaveLabelsGray8(s.labels, s.depth.width, s.depth.height, (d / "label.png").string());
  SaveRgbPng(PreviewImage(s), (d / "rgb.png").string());
  {
    // synth.json: what the accuracy suite and humans want to know about the scene.
    nlohmann::ordered_json j;
    j["target"] = s.target.name;
    j["distance_m"] = s.distance_m;
    j["table_angle_deg"] = s.table_angle_rad / kDeg;
    j["occlusion_achieved"] = s.occlusion_achieved;
    j["target_detected"] = s.target_detected;
    j["gt_bbox"] = {s.gt_box.cx - s.gt_box.w / 2, s.gt_box.cy - s.gt_box.h / 2, s.gt_box.w, s.gt_box.h};
    j["classes"] = s.classes;
    const std::string path = (d / "synth.json").string();
    WriteFileAtomically(path, [&](std::ostream& os) { os << j.dump(1) << "\n"; });
  }
}

std::vector<std::string> SynthSceneFileNames(const std::string& target_name) {
  return {"depth.png", "camera.json", "gt.json", target_name + ".ply", "detections.json", "prior.pyr",
          "classes.txt", "label.png", "rgb.png", "synth.json"};
}

void WriteSynthSequence(const std::vector<SynthScene>& frames, const std::string& dir, const std::string& name) {
  namespace fs = std::filesystem;
  if (frames.empty()) throw Error(dir + ": no frames to write");
  if (name.empty() || name.find_first_of("/\\ ") != std::string::npos)
    throw Error("synth sequence name '" + name + "' must be a plain file-name stem");
  const fs::path models = fs::path(dir) / "models";
  std::error_code ec;
  fs::create_directories(models, ec);
  if (ec || !fs::is_directory(models)) throw Error(models.string() + ": cannot create directory");
  SaveMeshPly(frames.front().target, (models / (frames.front().target.name + ".ply")).string());
  for (std::size_t t = 0; t < frames.size(); ++t) {
    char folder[64];
    std::snprintf(folder, sizeof folder, "_0000_%06zu", t + 1);
    WriteSynthScene(frames[t], (fs::path(dir) / "scenes" / (name + folder)).string());
  }
}

}  // namespace posefilter
