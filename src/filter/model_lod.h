// src/filter/model_lod.h — what the filter derives from a mesh for one level of detail
// (internal; the public face is posefilter/prepared_model.h). Built once by BuildModelLod,
// unchanged after: every member is read-only for the estimates that share it.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "posefilter/filter_options.h"
#include "posefilter/mesh.h"
#include "posefilter/prepared_model.h"
#include "posefilter/stable_poses.h"
#include "render/face_planes.h"

namespace posefilter::filter {

// A mesh simplified for the coarse pixel grid of one face budget (anneal.simplify).
struct CoarseMesh {
  int budget = 0;       // faces asked for: CoarseMeshFaces(level-of-detail faces, factor)
  bool simplified = false;  // false: meshoptimizer could not reach the budget; weigh `lod` as it is
  Mesh mesh{};                        // the simplified mesh (empty when !simplified)
  render::FacePlanes face_planes{};   // of `mesh` (the cpu kernel's pre-cull)
};

struct ModelLod {
  int lod_max_faces = 0;  // the FilterOptions::render.lod_max_faces it was made for (0: full mesh)
  Mesh lod{};             // MeshAtLod(mesh, lod_max_faces): the mesh the filter weighs (name kept)
  double diameter = 0;    // lod's diameter, metres (cell windows, volumes' depth extension)
  render::FacePlanes face_planes{};  // of `lod`
  // The simplified meshes of the pixel levels of factor > 1 (anneal.simplify): one per distinct
  // budget of the fine level's factors 2–4 (adaptive resolution) and of the coarse level's
  // (those times anneal.subsample, when a run anneals); empty when no option set simplifies, and
  // no entry for a budget the level-of-detail mesh already meets.
  std::vector<CoarseMesh> coarse{};
  std::vector<int> coarse_factors{};  // the pixel-grid factors the coarse list was made for
  // The convex hull's vertices (object frame, metres; the contact prior), when prepared
  // (has_hull); hull_error: ComputeConvexHull's message when it could not be computed.
  bool has_hull = false;
  std::vector<Eigen::Vector3d> hull{};
  std::string hull_error{};
  // The stable poses (support.stable_start, polish.stable), most probable first, and the
  // centre of mass (object frame) when prepared (has_stable); stable_error as hull_error.
  bool has_stable = false;
  std::vector<StablePose> stable{};
  std::string stable_error{};
  Eigen::Vector3d com_obj = Eigen::Vector3d::Zero();
  // The axis-aligned bounding box's corners (object frame, metres; bit i of the index picks
  // max over min along axis i).
  std::array<Eigen::Vector3d, 8> bbox_corners{};
  // The box the polish turns the model in (object frame): its axes (columns, right-handed),
  // centre and half extents along them. The axis-aligned bounding box, or the box along the
  // vertices' principal axes when that one is at least 10 % smaller (an elongated model
  // drawn at an angle to its own axes, as the YCB scissors).
  Eigen::Matrix3d box_axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d box_centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_half = Eigen::Vector3d::Zero();

  // The coarse mesh prepared for this budget, or nullptr (not prepared).
  const CoarseMesh* Coarse(int budget) const;
};

// What an option set reads of a level of detail; parts are unioned over the option sets a
// model is prepared for.
struct ModelNeeds {
  int lod_max_faces = 0;
  bool hull = false;                // support.contact > 0 with support.plane
  bool stable = false;              // support.stable_start > 0 with support.plane (runs only)
  std::vector<int> coarse_factors;  // the pixel-level factors > 1 that weigh a simplified mesh (CoarseMesh)
};
// What an estimate with `options` reads (`runs`: it runs the filter; WeighPoses and the
// polish of given poses do not; `plane`: its scene has a support plane — false leaves out the
// hull and the stable poses, which only a plane makes the filter read).
ModelNeeds NeedsOf(const FilterOptions& options, bool runs, bool plane = true);
// Whether `lod` holds everything `needs` asks for.
bool Meets(const ModelLod& lod, const ModelNeeds& needs);
// Builds a level of detail of a valid mesh; counts it (ModelLodsPrepared).
std::shared_ptr<const ModelLod> BuildModelLod(const Mesh& mesh, const ModelNeeds& needs);
// The level of detail an estimate uses: the model's when it has one for these options (and a
// scene with or without a support plane), else one built on the fly for it (counted). Throws
// Error naming the mesh when it is invalid.
std::shared_ptr<const ModelLod> LodFor(const PreparedModel* model, const Mesh& mesh, const FilterOptions& options,
                                       bool runs, bool plane);

}  // namespace posefilter::filter
