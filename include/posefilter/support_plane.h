// posefilter/support_plane.h — the dominant plane of a depth image (the table the objects
// stand on) and which pixels lie on it.
//
// Objects on a table are seen against the table: a pose laid into the table plane, or sunk
// below it, explains the table's depth as well as a thin object explains its own few
// centimetres of relief. The filter therefore takes the table's pixels out of the scene it
// scores against (FilterOptions::support.plane; docs/ALGORITHM.md, "Support plane"): they
// are never inliers, never hide an object, and do not count in N_depth.
//
// Method: RANSAC over a regular grid of the valid depth pixels (back-projected to the camera
// frame), a least-squares refit on the inliers, then each pixel is "on the plane" when its
// point lies within a depth-dependent band of it. The band follows the sensor: residuals of
// structured-light depth grow with z², so it is k·σ₁·z² with σ₁ (metres at 1 m) measured
// from the plane's own residuals (median absolute deviation), clamped to
// [min_band_m, max_band_m]. Deterministic: the RANSAC draws come from a fixed seed.
//
// Frames and units: camera frame (OpenCV), metres; the plane is n·x + d = 0 with n a unit
// normal pointing towards the camera side (d > 0 for a plane in front of the camera).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/depth_image.h"

namespace posefilter {

struct SupportPlaneOptions {
  int samples = 4000;                // valid pixels the fit uses (regular grid), ≥ 50
  int iterations = 200;              // RANSAC hypotheses, ≥ 1
  double ransac_band_m = 0.01;       // RANSAC inlier distance at 1 m (× z²), metres, > 0
  // A plane is accepted only when at least this fraction of the sampled pixels lie on it: a
  // box face or a wall patch is not the support. (0, 1].
  double min_fraction = 0.15;
  double band_sigmas = 3.0;          // k: the pixel band is k·σ₁·z², > 0
  double min_band_m = 0.003;         // band clamp, metres, 0 < min ≤ max
  double max_band_m = 0.012;
  bool IsValid(std::string* why) const;
};

struct SupportPlane {
  bool found = false;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, towards the camera (camera frame)
  double offset = 0;            // n·x + offset = 0, metres
  double fraction = 0;          // fraction of the sampled pixels on the plane
  double sigma_1m = 0;          // residual σ₁ at 1 m (robust), metres
  // Signed height of a camera-frame point above the plane (towards the camera), metres.
  double Height(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  // The band half-width at depth z (metres): clamp(k·σ₁·z², min, max).
  double Band(double z, const SupportPlaneOptions& opt) const;
};

// The dominant plane of `depth`; found = false when no plane holds min_fraction of the valid
// pixels (or there are fewer than 50 of them). Throws Error on invalid options or a depth
// image whose size differs from the camera's.
SupportPlane FindSupportPlane(const DepthImage& depth, const Camera& camera, const SupportPlaneOptions& opt = {});

// Per pixel (row-major, width × height): 1 where the depth is valid and lies within the
// plane's band, 0 elsewhere (all 0 when !plane.found).
std::vector<std::uint8_t> SupportPlanePixels(const DepthImage& depth, const Camera& camera, const SupportPlane& plane,
                                             const SupportPlaneOptions& opt = {});

// ---- Support surfaces, plural --------------------------------------------------------------
//
// In a room the objects rest on a small raised surface (a chair's writing tablet, a shelf's
// board) while the dominant plane is the floor or a wall. FindSupportSurfaces finds every
// planar patch large enough to hold an object and says which are supports:
//   1. Planes are peeled off one after another (at most max_planes): RANSAC over the valid
//      pixels' regular grid (as FindSupportPlane) whose second and third points are drawn
//      within `neighbourhood` grid steps of the first, so that a plane of a few percent of
//      the image is hypothesised as often as a large one; the inliers of the best (band
//      ransac_band_m·z²) are refitted twice and leave the pool. A plane holding fewer than
//      min_fraction of the samples ends the peeling.
//   2. Each plane's inliers are split into pieces: 8-connected on the sample grid (a gap of
//      one sample bridged). Pieces whose outlines (convex hulls on the plane) lie within
//      merge_gap_m of each other are one patch (a tablet cut apart in the image by the
//      objects standing on it); its outline is their hull. A patch's area (m²) sums its
//      samples' footprints on the plane; a patch under min_area_m2 is dropped.
//   3. Up: among the patches whose normal does not point down the image (normal·y < 0.1 in
//      the camera frame: a camera looking down sees floors and tables face up, walls face
//      it), the direction whose parallel patches (within max_tilt_deg) have the largest
//      total area; a patch within max_tilt_deg of up is a support, another patch of at least
//      large_area_m2 is structure (a wall, a cupboard's side): neither is an object. A
//      horizontal patch less than min_rise_m above another one it lies over is the top of an
//      object standing there (a box lying flat), not a support: it is dropped.
//   4. Up is made square to the largest structure-sized patch within max_tilt_deg of vertical
//      when that patch is at least as large as the area that gave up (walls stand upright).
//      Supports are level: each takes up as its normal and the height most of its samples
//      share as its offset (a small patch's fit tilts by degrees under correlated noise).
//   Before a plane's samples leave the pool it is refitted twice on those within its pixel
//   band (Band below), so that the tops of thin objects on a small surface neither tilt it
//   nor widen its band, and a surface a few centimetres from another is peeled on its own;
//   the RANSAC band's samples next to those (on the sample grid) leave with them, the
//   surface's own noise, so that they do not make a plane grazing it.
// Frames and units: camera frame, metres; each patch's plane as SupportPlane (normal towards
// the camera). Deterministic (fixed RANSAC seed).
struct SupportSurfaceOptions {
  SupportPlaneOptions plane;       // RANSAC samples, iterations and bands of each plane (min_fraction unused)
  int max_planes = 8;              // planes peeled off, ≥ 1
  double min_fraction = 0.01;      // a plane holds at least this fraction of the samples, (0, 1]
  int neighbourhood = 10;          // a hypothesis' points within this many grid steps, ≥ 1
  double min_area_m2 = 0.015;      // a patch's area to hold an object, m², > 0
  double max_tilt_deg = 12;        // a support's normal within this of up, degrees, (0, 90)
  double large_area_m2 = 0.12;     // a non-support patch this large is structure, m², > 0
  double margin_m = 0.05;          // a point is over a patch when its foot lies within this of its outline, m, ≥ 0
  double min_rise_m = 0.15;        // a support stands at least this high above one below it, m, ≥ 0
  double merge_gap_m = 0.15;       // a plane's patches whose outlines lie this close are one, m, ≥ 0
  bool IsValid(std::string* why) const;
};

struct SupportSurface {
  SupportPlane plane;              // the patch's plane (normal towards the camera) and band
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // plane coordinates: origin + a·e1 + b·e2
  Eigen::Vector3d e1 = Eigen::Vector3d::Zero(), e2 = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector2d> outline;  // convex hull of the patch's samples, (a, b), counter-clockwise
  double area_m2 = 0;              // seen area of the patch
  bool support = false;            // parallel to up: objects can rest on it
  // True when the foot of p (its projection along the normal) lies within margin_m of the outline.
  bool Over(const Eigen::Vector3d& p, double margin_m) const;
  // The band half-width at depth z (metres): SupportPlane::Band with its upper clamp grown by
  // z² beyond 1 m (a far floor's noise outgrows max_band_m).
  double Band(double z, const SupportSurfaceOptions& opt) const;
};

struct SupportSurfaces {
  std::vector<SupportSurface> patches;  // supports first, then structure; each group largest first
  int supports = 0;                     // patches[0, supports) are supports
  Eigen::Vector3d up = Eigen::Vector3d::Zero();  // camera frame; zero when there is no support
  // The support just below p (camera frame): of the supports p lies over (margin_m), the one
  // of least height above which p stands (height ≥ −its band at p's depth); −1 when none.
  // Supports more than max_height_m below p are not looked at (metres).
  int Below(const Eigen::Vector3d& p, const SupportSurfaceOptions& opt, double max_height_m = 1e30) const;
};

// Throws Error on invalid options or a depth image whose size differs from the camera's.
SupportSurfaces FindSupportSurfaces(const DepthImage& depth, const Camera& camera, const SupportSurfaceOptions& opt = {});

// Distance (metres, or the plane's units) between two convex polygons given counter-clockwise:
// the least distance from a vertex of one to an edge of the other, 0 when one holds a vertex
// of the other; 1e30 when either is empty.
double HullDistance(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);

// Per pixel (row-major): index + 1 of the patch the pixel's point lies on (within its band and
// over it by margin_m; the first such patch), 0 for none or missing depth.
std::vector<int> SupportSurfacePixels(const DepthImage& depth, const Camera& camera, const SupportSurfaces& surfaces,
                                      const SupportSurfaceOptions& opt = {});

}  // namespace posefilter
