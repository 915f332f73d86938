// src/filter/prepared_model.cc — PrepareModel (posefilter/prepared_model.h) and the levels of
// detail it holds (filter/model_lod.h): the LOD mesh, its diameter and face planes, the coarse
// meshes, hull, stable poses and polish box, each computed once.
#include "posefilter/prepared_model.h"

#include <algorithm>
#include <atomic>

#include <Eigen/Eigenvalues>

#include "filter/driver.h"
#include "filter/model_lod.h"
#include "posefilter/error.h"
#include "posefilter/mesh_simplify.h"
#include "posefilter/option_table.h"
#include "posefilter/render.h"
#include "posefilter/stage1.h"

namespace posefilter {
namespace {

std::atomic<std::uint64_t> lods_prepared{0};

// The cpu kernel's pre-cull table of `mesh` (only its arrays are read).
render::FacePlanes FacePlanesOf(const Mesh& mesh) {
  return render::BuildFacePlanes(MakeKernelParams(mesh, Eigen::Isometry3d::Identity(), Camera{}));
}

}  // namespace

namespace filter {

const CoarseMesh* ModelLod::Coarse(int budget) const {
  for (const CoarseMesh& c : coarse)
    if (c.budget == budget) return &c;
  return nullptr;
}

ModelNeeds NeedsOf(const FilterOptions& options, bool runs, bool plane) {
  ModelNeeds n;
  n.lod_max_faces = options.render.lod_max_faces;
  n.hull = plane && options.support.contact > 0 && options.support.plane;
  n.stable = plane && runs && options.support.stable_start > 0 && options.support.plane;
  auto add = [&n](int factor) {
    if (factor > 1 && std::find(n.coarse_factors.begin(), n.coarse_factors.end(), factor) == n.coarse_factors.end())
      n.coarse_factors.push_back(factor);
  };
  // With anneal.simplify every level of factor > 1 weighs a simplified mesh: the fine level
  // (factor 1–4 with adaptive resolution, FineFactor) and, when the run anneals on the coarse
  // grid, the coarse level (the fine factor times anneal.subsample).
  if (options.anneal.simplify) {
    const int max_fine = options.render.adaptive_resolution ? 4 : 1;
    for (int f = 1; f <= max_fine; ++f) add(f);
    if (runs && options.anneal.subsample > 1 && AnnealIterations(options) > 0)
      for (int f = 1; f <= max_fine; ++f) add(f * options.anneal.subsample);
  }
  // render.lod_face_px: the mesh strides 2–4 of MeshFactor, at any pixel level.
  if (options.render.lod_face_px > 0)
    for (int f = 2; f <= 4; ++f) add(f);
  return n;
}

bool Meets(const ModelLod& lod, const ModelNeeds& needs) {
  if (lod.lod_max_faces != needs.lod_max_faces) return false;
  if (needs.hull && !lod.has_hull) return false;
  if (needs.stable && !lod.has_stable) return false;
  for (int f : needs.coarse_factors)
    if (std::find(lod.coarse_factors.begin(), lod.coarse_factors.end(), f) == lod.coarse_factors.end()) return false;
  return true;
}

std::shared_ptr<const ModelLod> BuildModelLod(const Mesh& mesh, const ModelNeeds& needs) {
  auto out = std::make_shared<ModelLod>();
  ModelLod& m = *out;
  m.lod_max_faces = needs.lod_max_faces;
  Mesh storage;
  const Mesh& lod = MeshAtLod(mesh, needs.lod_max_faces, &storage);
  if (&lod == &mesh)
    m.lod = mesh;
  else
    m.lod = std::move(storage);
  m.diameter = m.lod.Diameter();
  m.face_planes = FacePlanesOf(m.lod);
  // Coarse levels (FilterOptions::anneal.simplify): the mesh simplified to faces / factor² faces
  // (at least kCoarseMinFaces); a mesh meshoptimizer cannot bring to the budget is weighed as
  // it is.
  const int faces = int(m.lod.faces.size());
  m.coarse_factors = needs.coarse_factors;
  for (int factor : needs.coarse_factors) {
    const int budget = CoarseMeshFaces(faces, factor);
    if (faces <= budget || m.Coarse(budget)) continue;
    CoarseMesh& c = m.coarse.emplace_back();
    c.budget = budget;
    try {
      c.mesh = SimplifyMesh(m.lod, budget);
      c.simplified = !c.mesh.faces.empty();
    } catch (const Error&) {
    }
  }
  for (CoarseMesh& c : m.coarse)  // after the list stops growing: the tables point at its meshes
    if (c.simplified) c.face_planes = FacePlanesOf(c.mesh);
  if (needs.hull) {
    m.has_hull = true;
    std::vector<Eigen::Vector3d> pts;
    for (const auto& v : m.lod.vertices) pts.push_back(v.cast<double>());
    try {
      m.hull = ComputeConvexHull(pts, "mesh '" + m.lod.name + "'").vertices;
    } catch (const Error& e) {
      m.hull_error = e.what();
    }
  }
  if (needs.stable) {
    m.has_stable = true;
    try {
      m.stable = ComputeStablePoses(m.lod);
    } catch (const Error& e) {
      m.stable_error = e.what();
    }
    if (!m.stable.empty())
      m.com_obj = m.stable[0].T_table_obj.inverse() * Eigen::Vector3d(0, 0, m.stable[0].com_height_m);
  }
  const Eigen::Vector3d lo = m.lod.Min().cast<double>(), hi = m.lod.Max().cast<double>();
  for (int i = 0; i < 8; ++i)
    m.bbox_corners[i] = Eigen::Vector3d(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  m.box_centre = 0.5 * (lo + hi);
  m.box_half = 0.5 * (hi - lo);
  {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& v : m.lod.vertices) mean += v.cast<double>();
    mean /= double(m.lod.vertices.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& v : m.lod.vertices) cov += (v.cast<double>() - mean) * (v.cast<double>() - mean).transpose();
    Eigen::Matrix3d A = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
    if (A.determinant() < 0) A.col(2) = -A.col(2);
    Eigen::Vector3d plo = Eigen::Vector3d::Constant(1e30), phi = Eigen::Vector3d::Constant(-1e30);
    for (const auto& v : m.lod.vertices) {
      const Eigen::Vector3d q = A.transpose() * v.cast<double>();
      plo = plo.cwiseMin(q);
      phi = phi.cwiseMax(q);
    }
    if ((phi - plo).prod() < 0.9 * (hi - lo).prod() && A.allFinite()) {
      m.box_axes = A;
      m.box_centre = A * (0.5 * (plo + phi));
      m.box_half = 0.5 * (phi - plo);
    }
  }
  ++lods_prepared;
  return out;
}

std::shared_ptr<const ModelLod> LodFor(const PreparedModel* model, const Mesh& mesh, const FilterOptions& options,
                                       bool runs, bool plane) {
  const ModelNeeds needs = NeedsOf(options, runs, plane);
  if (model)
    if (std::shared_ptr<const ModelLod> lod = model->Find(needs)) return lod;
  std::string why;
  if (!mesh.IsValid(&why)) throw Error("mesh '" + mesh.name + "': " + why);
  return BuildModelLod(mesh, needs);
}

}  // namespace filter

PreparedModel::PreparedModel(Mesh mesh, std::vector<std::shared_ptr<const filter::ModelLod>> lods,
                             std::shared_ptr<const PpfModel> ppf, PpfOptions ppf_options, std::string ppf_status)
    : mesh_(std::move(mesh)),
      lods_(std::move(lods)),
      ppf_(std::move(ppf)),
      ppf_options_(ppf_options),
      ppf_status_(std::move(ppf_status)) {}

bool PreparedModel::HasPpf(const PpfOptions& options) const {
  // The cache file's name hashes the mesh and the options the table depends on.
  return ppf_ && PpfCachePath(mesh_, ppf_options_, "/") == PpfCachePath(mesh_, options, "/");
}

std::shared_ptr<const filter::ModelLod> PreparedModel::Find(const filter::ModelNeeds& needs) const {
  for (const auto& lod : lods_)
    if (filter::Meets(*lod, needs)) return lod;
  return nullptr;
}

bool PreparedModel::Covers(const FilterOptions& options) const {
  return Find(filter::NeedsOf(options, true)) != nullptr;
}

std::vector<int> PreparedModel::LodBudgets() const {
  std::vector<int> out;
  for (const auto& lod : lods_) out.push_back(lod->lod_max_faces);
  return out;
}

const Mesh* PreparedModel::Lod(int lod_max_faces) const {
  for (const auto& lod : lods_)
    if (lod->lod_max_faces == lod_max_faces) return &lod->lod;
  return nullptr;
}

namespace {

std::vector<std::shared_ptr<const filter::ModelLod>> PrepareLods(const Mesh& mesh, const std::vector<FilterOptions>& options) {
  if (options.empty()) throw Error("PrepareModel: no option set");
  for (const FilterOptions& o : options) ThrowIfInvalid(o, OptionNaming::kField);
  std::string why;
  if (!mesh.IsValid(&why)) throw Error("mesh '" + mesh.name + "': " + why);
  // One level of detail per face budget, with the union of what its option sets read.
  std::vector<filter::ModelNeeds> needs;
  for (const FilterOptions& o : options) {
    const filter::ModelNeeds n = filter::NeedsOf(o, true);
    auto it = std::find_if(needs.begin(), needs.end(),
                           [&](const filter::ModelNeeds& e) { return e.lod_max_faces == n.lod_max_faces; });
    if (it == needs.end()) {
      needs.push_back(n);
      continue;
    }
    it->hull = it->hull || n.hull;
    it->stable = it->stable || n.stable;
    for (int f : n.coarse_factors)
      if (std::find(it->coarse_factors.begin(), it->coarse_factors.end(), f) == it->coarse_factors.end())
        it->coarse_factors.push_back(f);
  }
  std::vector<std::shared_ptr<const filter::ModelLod>> lods;
  for (const filter::ModelNeeds& n : needs) lods.push_back(filter::BuildModelLod(mesh, n));
  return lods;
}

}  // namespace

std::shared_ptr<const PreparedModel> PrepareModel(Mesh mesh, const std::vector<FilterOptions>& options) {
  auto lods = PrepareLods(mesh, options);
  return std::make_shared<const PreparedModel>(std::move(mesh), std::move(lods));
}

std::shared_ptr<const PreparedModel> PrepareModel(Mesh mesh, const std::vector<FilterOptions>& options,
                                                  const PpfPreparation& ppf) {
  auto lods = PrepareLods(mesh, options);
  std::string why;
  if (!ppf.options.IsValid(&why)) throw Error("PrepareModel: invalid PPF option: " + why);
  std::string status;
  auto table = std::make_shared<const PpfModel>(LoadOrBuildPpfModel(mesh, ppf.options, ppf.cache_dir, &status));
  return std::make_shared<const PreparedModel>(std::move(mesh), std::move(lods), std::move(table), ppf.options,
                                               std::move(status));
}

AutoStage1 AutoPriorForModels(const DepthImage& depth, const Camera& camera, const std::vector<const PreparedModel*>& models,
                              const std::vector<std::string>& names, const std::string& what,
                              const AutoPriorOptions& opt) {
  if (names.size() != models.size()) throw Error(what + ": one name per model needed");
  Stage1Options so;
  so.kind = Stage1Kind::kAuto;
  so.what = what;
  so.auto_prior = opt;
  std::vector<Stage1Object> objects;
  for (std::size_t k = 0; k < models.size(); ++k)  // the model's table, else one built for the call
    objects.push_back({names[k], &models[k]->mesh(), models[k]->HasPpf(opt.ppf) ? models[k]->ppf() : nullptr});
  Stage1 s = BuildStage1(SceneInput{depth, camera}, objects, so);
  return {std::move(s.prior), std::move(s.seeds)};
}

std::shared_ptr<const PreparedModel> PrepareModel(Mesh mesh, const FilterOptions& options) {
  return PrepareModel(std::move(mesh), std::vector<FilterOptions>{options});
}

std::uint64_t ModelLodsPrepared() { return lods_prepared.load(); }

}  // namespace posefilter
