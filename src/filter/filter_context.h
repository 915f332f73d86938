// src/filter/filter_context.h — the float engines' state, split by lifetime (internal;
// docs/ARCHITECTURE.md, "The filter's state"):
//   - the model (ModelLod, model_lod.h): what a mesh alone gives, prepared once and shared;
//   - the scene (PreparedScene, scene_prep.h): what a frame alone gives, made once per estimate;
//   - the Context: what one estimate derives from both with the prior and the options — the
//     pixel levels, the volumes, the hypothesis labels, the seeds. Built by BuildContext and
//     read-only after (its volume caches fill in behind their own lock);
//   - the RunState: what changes from one iteration to the next (the annealed thresholds, the
//     pixel level of the moment), owned by the run;
//   - the Scratch: what weighings write as they go (the engine's weigher with its per-worker
//     workspaces or device kernels, scene normals, cell windows), owned by the engine that runs
//     the estimate and used by one estimate's serial steps at a time.
// particle_filter.cc builds them and weighs particles in them; the polish (polish.cc) and the
// driver (driver.cc) use them too.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "filter/diffusion.h"
#include "filter/driver.h"
#include "filter/engine_weigh.h"
#include "filter/model_lod.h"
#include "filter/scene_prep.h"
#include "posefilter/filter.h"
#include "posefilter/mesh.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"
#include "posefilter/stable_poses.h"
#include "posefilter/support_plane.h"
#include "prior/volume_cache.h"
#include "render/cpu_kernel.h"
#include "render/scene_normals.h"

namespace posefilter::filter {

struct EngineRow;  // engine_registry.h

// One pixel level: the scoring scene on every factor-th pixel of every factor-th row (pixel
// (i, j) is the full image's (factor·i, factor·j); fx, fy, cx, cy divided by factor), its
// N_depth table (of the support depth), and the mesh weighed there with its face planes for the
// cpu kernel's back-face pre-cull (render/face_planes.h): the model's level-of-detail mesh, or
// on the coarse level its simplified mesh; both point into the context's ModelLod.
struct Level {
  int factor = 1;
  SceneInput scene{};
  render::ValidDepthSat valid_depth{};
  const Mesh* mesh = nullptr;
  const render::FacePlanes* face_planes = nullptr;
};

// Which of the context's levels a weighing uses (index into Context::levels and the scratch's
// per-level members).
enum LevelIndex { kFineLevel = 0, kCoarseLevel = 1 };

// Everything one estimate needs that does not change between iterations: read-only once built.
struct Context {
  std::shared_ptr<const PreparedScene> prep;  // the scene scored against (prep->scoring)
  std::shared_ptr<const ModelLod> model;      // the mesh's level of detail and what it gives
  const Prior* prior = nullptr;  // the caller's prior: borrowed for the estimate, never null once built
  int cls = 0;
  FilterOptions opt{};
  prior::VolumeCache volumes{};  // heuristic volume per cell (base frame), computed on demand
  std::vector<int> hypothesis{};     // niching: cells sharing one decoded box share an id
  int hypothesis_count = 0;
  const EngineRow* engine = nullptr;  // FilterOptions::engine's row (engine_registry.h); never null once built
  render::CpuTarget cpu_target = render::CpuTarget::kPortable;  // FilterOptions::cpu_isa, resolved
  // The pixel levels particles are weighed on (docs/ALGORITHM.md, "Pixel levels"): the fine
  // level (every fine.factor-th pixel of every fine.factor-th row; 1 = every pixel, more for
  // objects larger than max_window_px pixels, FilterOptions::render.adaptive_resolution) for the
  // answer's weighings, and the coarse level (factor fine.factor · anneal_subsample; factor 0:
  // none) for the annealing iterations; RunState::level selects the level of the moment.
  // Windows are full-image pixel rectangles, mapped to the level's grid when weighed.
  std::array<Level, 2> levels{};
  // Contact prior (FilterOptions::support.contact): the model's convex-hull vertices (object
  // frame, metres); empty when the prior is off or there is no support plane.
  std::span<const Eigen::Vector3d> hull{};
  // The mesh's stable poses (FilterOptions::support.stable_start); empty without a support
  // plane or when the context does not run the filter. A stable start stands on the point of
  // the plane below the centre of its cell's visible surface: surface_volumes are the
  // heuristic volumes without the depth extension.
  std::span<const StablePose> stable{};
  prior::VolumeCache surface_volumes{};
  // The scene's pose seeds the filter starts particles at (FilterOptions::seed_start): pose
  // (object → base) and prior cell; seed_cdf holds their cumulative scores. Empty: no seeds.
  std::vector<std::pair<Pose6, int>> seeds{};
  std::vector<double> seed_cdf{};

