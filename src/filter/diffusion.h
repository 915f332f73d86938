// src/filter/diffusion.h — particles and the diffusion step of §7.6 (internal).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "posefilter/camera.h"
#include "posefilter/filter.h"
#include "posefilter/heuristics.h"
#include "posefilter/pose.h"
#include "posefilter/prior.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/support_plane.h"
#include "prior/volume_cache.h"

namespace posefilter::filter {

struct Particle {
  Pose6 pose;           // object → base
  int cell = 0;         // absolute index into the prior's cells
  double weight = 0;    // eq. 7.4 [ALGORITHM.md]
  bool scored = false;  // weight is current (elite particles are carried unchanged)
  // Mean (scene − rendered) depth over the fragments within the align band at the last
  // weighing, metres (0 when none): what kAlignDepth shifts by.
  double depth_offset = 0;
  // The point-to-plane ICP step solved at the last weighing: (ω rad, τ m), camera frame.
  // Only weighings that asked for it solve it (icp_known); the filter asks lazily, for the
  // parents whose children drew the kIcpStep move.
  std::array<double, 6> icp_step{};
  bool icp_valid = false;
  bool icp_known = false;
};

// Solves the (damped) 6×6 ICP normal equations of a kernel result; false when too few
// fragments or a degenerate system. Steps are clamped to 0.3 rad and 5 cm.
bool SolveIcpStep(const ScoreKernelResult& r, std::array<double, 6>* step);

// What diffusion reads: the pyramid layout, the heuristic volume of every cell, the options,
// and the support plane with the point of the object the kOnPlane move turns about.
struct DiffusionContext {
  const Camera& camera;
  const PyramidLayout& layout;
  const prior::VolumeCache& volumes;  // computed on demand: diffusion runs on one thread
  const FilterOptions& opt;
  const SupportPlane* plane;          // null: no support plane (kOnPlane never drawn)
  // The support surfaces (null or none: `plane` for every particle): kOnPlane turns and slides
  // an object on the support just below it, and leaves one over no support unchanged.
  const SupportSurfaces* surfaces;
  Eigen::Vector3d pivot;              // object frame, metres (the model's bounding-box centre)
  std::vector<double> move_cdf;  // cumulative, normalised FilterOptions::diffusion.move_probabilities

  DiffusionContext(const Camera& c, const PyramidLayout& l, const prior::VolumeCache& v, const FilterOptions& o,
                   const SupportPlane* support = nullptr, const Eigen::Vector3d& pivot_obj = Eigen::Vector3d::Zero(),
                   const SupportSurfaces* surfaces = nullptr);
  // The move for a uniform draw u in [0, 1).
  Move PickMove(double u) const;
};

// The cell a kNeighbourCell / kOtherLevel move reaches from `cell`, or −1 when that cell is
// off the grid or has no valid heuristic volume.
int MoveCell(const DiffusionContext& ctx, int cell, Move move, Rng& rng);

// Applies `move` to the particle: Gaussian noise with σ_t = d·σ_t0, σ_r = d·σ_r0 where
// d = max(1 − best_weight, min_sigma_fraction) (linear decay of §7.6); a flip adds π; a cell
// move carries the particle by the difference of the two volumes' centres; align-depth moves
// it along the camera ray through its origin so its depth changes by depth_offset. Angles are
// wrapped to (−π, π]; kOnPlane turns the object about the plane's normal through the pivot
// by σ_r·N(0, 1) and shifts it along two in-plane axes by σ_t·N(0, 1) each, so an object
// resting on the table stays on it. The particle is marked unscored.
void ApplyMove(const DiffusionContext& ctx, Move move, Particle* p, double best_weight, Rng& rng);

}  // namespace posefilter::filter
