// Room scenes of real object meshes on small raised surfaces (room_world.h).
//
// Construction, in the room frame R (z up, floor z = 0), then in the camera frame:
//  1. Supports: the first is a chair's writing tablet, a stool, a side table, a crate or a
//     shelf's board; with two_surfaces_probability a second raised surface (not a shelf)
//     stands 0.45–0.9 m from it, its top at least 10 cm higher or lower.
//  2. Objects: distinct classes in stable poses, placed on the surfaces' tops (surface frame
//     S: z up, origin at the top's centre) within their outline, touching a neighbour
//     (touch_probability) or 1–8 cm away; an object that does not fit is left out.
//  3. Per view (at most 40): the camera looks at the objects' centre; walls behind and beside
//     the supports; furniture around, outside the line of sight to the objects and clear of
//     the camera; distractors on furniture tops and the floor; rendering (z-buffered); the
//     view is kept when the supports cover [min_surface_view, max_surface_view] of the image
//     and an object is a target.
//  4. The table world's sensor model, targets, boxes and masks (world_parts.h).
// Independent Rng streams (Split) drive the objects, the supports, each view and the prior.
#include "posefilter/room_world.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <set>

#include "core/option_check.h"
#include "posefilter/error.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/synth.h"
#include "synth/synth_util.h"
#include "synth/world_parts.h"