  const SceneInput& scene() const { return prep->scoring; }
  const Level& fine() const { return levels[kFineLevel]; }
  bool has_coarse() const { return levels[kCoarseLevel].factor > 1; }
  // The support plane (camera frame; found = false: none, or support.plane off) and every
  // support surface (empty without a plane): the contact prior, stable starts, the on-plane
  // move and the stable re-search use the one just below the object (PlaneBelow).
  const SupportPlane& plane() const { return prep->plane; }
  const SupportSurfaces& surfaces() const;
};

// What one run changes from iteration to iteration: the inlier thresholds (annealed) and the
// pixel level weighings use.
struct RunState {
  InlierParams inlier{};
  LevelIndex level = kFineLevel;
};
// The final thresholds on the fine level: weighings of given poses and the polish.
RunState FinalRunState(const Context& ctx);

// What weighings write as they go, owned by the engine running the estimate: the engine's
// weigher (engine_weigh.h: its per-worker workspaces, kept from one weighing round to the next
// so that their buffers are allocated and touched once, or its device state per level); per
// level the scene normals (computed tile by tile where ICP weighings render); and the window of
// each cell, computed on demand by the serial steps (window_ready[c]: windows[c] is set).
// Used by one estimate's serial steps at a time.
struct Scratch {
  std::unique_ptr<ParticleWeigher> weigher{};
  std::array<render::SceneNormalTiles, 2> normals{};
  std::vector<PixelRect> windows{};
  std::vector<std::uint8_t> window_ready{};
};
// The scratch of an estimate in `ctx`: the weigher of ctx.engine's row, windows unset, normals
// sized to each level.
Scratch MakeScratch(const Context& ctx);

// The plane of the support surface just below p (camera frame; SupportSurfaces::Below with the
// default SupportSurfaceOptions that PrepareScene finds them with), or nullptr: no support
// plane, or none under p.
inline const SupportPlane* PlaneBelow(const Context& ctx, const Eigen::Vector3d& p) {
  static const SupportSurfaceOptions kDefaults{};
  if (!ctx.plane().found) return nullptr;
  const int k = ctx.surfaces().Below(p, kDefaults);
  return k < 0 ? nullptr : &ctx.surfaces().patches[std::size_t(k)].plane;
}

// Checks the class and prior (the options were checked by the caller, ThrowIfInvalid; the mesh
// when its level of detail was prepared) and sets up volumes, levels and hypotheses for every
// cell. `runs`: the context will run the filter (EstimatePose), so it also gets the coarse
// level of the annealing iterations, the stable poses and the seeds; weighing given poses and
// the polish need only every pixel. `model` must hold what NeedsOf(options, runs) asks for
// (LodFor). The context shares `prep` and `model`; `prior` must outlive it. `poses` (weighing
// given poses; may be null): render.lod_face_px's mesh stride comes from the nearest of them
// (its box centre's depth), not from the most probable cell, so that one pose weighs with one
// mesh in any frame and mask.
Context BuildContext(std::shared_ptr<const PreparedScene> prep, std::shared_ptr<const ModelLod> model,
                     const Prior& prior, int cls, const FilterOptions& options, bool runs,
                     const std::vector<Pose6>* poses = nullptr);

// Weighs every particle not yet scored in `run`'s state, as one batch of the scratch's weigher;
// `icp`: also solve each one's ICP step (the kIcpStep move's input).
void WeighAll(const Context& ctx, const RunState& run, Scratch& scratch, std::vector<Particle>& ps, FilterStats* stats,
              bool icp = false);

}  // namespace posefilter::filter
