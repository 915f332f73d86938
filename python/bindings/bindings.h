// python/bindings/bindings.h — what the files of the `posefilter._posefilter` extension share:
// numpy ↔ library conversions (convert.cc), keyword options (keywords.cc), detections from
// Python values (priors.cc), and the functions that bind each part of the API to the module
// (module.cc calls them in order).
//
// A thin layer over include/posefilter/: every computation is the library's; these files only
// convert between numpy arrays and the library's types and check what they convert.
// Conventions (docs/ALGORITHM.md §1, docs/PYTHON.md): metres, radians; depth arrays are H×W
// camera z (0 = missing);
// 4×4 poses map object → camera (T_cam_obj) unless named otherwise; a 6-vector pose is
// (x, y, z, roll, pitch, yaw), object → base, T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll) (eq. 6.2 [ALGORITHM.md]).
// Errors: posefilter::Error and every bad argument become posefilter.Error, a ValueError;
// an unknown keyword or a value of the wrong type is a TypeError.
#pragma once

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "filter/cdf_sampler.h"
#include "posefilter/auto_prior.h"
#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/heuristics.h"
#include "posefilter/mesh.h"
#include "posefilter/mask_prior.h"
#include "posefilter/stage1.h"
#include "posefilter/metrics.h"
#include "posefilter/option_table.h"
#include "posefilter/overlay.h"
#include "posefilter/pose.h"
#include "posefilter/prior.h"
#include "posefilter/projection.h"
#include "posefilter/render.h"
#include "posefilter/scene_pass.h"
#include "posefilter/rng.h"
#include "posefilter/scene_io.h"
#include "posefilter/synth.h"
#include "posefilter/tracker.h"
#include "posefilter/version.h"


namespace py = pybind11;
using namespace pybind11::literals;

