// python/bindings/estimator.cc — the Estimator class (Python's entry to EstimatePose) and its Result and BatchResult.
#include <mutex>

#include "bindings.h"
#include "posefilter/estimate_scene.h"
#include "posefilter/prepared_model.h"
#include "posefilter/stage1.h"
#include "posefilter/support_plane.h"
#include "posefilter/view.h"

namespace posefilter::python {

struct BatchResult {
  std::vector<EstimateResult> items;
};

py::dict StatsDict(const FilterStats& s) {
  return py::dict("init_cdf_reads"_a = s.init_cdf_reads, "init_cdf_reads_linear"_a = s.init_cdf_reads_linear,
                  "resample_cdf_reads"_a = s.resample_cdf_reads,
                  "resample_cdf_reads_linear"_a = s.resample_cdf_reads_linear, "faces_total"_a = s.faces_total,
                  "faces_front"_a = s.faces_front, "fragments"_a = s.fragments, "weighings"_a = s.weighings);
}

// The stage-1 options (posefilter/stage1.h) of a prior argument that is not None, "none" or a
// Prior: "auto", a detections JSON path or a list of detections.
Stage1Options Stage1FromPython(py::handle prior_arg) {
  Stage1Options so;
  if (py::isinstance<py::str>(prior_arg) && prior_arg.cast<std::string>() == "auto") {
    // No detector: candidate regions of the depth image for every mesh (posefilter/auto_prior.h).
    so.kind = Stage1Kind::kAuto;
    so.what = "prior 'auto'";
    so.cache_dir = DefaultPpfCacheDir();
    return so;
  }
  so.kind = Stage1Kind::kDetections;
  so.check_detections = true;
  if (py::isinstance<py::str>(prior_arg) || py::hasattr(prior_arg, "__fspath__")) {
    so.what = py::str(py::module_::import("os").attr("fspath")(prior_arg));
    so.detections = ReadDetectionsJson(so.what);
  } else if (py::isinstance<py::sequence>(prior_arg)) {
    so.detections = DetectionsFrom(prior_arg);
  } else {
    throw py::type_error("prior: expected None (or 'none'), 'auto', a Prior, a detections JSON path or a list of detections");
  }
  return so;
}

Stage1 Stage1OfPriorArg(py::handle prior_arg, const std::vector<std::string>& objs, const std::vector<const Mesh*>& meshes,
                        const SceneInput& scene) {
  Stage1 stage1;
  if (py::isinstance<Prior>(prior_arg)) {
    stage1.prior = prior_arg.cast<Prior>();
    stage1.seeds.resize(objs.size());
    return stage1;
  }
  const Stage1Options so = Stage1FromPython(prior_arg);
  std::vector<Stage1Object> objects;
  for (std::size_t i = 0; i < objs.size(); ++i) objects.push_back({objs[i], meshes[i]});
  stage1 = BuildStage1(scene, objects, so);
  WarnAll(stage1.warnings);
  return stage1;
}

// The meshes an Estimator has prepared (PrepareModel with its options), most recent last: an
// estimate on a mesh equal to one of them (name, vertices and faces) reuses its model.
// Shared by the Estimator's copies, behind one lock (estimates run without the GIL).
class ModelCache {
 public:
  // At most this many models are kept (count); the least recently used goes first.
  static constexpr std::size_t kMaxModels = 64;

  std::shared_ptr<const PreparedModel> Get(const Mesh& mesh, const FilterOptions& options) {
    {
      const std::lock_guard<std::mutex> hold(lock_);
      for (auto it = models_.begin(); it != models_.end(); ++it) {
        const Mesh& m = (*it)->mesh();
        if (m.name == mesh.name && m.faces == mesh.faces && m.vertices == mesh.vertices) {
          std::shared_ptr<const PreparedModel> found = *it;
          models_.erase(it);
          models_.push_back(found);
          return found;
        }
      }
    }
    std::shared_ptr<const PreparedModel> made = PrepareModel(mesh, options);  // outside the lock
    const std::lock_guard<std::mutex> hold(lock_);
    models_.push_back(made);
    if (models_.size() > kMaxModels) models_.erase(models_.begin());
    return made;
  }
  std::size_t size() {
    const std::lock_guard<std::mutex> hold(lock_);
    return models_.size();
  }

