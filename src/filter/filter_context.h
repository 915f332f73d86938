// src/filter/filter_context.h — the float engines' per-estimate state (internal): the pixel
// levels and the Context one run of the filter, the weighing of given poses and the final
// polish share, with the steps that build it and weigh particles in it
// (src/filter/particle_filter.cc). The polish (src/filter/polish.cc) and the driver
// (src/filter/driver.cc) use them too.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "filter/diffusion.h"
#include "filter/driver.h"
#include "filter/scene_prep.h"
#include "posefilter/filter.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"
#include "posefilter/stable_poses.h"
#include "posefilter/support_plane.h"
#include "prior/volume_cache.h"
#include "render/cpu_kernel.h"
#include "render/gpu_kernel.h"
#include "render/scene_normals.h"

namespace posefilter::filter {

// One pixel level: the scoring scene on every factor-th pixel of every factor-th row (pixel
// (i, j) is the full image's (factor·i, factor·j); fx, fy, cx, cy divided by factor), its
// N_depth table (of the support depth), its scene normals (computed tile by tile where ICP
// weighings render), and the mesh weighed there (empty: the context's mesh) with its face
// planes for the cpu kernel's back-face pre-cull (render/face_planes.h; empty for the
// reference engine), and for the gpu engine the level's model and scene on the device (made by
// the first weighing on the level).
struct Level {
  int factor = 1;
  SceneInput scene{};
  render::ValidDepthSat valid_depth{};
  mutable render::SceneNormalTiles normals{};
  Mesh mesh{};
  render::FacePlanes face_planes{};
  mutable std::shared_ptr<render::GpuKernel> gpu{};
};

// Everything one run needs that does not change between iterations.
struct Context {
  const SceneInput& scene;
  const Mesh& mesh;
  const Prior& prior;
  int cls;
  const FilterOptions& opt;
  prior::VolumeCache volumes{};      // heuristic volume per cell (base frame), computed on demand
  // Window per cell, computed on demand by PrepareCell (from the serial steps only).
  mutable std::vector<PixelRect> windows{};
  InlierParams inlier{};             // this iteration's inlier thresholds (annealed)
  std::vector<int> hypothesis{};     // niching: cells sharing one decoded box share an id
  int hypothesis_count = 0;
  std::array<Eigen::Vector3d, 8> bbox_corners{};  // the model's bounding box, object frame, m
  // The box the polish turns the model in (object frame): its axes (columns, right-handed),
  // centre and half extents along them. The axis-aligned bounding box, or the box along the
  // vertices' principal axes when that one is at least 10 % smaller (an elongated model
  // drawn at an angle to its own axes, as the YCB scissors).
  Eigen::Matrix3d box_axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d box_centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_half = Eigen::Vector3d::Zero();
  Engine engine = Engine::kCpu;                                 // FilterOptions::engine, parsed
  render::CpuTarget cpu_target = render::CpuTarget::kPortable;  // FilterOptions::cpu_isa, resolved
  // One scratch memory per worker thread (cpu kernel; holds the reference's too), kept from
  // one weighing round to the next so that its buffers are allocated and touched once.
  mutable std::vector<render::CpuWorkspace> workspaces{};
  // The pixel levels particles are weighed on (docs/ALGORITHM.md, "Pixel levels"): the fine
  // level (every fine.factor-th pixel of every fine.factor-th row; 1 = every pixel, more for
  // objects larger than max_window_px pixels, FilterOptions::render.adaptive_resolution) for the
  // answer's weighings, and the coarse level (factor fine.factor · anneal_subsample) for the
  // annealing iterations; `coarse` selects the level of the moment. Windows are full-image
  // pixel rectangles, mapped to the level's grid when weighed.
  Level fine{};
  Level coarse_level{};
  bool coarse = false;
  double diameter = 0;  // the mesh's, metres (cell windows)
  // Contact prior (FilterOptions::support.contact): the support plane (camera frame) and the mesh's
  // convex-hull vertices (object frame, metres); empty when the prior is off or no plane.
  SupportPlane plane{};
  // Every support surface: the contact prior, stable starts, the on-plane move and the stable
  // re-search use the one just below the object (PlaneBelow), and are off where there is none.
  SupportSurfaces surfaces{};
  std::vector<Eigen::Vector3d> hull{};
  // The mesh's stable poses (FilterOptions::support.stable_start); empty without a support plane. A
  // stable start stands on the point of the plane below the centre of its cell's visible
  // surface: surface_volumes are the heuristic volumes without the depth extension.
  std::vector<StablePose> stable{};
  prior::VolumeCache surface_volumes{};
  Eigen::Vector3d com_obj = Eigen::Vector3d::Zero();  // the mesh's centre of mass, object frame
  mutable std::vector<std::uint8_t> window_ready{};  // per cell: windows[c] is set
  // The scene's pose seeds the filter starts particles at (FilterOptions::seed_start): pose
  // (object → base) and prior cell; seed_cdf holds their cumulative scores. Empty: no seeds.
  std::vector<std::pair<Pose6, int>> seeds{};
  std::vector<double> seed_cdf{};
};

// The plane of the support surface just below p (camera frame; SupportSurfaces::Below with the
// default SupportSurfaceOptions that PrepareScene finds them with), or nullptr: no support
// plane, or none under p.
inline const SupportPlane* PlaneBelow(const Context& ctx, const Eigen::Vector3d& p) {
  static const SupportSurfaceOptions kDefaults{};
  if (!ctx.plane.found) return nullptr;
  const int k = ctx.surfaces.Below(p, kDefaults);
  return k < 0 ? nullptr : &ctx.surfaces.patches[std::size_t(k)].plane;
}

// Checks the mesh, class and prior (the options were checked by the caller, ThrowIfInvalid) and
// precomputes volumes, windows and N_depth for every cell.
// `runs`: the context will run the filter (EstimatePose), so it also gets the coarse level
// of the annealing iterations; weighing given poses and the polish need only every pixel.
// `prep` (PrepareScene's, already validated) must outlive the context: the context scores
// against prep.scoring and reads volumes and N_depth from prep.support.
Context BuildContext(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                     const FilterOptions& options, bool runs);

// Weighs every particle not yet scored (threads over particles; each owns a workspace);
// `icp`: also solve each one's ICP step (the kIcpStep move's input).
void WeighAll(const Context& ctx, std::vector<Particle>& ps, FilterStats* stats, bool icp = false);

}  // namespace posefilter::filter