namespace posefilter::python {

[[noreturn]] inline void Fail(const std::string& message) { throw Error(message); }

// ---------------------------------------------------------------- array conversions (convert.cc)

std::string ShapeString(const py::array& a);
// Any array-like of numbers → C-contiguous float64 array (a copy where needed).
py::array_t<double, py::array::c_style | py::array::forcecast> AsDoubles(py::handle h, const std::string& what);
void CheckShape(const py::array& a, std::initializer_list<py::ssize_t> shape, const std::string& what);
void CheckFinite(const double* v, py::ssize_t n, const std::string& what);
// A 4×4 rigid transform (last row [0, 0, 0, 1], rotation block orthonormal with det +1).
Eigen::Isometry3d TransformFrom(py::handle h, const std::string& what);
Eigen::Matrix3d Matrix3From(py::handle h, const std::string& what);
Eigen::Vector3d Vector3From(py::handle h, const std::string& what);
Pose6 Pose6From(py::handle h, const std::string& what);
py::array_t<double> ToNumpy(const Eigen::Isometry3d& T);
py::array_t<double> ToNumpy(const Pose6& p);
py::array_t<double> ToNumpy(const std::vector<double>& v);
// N×3 points, metres (float32 inside the library).
std::vector<Eigen::Vector3f> PointsFrom(py::handle h, const std::string& what);
py::array_t<float> ToNumpy(const std::vector<Eigen::Vector3f>& pts);
// Depth array → DepthImage. float32/float64 are metres; uint16 needs depth_scale (metres per
// unit, BOP/PNG convention). Any strides (a non-contiguous view is copied element by element).
// With a camera, the shape must be (camera.height, camera.width).
DepthImage DepthFrom(py::handle h, std::optional<double> depth_scale, const Camera* camera, const std::string& what);
py::array_t<float> ToNumpy(const DepthImage& d);
RgbImage RgbFrom(py::handle h, const std::string& what);
py::array_t<std::uint8_t> ToNumpy(const RgbImage& img);
Camera CheckedCamera(const Camera& c, const std::string& what);
std::string Repr(const Camera& c);

// N 4×4 transforms → an (N, 4, 4) float64 array.
py::array_t<double> StackPoses(const std::vector<Eigen::Isometry3d>& Ts);
// A box (centre x, y, size w, h; pixels) → the tuple (cx, cy, w, h).
py::tuple BoxTuple(const Box& b);

// ---------------------------------------------------------------- keyword options (keywords.cc)

// ---------------------------------------------------------------- keyword options

// One keyword option of an options struct: its name, a setter from a Python value and a getter.
template <class Options>
struct Keyword {
  std::string name;
  std::function<void(Options&, py::handle)> set;
  std::function<py::object(const Options&)> get;
};

template <class Options, class T>
Keyword<Options> Field(const char* name, T Options::*m) {
  return {name, [m](Options& o, py::handle h) { o.*m = h.cast<T>(); },
          [m](const Options& o) { return py::cast(o.*m); }};
}

template <class Options, class S, class T>
Keyword<Options> Nested(const char* name, S Options::*s, T S::*m) {
  return {name, [s, m](Options& o, py::handle h) { (o.*s).*m = h.cast<T>(); },
          [s, m](const Options& o) { return py::cast((o.*s).*m); }};
}

// One keyword per row of the option table (posefilter/option_table.h): the CLI name with
// '-' as '_'.
const std::vector<Keyword<FilterOptions>>& FilterKeywords();
// The Python type of an option's values, as the .pyi spells it ("int", "Sequence[float]").
std::string PythonTypeName(OptionType t);
// The start of a row's line in a docstring's keyword list: "  name: type = default, range".
std::string KeywordDocHead(const OptionInfo& f, const std::string& default_text);
// Estimator's docstring: every keyword with its type, default, range, engines and meaning.
const std::string& EstimatorDoc();
// make_synth_scene's keywords: "camera", then one per row of SynthOptionTable (the field:
// "min_distance_m"); target_mesh is make_synth_scene's own.
const std::vector<Keyword<SynthOptions>>& SynthKeywords();
// One keyword per row of TrackOptionTable, ScenePassOptionTable and AutoPriorOptionTable (the
// row's Python spelling: "lost_weight", "constant_velocity", "scene_pass_band", "auto_min_height").
const std::vector<Keyword<TrackOptions>>& TrackKeywords();
const std::vector<Keyword<ScenePassOptions>>& ScenePassKeywords();
const std::vector<Keyword<AutoPriorOptions>>& AutoPriorKeywords();

// The names of `keywords`, in order.
template <class Options>
std::vector<std::string> KeywordNames(const std::vector<Keyword<Options>>& keywords) {
  std::vector<std::string> names;
  for (const auto& k : keywords) names.push_back(k.name);
  return names;
}

template <class Options>
std::string KeywordList(const std::vector<Keyword<Options>>& keywords) {
  std::string s;
  for (const auto& k : keywords) s += (s.empty() ? "" : ", ") + k.name;
  return s;
}

// Applies keyword arguments; an unknown name or a value of the wrong type → TypeError naming it.
template <class Options>
void ApplyKeywords(Options* o, const py::kwargs& kw, const std::vector<Keyword<Options>>& keywords,
                   const std::string& what, const std::set<std::string>& skip = {}) {
  for (const auto& item : kw) {
    const std::string name = py::str(item.first);
    if (skip.count(name)) continue;
    const Keyword<Options>* k = nullptr;
    for (const auto& cand : keywords)
      if (cand.name == name) k = &cand;
    if (!k) throw py::type_error(what + ": unknown option '" + name + "' (options: " + KeywordList(keywords) + ")");
    try {
      k->set(*o, item.second);
    } catch (const py::cast_error&) {
      throw py::type_error(what + ": option '" + name + "' cannot take the value " +
                           std::string(py::repr(item.second)) + " (expected " +
                           std::string(py::str(py::type::handle_of(k->get(*o)).attr("__name__"))) + ")");
    }
  }
}

template <class Options>
py::dict KeywordDict(const Options& o, const std::vector<Keyword<Options>>& keywords) {
  py::dict d;
  for (const auto& k : keywords) d[py::str(k.name)] = k.get(o);
  return d;
}

// `o` if valid (else Error naming the keyword); warns (UserWarning) once per option set away
// from its default that o.engine does not read.
FilterOptions CheckedFilterOptions(const FilterOptions& o);

// ---------------------------------------------------------------- priors (priors.cc)

Detection DetectionFrom(py::handle h, std::size_t index);
std::vector<Detection> DetectionsFrom(py::handle h);
// Each message as a Python UserWarning (an exception if the warnings filter makes it one).
void WarnAll(const std::vector<std::string>& messages);
int ClassOf(const Prior& prior, py::handle cls);

// The stage 1 (posefilter/stage1.h) of a `prior=` argument other than None (estimator.cc): a
// Prior as it is, or 'auto' (no detector, over `meshes`, named objs), a detections JSON path or a
// list of detections (classes: objs, then the detections' others) for the objects; the
// detections' warnings as Python warnings. TypeError for another argument.
Stage1 Stage1OfPriorArg(py::handle prior_arg, const std::vector<std::string>& objs, const std::vector<const Mesh*>& meshes,
                        const SceneInput& scene);

// ---------------------------------------------------------------- the module's parts

// Camera, Mesh, shapes and poses (geometry.cc).
void BindGeometry(py::module_& m);
// Depth and image files, overlays and renderings, JSON files, metrics (io_metrics.cc).
void BindIoAndMetrics(py::module_& m);
// Detections, pyramid layouts, priors and their sampling (priors.cc).
void BindPriors(py::module_& m);
// Result, BatchResult and Estimator (estimator.cc).
void BindEstimation(py::module_& m);
// Synthetic scenes (synth.cc).
void BindSynth(py::module_& m);
// Tracker and TrackResult (tracker.cc).
void BindTracking(py::module_& m);
// Dataset targets and RunDataset (dataset.cc).
void BindDataset(py::module_& m);

}  // namespace posefilter::python