 private:
  std::mutex lock_;
  std::vector<std::shared_ptr<const PreparedModel>> models_;
};

class Estimator {
 public:
  explicit Estimator(const FilterOptions& o) : options_(CheckedFilterOptions(o)) {}
  const FilterOptions& options() const { return options_; }
  // Meshes prepared so far and kept (ModelCache).
  std::size_t prepared_models() const { return models_->size(); }

  // See the docstring in PYBIND11_MODULE.
  py::object Estimate(py::handle depth, const Camera& camera, py::handle mesh_arg, py::handle prior_arg,
                      py::handle obj_arg, std::optional<double> depth_scale, py::handle progress,
                      py::handle mask_arg, bool scene_pass) const {
    CheckedCamera(camera, "camera");
    SceneInput scene{DepthFrom(depth, depth_scale, &camera, "depth"), camera};
    ValidateScene(scene, "depth");
    // The object's instance mask (H x W, non-zero = the object): scored against, and its box
    // is the prior when none is given.
    InstanceMask mask;
    if (!mask_arg.is_none()) {
      if (!py::isinstance<py::array>(mask_arg)) Fail("mask: expected a numpy array (H x W)");
      const auto a = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(mask_arg);
      if (!a || a.ndim() != 2 || a.shape(0) != camera.height || a.shape(1) != camera.width) {
        std::ostringstream os;
        os << "mask: expected shape (" << camera.height << ", " << camera.width << ") (the camera's height, width)";
        Fail(os.str());
      }
      LabelImage l{camera.width, camera.height, std::vector<std::uint16_t>(std::size_t(camera.width) * camera.height)};
      for (std::size_t i = 0; i < l.ids.size(); ++i) l.ids[i] = a.data()[i] ? 1 : 0;
      mask = MasksFromLabels(l, {{1, "mask"}}, "mask").front();
      scene.mask = mask.pixels;
    }

    // Meshes: one Mesh, or a sequence of them (batch).
    const bool batch = !py::isinstance<Mesh>(mesh_arg);
    std::vector<Mesh> meshes;
    if (!batch) {
      meshes.push_back(mesh_arg.cast<Mesh>());
    } else {
      if (!py::isinstance<py::sequence>(mesh_arg) || py::isinstance<py::str>(mesh_arg))
        throw py::type_error("mesh: expected a Mesh or a sequence of Mesh");
      for (py::handle m : mesh_arg) {
        if (!py::isinstance<Mesh>(m)) throw py::type_error("mesh: every element must be a Mesh");
        meshes.push_back(m.cast<Mesh>());
      }
      if (meshes.empty()) Fail("mesh: empty list of meshes");
    }
    if (!scene.mask.empty() && meshes.size() != 1) Fail("mask: a mask is the instance of one object; give one Mesh");
    // Object names = prior classes: obj (str or list), default the meshes' names.
    std::vector<std::string> objs;
    if (obj_arg.is_none()) {
      for (const auto& m : meshes) objs.push_back(m.name);
    } else if (py::isinstance<py::str>(obj_arg)) {
      if (batch && meshes.size() != 1) Fail("obj: give one name per mesh (a list) for several meshes");
      objs.push_back(obj_arg.cast<std::string>());
    } else {
      for (py::handle o : obj_arg) objs.push_back(py::str(o));
      if (objs.size() != meshes.size())
        Fail("obj: " + std::to_string(objs.size()) + " names for " + std::to_string(meshes.size()) + " meshes");
    }
    for (std::size_t i = 0; i < objs.size(); ++i) {
      if (objs[i].empty()) Fail("obj: mesh " + std::to_string(i) + " has no name; pass obj=...");
      // As the CLI's --mesh: one name per object (the prior's classes and the results' keys).
      for (std::size_t j = 0; j < i; ++j)
        if (objs[j] == objs[i])
          Fail("obj: name '" + objs[i] + "' given twice (meshes " + std::to_string(j) + " and " + std::to_string(i) +
               "); give each object its own name (load_mesh(..., name=...) or obj=[...])");
    }

    // The prior: None or "none" (uniform), "auto", a Prior, a detections JSON path, or a list of detections.
    const int W = camera.width, H = camera.height;
    // None or "none" (as the CLI's --prior none): no detector, a uniform prior (with a mask:
    // the prior of its box).
    const bool no_prior =
        prior_arg.is_none() || (py::isinstance<py::str>(prior_arg) && prior_arg.cast<std::string>() == "none");
    std::vector<const Mesh*> mesh_ptrs;
    for (const Mesh& m : meshes) mesh_ptrs.push_back(&m);
    Stage1 stage1;
    if (!no_prior) {
      stage1 = Stage1OfPriorArg(prior_arg, objs, mesh_ptrs, scene);
    } else {
      Stage1Options so;
      if (!scene.mask.empty()) {
        mask.cls = objs[0];
        so.kind = Stage1Kind::kMasks;
        so.masks = {mask};
      }
      std::vector<Stage1Object> objects;
      for (std::size_t i = 0; i < meshes.size(); ++i) objects.push_back({objs[i], &meshes[i]});
      stage1 = BuildStage1(scene, objects, so);
      if (so.kind == Stage1Kind::kMasks) stage1.prior = std::move(stage1.instances.at(0).prior);
    }
    const Prior& prior = stage1.prior;
    if (prior.layout.image_width != W || prior.layout.image_height != H)
      Fail("prior: made for a " + std::to_string(prior.layout.image_width) + "x" +
           std::to_string(prior.layout.image_height) + " image but the camera is " + std::to_string(W) + "x" +
           std::to_string(H));
    std::vector<int> cls(objs.size());
    for (std::size_t i = 0; i < objs.size(); ++i) {
      cls[i] = prior.ClassIndex(objs[i]);
      if (cls[i] < 0) Fail("obj: '" + objs[i] + "' is not a class of the prior");
      if (!(prior.ClassMass(cls[i]) > 0)) Fail("prior: holds no probability for '" + objs[i] + "'");
      meshes[i].name = objs[i];
    }

    const py::object callback = py::reinterpret_borrow<py::object>(progress);
    if (!callback.is_none() && !PyCallable_Check(callback.ptr())) throw py::type_error("progress: expected a callable");
    BatchResult out;
    {
      // The filter runs without the GIL; between iterations it takes the GIL back briefly to
      // honour Ctrl-C and to call `progress(obj, iteration, best_weight)`.
      py::gil_scoped_release release;
      std::vector<SceneEstimateObject> jobs(meshes.size());
      for (std::size_t i = 0; i < meshes.size(); ++i) {
        const std::string name = objs[i];
        jobs[i].progress = [&callback, name](int it, double w) {
          py::gil_scoped_acquire acquire;
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (!callback.is_none()) callback(name, it, w);
        };
        jobs[i].mesh = &meshes[i];
        jobs[i].model = models_->Get(meshes[i], options_);  // prepared once per mesh
        jobs[i].cls = cls[i];
        jobs[i].mask = scene.mask;
        jobs[i].seeds = i < stage1.seeds.size() ? stage1.seeds[i] : std::vector<PoseSeed>{};
      }
      // Several objects sharing the prior, without a mask: the joint scene pass
      // (posefilter/estimate_scene.h).
      EstimateSceneOptions so;
      so.scene_pass = scene_pass && scene.mask.empty();
      std::vector<SceneEstimate> est = EstimateScene(scene, prior, jobs, options_, so);
      for (std::size_t i = 0; i < est.size(); ++i) {
        out.items.push_back(std::move(est[i].result));
        if (!(est[i].passed && est[i].pass.replaced)) out.items.back().particle_history = std::move(est[i].particles);
        out.items.back().obj = objs[i];
      }
    }
    if (!batch) return py::cast(std::move(out.items[0]));
    return py::cast(std::move(out));
  }

