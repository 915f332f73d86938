// eval/bop_metrics.cc — VSD, MSSD, MSPD, their BOP 2019 recalls and AR, YCB-Video AUC
// (bop_metrics.h has the formulas).
#include "posefilter/bop_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "core/option_check.h"
#include "posefilter/error.h"
#include "posefilter/metrics.h"
#include "posefilter/render.h"

namespace posefilter {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void CheckPoints(const std::vector<Eigen::Vector3f>& pts, const std::vector<Eigen::Isometry3d>& syms,
                 const char* what) {
  if (pts.empty()) throw Error(std::string(what) + ": empty point set");
  if (syms.empty()) throw Error(std::string(what) + ": no symmetry transformations (the identity is needed)");
}

bool ValidList(const std::vector<double>& v, double hi) {
  if (v.empty()) return false;
  for (double x : v)
    if (!std::isfinite(x) || x <= 0 || x > hi) return false;
  return true;
}

// errors[e][g]: error of estimate e (score order) w.r.t. gt instance g.
using ErrorMatrix = std::vector<std::vector<double>>;

// BOP matching at one threshold: estimates in order, each takes the unmatched gt with the
// smallest error < th. Returns the number of matched gt instances.
int CountMatches(const ErrorMatrix& err, std::size_t n_gt, double th) {
  std::vector<bool> taken(n_gt, false);
  int matched = 0;
  for (const auto& row : err) {
    int best = -1;
    for (std::size_t g = 0; g < n_gt; ++g)
      if (!taken[g] && row[g] < th && (best < 0 || row[g] < row[best])) best = static_cast<int>(g);
    if (best >= 0) {
      taken[best] = true;
      ++matched;
    }
  }
  return matched;
}

// Assignment without threshold: each estimate in order takes the unmatched gt with the smallest
// error. Returns per gt the index of its estimate (−1 = none).
std::vector<int> Assign(const ErrorMatrix& err, std::size_t n_gt) {
  std::vector<int> est_of(n_gt, -1);
  for (std::size_t e = 0; e < err.size(); ++e) {
    int best = -1;
    for (std::size_t g = 0; g < n_gt; ++g)
      if (est_of[g] < 0 && (best < 0 || err[e][g] < err[e][best])) best = static_cast<int>(g);
    if (best >= 0) est_of[best] = static_cast<int>(e);
  }
  return est_of;
}

// Sums of matched counts per (metric, threshold) for a group of instances.
struct Tally {
  int n = 0, n_estimated = 0;
  double add_hits = 0, adds_hits = 0;
  double vsd_hits = 0, mssd_hits = 0, mspd_hits = 0;  // summed over thresholds (and τ)
  std::vector<double> add_err, adds_err;              // per instance, for the AUC
};

}  // namespace

std::vector<double> Multiples(double start, int count) {
  std::vector<double> v;
  for (int k = 1; k <= count; ++k) v.push_back(start * k);
  return v;
}

bool BopEvalOptions::IsValid(std::string* why) const {
  if (!std::isfinite(vsd_delta_m) || vsd_delta_m < 0) return Fail(why, "vsd_delta_m must be finite and ≥ 0 (metres)");
  if (!ValidList(vsd_taus, 1e9)) return Fail(why, "vsd_taus must be a non-empty list of finite values > 0");
  if (!ValidList(vsd_thresholds, 1)) return Fail(why, "vsd_thresholds must be a non-empty list of values in (0, 1]");
  if (!ValidList(mssd_thresholds, 1e9))
    return Fail(why, "mssd_thresholds must be a non-empty list of finite values > 0");
  if (!ValidList(mspd_thresholds_px, 1e9))
    return Fail(why, "mspd_thresholds_px must be a non-empty list of finite values > 0");
  if (!std::isfinite(add_threshold) || add_threshold <= 0) return Fail(why, "add_threshold must be finite and > 0");
  if (!std::isfinite(auc_max_m) || auc_max_m <= 0) return Fail(why, "auc_max_m must be finite and > 0 (metres)");
  if (!std::isfinite(max_sym_disc_step) || max_sym_disc_step <= 0)
    return Fail(why, "max_sym_disc_step must be finite and > 0");
  if (max_points < 1) return Fail(why, "max_points must be ≥ 1");
  return true;
}

