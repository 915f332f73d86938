// python/bindings/tracker.cc — Tracker (posefilter/tracker.h) and TrackResult for Python.
#include "bindings.h"

#include <set>
#include <string>

namespace posefilter::python {
namespace {

// The keywords of TrackOptions besides the filter's: name, field.
struct TrackKeyword {
  const char* name;
  double TrackOptions::*field;
};
constexpr TrackKeyword kTrackKeywords[] = {
    {"lost_weight", &TrackOptions::lost_weight},   {"refresh_weight", &TrackOptions::refresh_weight},
    {"search_t", &TrackOptions::search_t_m},       {"search_r", &TrackOptions::search_r_rad},
    {"window_margin", &TrackOptions::window_margin},
};

class PyTracker {
 public:
  PyTracker(py::handle meshes_arg, py::handle init_arg, const py::kwargs& kw) {
    TrackOptions o;
    std::set<std::string> own = {"constant_velocity", "scene_pass"};
    for (const auto& k : kTrackKeywords) own.insert(k.name);
    for (const auto& item : kw) {
      const std::string name = py::str(item.first);
      if (name == "constant_velocity" || name == "scene_pass") {
        (name == "scene_pass" ? o.scene_pass : o.constant_velocity) = item.second.cast<bool>();
        continue;
      }
      for (const auto& k : kTrackKeywords)
        if (name == k.name) {
          try {
            o.*k.field = item.second.cast<double>();
          } catch (const py::cast_error&) {
            throw py::type_error("Tracker: option '" + name + "' expects a number, got " + std::string(py::repr(item.second)));
          }
        }
    }
    ApplyKeywords(&o.filter, kw, FilterKeywords(), "Tracker", own);
    if (!init_arg.is_none()) {
      if (!py::isinstance<py::dict>(init_arg)) throw py::type_error("Tracker: init expects a dict of Estimator options");
      ApplyKeywords(&o.init, init_arg.cast<py::kwargs>(), FilterKeywords(), "Tracker init");
    }
    CheckedFilterOptions(o.filter);
    CheckedFilterOptions(o.init);
    std::string why;
    if (!o.IsValid(&why)) Fail("Tracker: invalid option " + why);
    std::vector<Mesh> meshes;
    if (py::isinstance<Mesh>(meshes_arg)) {
      meshes.push_back(meshes_arg.cast<Mesh>());
    } else {
      if (!py::isinstance<py::sequence>(meshes_arg) || py::isinstance<py::str>(meshes_arg))
        throw py::type_error("meshes: expected a Mesh or a sequence of Mesh");
      for (py::handle m : meshes_arg) {
        if (!py::isinstance<Mesh>(m)) throw py::type_error("meshes: every element must be a Mesh");
        meshes.push_back(m.cast<Mesh>());
      }
    }
    tracker_ = std::make_unique<Tracker>(std::move(meshes), o);
  }

  void Reset(const std::string& obj, py::handle T) { tracker_->Reset(obj, TransformFrom(T, "pose")); }

  std::vector<TrackResult> Track(py::handle depth, const Camera& camera, py::handle prior_arg,
                                 std::optional<double> depth_scale) {
    CheckedCamera(camera, "camera");
    SceneInput frame{DepthFrom(depth, depth_scale, &camera, "depth"), camera};
    ValidateScene(frame, "depth");
    std::vector<std::string> names;
    std::vector<const Mesh*> meshes;
    for (const Mesh& m : tracker_->meshes()) names.push_back(m.name), meshes.push_back(&m);
    // The stage 1: none, 'auto' (made only when an object needs it), a fixed prior, or a
    // callable(depth, camera) returning one (called with the GIL, only when needed).
    Stage1Fn stage1;
    const py::object arg = py::reinterpret_borrow<py::object>(prior_arg);
    auto to_stage1 = [&names, &meshes](py::handle p, const SceneInput& fr) {
      Stage1 made = Stage1OfPriorArg(p, names, meshes, fr);
      TrackStage1 s;
      s.prior = std::move(made.prior);
      for (std::size_t k = 0; k < made.seeds.size() && k < names.size(); ++k)
        if (!made.seeds[k].empty()) s.seeds[names[k]] = std::move(made.seeds[k]);
      return s;
    };
    TrackStage1 fixed;
    if (arg.is_none()) {
    } else if (py::isinstance<py::str>(arg) && arg.cast<std::string>() == "auto") {
      stage1 = [this](const SceneInput& fr) {
        return AutoTrackStage1(fr, tracker_->meshes(), DefaultPpfCacheDir(), "prior 'auto'");
      };
    } else if (PyCallable_Check(arg.ptr()) && !py::isinstance<Prior>(arg)) {
      stage1 = [&arg, &to_stage1, &depth](const SceneInput& fr) {
        py::gil_scoped_acquire acquire;
        const py::object p = arg(depth, fr.camera);
        if (p.is_none()) return TrackStage1{};
        return to_stage1(p, fr);
      };
    } else {
      fixed = to_stage1(arg, frame);
      stage1 = [&fixed](const SceneInput&) { return fixed; };
    }
    std::vector<TrackResult> results;
    {
      py::gil_scoped_release release;
      results = tracker_->Track(frame, stage1);
    }
    // Without a stage 1, an object with no pose can never start: say so, once per object.
    if (arg.is_none()) {
      for (const TrackResult& r : results) {
        if (r.status != TrackStatus::kNotStarted || !warned_.insert(r.obj).second) continue;
        const std::string msg = "Tracker.track: '" + r.obj + "' has no pose and prior=None cannot start it; "
                                "call reset('" + r.obj + "', pose) or pass prior='auto', a Prior or a callable";
        if (PyErr_WarnEx(PyExc_RuntimeWarning, msg.c_str(), 1) != 0) throw py::error_already_set();
      }
    }
    return results;
  }