 private:
  FilterOptions options_;
  std::shared_ptr<ModelCache> models_ = std::make_shared<ModelCache>();
};

// Result.view / BatchResult.view: the viewer page (posefilter/view.h) of `results` on their
// frame. `meshes`: a Mesh or a sequence of them (one per result); `gt`: None, a 4×4 T_cam_obj
// (one result) or a sequence with one 4×4 or None per result.
void WriteResultsView(const std::vector<const EstimateResult*>& results, const std::string& path, py::handle depth,
                      const Camera& camera, py::handle meshes, std::optional<double> depth_scale, py::handle rgb,
                      py::handle gt, bool support_plane, const std::string& title) {
  ViewScene v;
  v.title = title;
  v.camera = CheckedCamera(camera, "camera");
  v.depth = DepthFrom(depth, depth_scale, &v.camera, "depth");
  if (!rgb.is_none()) v.rgb = RgbFrom(rgb, "rgb");
  if (support_plane) v.planes.push_back(FindSupportPlane(v.depth, v.camera));
  std::vector<Mesh> ms;
  if (py::isinstance<Mesh>(meshes)) ms.push_back(meshes.cast<Mesh>());
  else if (py::isinstance<py::sequence>(meshes) && !py::isinstance<py::str>(meshes))
    for (py::handle m : meshes) {
      if (!py::isinstance<Mesh>(m)) throw py::type_error("mesh: every element must be a Mesh");
      ms.push_back(m.cast<Mesh>());
    }
  else throw py::type_error("mesh: expected a Mesh or a sequence of Mesh");
  if (ms.size() != results.size())
    Fail("mesh: " + std::to_string(ms.size()) + " meshes for " + std::to_string(results.size()) + " results");
  std::vector<py::object> gts(results.size(), py::none());
  if (!gt.is_none()) {
    if (results.size() == 1 && py::array::ensure(gt) && py::array::ensure(gt).ndim() == 2) gts[0] = py::reinterpret_borrow<py::object>(gt);
    else {
      std::size_t i = 0;
      for (py::handle g : gt) {
        if (i >= gts.size()) Fail("gt: more poses than results");
        gts[i++] = py::reinterpret_borrow<py::object>(g);
      }
      if (i != gts.size()) Fail("gt: " + std::to_string(i) + " poses for " + std::to_string(results.size()) + " results");
    }
  }
  for (std::size_t i = 0; i < results.size(); ++i) {
    ViewObject o;
    o.name = results[i]->obj;
    o.mesh = ms[i];
    o.T_cam_obj = results[i]->T_cam_obj;
    o.weight = results[i]->weight;
    o.particles = results[i]->particle_history;
    if (!gts[i].is_none()) o.gt_T_cam_obj = TransformFrom(gts[i], "gt");
    v.objects.push_back(std::move(o));
  }
  py::gil_scoped_release release;
  WriteViewHtml(v, path);
}

py::list ParticleHistory(const EstimateResult& r) {
  py::list out;
  for (const ParticleSet& s : r.particle_history) {
    py::array_t<double> poses({py::ssize_t(s.poses.size()), py::ssize_t(6)});
    auto p = poses.mutable_unchecked<2>();
    for (std::size_t i = 0; i < s.poses.size(); ++i) {
      const Pose6& q = s.poses[i];
      const double v[6] = {q.x, q.y, q.z, q.roll, q.pitch, q.yaw};
      for (int k = 0; k < 6; ++k) p(py::ssize_t(i), k) = v[k];
    }
    out.append(py::dict("run"_a = s.run, "iteration"_a = s.iteration, "poses6"_a = poses, "weights"_a = ToNumpy(s.weights)));
  }
  return out;
}

void BindEstimation(py::module_& m) {
  // ---- Estimation
  py::class_<EstimateResult>(m, "Result", "The pose of one object.")
      .def_readonly("obj", &EstimateResult::obj)
      .def_property_readonly("pose", [](const EstimateResult& r) { return ToNumpy(r.T_cam_obj); }, "4x4 T_cam_obj, object → camera")
      .def_property_readonly("T_cam_obj", [](const EstimateResult& r) { return ToNumpy(r.T_cam_obj); }, "= pose")
      .def_property_readonly("pose6", [](const EstimateResult& r) { return ToNumpy(r.pose_base); },
                             "(x, y, z, roll, pitch, yaw), object → base (= camera when base_to_camera is identity)")
      .def_readonly("weight", &EstimateResult::weight, "best weight, eq. 7.4")
      .def_readonly("cell", &EstimateResult::cell)
      .def_readonly("iterations", &EstimateResult::iterations, "iterations summed over restarts")
      .def_readonly("converged", &EstimateResult::converged)
      .def_readonly("time_ms", &EstimateResult::time_ms)
      .def_property_readonly("best_weight_history", [](const EstimateResult& r) { return ToNumpy(r.best_weight_history); })
      .def_property_readonly("iteration_ms", [](const EstimateResult& r) { return ToNumpy(r.iteration_ms); })
      .def_property_readonly("stats", [](const EstimateResult& r) { return StatsDict(r.stats); })
      .def_property_readonly("particle_history", &ParticleHistory,
                             "with Estimator(record_particles=True): one dict per iteration of every run (run, "
                             "iteration, poses6 N x 6 object → base, weights N; best first); else []")
      .def("view", [](const EstimateResult& r, const std::string& path, py::handle depth, const Camera& camera,
                      py::handle mesh, std::optional<double> depth_scale, py::handle rgb, py::handle gt,
                      bool support_plane, const std::string& title) {
        WriteResultsView({&r}, path, depth, camera, mesh, depth_scale, rgb, gt, support_plane, title);
      }, "path"_a, "depth"_a, "camera"_a, "mesh"_a, py::kw_only(), "depth_scale"_a = py::none(), "rgb"_a = py::none(),
         "gt"_a = py::none(), "support_plane"_a = true, "title"_a = "",
         "Writes the 3D viewer page (one HTML file, docs/VIEWER.md) of this result on its frame: depth (as for "
         "estimate), camera, the Mesh; rgb H x W x 3 uint8 colours the point cloud; gt a 4x4 T_cam_obj. Particles "
         "are shown when the Estimator had record_particles=True.")
      .def("__repr__", [](const EstimateResult& r) {
        std::ostringstream os;
        os << "Result('" << r.obj << "', weight=" << r.weight << ", iterations=" << r.iterations << ", time_ms=" << r.time_ms << ")";
        return os.str();
      });

  py::class_<BatchResult>(m, "BatchResult", "Poses of several objects (one estimate call).")
      .def("__len__", [](const BatchResult& b) { return b.items.size(); })
      .def("__getitem__", [](const BatchResult& b, py::ssize_t i) {
        const py::ssize_t n = py::ssize_t(b.items.size());
        if (i < 0) i += n;
        if (i < 0 || i >= n) throw py::index_error("BatchResult index out of range");
        return b.items[i];
      })
      .def("__iter__", [](const BatchResult& b) { return py::make_iterator(b.items.begin(), b.items.end()); },
           py::keep_alive<0, 1>())
      .def_property_readonly("objs", [](const BatchResult& b) {
        std::vector<std::string> o;
        for (const auto& r : b.items) o.push_back(r.obj);
        return o;
      })
      .def_property_readonly("poses", [](const BatchResult& b) {
        std::vector<Eigen::Isometry3d> Ts;
        for (const auto& r : b.items) Ts.push_back(r.T_cam_obj);
        return StackPoses(Ts);
      }, "N x 4 x 4 T_cam_obj")
      .def_property_readonly("poses6", [](const BatchResult& b) {
        py::array_t<double> out({py::ssize_t(b.items.size()), py::ssize_t(6)});
        auto o = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < b.items.size(); ++i) {
          const Pose6& p = b.items[i].pose_base;
          const double v[6] = {p.x, p.y, p.z, p.roll, p.pitch, p.yaw};
          for (int k = 0; k < 6; ++k) o(i, k) = v[k];
        }
        return out;
      }, "N x 6 (x, y, z, roll, pitch, yaw), object → base")
      .def_property_readonly("weights", [](const BatchResult& b) {
        std::vector<double> w;
        for (const auto& r : b.items) w.push_back(r.weight);
        return ToNumpy(w);
      })
      .def("view", [](const BatchResult& b, const std::string& path, py::handle depth, const Camera& camera,
                      py::handle meshes, std::optional<double> depth_scale, py::handle rgb, py::handle gt,
                      bool support_plane, const std::string& title) {
        std::vector<const EstimateResult*> rs;
        for (const auto& r : b.items) rs.push_back(&r);
        WriteResultsView(rs, path, depth, camera, meshes, depth_scale, rgb, gt, support_plane, title);
      }, "path"_a, "depth"_a, "camera"_a, "meshes"_a, py::kw_only(), "depth_scale"_a = py::none(), "rgb"_a = py::none(),
         "gt"_a = py::none(), "support_plane"_a = true, "title"_a = "",
         "Writes the 3D viewer page of these results on their frame (as Result.view; meshes and gt one per result).")
      .def("__repr__", [](const BatchResult& b) { return "BatchResult(" + std::to_string(b.items.size()) + " objects)"; });