std::vector<Eigen::Isometry3d> SymmetryTransformations(const DatasetModel& model, double max_sym_disc_step) {
  if (!std::isfinite(max_sym_disc_step) || max_sym_disc_step <= 0)
    throw Error("SymmetryTransformations: max_sym_disc_step must be finite and > 0");
  std::vector<Eigen::Isometry3d> disc = {Eigen::Isometry3d::Identity()};
  disc.insert(disc.end(), model.symmetries_discrete.begin(), model.symmetries_discrete.end());
  if (model.symmetries_continuous.empty()) return disc;
  // Rotations about each continuous axis through its offset o: x ↦ R(x − o) + o.
  const int n = static_cast<int>(std::ceil(std::numbers::pi / max_sym_disc_step));
  std::vector<Eigen::Isometry3d> cont;
  for (const auto& c : model.symmetries_continuous) {
    for (int k = 0; k < n; ++k) {
      if (k == 0 && !cont.empty()) continue;  // the identity once
      Eigen::Isometry3d C = Eigen::Isometry3d::Identity();
      C.linear() = Eigen::AngleAxisd(2 * std::numbers::pi * k / n, c.axis.normalized()).toRotationMatrix();
      C.translation() = c.offset - C.linear() * c.offset;
      cont.push_back(C);
    }
  }
  std::vector<Eigen::Isometry3d> out;
  for (const auto& D : disc)
    for (const auto& C : cont) out.push_back(C * D);
  return out;
}

double MssdError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                 const Eigen::Isometry3d& T_gt, const std::vector<Eigen::Isometry3d>& syms) {
  CheckPoints(pts, syms, "MSSD");
  std::vector<Eigen::Vector3d> est(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) est[i] = T_est * pts[i].cast<double>();
  double best = kInf;
  for (const auto& S : syms) {
    const Eigen::Isometry3d G = T_gt * S;
    double worst2 = 0;
    for (std::size_t i = 0; i < pts.size() && worst2 < best * best; ++i)
      worst2 = std::max(worst2, (est[i] - G * pts[i].cast<double>()).squaredNorm());
    best = std::min(best, std::sqrt(worst2));
  }
  return best;
}

double MspdError(const std::vector<Eigen::Vector3f>& pts, const Eigen::Isometry3d& T_est,
                 const Eigen::Isometry3d& T_gt, const std::vector<Eigen::Isometry3d>& syms, const Camera& camera) {
  CheckPoints(pts, syms, "MSPD");
  std::vector<Eigen::Vector2d> est(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) est[i] = camera.Project(T_est * pts[i].cast<double>());
  double best = kInf;
  for (const auto& S : syms) {
    const Eigen::Isometry3d G = T_gt * S;
    double worst2 = 0;
    for (std::size_t i = 0; i < pts.size() && worst2 < best * best; ++i)
      worst2 = std::max(worst2, (est[i] - camera.Project(G * pts[i].cast<double>())).squaredNorm());
    best = std::min(best, std::sqrt(worst2));
  }
  return std::isfinite(best) ? best : kInf;
}

DepthImage DepthToDistance(const DepthImage& depth, const Camera& camera) {
  DepthImage out(depth.width, depth.height, 0.f);
  for (int v = 0; v < depth.height; ++v) {
    const double y = (v - camera.cy) / camera.fy;
    for (int u = 0; u < depth.width; ++u) {
      const float z = depth.at(u, v);
      if (z <= 0) continue;
      const double x = (u - camera.cx) / camera.fx;
      out.at(u, v) = static_cast<float>(z * std::sqrt(x * x + y * y + 1));
    }
  }
  return out;
}

namespace {

// VSD from the three distance images (metres).
std::vector<double> VsdFromDistances(const DepthImage& dist_test, const DepthImage& dist_est,
                                     const DepthImage& dist_gt, double delta_m, const std::vector<double>& taus,
                                     double diameter_m) {
  const std::size_t n = dist_test.data.size();
  long n_union = 0, n_inter = 0;
  std::vector<double> diffs;  // |D_e − D_g| / diameter on the intersection
  for (std::size_t i = 0; i < n; ++i) {
    const float t = dist_test.data[i], e = dist_est.data[i], g = dist_gt.data[i];
    const bool vg = g > 0 && (g - t <= delta_m || t == 0);
    const bool ve = e > 0 && ((e - t <= delta_m || t == 0) || vg);
    if (vg || ve) ++n_union;
    if (vg && ve) {
      ++n_inter;
      diffs.push_back(std::abs(double(e) - double(g)) / diameter_m);
    }
  }
  std::vector<double> errors;
  for (double tau : taus) {
    if (n_union == 0) {
      errors.push_back(1.0);
      continue;
    }
    long cost = 0;
    for (double d : diffs) cost += d >= tau;
    errors.push_back(double(cost + (n_union - n_inter)) / double(n_union));
  }
  return errors;
}

}  // namespace