  const Tracker& tracker() const { return *tracker_; }

 private:
  std::unique_ptr<Tracker> tracker_;
  std::set<std::string> warned_;  // objects Track warned cannot start
};

}  // namespace

void BindTracking(py::module_& m) {
  py::class_<TrackResult>(m, "TrackResult", "One object in one frame of a Tracker.")
      .def_readonly("obj", &TrackResult::obj)
      .def_property_readonly("status", [](const TrackResult& r) { return std::string(TrackStatusName(r.status)); },
                             "'tracked', 'initialised', 'lost' or 'not-started'")
      .def_property_readonly("pose", [](const TrackResult& r) { return ToNumpy(r.T_cam_obj); }, "4x4 T_cam_obj, object → camera")
      .def_readonly("weight", &TrackResult::weight, "best weight of the step that gave the pose")
      .def_readonly("iterations", &TrackResult::iterations)
      .def_readonly("time_ms", &TrackResult::time_ms)
      .def("__repr__", [](const TrackResult& r) {
        std::ostringstream os;
        os << "TrackResult('" << r.obj << "', " << TrackStatusName(r.status) << ", weight=" << r.weight
           << ", time_ms=" << r.time_ms << ")";
        return os.str();
      });

  py::class_<PyTracker>(m, "Tracker",
                        "Tracks objects through depth frames: each object's pose in one frame seeds the next "
                        "(docs/PYTHON.md, 'Tracking').\n\n"
                        "Tracker(meshes, init=None, **options): meshes a Mesh or a list (their names are the "
                        "objects); options: lost_weight, refresh_weight, search_t (m), search_r (rad), "
                        "window_margin, constant_velocity, scene_pass, and any Estimator option for the tracking step "
                        "(defaults: Tracker.defaults()); init: a dict of Estimator options for the full estimate "
                        "that starts and restarts objects.")
      .def(py::init([](py::handle meshes, py::handle init, const py::kwargs& kw) { return PyTracker(meshes, init, kw); }),
           "meshes"_a, py::kw_only(), "init"_a = py::none())
      .def_static("defaults", [] {
        const TrackOptions o;
        py::dict d = KeywordDict(o.filter, FilterKeywords());
        for (const auto& k : kTrackKeywords) d[k.name] = o.*k.field;
        d["constant_velocity"] = o.constant_velocity;
        d["scene_pass"] = o.scene_pass;
        return d;
      }, "dict of the default options (the tracking step's filter options and the tracker's own)")
      .def("reset", &PyTracker::Reset, "obj"_a, "pose"_a, "Start (or restart) obj at a known 4x4 pose (object → camera).")
      .def("track", &PyTracker::Track, "depth"_a, "camera"_a, "prior"_a = py::none(), py::kw_only(),
           "depth_scale"_a = py::none(),
           "Process the next frame; returns one TrackResult per mesh. prior: the stage 1 that starts objects and "
           "restarts lost ones: None (objects start only from reset), 'auto', a Prior, a detections JSON path or "
           "list, or a callable(depth, camera) returning one of those (called only when an object needs it). "
           "Runs without the GIL.")
      .def_property_readonly("frames", [](const PyTracker& t) { return t.tracker().frames(); }, "frames processed")
      .def_property_readonly("objs", [](const PyTracker& t) {
        std::vector<std::string> n;
        for (const Mesh& m : t.tracker().meshes()) n.push_back(m.name);
        return n;
      })
      .def("__repr__", [](const PyTracker& t) {
        return "Tracker(" + std::to_string(t.tracker().meshes().size()) + " objects, " + std::to_string(t.tracker().frames()) +
               " frames)";
      });
}

}  // namespace posefilter::python