namespace posefilter {
namespace {

using synth::kDeg;
using synth::kPad;
constexpr int kViews = 40;
constexpr int kRoomLayoutAttempts = 8;  // layouts drawn before a seed is given up
constexpr int kLayoutStreams = 6;        // the streams one layout splits from its root (TryRoomScene)

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Polygon = std::vector<Vec2>;

using synth::InRange;

Eigen::Isometry3d Pose(const Vec3& t, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A rendered solid of the room: its mesh and pose (mesh → room).
struct Part {
  std::shared_ptr<const Mesh> mesh;
  Eigen::Isometry3d T_R = Eigen::Isometry3d::Identity();
  int support = -1;  // index of the support surface whose top it is, else -1
};

// A horizontal top things can rest on: frame S (z up, origin at the top's centre), half
// sides (a disc: radius a), and the clearance above it (metres).
struct Top {
  Eigen::Isometry3d T_R_S = Eigen::Isometry3d::Identity();
  double a = 0, b = 0;
  bool disc = false;
  double clearance = 10;
  bool Inside(const Vec2& p, double margin) const {
    if (disc) return p.norm() <= a - margin;
    return std::fabs(p.x()) <= a - margin && std::fabs(p.y()) <= b - margin;
  }
};

struct Furniture {
  std::vector<Part> parts;
  std::vector<Top> tops;
  Vec2 centre = Vec2::Zero();  // room frame, on the floor
  double radius = 0;           // footprint radius about the centre, metres
};

std::shared_ptr<const Mesh> BoxMesh(double sx, double sy, double sz) {
  return std::make_shared<const Mesh>(MakeBox(sx, sy, sz, "furniture"));
}
std::shared_ptr<const Mesh> CylinderMesh(double r, double h) {
  return std::make_shared<const Mesh>(MakeCylinder(r, h, 12, "furniture"));
}

// Parts of a piece of furniture in its frame F (origin on the floor at its centre, x right,
// y its front, z up); `place` turns F into the room.
struct Builder {
  Furniture f;
  Eigen::Isometry3d T_R_F = Eigen::Isometry3d::Identity();
  void Box(const Vec3& centre_F, double sx, double sy, double sz, int support = -1) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = centre_F;
    f.parts.push_back({BoxMesh(sx, sy, sz), T_R_F * T, support});
  }
  void Cylinder(const Vec3& centre_F, double r, double h, int support = -1) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = centre_F;
    f.parts.push_back({CylinderMesh(r, h), T_R_F * T, support});
  }
  // A top of half sides a × b (or a disc of radius a) centred at c_F with `clearance` above it.
  void AddTop(const Vec3& c_F, double a, double b, bool disc, double clearance = 10) {
    Top t;
    t.T_R_S = T_R_F * Pose(c_F, 0);
    t.a = a, t.b = b, t.disc = disc, t.clearance = clearance;
    f.tops.push_back(t);
  }
};

enum class Kind { kTabletChair, kStool, kSideTable, kCrate, kShelf, kDesk };

// Draws h in [lo, hi] ∩ [min_h, max_h], or in [min_h, max_h] when they do not meet.
double Height(double lo, double hi, double min_h, double max_h, Rng& rng) {
  const double a = std::max(lo, min_h), b = std::min(hi, max_h);
  return a <= b ? rng.Uniform(a, b) : rng.Uniform(min_h, max_h);
}

// One piece of furniture of `kind` at `centre` turned by `yaw`. Its first top is the surface
// a support's objects rest on (height `h`, sides sa × sb; a disc of diameter sa for a stool);
// `support` labels that top's part. Shelves: `boards` boards, the top one at h; the objects'
// board is `board` (0 = the top one, 1 = the one below, ...).
Furniture Build(Kind kind, const Vec2& centre, double yaw, double h, double sa, double sb, int support, Rng& rng,
                int boards = 3, int board = 0) {
  Builder b;
  b.T_R_F = Pose(Vec3(centre.x(), centre.y(), 0), yaw);
  b.f.centre = centre;
  const double t = 0.025;  // board thickness
  switch (kind) {
    case Kind::kTabletChair: {
      // Seat 42 cm square at 45 cm, four legs, a backrest on two posts, and the writing tablet
      // (sa × sb, its top at h) on a post from the seat's right edge.
      const double seat = 0.42, sh = 0.45;
      b.Box(Vec3(0, 0, sh - 0.015), seat, seat, 0.03);
      for (int i = 0; i < 4; ++i)
        b.Cylinder(Vec3((i & 1 ? 1 : -1) * 0.18, (i & 2 ? 1 : -1) * 0.18, (sh - 0.03) / 2), 0.012, sh - 0.03);
      const double back_top = std::max(sh + 0.3, std::min(h + 0.15, 0.9));
      for (int i = 0; i < 2; ++i) b.Cylinder(Vec3((i ? 1 : -1) * 0.18, -0.2, 0.5 * (sh + back_top)), 0.011, back_top - sh);
      b.Box(Vec3(0, -0.2, back_top - 0.12), seat, 0.02, 0.22);
      const Vec3 tc(0.21 - 0.5 * sa + 0.08, 0.1 + 0.5 * sb - 0.12, h - 0.01);
      b.Box(tc, sa, sb, 0.02, support);
      // Its post, from the floor to the tablet's corner on the chair's right.
      b.Cylinder(Vec3(tc.x() + 0.5 * sa - 0.03, tc.y() - 0.5 * sb + 0.03, 0.5 * (h - 0.02)), 0.012, h - 0.02);
      b.AddTop(Vec3(tc.x(), tc.y(), h), 0.5 * sa, 0.5 * sb, false);
      b.f.radius = std::max(0.32, std::hypot(std::fabs(tc.x()) + 0.5 * sa, std::fabs(tc.y()) + 0.5 * sb));
      break;
    }
    case Kind::kStool: {
      const double r = 0.5 * sa;
      b.Cylinder(Vec3(0, 0, h - 0.015), r, 0.03, support);
      const int legs = 3 + int(rng.UniformInt(2));
      for (int i = 0; i < legs; ++i) {
        const double a = 2 * M_PI * i / legs;
        b.Cylinder(Vec3(0.7 * r * std::cos(a), 0.7 * r * std::sin(a), 0.5 * (h - 0.03)), 0.014, h - 0.03);
      }
      b.AddTop(Vec3(0, 0, h), r, r, true);
      b.f.radius = r;
      break;
    }
    case Kind::kSideTable:
    case Kind::kDesk: {
      b.Box(Vec3(0, 0, h - 0.015), sa, sb, 0.03, support);
      for (int i = 0; i < 4; ++i)
        b.Box(Vec3((i & 1 ? 1 : -1) * (0.5 * sa - 0.04), (i & 2 ? 1 : -1) * (0.5 * sb - 0.04), 0.5 * (h - 0.03)), 0.04, 0.04,
              h - 0.03);
      if (kind == Kind::kDesk)  // a modesty panel at the back
        b.Box(Vec3(0, -0.5 * sb + 0.06, 0.5 * h), sa - 0.1, 0.015, 0.4 * h);
      b.AddTop(Vec3(0, 0, h), 0.5 * sa, 0.5 * sb, false);
      b.f.radius = 0.5 * std::hypot(sa, sb);
      break;
    }
    case Kind::kCrate: {
      b.Box(Vec3(0, 0, 0.5 * h), sa, sb, h, support);
      b.AddTop(Vec3(0, 0, h), 0.5 * sa, 0.5 * sb, false);
      b.f.radius = 0.5 * std::hypot(sa, sb);
      break;
    }
    case Kind::kShelf: {
      // sa wide, sb deep; `boards` boards, the top one at h, evenly spaced down to ≥ 8 cm;
      // two side panels and a back panel.
      const double side = 0.02, inner = sa - 2 * side;
      const double low = std::max(0.08, h - 0.45 * (boards - 1));
      const double gap = boards > 1 ? (h - low) / (boards - 1) : 0;
      for (int k = 0; k < boards; ++k) {
        const double zk = h - k * gap;
        b.Box(Vec3(0, 0, zk - 0.5 * t), inner, sb, t, k == board ? support : -1);
        b.AddTop(Vec3(0, 0.01, zk), 0.5 * inner, 0.5 * sb - 0.01, false, k == 0 ? 10.0 : gap - t);
      }
      for (int i = 0; i < 2; ++i) b.Box(Vec3((i ? 1 : -1) * (0.5 * sa - 0.5 * side), 0, 0.5 * (h + 0.01)), side, sb, h + 0.01);
      b.Box(Vec3(0, -0.5 * sb - 0.005, 0.5 * (h + 0.01)), sa, 0.01, h + 0.01);
      // The objects' board first.
      std::swap(b.f.tops[0], b.f.tops[std::size_t(board)]);
      b.f.radius = 0.5 * std::hypot(sa, sb);
      break;
    }
  }
  return b.f;
}

// A placed object: its model, stable pose and pose in the room, footprint in its top's frame.
struct PlacedInRoom {
  int model = -1;
  int pose = -1;
  int support = 0;
  Eigen::Isometry3d T_R_obj = Eigen::Isometry3d::Identity();
  Polygon footprint;
};

// The object's pose on a top (frame S) at position 0, its footprint, its height above the top.
struct Resting {
  Eigen::Isometry3d T_S_obj = Eigen::Isometry3d::Identity();
  Polygon footprint;
  double radius = 0, height = 0;
};

Resting Rest(const Mesh& mesh, const Eigen::Isometry3d& T_table_obj, double yaw) {
  Resting r;
  r.T_S_obj = Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * T_table_obj;
  std::vector<Vec2> xy;
  for (const auto& v : mesh.vertices) {
    const Vec3 p = r.T_S_obj * v.cast<double>();
    xy.push_back(p.head<2>());
    r.height = std::max(r.height, p.z());
  }
  r.footprint = synth::ConvexHull2d(std::move(xy));
  for (const Vec2& q : r.footprint) r.radius = std::max(r.radius, q.norm());
  return r;
}

// Places `rest` on `top` clear of `taken` (footprints in the top's frame): with touch, pushed
// out from a random taken footprint until clear (0–3 mm gap), else at a random point 1–8 cm
// clear of the others. Returns the shift, or false when it does not fit (40 tries).
bool PlaceOnTop(const Resting& rest, const Top& top, const std::vector<Polygon>& taken, double touch_probability, Rng& rng,
                Vec2* at) {
  if (rest.height > top.clearance - 0.01) return false;
  auto inside = [&](const Polygon& fp) {
    for (const Vec2& q : fp)
      if (!top.Inside(q, 0.005)) return false;
    return true;
  };
  for (int attempt = 0; attempt < 40; ++attempt) {
    const bool touch = !taken.empty() && rng.Uniform() < touch_probability;
    const double gap = touch ? rng.Uniform(0.0, 0.003) : rng.Uniform(0.01, 0.08);
    auto clear = [&](const Vec2& p) {
      const Polygon fp = synth::Shifted(rest.footprint, p);
      for (const Polygon& q : taken)
        if (!synth::Separated(fp, q, gap)) return false;
      return true;
    };
    Vec2 p;
    if (touch) {
      const Polygon& anchor = taken[rng.UniformInt(taken.size())];
      Vec2 base = Vec2::Zero();
      for (const Vec2& q : anchor) base += q;
      base /= double(anchor.size());
      const double theta = rng.Uniform(0, 2 * M_PI);
      const Vec2 dir(std::cos(theta), std::sin(theta));
      double lo = 0, hi = -1;
      for (double s = 0.005; s <= 0.6; s += 0.005) {
        if (clear(base + s * dir)) {
          hi = s;
          break;
        }
        lo = s;
      }
      if (hi < 0) continue;
      for (int it = 0; it < 12; ++it) {
        const double mid = 0.5 * (lo + hi);
        (clear(base + mid * dir) ? hi : lo) = mid;
      }
      p = base + hi * dir;
    } else {
      p = Vec2(rng.Uniform(-top.a, top.a), rng.Uniform(-(top.disc ? top.a : top.b), top.disc ? top.a : top.b));
      if (!clear(p)) continue;
    }
    if (!inside(synth::Shifted(rest.footprint, p))) continue;
    *at = p;
    return true;
  }
  return false;
}

// A YCB-size primitive: a box (4–20 cm sides) or a cylinder (radius 2.5–6 cm, 6–22 cm high),
// standing; the mesh is centred on its bounding box.
std::shared_ptr<const Mesh> Primitive(Rng& rng, double* height) {
  if (rng.Uniform() < 0.6) {
    const double sx = rng.Uniform(0.04, 0.2), sy = rng.Uniform(0.04, 0.2), sz = rng.Uniform(0.03, 0.2);
    *height = sz;
    return std::make_shared<const Mesh>(MakeBox(sx, sy, sz, "distractor"));
  }
  const double r = rng.Uniform(0.025, 0.06), h = rng.Uniform(0.06, 0.22);
  *height = h;
  return std::make_shared<const Mesh>(MakeCylinder(r, h, 24, "distractor"));
}

// Distance from p to the segment [a, b] (2-D).
double SegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double t = d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

}  // namespace