std::vector<double> VsdErrors(const Mesh& mesh, const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_gt,
                              const DepthImage& test_depth, const Camera& camera, double delta_m,
                              const std::vector<double>& taus, double diameter_m) {
  if (test_depth.width != camera.width || test_depth.height != camera.height)
    throw Error("VSD: test depth is " + std::to_string(test_depth.width) + "x" + std::to_string(test_depth.height) +
                ", the camera " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  if (!(diameter_m > 0) || !std::isfinite(diameter_m)) throw Error("VSD: diameter must be finite and > 0");
  if (!(delta_m >= 0) || !std::isfinite(delta_m)) throw Error("VSD: delta must be finite and ≥ 0");
  DepthImage est(camera.width, camera.height, 0.f), gt(camera.width, camera.height, 0.f);
  RenderDepth(mesh, T_est, camera, &est);
  RenderDepth(mesh, T_gt, camera, &gt);
  return VsdFromDistances(DepthToDistance(test_depth, camera), DepthToDistance(est, camera),
                          DepthToDistance(gt, camera), delta_m, taus, diameter_m);
}

double YcbvAuc(const std::vector<double>& errors_m, double max_m) {
  if (!(max_m > 0) || !std::isfinite(max_m)) throw Error("YcbvAuc: max must be finite and > 0");
  if (errors_m.empty()) return 0;
  const double n = static_cast<double>(errors_m.size());
  std::vector<double> d;
  for (double e : errors_m)
    if (e <= max_m) d.push_back(e);  // ∞, NaN and errors above the cap never count
  if (d.empty()) return 0;
  std::sort(d.begin(), d.end());
  // VOCap: mrec = [0, d_1..d_m, max], mpre = [0, 1/n..m/n, m/n]; sum over changes of mrec of
  // (mrec_i − mrec_{i−1})·mpre_i. Equal errors: the step is taken at the first of them.
  double area = 0, prev = 0;
  for (std::size_t k = 0; k < d.size(); ++k) {
    if (d[k] != prev) area += (d[k] - prev) * double(k + 1) / n;
    prev = d[k];
  }
  if (max_m != prev) area += (max_m - prev) * double(d.size()) / n;
  return area / max_m;
}

BopEvalReport EvaluateBop(const Dataset& ds, const std::vector<BopResult>& results, const BopEvalOptions& opt,
                          const EvalProgressFn& progress) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("invalid evaluation option: " + why);
  BopEvalReport rep;
  rep.n_results = static_cast<int>(results.size());

  // Mean time per image (BOP: −1 unless every row has a time).
  {
    std::map<std::pair<int, int>, double> times;
    bool all = !results.empty();
    for (const auto& r : results) {
      if (r.time_s < 0) all = false;
      times[{r.scene_id, r.im_id}] = r.time_s;
    }
    if (all) {
      double s = 0;
      for (const auto& [k, t] : times) s += t;
      rep.mean_time_s = s / times.size();
    }
  }

  // Results by image and object, best score first.
  std::map<std::tuple<int, int, int>, std::vector<const BopResult*>> by_target;
  for (const auto& r : results) {
    if (!ds.Model(r.obj_id))
      throw Error("results: scene " + std::to_string(r.scene_id) + ", image " + std::to_string(r.im_id) +
                  ": obj_id " + std::to_string(r.obj_id) + " has no model in " + ds.root);
    by_target[{r.scene_id, r.im_id, r.obj_id}].push_back(&r);
  }
  for (auto& [k, v] : by_target)
    std::stable_sort(v.begin(), v.end(), [](const BopResult* a, const BopResult* b) { return a->score > b->score; });

  // Per-model data, loaded on first use.
  struct ModelData {
    const DatasetModel* model = nullptr;
    std::vector<Eigen::Vector3f> pts;
    std::vector<Eigen::Isometry3d> syms;
    Mesh mesh;
    bool has_mesh = false;
  };
  std::map<int, ModelData> models;
  auto model_data = [&](int obj_id) -> ModelData& {
    ModelData& m = models[obj_id];
    if (!m.model) {
      m.model = ds.Model(obj_id);
      m.pts = LoadDatasetPoints(*m.model, opt.max_points);
      m.syms = SymmetryTransformations(*m.model, opt.max_sym_disc_step);
    }
    if (opt.compute_vsd && !m.has_mesh) {
      m.mesh = LoadDatasetMesh(*m.model);
      m.has_mesh = true;
    }
    return m;
  };

  std::map<int, Tally> per_obj;
  Tally all;
  const double n_vsd = double(opt.vsd_taus.size() * opt.vsd_thresholds.size());

  // Targets grouped by image.
  std::map<std::pair<int, int>, std::vector<const DatasetTarget*>> by_image;
  for (const auto& t : ds.targets) by_image[{t.scene_id, t.im_id}].push_back(&t);
  int done = 0;
  for (const auto& [key, targets] : by_image) {
    const DatasetImage* im = ds.Image(key.first, key.second);
    if (!im) throw Error("targets: scene " + std::to_string(key.first) + ", image " + std::to_string(key.second) +
                         " is not in the dataset");
    if (!im->has_gt)
      throw Error("scene " + std::to_string(im->scene_id) + ", image " + std::to_string(im->im_id) +
                  ": no ground truth (scene_gt.json) to evaluate against");
    SceneInput scene;
    bool scene_loaded = false;
    for (const DatasetTarget* t : targets) {
      ModelData& md = model_data(t->obj_id);
      const double diam = md.model->diameter_m;
      std::vector<int> gt_idx;
      for (std::size_t g = 0; g < im->gt.size(); ++g)
        if (im->gt[g].obj_id == t->obj_id) gt_idx.push_back(static_cast<int>(g));
      if (gt_idx.empty())
        throw Error((ds.targets_source.empty() ? std::string("targets") : ds.targets_source) + ": scene " +
                    std::to_string(t->scene_id) + ", image " + std::to_string(t->im_id) + ": obj_id " +
                    std::to_string(t->obj_id) + " has no gt instance");
      std::vector<const BopResult*> ests;
      if (const auto it = by_target.find({t->scene_id, t->im_id, t->obj_id}); it != by_target.end()) ests = it->second;
      if (ests.size() > std::size_t(t->inst_count)) ests.resize(t->inst_count);
      rep.n_results_used += static_cast<int>(ests.size());
      // The depth (VSD) and the image width (MSPD) come from the depth PNG when needed.
      if (!ests.empty() && (opt.compute_vsd || im->camera.width == 0) && !scene_loaded) {
        scene = LoadDatasetScene(*im);
        scene_loaded = true;
      }
      const double width = scene_loaded ? scene.camera.width : im->camera.width;

      const std::size_t ng = gt_idx.size(), ne = ests.size();
      ErrorMatrix add(ne, std::vector<double>(ng)), adds = add, mssd = add, mspd = add;
      std::vector<ErrorMatrix> vsd(opt.vsd_taus.size(), ErrorMatrix(ne, std::vector<double>(ng, 1.0)));
      for (std::size_t e = 0; e < ne; ++e) {
        for (std::size_t g = 0; g < ng; ++g) {
          const Eigen::Isometry3d& Tg = im->gt[gt_idx[g]].T_cam_obj;
          const Eigen::Isometry3d& Te = ests[e]->T_cam_obj;
          add[e][g] = AddError(md.pts, Te, Tg);
          adds[e][g] = AddSError(md.pts, Te, Tg);
          mssd[e][g] = MssdError(md.pts, Te, Tg, md.syms);
          // In pixels of a 640-wide image, so the thresholds 5…50 px scale by width/640.
          mspd[e][g] = MspdError(md.pts, Te, Tg, md.syms, im->camera) * 640.0 / width;
          if (opt.compute_vsd) {
            const std::vector<double> v =
                VsdErrors(md.mesh, Te, Tg, scene.depth, scene.camera, opt.vsd_delta_m, opt.vsd_taus, diam);
            for (std::size_t k = 0; k < v.size(); ++k) vsd[k][e][g] = v[k];
          }
        }
      }

      // Recalls (matched counts summed over thresholds).
      Tally local;
      local.n = static_cast<int>(ng);
      local.add_hits = CountMatches(add, ng, opt.add_threshold * diam);
      local.adds_hits = CountMatches(adds, ng, opt.add_threshold * diam);
      for (double th : opt.mssd_thresholds) local.mssd_hits += CountMatches(mssd, ng, th * diam);
      for (double th : opt.mspd_thresholds_px) local.mspd_hits += CountMatches(mspd, ng, th);
      if (opt.compute_vsd)
        for (const auto& m : vsd)
          for (double th : opt.vsd_thresholds) local.vsd_hits += CountMatches(m, ng, th);

      // Per-instance errors (assignment per metric).
      const std::vector<int> a_add = Assign(add, ng), a_adds = Assign(adds, ng), a_mssd = Assign(mssd, ng),
                             a_mspd = Assign(mspd, ng);
      // VSD: the estimate with the smallest mean error over τ.
      ErrorMatrix vsd_mean(ne, std::vector<double>(ng, 0.0));
      for (std::size_t e = 0; e < ne; ++e)
        for (std::size_t g = 0; g < ng; ++g)
          for (const auto& m : vsd) vsd_mean[e][g] += m[e][g] / double(vsd.size());
      const std::vector<int> a_vsd = Assign(vsd_mean, ng);
      for (std::size_t g = 0; g < ng; ++g) {
        BopTargetEval te;
        te.scene_id = t->scene_id;
        te.im_id = t->im_id;
        te.obj_id = t->obj_id;
        te.gt_index = gt_idx[g];
        te.estimated = a_adds[g] >= 0;
        if (a_add[g] >= 0) te.add_m = add[a_add[g]][g];
        if (a_adds[g] >= 0) te.adds_m = adds[a_adds[g]][g];
        if (a_mssd[g] >= 0) te.mssd_m = mssd[a_mssd[g]][g];
        if (a_mspd[g] >= 0) te.mspd_px = mspd[a_mspd[g]][g];
        if (opt.compute_vsd && a_vsd[g] >= 0)
          for (const auto& m : vsd) te.vsd.push_back(m[a_vsd[g]][g]);
        local.n_estimated += te.estimated;
        local.add_err.push_back(te.add_m);
        local.adds_err.push_back(te.adds_m);
        rep.instances.push_back(std::move(te));
      }
      for (Tally* tl : {&per_obj[t->obj_id], &all}) {
        tl->n += local.n;
        tl->n_estimated += local.n_estimated;
        tl->add_hits += local.add_hits;
        tl->adds_hits += local.adds_hits;
        tl->vsd_hits += local.vsd_hits;
        tl->mssd_hits += local.mssd_hits;
        tl->mspd_hits += local.mspd_hits;
        tl->add_err.insert(tl->add_err.end(), local.add_err.begin(), local.add_err.end());
        tl->adds_err.insert(tl->adds_err.end(), local.adds_err.begin(), local.adds_err.end());
      }
    }
    ++done;
    if (progress) progress(done, static_cast<int>(by_image.size()));
  }

  auto scores = [&](const Tally& t, int obj_id, const std::string& name, double diam) {
    BopScores s;
    s.obj_id = obj_id;
    s.name = name;
    s.diameter_m = diam;
    s.n_instances = t.n;
    s.n_estimated = t.n_estimated;
    if (t.n == 0) return s;
    s.add_recall = t.add_hits / t.n;
    s.adds_recall = t.adds_hits / t.n;
    s.auc_add = YcbvAuc(t.add_err, opt.auc_max_m);
    s.auc_adds = YcbvAuc(t.adds_err, opt.auc_max_m);
    s.mssd_recall = t.mssd_hits / (double(t.n) * opt.mssd_thresholds.size());
    s.mspd_recall = t.mspd_hits / (double(t.n) * opt.mspd_thresholds_px.size());
    s.vsd_recall = opt.compute_vsd ? t.vsd_hits / (double(t.n) * n_vsd) : kNaN;
    s.ar = (s.vsd_recall + s.mssd_recall + s.mspd_recall) / 3;
    return s;
  };
  for (const auto& [obj, t] : per_obj) {
    const DatasetModel* m = ds.Model(obj);
    rep.objects.push_back(scores(t, obj, m->name, m->diameter_m));
  }
  rep.overall = scores(all, 0, "all", 0);
  return rep;
}

}  // namespace posefilter