  py::class_<Estimator>(m, "Estimator", EstimatorDoc().c_str())
      .def(py::init([](const py::kwargs& kw) {
        FilterOptions o;
        ApplyKeywords(&o, kw, FilterKeywords(), "Estimator");
        return Estimator(o);
      }), EstimatorDoc().c_str())
      .def_property_readonly("options", [](const Estimator& e) { return KeywordDict(e.options(), FilterKeywords()); },
                             "dict of every option")
      .def_property_readonly("prepared_models", &Estimator::prepared_models,
                             "meshes prepared so far and kept (at most 64): an estimate on an equal mesh (name, "
                             "vertices, faces) reuses its level of detail, hull, stable poses and coarse meshes")
      .def_static("defaults", [] { return KeywordDict(FilterOptions{}, FilterKeywords()); }, "dict of the default options")
      .def_static("option_table", [] {
        // One dict per option: the table of posefilter/option_table.h.
        py::list rows;
        const FilterOptions defaults;
        const auto& keywords = FilterKeywords();
        std::size_t i = 0;
        for (const OptionInfo& f : FilterOptionTable()) {
          rows.append(py::dict("keyword"_a = f.Name(OptionNaming::kPython), "cli"_a = f.Name(OptionNaming::kCli),
                               "field"_a = f.field, "group"_a = f.group, "type"_a = PythonTypeName(f.type),
                               "default"_a = keywords[i++].get(defaults), "range"_a = f.RangeText(),
                               "engines"_a = f.EnginesText(), "help"_a = f.help));
        }
        return rows;
      }, "list of dicts (keyword, cli, field, group, type, default, range, engines, help), one per option")
      .def_static("option_names", [] { return KeywordNames(FilterKeywords()); })
      .def("estimate", &Estimator::Estimate, "depth"_a, "camera"_a, "mesh"_a, "prior"_a = py::none(), py::kw_only(),
           "obj"_a = py::none(), "depth_scale"_a = py::none(), "progress"_a = py::none(), "mask"_a = py::none(),
           "scene_pass"_a = true,
           "Pose(s) of mesh (a Mesh → Result; a list of Mesh → BatchResult) in depth (H x W float metres, or "
           "uint16 with depth_scale). prior: None or 'none' (uniform, or the mask's box), 'auto' (no detector: candidate "
           "regions of the depth), a Prior, a detections JSON path, "
           "or a list of Detection/dicts. obj: prior class name(s), default the meshes' names. mask: the "
           "object's instance mask (H x W, non-zero = the object; one Mesh), scored against. progress(obj, "
           "iteration, best_weight) is called after each iteration (best_weight: the best at the final inlier "
           "threshold, never falling; NaN while the first run anneals). scene_pass (a list of Mesh, no mask): after "
           "the per-object estimates, the joint scene pass re-estimates an object whose pixels a better estimate "
           "explains. Runs without the GIL.")
      .def("__repr__", [](const Estimator& e) {
        const auto& o = e.options();
        return "Estimator(particles=" + std::to_string(o.num_particles) + ", iterations=" +
               std::to_string(o.stop.max_iterations) + ", restarts=" + std::to_string(o.restarts) + ", seed=" +
               std::to_string(o.seed) + ", ...)";
      });
}

}  // namespace posefilter::python
