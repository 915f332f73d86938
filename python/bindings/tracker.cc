// python/bindings/tracker.cc — Tracker (posefilter/tracker.h) and TrackResult for Python.
#include "bindings.h"

#include <set>
#include <string>

namespace posefilter::python {
namespace {

// The names of `keywords` as a set: what ApplyKeywords of the other option set skips.
template <class Options>
std::set<std::string> KeywordSet(const std::vector<Keyword<Options>>& keywords) {
  const std::vector<std::string> names = KeywordNames(keywords);
  return {names.begin(), names.end()};
}

class PyTracker {
 public:
  PyTracker(py::handle meshes_arg, py::handle init_arg, const py::kwargs& kw) {
    TrackOptions o;
    // Each keyword is the tracker's own (a row of TrackOptionTable) or the tracking step's
    // filter option; an unknown one is a TypeError listing the filter's.
    ApplyKeywords(&o.filter, kw, FilterKeywords(), "Tracker", KeywordSet(TrackKeywords()));
    ApplyKeywords(&o, kw, TrackKeywords(), "Tracker", KeywordSet(FilterKeywords()));
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

// The Tracker's docstring: its own keywords from TrackOptionTable, with type, default, range and
// meaning.
const std::string& TrackerDoc() {
  static const std::string doc = [] {
    std::string d =
        "Tracks objects through depth frames: each object's pose in one frame seeds the next (docs/PYTHON.md, "
        "'Tracking').\n\n"
        "Tracker(meshes, init=None, **options): meshes a Mesh or a list (their names are the objects); options: "
        "the tracker's own (below; Tracker.option_names()) and any Estimator option for the tracking step "
        "(defaults: Tracker.defaults()); init: a dict of Estimator options for the full estimate that starts and "
        "restarts objects.\n\nThe tracker's keywords (type = default, range: meaning):\n";
    const TrackOptions defaults;
    for (const OptionInfo& f : TrackOptionTable()) d += KeywordDocHead(f, f.ValueText(defaults)) + ": " + f.help + "\n";
    return d;
  }();
  return doc;
}

}  // namespace

void BindTracking(py::module_& m) {
  py::class_<TrackResult>(m, "TrackResult", "One object in one frame of a Tracker.")
      .def_readonly("obj", &TrackResult::obj)
      .def_property_readonly("status", [](const TrackResult& r) { return std::string(TrackStatusName(r.status)); },
                             "'tracked', 'initialised', 'lost' or 'not-started'")
      .def_property_readonly("pose", [](const TrackResult& r) { return ToNumpy(r.T_cam_obj); }, "4x4 T_cam_obj, object → camera")
      .def_readonly("weight", &TrackResult::weight, "best weight of the step that gave the pose")
      .def_readonly("iterations", &TrackResult::iterations)
      .def_readonly("confirmed", &TrackResult::confirmed,
                    "tracked by the confirmation of its prediction, without the particle search (option confirm)")
      .def_readonly("time_ms", &TrackResult::time_ms)
      .def("__repr__", [](const TrackResult& r) {
        std::ostringstream os;
        os << "TrackResult('" << r.obj << "', " << TrackStatusName(r.status) << ", weight=" << r.weight
           << ", time_ms=" << r.time_ms << ")";
        return os.str();
      });

  py::class_<PyTracker>(m, "Tracker", TrackerDoc().c_str())
      .def(py::init([](py::handle meshes, py::handle init, const py::kwargs& kw) { return PyTracker(meshes, init, kw); }),
           "meshes"_a, py::kw_only(), "init"_a = py::none())
      .def_static("defaults", [] {
        const TrackOptions o;
        py::dict d = KeywordDict(o.filter, FilterKeywords());
        for (const auto& [name, value] : KeywordDict(o, TrackKeywords())) d[name] = value;
        return d;
      }, "dict of the default options (the tracking step's filter options and the tracker's own)")
      .def_static("option_names", [] { return KeywordNames(TrackKeywords()); },
                  "the tracker's own keywords (TrackOptionTable's rows, docs/OPTIONS.md 'Tracker'), in order; the "
                  "tracking step's filter options are Estimator.option_names()")
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
