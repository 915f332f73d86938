// posefilter/prepared_model.h — a mesh prepared once for the filter, shared by every estimate.
//
// Everything the filter derives from a mesh alone is computed when the model is prepared and
// never changes after (docs/ARCHITECTURE.md, "The filter's state"): per level of detail
// (FilterOptions::render.lod_max_faces) the simplified mesh, its diameter and the cpu kernel's
// face planes, the coarse meshes of the annealing's pixel grids (anneal.simplify), the convex
// hull of the contact prior (support.contact), the stable poses (support.stable_start) and the
// box the polish turns the model in. A PreparedModel is immutable: one instance may serve any
// number of estimates on any number of threads at once, held by std::shared_ptr<const ...>.
//
//   auto model = PrepareModel(mesh, options);               // once per mesh
//   for (const SceneInput& frame : frames)
//     results.push_back(EstimatePose(frame, *model, prior, cls, options));  // posefilter/filter.h
//
// EstimatePose(scene, mesh, ...) prepares the mesh on the fly for the one estimate (the same
// numbers, bit for bit); an estimate whose options need a level of detail or a part the model
// was not prepared for (another lod_max_faces, say) also prepares that on the fly.
//
// A model may also hold the mesh's PPF model (posefilter/ppf.h), the table of `--prior auto`'s
// pose proposals (PrepareModel with a PpfPreparation): AutoPriorForModels then proposes poses
// with it, where BuildStage1 on the mesh alone (posefilter/stage1.h) loads (or builds) it again
// on every call.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "posefilter/auto_prior.h"
#include "posefilter/filter_options.h"
#include "posefilter/mesh.h"
#include "posefilter/ppf.h"
#include "posefilter/prior.h"

namespace posefilter {

namespace filter {
struct ModelLod;    // one level of detail's derived data (src/filter/model_lod.h)
struct ModelNeeds;  // what an estimate reads of one (ditto)
}  // namespace filter

// The PPF part of a preparation: the voting's options (AutoPriorOptions::ppf) and the cache
// folder LoadOrBuildPpfModel reads and writes ("" = no cache; DefaultPpfCacheDir()).
struct PpfPreparation {
  PpfOptions options;
  std::string cache_dir;
};

class PreparedModel {
 public:
  // Use PrepareModel.
  PreparedModel(Mesh mesh, std::vector<std::shared_ptr<const filter::ModelLod>> lods,
                std::shared_ptr<const PpfModel> ppf = nullptr, PpfOptions ppf_options = {}, std::string ppf_status = "");

  // The mesh as given (object frame, metres; its name is the estimates' EstimateResult::obj).
  const Mesh& mesh() const { return mesh_; }
  // Whether an estimate (or WeighPoses) with these options finds everything it needs here.
  bool Covers(const FilterOptions& options) const;
  // The face budgets (render.lod_max_faces) of the levels of detail held, in preparation order.
  std::vector<int> LodBudgets() const;
  // The mesh weighed at face budget `lod_max_faces` (MeshAtLod: `mesh()` itself when it has no
  // more faces, name kept), or nullptr when no level of detail of that budget is held.
  const Mesh* Lod(int lod_max_faces) const;
  // The level of detail that holds everything `needs` asks for, or nullptr. Internal:
  // filter/model_lod.h describes both types.
  std::shared_ptr<const filter::ModelLod> Find(const filter::ModelNeeds& needs) const;

  // The mesh's PPF model, or nullptr when it was prepared without one.
  const PpfModel* ppf() const { return ppf_.get(); }
  // Whether ppf() is the table `options` build (their table options agree: PpfCachePath).
  bool HasPpf(const PpfOptions& options) const;
  // LoadOrBuildPpfModel's status when ppf() was prepared ("loaded", "built", ...); "" without.
  const std::string& ppf_status() const { return ppf_status_; }

 private:
  Mesh mesh_;
  std::vector<std::shared_ptr<const filter::ModelLod>> lods_;
  std::shared_ptr<const PpfModel> ppf_;
  PpfOptions ppf_options_;
  std::string ppf_status_;
};

// Prepares `mesh` for estimates with any of the given option sets (at least one; each valid,
// FilterOptions::IsValid): one level of detail per distinct render.lod_max_faces, each with the
// parts those options read. Throws Error naming the mesh when it is invalid (Mesh::IsValid),
// and Error on invalid options. A convex hull or stable poses that cannot be computed (a flat
// mesh) are not an error here: an estimate that needs them throws that error instead.
std::shared_ptr<const PreparedModel> PrepareModel(Mesh mesh, const std::vector<FilterOptions>& options);
std::shared_ptr<const PreparedModel> PrepareModel(Mesh mesh, const FilterOptions& options = {});
// The same, with the mesh's PPF model (LoadOrBuildPpfModel with ppf.options and ppf.cache_dir).
// Throws Error as above, and on invalid PPF options.
std::shared_ptr<const PreparedModel> PrepareModel(Mesh mesh, const std::vector<FilterOptions>& options,
                                                  const PpfPreparation& ppf);

// The stage 1 of `--prior auto` on prepared models: the prior (PriorFromDetections of
// ProposeAuto's detections on the thesis pyramid, the objects' names, each once, as its
// classes) and per object (in the models' order) its pose seeds.
struct AutoStage1 {
  Prior prior;
  std::vector<std::vector<PoseSeed>> seeds;
};
// BuildStage1 with Stage1Kind::kAuto and `opt` (posefilter/stage1.h) on prepared models, named
// names[k]: each model's PPF model where it holds the one opt.ppf builds (HasPpf), else one
// built for this call (without a cache). The same stage 1, bit for bit, as BuildStage1 on the
// models' meshes; throws Error as it does ("<what>: no candidates: …" when no region stands
// above the support plane, a mesh in the wrong units naming it), and when names and models
// differ in number.
AutoStage1 AutoPriorForModels(const DepthImage& depth, const Camera& camera, const std::vector<const PreparedModel*>& models,
                              const std::vector<std::string>& names, const std::string& what,
                              const AutoPriorOptions& opt = {});

// How many levels of detail this process has prepared so far (PrepareModel, and estimates that
// prepare on the fly), counted once each: how tests check that a mesh is prepared once.
std::uint64_t ModelLodsPrepared();

}  // namespace posefilter