bool RoomSceneOptions::IsValid(std::string* why) const {
  std::string sub;
  if (!camera.IsValid(&sub)) return Fail(why, "camera: " + sub);
  if (camera.width < 80 || camera.height < 60) return Fail(why, "camera: image must be at least 80×60 pixels");
  if (!(depth_scale > 0 && std::isfinite(depth_scale))) return Fail(why, "depth_scale must be finite and > 0");
  if (min_objects < 1 || max_objects < min_objects || max_objects > 20)
    return Fail(why, "objects per scene must satisfy 1 <= min_objects <= max_objects <= 20");
  if (!(InRange(min_distance_m, 0.3, 5) && InRange(max_distance_m, min_distance_m, 5)))
    return Fail(why, "distances must satisfy 0.3 <= min_distance_m <= max_distance_m <= 5 m");
  if (!(InRange(min_elevation_deg, 5, 85) && InRange(max_elevation_deg, min_elevation_deg, 85)))
    return Fail(why, "elevations must satisfy 5 <= min_elevation_deg <= max_elevation_deg <= 85");
  if (!(InRange(min_surface_height_m, 0.1, 2) && InRange(max_surface_height_m, min_surface_height_m, 2)))
    return Fail(why, "surface heights must satisfy 0.1 <= min_surface_height_m <= max_surface_height_m <= 2 m");
  if (!(InRange(min_surface_size_m, 0.15, 1.5) && InRange(max_surface_size_m, min_surface_size_m, 1.5)))
    return Fail(why, "surface sizes must satisfy 0.15 <= min_surface_size_m <= max_surface_size_m <= 1.5 m");
  if (!(InRange(min_surface_view, 0, 1) && InRange(max_surface_view, min_surface_view, 1)))
    return Fail(why, "surface view fractions must satisfy 0 <= min_surface_view <= max_surface_view <= 1");
  if (!InRange(shelf_probability, 0, 1)) return Fail(why, "shelf_probability must be in [0, 1]");
  if (!InRange(two_surfaces_probability, 0, 1)) return Fail(why, "two_surfaces_probability must be in [0, 1]");
  if (min_furniture < 0 || max_furniture < min_furniture || max_furniture > 20)
    return Fail(why, "furniture must satisfy 0 <= min_furniture <= max_furniture <= 20");
  if (min_distractors < 0 || max_distractors < min_distractors || max_distractors > 30)
    return Fail(why, "distractors must satisfy 0 <= min_distractors <= max_distractors <= 30");
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

namespace {

// One layout of the scene drawn from `root` (options checked by the caller); nullopt when no
// object fits on the supports or no view shows an object well enough.
std::optional<TableScene> TryRoomScene(const TableWorld& world, const RoomSceneOptions& opt, Rng root) {
  const std::vector<TableModel>& models = world.models();
  Rng rng_objects = root.Split(), rng_support = root.Split(), rng_view = root.Split(), rng_sensor = root.Split(),
      rng_prior = root.Split(), rng_mask = root.Split();
  const Camera& cam = opt.camera;
  const int W = cam.width, H = cam.height;
  const double hmin = opt.min_surface_height_m, hmax = opt.max_surface_height_m;
  auto size = [&](double hi) { return rng_support.Uniform(opt.min_surface_size_m, std::max(opt.min_surface_size_m, std::min(hi, opt.max_surface_size_m))); };

  // 1. Supports.
  std::vector<Furniture> supports;
  const bool shelf = rng_support.Uniform() < opt.shelf_probability;
  const double yaw0 = rng_support.Uniform(-M_PI, M_PI);
  if (shelf) {
    const int boards = 2 + int(rng_support.UniformInt(2));
    const double h = rng_support.Uniform(hmin, hmax);
    // The objects' board: the top one, or (when the boards are ≥ 38 cm apart) one below it.
    const double low = std::max(0.08, h - 0.45 * (boards - 1)), gap = (h - low) / (boards - 1);
    int board = 0;
    if (gap >= 0.38 && h - gap >= hmin && rng_support.Uniform() < 0.4) board = 1;
    supports.push_back(Build(Kind::kShelf, Vec2::Zero(), yaw0, h, rng_support.Uniform(0.6, 1.0), rng_support.Uniform(0.28, 0.4), 0,
                             rng_support, boards, board));
  } else {
    const Kind kinds[4] = {Kind::kTabletChair, Kind::kStool, Kind::kSideTable, Kind::kCrate};
    const Kind kind = kinds[rng_support.UniformInt(4)];
    const double h = kind == Kind::kTabletChair ? Height(0.6, 0.8, hmin, hmax, rng_support)
                     : kind == Kind::kStool     ? Height(0.45, 0.8, hmin, hmax, rng_support)
                     : kind == Kind::kCrate     ? Height(0.4, 0.65, hmin, hmax, rng_support)
                                                : Height(0.5, 0.9, hmin, hmax, rng_support);
    const double sa = size(kind == Kind::kStool ? 0.45 : 0.6), sb = size(kind == Kind::kTabletChair ? 0.4 : 0.6);
    supports.push_back(Build(kind, Vec2::Zero(), yaw0, h, sa, sb, 0, rng_support));
  }
  if (rng_support.Uniform() < opt.two_surfaces_probability) {
    const Kind kinds[4] = {Kind::kTabletChair, Kind::kStool, Kind::kSideTable, Kind::kCrate};
    const Kind kind = kinds[rng_support.UniformInt(4)];
    const double h0 = supports[0].tops[0].T_R_S.translation().z();
    double h = h0;
    for (int k = 0; k < 10 && std::fabs(h - h0) < 0.1; ++k) h = rng_support.Uniform(hmin, hmax);
    const double sa = size(kind == Kind::kStool ? 0.45 : 0.6), sb = size(0.6);
    const double theta = rng_support.Uniform(-M_PI, M_PI), yaw = rng_support.Uniform(-M_PI, M_PI);
    Furniture f = Build(kind, Vec2::Zero(), yaw, h, sa, sb, 1, rng_support);
    const double d = supports[0].radius + f.radius + rng_support.Uniform(0.05, 0.3);
    if (std::fabs(h - h0) >= 0.1) supports.push_back(Build(kind, d * Vec2(std::cos(theta), std::sin(theta)), yaw, h, sa, sb, 1, rng_support));
  }

  // 2. Objects on the supports' first tops: the first ceil(k / n) on the first, the rest on the
  // second; classes in a shuffled order, one that does not fit is skipped.
  const int object_choices = opt.max_objects - opt.min_objects + 1;
  const int k = opt.min_objects + int(rng_objects.UniformInt(std::uint64_t(object_choices)));
  std::vector<int> order(models.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  for (std::size_t i = 0; i + 1 < order.size(); ++i) std::swap(order[i], order[i + rng_objects.UniformInt(order.size() - i)]);
  std::vector<PlacedInRoom> placed;
  std::vector<std::vector<Polygon>> taken(supports.size());
  std::size_t next_class = 0;
  for (std::size_t sidx = 0; sidx < supports.size(); ++sidx) {
    const int want = sidx == 0 ? (k + int(supports.size()) - 1) / int(supports.size()) : k - int(placed.size());
    const Top& top = supports[sidx].tops[0];
    for (int n = 0; n < want && next_class < order.size();) {
      const int m = order[next_class++];
      const TableModel& model = models[std::size_t(m)];
      const int pose = synth::DrawPose(model.poses, rng_objects);
      const Resting rest = Rest(model.mesh, model.poses[std::size_t(pose)].T_table_obj, rng_objects.Uniform(-M_PI, M_PI));
      Vec2 at;
      if (!PlaceOnTop(rest, top, taken[sidx], opt.touch_probability, rng_objects, &at)) continue;
      PlacedInRoom p;
      p.model = m;
      p.pose = pose;
      p.support = int(sidx);
      Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
      shift.translation() << at.x(), at.y(), 0;
      p.T_R_obj = top.T_R_S * shift * rest.T_S_obj;
      p.footprint = synth::Shifted(rest.footprint, at);
      taken[sidx].push_back(p.footprint);
      placed.push_back(p);
      ++n;
    }
  }
  // Classes the objects do not use: YCB distractors.
  std::vector<int> spare(order.begin() + std::ptrdiff_t(next_class), order.end());
  // A distractor beside the objects on the first support, sometimes.
  std::vector<Part> near_parts;
  if (rng_objects.Uniform() < 0.4) {
    double hgt = 0;
    const std::shared_ptr<const Mesh> mesh = Primitive(rng_objects, &hgt);
    const Resting rest = Rest(*mesh, Pose(Vec3(0, 0, 0.5 * hgt), 0), rng_objects.Uniform(-M_PI, M_PI));
    Vec2 at;
    if (PlaceOnTop(rest, supports[0].tops[0], taken[0], 0.3, rng_objects, &at)) {
      Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
      shift.translation() << at.x(), at.y(), 0;
      near_parts.push_back({mesh, supports[0].tops[0].T_R_S * shift * rest.T_S_obj, -1});
      taken[0].push_back(synth::Shifted(rest.footprint, at));
    }
  }
  if (placed.empty()) return std::nullopt;

  Vec3 centre = Vec3::Zero();
  for (const PlacedInRoom& p : placed) centre += p.T_R_obj.translation();
  centre /= double(placed.size());

  // 3. Views.
  TableScene s;
  s.camera = cam;
  s.depth_scale = opt.depth_scale;
  s.classes = world.ClassNames();
  bool have = false;
  for (int view = 0; view < kViews; ++view) {
    Rng rng = rng_view.Split();
    // Camera: at the objects' centre (± 3 cm, 2–8 cm up), shelves from their front (± 35°).
    const Vec3 look = centre + Vec3(rng.Uniform(-0.03, 0.03), rng.Uniform(-0.03, 0.03), rng.Uniform(0.02, 0.08));
    const double elev = rng.Uniform(opt.min_elevation_deg, opt.max_elevation_deg) * kDeg;
    const double az = shelf ? yaw0 + M_PI / 2 + rng.Uniform(-35, 35) * kDeg : rng.Uniform(-M_PI, M_PI);
    const double dist = rng.Uniform(opt.min_distance_m, opt.max_distance_m);
    const double roll = rng.Uniform(-8, 8) * kDeg;
    const Vec3 C = look + dist * Vec3(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
    const Vec3 zf = (look - C).normalized();
    const Vec3 x = zf.cross(Vec3::UnitZ()).normalized(), y = zf.cross(x);
    const Vec3 xr = std::cos(roll) * x + std::sin(roll) * y, yr = zf.cross(xr);
    Eigen::Isometry3d T_R_C = Eigen::Isometry3d::Identity();
    T_R_C.linear() << xr, yr, zf;
    T_R_C.translation() = C;
    const Eigen::Isometry3d T_C_R = T_R_C.inverse();
    const Vec2 c2 = C.head<2>();
    // The camera must be clear of the supports' parts (10 cm).
    auto inside_part = [&](const Part& part, const Vec3& p, double margin) {
      const Vec3 q = part.T_R.inverse() * p;
      return (q.array().abs() <= (0.5 * (part.mesh->Max() - part.mesh->Min()).cast<double>().array() + margin)).all();
    };
    bool blocked = false;
    for (const Furniture& f : supports)
      for (const Part& part : f.parts) blocked = blocked || inside_part(part, C, 0.1);
    if (blocked) continue;

    // Walls: behind the supports as seen from the camera (turned ±25°; a shelf's back against
    // it), and on each side with probability 0.5, clear of the camera and the supports.
    std::vector<Part> parts;
    std::vector<Mesh> planes;  // floor and walls, rendered as grids (near-plane safe)
    planes.reserve(4);
    const Vec2 fwd2 = (look.head<2>() - c2).normalized();
    const double wall_yaw = shelf ? yaw0 + M_PI : std::atan2(fwd2.y(), fwd2.x()) - M_PI / 2 + rng.Uniform(-25, 25) * kDeg;
    const Vec2 wy(-std::sin(wall_yaw), std::cos(wall_yaw));  // away from the camera: the back wall's normal points -wy
    const Vec2 wx(std::cos(wall_yaw), std::sin(wall_yaw));
    double reach_back = 0, reach_left = 0, reach_right = 0;  // the supports' extent along ±wx, wy
    for (const Furniture& f : supports) {
      reach_back = std::max(reach_back, f.centre.dot(wy) + f.radius);
      reach_left = std::max(reach_left, -f.centre.dot(wx) + f.radius);
      reach_right = std::max(reach_right, f.centre.dot(wx) + f.radius);
    }
    // (A shelf's back panel reaches its top's half depth + 2 cm behind its centre.)
    const double back = shelf ? supports[0].tops[0].b + 0.025 + rng.Uniform(0.0, 0.03)
                              : std::max(reach_back + 0.02, rng.Uniform(0.3, 3.0));
    const double cam_x = c2.dot(wx);
    const double left = rng.Uniform() < 0.5 ? std::max({rng.Uniform(0.8, 3.0), reach_left + 0.05, -cam_x + 0.3}) : -1;
    const double right = rng.Uniform() < 0.5 ? std::max({rng.Uniform(0.8, 3.0), reach_right + 0.05, cam_x + 0.3}) : -1;
    const double front = c2.dot(wy) - 4.0;  // the room goes on behind the camera
    const Vec3 X(wx.x(), wx.y(), 0), Y(wy.x(), wy.y(), 0), Z = Vec3::UnitZ();
    const double room_h = 2.6;
    const double x0 = left > 0 ? -left : -5.0, x1 = right > 0 ? right : 5.0;
    planes.push_back(synth::PlaneGridMesh(Vec3::Zero(), X, Y, x0, x1, front, back, 0.25, T_C_R, 0.1));  // floor, up
    // Back wall, facing the camera (normal −Y): axes X and Z give X × Z = −Y.
    planes.push_back(synth::PlaneGridMesh(back * Y, X, Z, x0, x1, 0, room_h, 0.25, T_C_R, 0.1));
    // Side walls facing into the room: Y × Z = X on the left, Z × Y = −X on the right.
    if (left > 0) planes.push_back(synth::PlaneGridMesh(-left * X, Y, Z, front, back, 0, room_h, 0.25, T_C_R, 0.1));
    if (right > 0) planes.push_back(synth::PlaneGridMesh(right * X, Z, Y, 0, room_h, front, back, 0.25, T_C_R, 0.1));
    auto in_room = [&](const Vec2& p, double r) {
      const double px = p.dot(wx), py = p.dot(wy);
      return py + r < back && (left < 0 || px - r > -left) && (right < 0 || px + r < right);
    };

    // Furniture around: not on the line of sight to any object, clear of the camera (40 cm)
    // and of other furniture.
    std::vector<Furniture> furniture = supports;
    const int furniture_choices = opt.max_furniture - opt.min_furniture + 1;
    const int nf = opt.min_furniture + int(rng.UniformInt(std::uint64_t(furniture_choices)));
    for (int i = 0, tries = 0; i < nf && tries < 60; ++tries) {
      const double u = rng.Uniform();
      const Kind kind = u < 0.35 ? Kind::kTabletChair : u < 0.55 ? Kind::kDesk : u < 0.7 ? Kind::kShelf : u < 0.85 ? Kind::kStool : Kind::kCrate;
      // Mostly beyond the objects as the camera sees them (within ±70° of its horizontal view
      // direction), else anywhere around.
      const double fwd_angle = std::atan2(fwd2.y(), fwd2.x());
      const double th = rng.Uniform() < 0.7 ? fwd_angle + rng.Uniform(-70, 70) * kDeg : rng.Uniform(-M_PI, M_PI);
      const double r0 = rng.Uniform(0.5, 3.0), yaw = rng.Uniform(-M_PI, M_PI);
      const Vec2 pos = look.head<2>() + r0 * Vec2(std::cos(th), std::sin(th));
      Furniture f;
      switch (kind) {
        case Kind::kTabletChair:
          f = Build(kind, pos, yaw, rng.Uniform(0.6, 0.8), rng.Uniform(0.25, 0.6), rng.Uniform(0.25, 0.4), -1, rng);
          break;
        case Kind::kDesk:
          f = Build(kind, pos, yaw, rng.Uniform(0.7, 0.78), rng.Uniform(1.0, 1.6), rng.Uniform(0.55, 0.8), -1, rng);
          break;
        case Kind::kShelf:
          f = Build(kind, pos, yaw, rng.Uniform(0.5, 1.8), rng.Uniform(0.6, 1.0), rng.Uniform(0.28, 0.4), -1, rng,
                    2 + int(rng.UniformInt(3)));
          break;
        case Kind::kStool:
          f = Build(kind, pos, yaw, rng.Uniform(0.45, 0.8), rng.Uniform(0.28, 0.4), 0, -1, rng);
          break;
        default:
          f = Build(kind, pos, yaw, rng.Uniform(0.2, 0.6), rng.Uniform(0.25, 0.6), rng.Uniform(0.25, 0.6), -1, rng);
          break;
      }
      bool ok = in_room(pos, f.radius) && (pos - c2).norm() > f.radius + 0.4;
      for (const PlacedInRoom& p : placed) ok = ok && SegmentDistance(pos, c2, p.T_R_obj.translation().head<2>()) > f.radius + 0.1;
      for (const Furniture& g : furniture) ok = ok && (pos - g.centre).norm() > f.radius + g.radius + 0.05;
      if (!ok) continue;
      furniture.push_back(std::move(f));
      ++i;
    }
    for (const Furniture& f : furniture) parts.insert(parts.end(), f.parts.begin(), f.parts.end());
    parts.insert(parts.end(), near_parts.begin(), near_parts.end());

    // Distractors: on other furniture's tops (not the supports' object tops) or on the floor
    // within 2 m of the objects, never on the line of sight to an object.
    const int distractor_choices = opt.max_distractors - opt.min_distractors + 1;
    const int nd = opt.min_distractors + int(rng.UniformInt(std::uint64_t(distractor_choices)));
    std::vector<std::vector<Polygon>> on_top;
    std::vector<const Top*> tops;
    for (std::size_t fi = 0; fi < furniture.size(); ++fi)
      for (std::size_t ti = 0; ti < furniture[fi].tops.size(); ++ti)
        if (!(fi < supports.size() && ti == 0)) tops.push_back(&furniture[fi].tops[ti]);
    on_top.resize(tops.size());
    std::vector<Polygon> floor_taken;
    Top floor_top;
    floor_top.T_R_S = Pose(Vec3(look.x(), look.y(), 0), 0);
    floor_top.a = floor_top.b = 2.0;
    for (int i = 0; i < nd; ++i) {
      std::shared_ptr<const Mesh> mesh;
      Eigen::Isometry3d T_table = Eigen::Isometry3d::Identity();
      if (!spare.empty() && rng.Uniform() < 0.5) {
        const TableModel& m = models[std::size_t(spare[rng.UniformInt(spare.size())])];
        mesh = std::shared_ptr<const Mesh>(&m.mesh, [](const Mesh*) {});  // the world outlives the scene's making
        T_table = m.poses[std::size_t(synth::DrawPose(m.poses, rng))].T_table_obj;
      } else {
        double hgt = 0;
        mesh = Primitive(rng, &hgt);
        T_table.translation() = Vec3(0, 0, 0.5 * hgt);
      }
      const Resting rest = Rest(*mesh, T_table, rng.Uniform(-M_PI, M_PI));
      const bool on_floor = tops.empty() || rng.Uniform() < 0.35;
      const std::size_t ti = on_floor ? 0 : rng.UniformInt(tops.size());
      const Top& top = on_floor ? floor_top : *tops[ti];
      std::vector<Polygon>& tk = on_floor ? floor_taken : on_top[ti];
      Vec2 at;
      if (!PlaceOnTop(rest, top, tk, 0.3, rng, &at)) continue;
      Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
      shift.translation() << at.x(), at.y(), 0;
      const Eigen::Isometry3d T = top.T_R_S * shift * rest.T_S_obj;
      const Vec2 p2 = T.translation().head<2>();
      if (on_floor) {
        bool ok = in_room(p2, rest.radius) && (p2 - c2).norm() > 0.3;
        for (const PlacedInRoom& p : placed) ok = ok && SegmentDistance(p2, c2, p.T_R_obj.translation().head<2>()) > rest.radius + 0.05;
        for (const Furniture& g : furniture) ok = ok && (p2 - g.centre).norm() > rest.radius + g.radius;
        if (!ok) continue;
      }
      tk.push_back(synth::Shifted(rest.footprint, at));
      parts.push_back({mesh, T, -1});
    }
    // Parts that reach behind the camera's near plane are left out (the renderer would skip
    // their triangles anyway); a view that would lose a support's top is not taken.
    std::vector<Part> kept;
    bool support_lost = false;
    for (Part& part : parts) {
      bool near = false;
      for (const auto& v : part.mesh->vertices) near = near || (T_C_R * (part.T_R * v.cast<double>())).z() < 0.1;
      support_lost = support_lost || (near && part.support >= 0);
      if (!near) kept.push_back(std::move(part));
    }
    if (support_lost) continue;
    parts = std::move(kept);

    // Objects' poses in the camera, their full silhouettes (on a padded canvas) and boxes.
    std::vector<TableObject> objects;
    std::vector<std::size_t> alone;
    for (const PlacedInRoom& p : placed) {
      TableObject o;
      o.model = p.model;
      o.cls = models[std::size_t(p.model)].mesh.name;
      o.stable_pose = p.pose;
      o.support = p.support;
      o.T_cam_obj = T_C_R * p.T_R_obj;
      objects.push_back(o);
    }
    // Rendering: planes, parts (a support's top labelled −1 − its index while counted), objects.
    DepthImage depth(W, H, 0.f);
    std::vector<int> labels(std::size_t(W) * H, 0);
    for (const Mesh& m : planes) RenderDepth(m, T_C_R, cam, &depth, &labels, 0);
    for (const Part& part : parts) RenderDepth(*part.mesh, T_C_R * part.T_R, cam, &depth, &labels, part.support >= 0 ? -1 - part.support : 0);
    for (std::size_t i = 0; i < objects.size(); ++i)
      RenderDepth(models[std::size_t(objects[i].model)].mesh, objects[i].T_cam_obj, cam, &depth, &labels, int(i) + 1);
    std::vector<double> view_fraction(supports.size(), 0.0);
    double total_view = 0;
    for (int& l : labels)
      if (l < 0) {
        view_fraction[std::size_t(-1 - l)] += 1.0 / (double(W) * H);
        total_view += 1.0 / (double(W) * H);
        l = 0;
      }
    const bool view_ok = total_view >= opt.min_surface_view && total_view <= opt.max_surface_view;
    if (!view_ok && have) continue;  // a fallback view is kept already: only views in range now
    int targets = 0;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      TableObject& o = objects[i];
      Camera big = cam;
      big.width = W + 2 * kPad;
      big.height = H + 2 * kPad;
      big.cx += kPad;
      big.cy += kPad;
      DepthImage d(big.width, big.height, 0.f);
      std::vector<int> lab(std::size_t(big.width) * big.height, 0);
      RenderDepth(models[std::size_t(o.model)].mesh, o.T_cam_obj, big, &d, &lab, 1);
      std::size_t n = 0;
      int u0 = W, u1 = -1, v0 = H, v1 = -1;
      for (int q = 0; q < big.width * big.height; ++q) {
        if (!lab[std::size_t(q)]) continue;
        ++n;
        const int u = q % big.width - kPad, v = q / big.width - kPad;
        if (u < 0 || v < 0 || u >= W || v >= H) continue;
        u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
      }
      if (u1 >= 0) o.box = Box{0.5 * (u0 + u1), 0.5 * (v0 + v1), double(u1 - u0 + 1), double(v1 - v0 + 1)};
      o.visible_px = int(synth::CountLabel(labels, int(i) + 1));
      o.visible_fraction = n == 0 ? 0.0 : double(o.visible_px) / double(n);
      o.target = o.visible_fraction >= opt.min_visible_fraction && o.visible_px >= opt.min_visible_px;
      targets += o.target;
    }
    if (targets == 0) continue;
    // Keep it: the first view in range, or (none in range yet) the first with a target, to be
    // replaced by a later view in range.
    std::vector<const Mesh*> meshes;
    std::vector<Eigen::Isometry3d> poses;
    for (const Mesh& m : planes) meshes.push_back(&m), poses.push_back(T_C_R);
    for (const Part& part : parts) meshes.push_back(part.mesh.get()), poses.push_back(T_C_R * part.T_R);
    for (const TableObject& o : objects) meshes.push_back(&models[std::size_t(o.model)].mesh), poses.push_back(o.T_cam_obj);
    Rng sensor = rng_sensor;  // the same sensor draws whichever view is kept
    s.depth = synth::ApplySensor(depth, labels, int(objects.size()), meshes, poses, cam, opt.sensor, sensor);
    s.clean_depth = std::move(depth);
    s.labels = std::move(labels);
    s.objects = std::move(objects);
    s.supports.clear();
    for (const Furniture& f : supports) {
      const Eigen::Isometry3d T_C_S = T_C_R * f.tops[0].T_R_S;
      const Vec3 n = T_C_S.linear() * Vec3::UnitZ();
      s.supports.push_back(Eigen::Vector4d(n.x(), n.y(), n.z(), -n.dot(T_C_S.translation())));
    }
    s.support_view_fractions = view_fraction;
    s.table_plane = s.supports[0];
    const Vec3 up = T_C_R.linear() * Vec3::UnitZ();
    s.floor_plane << up, -up.dot(T_C_R.translation());
    s.distance_m = dist;
    s.elevation_deg = elev / kDeg;
    have = true;
    if (view_ok) break;
  }
  if (!have) return std::nullopt;

  // 4. Prior: targets' boxes, false boxes; targets' masks (as the table world).
  const std::vector<std::string>& classes = s.classes;
  for (const TableObject& o : s.objects) {
    if (!o.target) continue;
    const double scale = rng_prior.Uniform(opt.box_scale_min, opt.box_scale_max);
    const double score = rng_prior.Uniform(0.6, 0.99);
    s.detections.push_back(synth::ToDetection(o.cls, score, synth::JitterBox(o.box, opt.box_jitter_px, scale, rng_prior)));
  }
  for (int i = 0; i < opt.false_positives; ++i) {
    const std::string cls = classes[rng_prior.UniformInt(classes.size())];
    const double score = rng_prior.Uniform(0.05, 0.9);
    const bool on_object = i % 2 == 0;
    const TableObject& other = s.objects[rng_prior.UniformInt(s.objects.size())];
    Box b;
    if (on_object && other.cls != cls && other.box.w > 0) {
      b = synth::JitterBox(other.box, opt.box_jitter_px, 1.0, rng_prior);
    } else {
      b.w = rng_prior.Uniform(40.0, 240.0);
      b.h = rng_prior.Uniform(40.0, 240.0);
      b.cx = rng_prior.Uniform(b.w / 2, std::max(b.w / 2, W - b.w / 2));
      b.cy = rng_prior.Uniform(b.h / 2, std::max(b.h / 2, H - b.h / 2));
    }
    s.detections.push_back(synth::ToDetection(cls, score, b));
  }
  s.masks.assign(std::size_t(W) * H, 0);
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    if (!s.objects[i].target) continue;
    const int shift = int(std::lround(rng_mask.Uniform(-opt.mask_boundary_px, opt.mask_boundary_px)));
    const std::vector<std::uint8_t> m = synth::NoisyMask(s.labels, int(i) + 1, W, H, shift, rng_mask);
    for (std::size_t q = 0; q < m.size(); ++q)
      if (m[q] && s.masks[q] == 0) s.masks[q] = std::uint16_t(i + 1);
  }
  return s;
}

}  // namespace

TableScene MakeRoomScene(const TableWorld& world, const RoomSceneOptions& opt, std::uint64_t seed) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("room scene options: " + why);
  if (opt.max_objects > int(world.models().size()))
    throw Error("room scene options: max_objects (" + std::to_string(opt.max_objects) + ") exceeds the world's " +
                std::to_string(world.models().size()) + " classes");
  // The first layout draws its kLayoutStreams streams from Rng(seed); a layout that shows no
  // object well enough is drawn again from the seed's later splits (the 7th, 8th, ...), so
  // every other seed's scene stays as it is.
  Rng later(seed);
  for (int k = 0; k < kLayoutStreams; ++k) later.Split();
  for (int attempt = 0; attempt < kRoomLayoutAttempts; ++attempt) {
    const Rng root = attempt == 0 ? Rng(seed) : later.Split();
    if (std::optional<TableScene> s = TryRoomScene(world, opt, root)) return std::move(*s);
  }
  throw Error("room scene " + std::to_string(seed) + ": no object fits on a support, or no view shows one well enough, in " +
              std::to_string(kRoomLayoutAttempts) + " layouts");
}

}  // namespace posefilter
