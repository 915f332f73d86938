// python/posefilter_module.cc — the `posefilter._posefilter` extension (pybind11).
//
// A thin layer over include/posefilter/: every computation is the library's; this file only
// converts between numpy arrays and the library's types and checks what it converts.
// Conventions (docs/ALGORITHM.md §1, docs/PYTHON.md): metres, radians; depth arrays are H×W
// camera z (0 = missing);
// 4×4 poses map object → camera (T_cam_obj) unless named otherwise; a 6-vector pose is
// (x, y, z, roll, pitch, yaw), object → base, T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll) (eq. 6.2).
// Errors: posefilter::Error and every bad argument become posefilter.Error, a ValueError;
// an unknown keyword or a value of the wrong type is a TypeError.
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
#include "posefilter/camera.h"
#include "posefilter/depth_image.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "posefilter/heuristics.h"
#include "posefilter/mesh.h"
#include "posefilter/mask_prior.h"
#include "posefilter/metrics.h"
#include "posefilter/overlay.h"
#include "posefilter/pose.h"
#include "posefilter/prior.h"
#include "posefilter/projection.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/scene_io.h"
#include "posefilter/synth.h"

namespace py = pybind11;
using namespace pybind11::literals;

namespace posefilter::python {
namespace {

// ---------------------------------------------------------------- array conversions

[[noreturn]] void Fail(const std::string& message) { throw Error(message); }

std::string ShapeString(const py::array& a) {
  std::ostringstream os;
  os << "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) os << (i ? ", " : "") << a.shape(i);
  os << (a.ndim() == 1 ? ",)" : ")");
  return os.str();
}

std::string DtypeString(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// Any array-like of numbers → C-contiguous float64 array (a copy where needed).
py::array_t<double, py::array::c_style | py::array::forcecast> AsDoubles(py::handle h, const std::string& what) {
  if (py::isinstance<py::array>(h)) {
    const auto a = py::reinterpret_borrow<py::array>(h);
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
      Fail(what + ": expected a numeric array, got dtype " + DtypeString(a));
  }
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a) Fail(what + ": expected an array of numbers");
  return a;
}

void CheckShape(const py::array& a, std::initializer_list<py::ssize_t> shape, const std::string& what) {
  bool ok = a.ndim() == py::ssize_t(shape.size());
  py::ssize_t i = 0;
  for (py::ssize_t s : shape) ok = ok && a.shape(i++) == s;
  if (!ok) {
    std::ostringstream os;
    os << what << ": expected shape (";
    i = 0;
    for (py::ssize_t s : shape) os << (i++ ? ", " : "") << s;
    os << (shape.size() == 1 ? ",)" : ")") << ", got " << ShapeString(a);
    Fail(os.str());
  }
}

void CheckFinite(const double* v, py::ssize_t n, const std::string& what) {
  for (py::ssize_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) Fail(what + ": holds NaN or inf");
}

// A 4×4 rigid transform (last row [0, 0, 0, 1], rotation block orthonormal with det +1).
Eigen::Isometry3d TransformFrom(py::handle h, const std::string& what) {
  const auto a = AsDoubles(h, what);
  CheckShape(a, {4, 4}, what);
  CheckFinite(a.data(), 16, what);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = a.at(r, c);
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9)
    Fail(what + ": the last row of a 4x4 pose must be [0, 0, 0, 1]");
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-4 ||
      std::fabs(R.determinant() - 1) > 1e-4)
    Fail(what + ": the 3x3 block of a 4x4 pose must be a rotation");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = m;
  return T;
}

Eigen::Matrix3d Matrix3From(py::handle h, const std::string& what) {
  const auto a = AsDoubles(h, what);
  CheckShape(a, {3, 3}, what);
  CheckFinite(a.data(), 9, what);
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a.at(r, c);
  return m;
}

Eigen::Vector3d Vector3From(py::handle h, const std::string& what) {
  const auto a = AsDoubles(h, what);
  CheckShape(a, {3}, what);
  CheckFinite(a.data(), 3, what);
  return {a.at(0), a.at(1), a.at(2)};
}

Pose6 Pose6From(py::handle h, const std::string& what) {
  const auto a = AsDoubles(h, what);
  CheckShape(a, {6}, what);
  CheckFinite(a.data(), 6, what);
  return {a.at(0), a.at(1), a.at(2), a.at(3), a.at(4), a.at(5)};
}

py::array_t<double> ToNumpy(const Eigen::Isometry3d& T) {
  py::array_t<double> out({4, 4});
  auto o = out.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) o(r, c) = T.matrix()(r, c);
  return out;
}

py::array_t<double> ToNumpy(const Pose6& p) {
  py::array_t<double> out(6);
  double* o = out.mutable_data();
  const double v[6] = {p.x, p.y, p.z, p.roll, p.pitch, p.yaw};
  std::memcpy(o, v, sizeof v);
  return out;
}

py::array_t<double> ToNumpy(const std::vector<double>& v) {
  py::array_t<double> out(py::ssize_t(v.size()));
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(double));
  return out;
}

// N×3 points, metres (float32 inside the library).
std::vector<Eigen::Vector3f> PointsFrom(py::handle h, const std::string& what) {
  const auto a = AsDoubles(h, what);
  if (a.ndim() != 2 || a.shape(1) != 3) Fail(what + ": expected an N x 3 array, got shape " + ShapeString(a));
  CheckFinite(a.data(), a.size(), what);
  std::vector<Eigen::Vector3f> pts(a.shape(0));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) pts[i] = Eigen::Vector3f(float(a.at(i, 0)), float(a.at(i, 1)), float(a.at(i, 2)));
  return pts;
}

py::array_t<float> ToNumpy(const std::vector<Eigen::Vector3f>& pts) {
  py::array_t<float> out({py::ssize_t(pts.size()), py::ssize_t(3)});
  auto o = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (int k = 0; k < 3; ++k) o(i, k) = pts[i][k];
  return out;
}

// Depth array → DepthImage. float32/float64 are metres; uint16 needs depth_scale (metres per
// unit, BOP/PNG convention). Any strides (a non-contiguous view is copied element by element).
// With a camera, the shape must be (camera.height, camera.width).
DepthImage DepthFrom(py::handle h, std::optional<double> depth_scale, const Camera* camera, const std::string& what) {
  if (!py::isinstance<py::array>(h)) Fail(what + ": expected a numpy array (H x W), got " + std::string(py::str(py::type::handle_of(h))));
  const auto a = py::reinterpret_borrow<py::array>(h);
  if (a.ndim() != 2) Fail(what + ": expected a 2-D array (H x W), got shape " + ShapeString(a));
  const int H = int(a.shape(0)), W = int(a.shape(1));
  if (H == 0 || W == 0) Fail(what + ": empty depth image, shape " + ShapeString(a));
  if (camera && (H != camera->height || W != camera->width)) {
    std::ostringstream os;
    os << what << ": shape " << ShapeString(a) << " differs from the camera's (height, width) = (" << camera->height
       << ", " << camera->width << ")";
    Fail(os.str());
  }
  DepthImage d(W, H);
  const bool is_u16 = py::isinstance<py::array_t<std::uint16_t>>(a);
  if (is_u16) {
    if (!depth_scale) Fail(what + ": uint16 depth needs depth_scale (metres per unit)");
    if (!(std::isfinite(*depth_scale) && *depth_scale > 0)) Fail(what + ": depth_scale must be finite and > 0");
    const auto v = a.unchecked<std::uint16_t, 2>();
    for (int r = 0; r < H; ++r)
      for (int c = 0; c < W; ++c) d.at(c, r) = float(v(r, c) * *depth_scale);
    return d;
  }
  if (depth_scale) Fail(what + ": depth_scale applies to uint16 depth only (float depth is in metres)");
  auto check = [&](double z, int r, int c) {
    if (!std::isfinite(z) || z < 0) {
      std::ostringstream os;
      os << what << ": " << (std::isnan(z) ? "NaN" : std::isinf(z) ? "inf" : "negative value") << " at row " << r
         << ", column " << c << " (depth is metres, 0 = missing)";
      Fail(os.str());
    }
  };
  if (py::isinstance<py::array_t<float>>(a)) {
    const auto v = a.unchecked<float, 2>();
    for (int r = 0; r < H; ++r)
      for (int c = 0; c < W; ++c) check(v(r, c), r, c), d.at(c, r) = v(r, c);
  } else if (py::isinstance<py::array_t<double>>(a)) {
    const auto v = a.unchecked<double, 2>();
    for (int r = 0; r < H; ++r)
      for (int c = 0; c < W; ++c) check(v(r, c), r, c), d.at(c, r) = float(v(r, c));
  } else {
    Fail(what + ": dtype " + DtypeString(a) + " not supported (float32/float64 metres, or uint16 with depth_scale)");
  }
  return d;
}

py::array_t<float> ToNumpy(const DepthImage& d) {
  py::array_t<float> out({py::ssize_t(d.height), py::ssize_t(d.width)});
  if (!d.data.empty()) std::memcpy(out.mutable_data(), d.data.data(), d.data.size() * sizeof(float));
  return out;
}

RgbImage RgbFrom(py::handle h, const std::string& what) {
  if (!py::isinstance<py::array_t<std::uint8_t>>(h))
    Fail(what + ": expected a uint8 numpy array (H x W x 3)");
  const auto a = py::reinterpret_borrow<py::array>(h);
  if (a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) == 0 || a.shape(1) == 0)
    Fail(what + ": expected shape (H, W, 3), got " + ShapeString(a));
  RgbImage img(int(a.shape(1)), int(a.shape(0)));
  const auto v = a.unchecked<std::uint8_t, 3>();
  for (int r = 0; r < img.height; ++r)
    for (int c = 0; c < img.width; ++c)
      for (int k = 0; k < 3; ++k) img.px(c, r)[k] = v(r, c, k);
  return img;
}

py::array_t<std::uint8_t> ToNumpy(const RgbImage& img) {
  py::array_t<std::uint8_t> out({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
  if (!img.data.empty()) std::memcpy(out.mutable_data(), img.data.data(), img.data.size());
  return out;
}

Camera CheckedCamera(const Camera& c, const std::string& what) {
  std::string why;
  if (!c.IsValid(&why)) Fail(what + ": invalid camera: " + why);
  return c;
}

std::string Repr(const Camera& c) {
  std::ostringstream os;
  os << "Camera(fx=" << c.fx << ", fy=" << c.fy << ", cx=" << c.cx << ", cy=" << c.cy << ", width=" << c.width
     << ", height=" << c.height << ")";
  return os.str();
}

// ---------------------------------------------------------------- keyword options

// One keyword option of an options struct: its name (the C++ field, nested ones prefixed
// with their struct, e.g. inlier_thr1_m), a setter from a Python value and a getter.
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

// Every FilterOptions field (filter.h), in declaration order. python/tests/test_options.py
// checks this list against the header, so a new field cannot be forgotten here.
const std::vector<Keyword<FilterOptions>>& FilterKeywords() {
  using O = FilterOptions;
  static const std::vector<Keyword<O>> k = {
      Field("engine", &O::engine),
      Field("cpu_isa", &O::cpu_isa),
      Field("num_particles", &O::num_particles),
      Field("max_iterations", &O::max_iterations),
      Field("confidence", &O::confidence),
      Field("alpha", &O::alpha),
      Field("beta", &O::beta),
      Field("gamma", &O::gamma),
      Field("delta", &O::delta),
      Field("edge_band_m", &O::edge_band_m),
      Nested("inlier_thr1_m", &O::inlier, &InlierParams::thr1_m),
      Nested("inlier_hard", &O::inlier, &InlierParams::hard),
      Nested("inlier_hard_thr_m", &O::inlier, &InlierParams::hard_thr_m),
      Field("anneal_start_m", &O::anneal_start_m),
      Field("anneal_fraction", &O::anneal_fraction),
      Field("anneal_subsample", &O::anneal_subsample),
      Field("anneal_simplify", &O::anneal_simplify),
      Field("zbuffer", &O::zbuffer),
      Field("support_plane", &O::support_plane),
      Field("contact", &O::contact),
      Field("stable_start", &O::stable_start),
      Field("contact_tolerance_m", &O::contact_tolerance_m),
      Field("contact_span_m", &O::contact_span_m),
      Field("occlusion_aware", &O::occlusion_aware),
      Field("max_window_px", &O::max_window_px),
      Field("adaptive_resolution", &O::adaptive_resolution),
      Field("min_window_diameters", &O::min_window_diameters),
      Field("grow_window", &O::grow_window),
      Field("near_m", &O::near_m),
      Field("lod_max_faces", &O::lod_max_faces),
      Field("init_oversample", &O::init_oversample),
      Field("fine_particle_fraction", &O::fine_particle_fraction),
      Field("num_elite", &O::num_elite),
      Field("resample_pool", &O::resample_pool),
      Field("region_cap", &O::region_cap),
      Field("rotation_cap", &O::rotation_cap),
      Field("tracker_bins", &O::tracker_bins),
      Field("sigma_t0_m", &O::sigma_t0_m),
      Field("sigma_r0_rad", &O::sigma_r0_rad),
      Field("min_sigma_fraction", &O::min_sigma_fraction),
      Field("move_probabilities", &O::move_probabilities),
      Field("align_band_m", &O::align_band_m),
      Nested("heuristics_percentile_lo", &O::heuristics, &HeuristicOptions::percentile_lo),
      Nested("heuristics_percentile_hi", &O::heuristics, &HeuristicOptions::percentile_hi),
      Nested("heuristics_depth_extension_m", &O::heuristics, &HeuristicOptions::depth_extension_m),
      Nested("heuristics_max_samples", &O::heuristics, &HeuristicOptions::max_samples),
      Nested("heuristics_max_depth_m", &O::heuristics, &HeuristicOptions::max_depth_m),
      Nested("heuristics_min_valid_pixels", &O::heuristics, &HeuristicOptions::min_valid_pixels),
      Field("restarts", &O::restarts),
      Field("stall_iterations", &O::stall_iterations),
      Field("stall_gain", &O::stall_gain),
      Field("polish_steps", &O::polish_steps),
      Field("polish_turns", &O::polish_turns),
      Field("polish_pivots", &O::polish_pivots),
      Field("polish_keep", &O::polish_keep),
      Field("polish_stable", &O::polish_stable),
      Field("polish_seeds", &O::polish_seeds),
      Field("polish_climbers", &O::polish_climbers),
      Field("seed", &O::seed),
      Field("threads", &O::threads),
  };
  return k;
}

const std::vector<Keyword<SynthOptions>>& SynthKeywords() {
  using O = SynthOptions;
  static const std::vector<Keyword<O>> k = {
      Field("camera", &O::camera),
      Field("depth_scale", &O::depth_scale),
      Field("target", &O::target),
      // target_mesh (a pointer) is handled by make_synth_scene itself.
      Field("min_distance_m", &O::min_distance_m),
      Field("max_distance_m", &O::max_distance_m),
      Field("occlusion", &O::occlusion),
      Field("clutter", &O::clutter),
      Field("noise_sigma_m", &O::noise_sigma_m),
      Field("hole_fraction", &O::hole_fraction),
      Field("missing_edges", &O::missing_edges),
      Field("box_jitter_px", &O::box_jitter_px),
      Field("miss_probability", &O::miss_probability),
      Field("false_positives", &O::false_positives),
  };
  return k;
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

// FilterOptions::IsValid names fields; name the keyword where it differs from the field.
std::string NameKeywords(std::string why) {
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto p = why.find(from);
    if (p != std::string::npos) why.replace(p, from.size(), to);
    return p != std::string::npos;
  };
  if (why.rfind("heuristics: ", 0) == 0) {
    why = why.substr(12);
    for (const char* f : {"percentile_lo", "percentile_hi", "depth_extension_m", "max_samples", "max_depth_m",
                          "min_valid_pixels"})
      for (auto p = why.find(f); p != std::string::npos; p = why.find(f, p + 11 + std::strlen(f)))
        why.replace(p, std::strlen(f), std::string("heuristics_") + f);
    return why;
  }
  if (!replace("hard inlier threshold", "inlier_hard_thr_m")) replace("inlier threshold", "inlier_thr1_m");
  if (why.find("move probabilit") != std::string::npos) why += " (keyword move_probabilities)";
  return why;
}

FilterOptions CheckedFilterOptions(const FilterOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) Fail("invalid filter option: " + NameKeywords(why));
  return o;
}

// ---------------------------------------------------------------- priors

Detection DetectionFrom(py::handle h, std::size_t index) {
  if (py::isinstance<Detection>(h)) return h.cast<Detection>();
  const std::string what = "detection " + std::to_string(index);
  if (!py::isinstance<py::dict>(h)) Fail(what + ": expected a Detection or a dict {class, score, bbox}");
  const auto d = py::reinterpret_borrow<py::dict>(h);
  for (const char* key : {"class", "score", "bbox"})
    if (!d.contains(key)) Fail(what + ": missing key '" + key + "'");
  Detection det;
  try {
    det.cls = d["class"].cast<std::string>();
    det.score = d["score"].cast<double>();
  } catch (const py::cast_error&) {
    Fail(what + ": 'class' must be a string and 'score' a number");
  }
  const auto b = AsDoubles(d["bbox"], what + ": 'bbox'");
  CheckShape(b, {4}, what + ": 'bbox'");
  det.x = b.at(0), det.y = b.at(1), det.w = b.at(2), det.h = b.at(3);
  return det;
}

std::vector<Detection> DetectionsFrom(py::handle h) {
  std::vector<Detection> out;
  std::size_t i = 0;
  for (py::handle item : h) out.push_back(DetectionFrom(item, i++));
  return out;
}

// Each message as a Python UserWarning (an exception if the warnings filter makes it one).
void WarnAll(const std::vector<std::string>& messages) {
  for (const auto& m : messages)
    if (PyErr_WarnEx(PyExc_UserWarning, m.c_str(), 1) != 0) throw py::error_already_set();
}

int ClassOf(const Prior& prior, py::handle cls) {
  if (py::isinstance<py::str>(cls)) {
    const std::string name = cls.cast<std::string>();
    const int c = prior.ClassIndex(name);
    if (c < 0) Fail("class '" + name + "' is not a class of the prior");
    return c;
  }
  int c = 0;
  try {
    c = cls.cast<int>();
  } catch (const py::cast_error&) {
    throw py::type_error("class: expected a class name (str) or index (int)");
  }
  if (c < 0 || c >= prior.layout.num_classes)
    Fail("class index " + std::to_string(c) + " out of range [0, " + std::to_string(prior.layout.num_classes) + ")");
  return c;
}

// ---------------------------------------------------------------- estimation

struct BatchResult {
  std::vector<EstimateResult> items;
};

py::dict StatsDict(const FilterStats& s) {
  return py::dict("init_cdf_reads"_a = s.init_cdf_reads, "init_cdf_reads_linear"_a = s.init_cdf_reads_linear,
                  "resample_cdf_reads"_a = s.resample_cdf_reads,
                  "resample_cdf_reads_linear"_a = s.resample_cdf_reads_linear, "faces_total"_a = s.faces_total,
                  "faces_front"_a = s.faces_front, "fragments"_a = s.fragments, "weighings"_a = s.weighings);
}

class Estimator {
 public:
  explicit Estimator(const FilterOptions& o) : options_(CheckedFilterOptions(o)) {}
  const FilterOptions& options() const { return options_; }

  // See the docstring in PYBIND11_MODULE.
  py::object Estimate(py::handle depth, const Camera& camera, py::handle mesh_arg, py::handle prior_arg,
                      py::handle obj_arg, std::optional<double> depth_scale, py::handle progress,
                      py::handle mask_arg) const {
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
    for (std::size_t i = 0; i < objs.size(); ++i)
      if (objs[i].empty()) Fail("obj: mesh " + std::to_string(i) + " has no name; pass obj=...");

    // The prior: None (uniform), a Prior, a detections JSON path, or a list of detections.
    const int W = camera.width, H = camera.height;
    Prior prior;
    if (prior_arg.is_none() && !scene.mask.empty()) {
      mask.cls = objs[0];
      const auto classes = ClassesForObjects(objs, {});
      prior = PriorFromDetections({MaskDetection(mask)}, PyramidLayout::Thesis(W, H, int(classes.size())), classes);
    } else if (prior_arg.is_none()) {
      const auto classes = ClassesForObjects(objs, {});
      prior = UniformPrior(PyramidLayout::Thesis(W, H, int(classes.size())), classes);
    } else if (py::isinstance<Prior>(prior_arg)) {
      prior = prior_arg.cast<Prior>();
    } else if (py::isinstance<py::str>(prior_arg) || py::hasattr(prior_arg, "__fspath__")) {
      const std::string path = py::str(py::module_::import("os").attr("fspath")(prior_arg));
      const auto dets = ReadDetectionsJson(path);
      WarnAll(CheckDetectionsForObjects(dets, objs, W, H, path));
      const auto classes = ClassesForObjects(objs, dets);
      prior = PriorFromDetections(dets, PyramidLayout::Thesis(W, H, int(classes.size())), classes);
    } else if (py::isinstance<py::sequence>(prior_arg)) {
      const auto dets = DetectionsFrom(prior_arg);
      WarnAll(CheckDetectionsForObjects(dets, objs, W, H, "prior"));
      const auto classes = ClassesForObjects(objs, dets);
      prior = PriorFromDetections(dets, PyramidLayout::Thesis(W, H, int(classes.size())), classes);
    } else {
      throw py::type_error("prior: expected None, a Prior, a detections JSON path or a list of detections");
    }
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
      for (std::size_t i = 0; i < meshes.size(); ++i) {
        const std::string& name = objs[i];
        const ProgressFn fn = [&callback, &name](int it, double w) {
          py::gil_scoped_acquire acquire;
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (!callback.is_none()) callback(name, it, w);
        };
        out.items.push_back(EstimatePose(scene, meshes[i], prior, cls[i], options_, fn));
        out.items.back().obj = name;
      }
    }
    if (!batch) return py::cast(std::move(out.items[0]));
    return py::cast(std::move(out));
  }

 private:
  FilterOptions options_;
};

// ---------------------------------------------------------------- synthetic scenes

SynthScene MakeScene(std::uint64_t seed, const py::kwargs& kw) {
  SynthOptions opt;
  ApplyKeywords(&opt, kw, SynthKeywords(), "make_synth_scene", {"target_mesh"});
  Mesh target_mesh;
  const py::object tm = kw.contains("target_mesh") ? py::object(kw["target_mesh"]) : py::object(py::none());
  if (!tm.is_none()) {
    if (!py::isinstance<Mesh>(tm)) throw py::type_error("make_synth_scene: target_mesh must be a Mesh");
    target_mesh = tm.cast<Mesh>();
    opt.target_mesh = &target_mesh;
  }
  std::string why;
  if (!opt.IsValid(&why)) Fail("make_synth_scene: invalid option: " + why);
  py::gil_scoped_release release;
  return MakeSynthScene(opt, seed);
}

py::array_t<double> StackPoses(const std::vector<Eigen::Isometry3d>& Ts) {
  py::array_t<double> out({py::ssize_t(Ts.size()), py::ssize_t(4), py::ssize_t(4)});
  auto o = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < Ts.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) o(i, r, c) = Ts[i].matrix()(r, c);
  return out;
}

py::tuple BoxTuple(const Box& b) { return py::make_tuple(b.cx, b.cy, b.w, b.h); }

}  // namespace
}  // namespace posefilter::python

// ================================================================ the module

PYBIND11_MODULE(_posefilter, m) {
  using namespace posefilter;
  using namespace posefilter::python;
  m.doc() = "posefilter: 6-DoF object pose estimation with a rendering particle filter (C++ core).";

  // posefilter::Error → posefilter.Error, a ValueError (bad input: files, arrays, options).
  py::register_exception<Error>(m, "Error", PyExc_ValueError);

  // ---- Camera
  py::class_<Camera>(m, "Camera", "Pinhole camera (OpenCV frame): intrinsics in pixels, base_to_camera 4x4.")
      .def(py::init([](double fx, double fy, double cx, double cy, int width, int height, py::object base_to_camera) {
             Camera c;
             c.fx = fx, c.fy = fy, c.cx = cx, c.cy = cy, c.width = width, c.height = height;
             if (!base_to_camera.is_none()) c.base_to_camera = TransformFrom(base_to_camera, "base_to_camera");
             return CheckedCamera(c, "Camera");
           }),
           py::kw_only(), "fx"_a = Camera{}.fx, "fy"_a = Camera{}.fy, "cx"_a = Camera{}.cx, "cy"_a = Camera{}.cy,
           "width"_a = Camera{}.width, "height"_a = Camera{}.height, "base_to_camera"_a = py::none())
      .def_readonly("fx", &Camera::fx)
      .def_readonly("fy", &Camera::fy)
      .def_readonly("cx", &Camera::cx)
      .def_readonly("cy", &Camera::cy)
      .def_readonly("width", &Camera::width)
      .def_readonly("height", &Camera::height)
      .def_property_readonly("base_to_camera", [](const Camera& c) { return ToNumpy(c.base_to_camera); })
      .def_property_readonly("K", [](const Camera& c) {
        py::array_t<double> K({3, 3});
        auto k = K.mutable_unchecked<2>();
        const double v[3][3] = {{c.fx, 0, c.cx}, {0, c.fy, c.cy}, {0, 0, 1}};
        for (int r = 0; r < 3; ++r)
          for (int q = 0; q < 3; ++q) k(r, q) = v[r][q];
        return K;
      })
      .def("project", [](const Camera& c, py::handle p) {
             const auto pts = PointsFrom(p, "points");
             py::array_t<double> out({py::ssize_t(pts.size()), py::ssize_t(2)});
             auto o = out.mutable_unchecked<2>();
             for (std::size_t i = 0; i < pts.size(); ++i) {
               if (!(pts[i].z() > 0)) Fail("points: point " + std::to_string(i) + " has z <= 0");
               const Eigen::Vector2d uv = c.Project(pts[i].cast<double>());
               o(i, 0) = uv.x(), o(i, 1) = uv.y();
             }
             return out;
           }, "points"_a, "Camera-frame points (N x 3, metres, z > 0) → pixels (N x 2, u = column, v = row).")
      .def("__repr__", [](const Camera& c) { return Repr(c); })
      .def(py::pickle([](const Camera& c) { return py::make_tuple(c.fx, c.fy, c.cx, c.cy, c.width, c.height, ToNumpy(c.base_to_camera)); },
                      [](py::tuple t) {
                        Camera c;
                        c.fx = t[0].cast<double>(), c.fy = t[1].cast<double>(), c.cx = t[2].cast<double>(), c.cy = t[3].cast<double>();
                        c.width = t[4].cast<int>(), c.height = t[5].cast<int>();
                        c.base_to_camera = TransformFrom(t[6], "base_to_camera");
                        return c;
                      }));

  // ---- Mesh
  py::class_<Mesh>(m, "Mesh", "Triangle mesh, object frame, metres; faces CCW seen from outside.")
      .def(py::init([](py::handle vertices, py::handle faces, const std::string& name) {
             Mesh mesh;
             mesh.name = name;
             mesh.vertices = PointsFrom(vertices, "vertices");
             if (!py::isinstance<py::array>(faces) && !py::isinstance<py::sequence>(faces)) Fail("faces: expected an M x 3 integer array");
             const auto fa = py::array::ensure(faces);
             if (!fa || (fa.dtype().kind() != 'i' && fa.dtype().kind() != 'u'))
               Fail("faces: expected an M x 3 integer array");
             const auto f = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(fa);
             if (f.ndim() != 2 || f.shape(1) != 3) Fail("faces: expected an M x 3 array, got shape " + ShapeString(f));
             for (py::ssize_t i = 0; i < f.shape(0); ++i) {
               std::array<std::uint32_t, 3> tri{};
               for (int k = 0; k < 3; ++k) {
                 const std::int64_t v = f.at(i, k);
                 if (v < 0 || v >= std::int64_t(mesh.vertices.size()))
                   Fail("faces: face " + std::to_string(i) + " indexes vertex " + std::to_string(v) + " of " +
                        std::to_string(mesh.vertices.size()));
                 tri[k] = std::uint32_t(v);
               }
               mesh.faces.push_back(tri);
             }
             std::string why;
             if (!mesh.IsValid(&why)) Fail("Mesh '" + name + "': " + why);
             return mesh;
           }),
           "vertices"_a, "faces"_a, "name"_a = "mesh")
      .def_readwrite("name", &Mesh::name, "object/class name (the prior class it is looked up as)")
      .def_property_readonly("vertices", [](const Mesh& s) { return ToNumpy(s.vertices); }, "V x 3 float32, metres (copy)")
      .def_property_readonly("faces", [](const Mesh& s) {
        py::array_t<std::uint32_t> out({py::ssize_t(s.faces.size()), py::ssize_t(3)});
        if (!s.faces.empty()) std::memcpy(out.mutable_data(), s.faces.data(), s.faces.size() * 3 * sizeof(std::uint32_t));
        return out;
      }, "F x 3 uint32 (copy)")
      .def("diameter", &Mesh::Diameter, "largest vertex distance, metres")
      .def("bounds", [](const Mesh& s) {
        const Eigen::Vector3f lo = s.Min(), hi = s.Max();
        return py::make_tuple(py::array_t<float>(3, lo.data()), py::array_t<float>(3, hi.data()));
      }, "(min, max) corners of the axis-aligned bounds, object frame, metres")
      .def("save_ply", [](const Mesh& s, const std::string& path) { SaveMeshPly(s, path); }, "path"_a)
      .def("__repr__", [](const Mesh& s) {
        return "Mesh('" + s.name + "', " + std::to_string(s.vertices.size()) + " vertices, " +
               std::to_string(s.faces.size()) + " faces)";
      });

  m.def("load_mesh", [](py::handle path, py::handle units, std::optional<std::string> name) {
    double scale = 1.0;
    if (py::isinstance<py::str>(units)) {
      const std::string u = units.cast<std::string>();
      if (u == "m") scale = 1.0;
      else if (u == "cm") scale = 0.01;
      else if (u == "mm") scale = 0.001;
      else Fail("load_mesh: units must be 'm', 'cm', 'mm' or a positive number (got '" + u + "')");
    } else {
      try {
        scale = units.cast<double>();
      } catch (const py::cast_error&) {
        throw py::type_error("load_mesh: units must be 'm', 'cm', 'mm' or a number");
      }
      if (!(std::isfinite(scale) && scale > 0)) Fail("load_mesh: units must be a finite number > 0");
    }
    Mesh mesh = LoadMesh(py::str(py::module_::import("os").attr("fspath")(path)), scale);
    if (name) mesh.name = *name;
    return mesh;
  }, "path"_a, "units"_a = 1.0, "name"_a = py::none(),
        "Loads a PLY/OBJ/STL mesh; units: 'm', 'cm', 'mm' or metres per file unit. Name defaults to the file stem.");
  m.def("make_box", &MakeBox, "sx"_a, "sy"_a, "sz"_a, "name"_a = "box", "Box of side lengths sx, sy, sz (metres).");
  m.def("make_cylinder", &MakeCylinder, "radius"_a, "height"_a, "segments"_a = 32, "name"_a = "cylinder");
  m.def("make_lshape", &MakeLShape, "size"_a, "thickness"_a, "depth"_a, "name"_a = "lshape");
  m.def("make_torus", &MakeTorus, "major_r"_a, "minor_r"_a, "nu"_a = 32, "nv"_a = 32, "name"_a = "torus");
  m.def("make_shape", &MakeShape, "kind"_a, "One of synth_class_names() with its default size.");
  m.def("synth_class_names", &SynthClassNames);

  // ---- Poses
  m.def("pose_to_transform", [](py::handle p) { return ToNumpy(PoseToTransform(Pose6From(p, "pose"))); }, "pose"_a,
        "(x, y, z, roll, pitch, yaw) → 4x4, T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll) (eq. 6.2).");
  m.def("transform_to_pose", [](py::handle T) { return ToNumpy(TransformToPose(TransformFrom(T, "T"))); }, "T"_a,
        "4x4 → (x, y, z, roll, pitch, yaw), pitch in [-pi/2, pi/2].");
  m.def("wrap_angle", &WrapAngle, "a"_a, "Angle wrapped to (-pi, pi].");

  // ---- Depth and images
  m.def("load_depth_png", [](const std::string& path, double depth_scale) { return ToNumpy(LoadDepthPng(path, depth_scale)); },
        "path"_a, "depth_scale"_a, "16-bit PNG → H x W float32 metres (value × depth_scale; 0 = missing).");
  m.def("save_depth_png", [](py::handle depth, const std::string& path, double depth_scale) {
    SaveDepthPng(DepthFrom(depth, std::nullopt, nullptr, "depth"), path, depth_scale);
  }, "depth"_a, "path"_a, "depth_scale"_a, "H x W metres → 16-bit PNG, value = round(metres / depth_scale).");
  m.def("load_rgb_png", [](const std::string& path) { return ToNumpy(LoadRgbPng(path)); }, "path"_a);
  m.def("save_rgb_png", [](py::handle img, const std::string& path) { SaveRgbPng(RgbFrom(img, "image"), path); },
        "image"_a, "path"_a);
  m.def("shade_depth", [](py::handle depth) { return ToNumpy(ShadeDepth(DepthFrom(depth, std::nullopt, nullptr, "depth"))); },
        "depth"_a, "Grey shading (H x W x 3 uint8): near bright, far dark, missing black.");
  m.def("draw_pose_overlay", [](py::handle image, const Mesh& mesh, py::handle T, const Camera& camera,
                                std::array<std::uint8_t, 3> color) {
    RgbImage img = RgbFrom(image, "image");
    CheckedCamera(camera, "camera");
    if (img.width != camera.width || img.height != camera.height) Fail("image: size differs from the camera's");
    DrawPoseOverlay(&img, mesh, TransformFrom(T, "T_cam_obj"), camera, color);
    return ToNumpy(img);
  }, "image"_a, "mesh"_a, "T_cam_obj"_a, "camera"_a, "color"_a = std::array<std::uint8_t, 3>{40, 220, 60},
        "A copy of image with mesh drawn at T_cam_obj: tinted silhouette and outline in color.");
  m.def("render_depth", [](const Mesh& mesh, py::handle T, const Camera& camera, py::handle depth) {
    CheckedCamera(camera, "camera");
    DepthImage d = depth.is_none() ? DepthImage(camera.width, camera.height) : DepthFrom(depth, std::nullopt, &camera, "depth");
    const Eigen::Isometry3d T_cam_obj = TransformFrom(T, "T_cam_obj");
    std::vector<int> labels(std::size_t(camera.width) * camera.height, 0);
    RenderDepth(mesh, T_cam_obj, camera, &d, &labels, 1);
    py::array_t<bool> mask({py::ssize_t(camera.height), py::ssize_t(camera.width)});
    bool* mk = mask.mutable_data();
    for (std::size_t i = 0; i < labels.size(); ++i) mk[i] = labels[i] == 1;
    return py::make_tuple(ToNumpy(d), mask);
  }, "mesh"_a, "T_cam_obj"_a, "camera"_a, "depth"_a = py::none(),
        "Renders mesh over depth (default empty) with a z-test: (depth H x W float32, mask of the pixels it won).");
  m.def("projected_box", [](const Mesh& mesh, py::handle T, const Camera& camera) {
    return BoxTuple(ProjectedBox(mesh, TransformFrom(T, "T_cam_obj"), camera));
  }, "mesh"_a, "T_cam_obj"_a, "camera"_a, "Bounding box (cx, cy, w, h) of the rendered silhouette, pixels (w = h = 0: not visible).");

  // ---- JSON files
  m.def("read_camera_json", [](const std::string& path) {
    const CameraFile f = ReadCameraJson(path);
    return py::make_tuple(f.camera, f.depth_scale);
  }, "path"_a, "→ (Camera, depth_scale).");
  m.def("write_camera_json", [](const Camera& c, const std::string& path, double depth_scale) {
    WriteCameraJson(CameraFile{c, depth_scale}, path);
  }, "camera"_a, "path"_a, "depth_scale"_a);
  m.def("read_gt_json", [](const std::string& path) {
    py::list out;
    for (const auto& g : ReadGtJson(path)) out.append(py::make_tuple(g.obj, ToNumpy(g.T_cam_obj)));
    return out;
  }, "path"_a, "→ [(obj, T_cam_obj 4x4)].");
  m.def("write_gt_json", [](py::handle objects, const std::string& path) {
    std::vector<GtObject> gt;
    for (py::handle o : objects) {
      if (!py::isinstance<py::sequence>(o) || py::isinstance<py::str>(o) || py::len(o) != 2 ||
          !py::isinstance<py::str>(o[py::int_(0)]))
        Fail("write_gt_json: expected (obj, T_cam_obj) pairs");
      gt.push_back({o[py::int_(0)].cast<std::string>(), TransformFrom(o[py::int_(1)], "T_cam_obj")});
    }
    WriteGtJson(gt, path);
  }, "objects"_a, "path"_a);
  m.def("read_results_json", [](const std::string& path) {
    py::list out;
    for (const auto& r : ReadResultsJson(path))
      out.append(py::dict("obj"_a = r.obj, "pose6"_a = ToNumpy(r.pose_base), "T_cam_obj"_a = ToNumpy(r.T_cam_obj),
                          "weight"_a = r.weight, "iterations"_a = r.iterations, "time_ms"_a = r.time_ms));
    return out;
  }, "path"_a, "results.json of `posefilter estimate` → list of dicts (obj, pose6, T_cam_obj, weight, iterations, time_ms).");

  // ---- Metrics
  py::class_<PoseErrors>(m, "PoseErrors", "Errors of one estimate (metres, degrees).")
      .def_readonly("add", &PoseErrors::add)
      .def_readonly("adds", &PoseErrors::adds)
      .def_readonly("rot_deg", &PoseErrors::rot_deg)
      .def_readonly("trans_m", &PoseErrors::trans_m)
      .def_readonly("diameter", &PoseErrors::diameter)
      .def_readonly("add_ok", &PoseErrors::add_ok)
      .def_readonly("adds_ok", &PoseErrors::adds_ok)
      .def("__repr__", [](const PoseErrors& e) {
        std::ostringstream os;
        os << std::boolalpha << "PoseErrors(add=" << e.add << ", adds=" << e.adds << ", rot_deg=" << e.rot_deg << ", trans_m=" << e.trans_m
           << ", diameter=" << e.diameter << ", add_ok=" << e.add_ok << ", adds_ok=" << e.adds_ok << ")";
        return os.str();
      });
  auto model_points = [](py::handle model) {
    return py::isinstance<Mesh>(model) ? SamplePoints(model.cast<const Mesh&>()) : PointsFrom(model, "points");
  };
  m.def("add_error", [model_points](py::handle model, py::handle Te, py::handle Tg) {
    return AddError(model_points(model), TransformFrom(Te, "T_est"), TransformFrom(Tg, "T_gt"));
  }, "model"_a, "T_est"_a, "T_gt"_a, "ADD, metres; model = Mesh (its sampled vertices) or N x 3 points.");
  m.def("adds_error", [model_points](py::handle model, py::handle Te, py::handle Tg) {
    return AddSError(model_points(model), TransformFrom(Te, "T_est"), TransformFrom(Tg, "T_gt"));
  }, "model"_a, "T_est"_a, "T_gt"_a, "ADD-S, metres.");
  m.def("rotation_error_deg", [](py::handle Re, py::handle Rg) {
    return RotationErrorDeg(Matrix3From(Re, "R_est"), Matrix3From(Rg, "R_gt"));
  }, "R_est"_a, "R_gt"_a);
  m.def("translation_error", [](py::handle te, py::handle tg) {
    return TranslationError(Vector3From(te, "t_est"), Vector3From(tg, "t_gt"));
  }, "t_est"_a, "t_gt"_a, "metres");
  m.def("pose_errors", [model_points](py::handle model, py::handle Te, py::handle Tg, double threshold, std::optional<double> diameter) {
    if (!diameter) {
      if (!py::isinstance<Mesh>(model)) Fail("pose_errors: give diameter= (metres) with a point array");
      diameter = model.cast<const Mesh&>().Diameter();
    }
    return ComputePoseErrors(model_points(model), *diameter, TransformFrom(Te, "T_est"), TransformFrom(Tg, "T_gt"), threshold);
  }, "model"_a, "T_est"_a, "T_gt"_a, "threshold"_a = 0.1, "diameter"_a = py::none(),
        "ADD, ADD-S, rotation/translation errors; ok = error < threshold·diameter (default the mesh's).");
  m.def("sample_points", [](const Mesh& mesh, int max_points) { return ToNumpy(SamplePoints(mesh, max_points)); },
        "mesh"_a, "max_points"_a = 2000);
  m.def("read_xyz_points", [](const std::string& path) { return ToNumpy(ReadXyzPoints(path)); }, "path"_a);

  // ---- Priors
  py::class_<Detection>(m, "Detection", "A 2D detection: class, score in [0, 1], bbox top-left (x, y) and size (w, h), pixels.")
      .def(py::init([](const std::string& cls, double score, py::handle bbox) {
             Detection d;
             d.cls = cls, d.score = score;
             const auto b = AsDoubles(bbox, "bbox");
             CheckShape(b, {4}, "bbox");
             d.x = b.at(0), d.y = b.at(1), d.w = b.at(2), d.h = b.at(3);
             return d;
           }),
           "cls"_a, "score"_a, "bbox"_a)
      .def_readwrite("cls", &Detection::cls)
      .def_readwrite("score", &Detection::score)
      .def_property_readonly("bbox", [](const Detection& d) { return py::make_tuple(d.x, d.y, d.w, d.h); })
      .def("__repr__", [](const Detection& d) {
        std::ostringstream os;
        os << "Detection('" << d.cls << "', " << d.score << ", (" << d.x << ", " << d.y << ", " << d.w << ", " << d.h << "))";
        return os.str();
      });

  py::class_<PyramidLayout>(m, "PyramidLayout", "Grid levels of the prior (thesis: 15x20, 30x40, 60x80 cells).")
      .def_static("thesis", &PyramidLayout::Thesis, "image_width"_a = 640, "image_height"_a = 480, "num_classes"_a = 21)
      .def_readonly("image_width", &PyramidLayout::image_width)
      .def_readonly("image_height", &PyramidLayout::image_height)
      .def_readonly("num_classes", &PyramidLayout::num_classes)
      .def_property_readonly("levels", [](const PyramidLayout& l) {
        py::list out;
        for (const auto& v : l.levels) out.append(py::make_tuple(v.rows, v.cols, v.anchor_w, v.anchor_h));
        return out;
      }, "[(rows, cols, anchor_w, anchor_h)] coarse to fine")
      .def("cell_count", &PyramidLayout::CellCount)
      .def("level_offset", &PyramidLayout::LevelOffset, "level"_a)
      .def("cell_row_col", [](const PyramidLayout& l, int cell) {
        int level = 0, row = 0, col = 0;
        l.CellRowCol(cell, &level, &row, &col);
        return py::make_tuple(level, row, col);
      }, "cell"_a, "→ (level, row, col)")
      .def("cell_index", &PyramidLayout::CellIndex, "level"_a, "row"_a, "col"_a)
      .def("anchor_box", [](const PyramidLayout& l, int cell) { return BoxTuple(l.AnchorBox(cell)); }, "cell"_a);

  py::class_<Prior>(m, "Prior", "Post-processed stage-1 prior: per cell a box and a probability per class.")
      .def_readonly("layout", &Prior::layout)
      .def_readonly("classes", &Prior::classes)
      .def_property_readonly("prob", [](const Prior& p) {
        py::array_t<float> out({py::ssize_t(p.layout.CellCount()), py::ssize_t(p.layout.num_classes)});
        std::memcpy(out.mutable_data(), p.prob.data(), p.prob.size() * sizeof(float));
        return out;
      }, "cells x classes float32: Prob (eq. 7.1–7.2) (copy)")
      .def_property_readonly("boxes", [](const Prior& p) {
        py::array_t<double> out({py::ssize_t(p.boxes.size()), py::ssize_t(4)});
        auto o = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < p.boxes.size(); ++i)
          o(i, 0) = p.boxes[i].cx, o(i, 1) = p.boxes[i].cy, o(i, 2) = p.boxes[i].w, o(i, 3) = p.boxes[i].h;
        return out;
      }, "cells x 4 float64: decoded box (cx, cy, w, h), pixels")
      .def("class_index", &Prior::ClassIndex, "name"_a, "-1 if absent")
      .def("class_mass", [](const Prior& p, py::handle cls) { return p.ClassMass(ClassOf(p, cls)); }, "cls"_a)
      .def("level_grid", [](const Prior& p, py::handle cls, int level) {
        const int c = ClassOf(p, cls);
        if (level < 0 || level >= int(p.layout.levels.size()))
          Fail("level " + std::to_string(level) + " out of range [0, " + std::to_string(p.layout.levels.size()) + ")");
        const PyramidLevel& L = p.layout.levels[level];
        py::array_t<float> out({py::ssize_t(L.rows), py::ssize_t(L.cols)});
        auto o = out.mutable_unchecked<2>();
        for (int r = 0; r < L.rows; ++r)
          for (int q = 0; q < L.cols; ++q) o(r, q) = p.Prob(p.layout.CellIndex(level, r, q), c);
        return out;
      }, "cls"_a, "level"_a, "Probabilities of one class on one level's grid (rows x cols).")
      .def("__repr__", [](const Prior& p) {
        return "Prior(" + std::to_string(p.layout.CellCount()) + " cells, " + std::to_string(p.classes.size()) + " classes)";
      });

  auto layout_for = [](py::handle layout_or_camera, int num_classes) {
    if (py::isinstance<PyramidLayout>(layout_or_camera)) return layout_or_camera.cast<PyramidLayout>();
    if (py::isinstance<Camera>(layout_or_camera)) {
      const auto& c = layout_or_camera.cast<const Camera&>();
      return PyramidLayout::Thesis(c.width, c.height, num_classes);
    }
    throw py::type_error("layout: expected a PyramidLayout or a Camera (thesis pyramid over its image)");
  };
  m.def("prior_from_detections", [layout_for](py::handle detections, py::handle layout, std::optional<std::vector<std::string>> classes,
                                              double floor_prob, double max_box_px) {
    const auto dets = DetectionsFrom(detections);
    const auto cls = classes ? *classes : ClassesForObjects({}, dets);
    DetectionPriorOptions opt;
    opt.floor_prob = floor_prob, opt.max_box_px = max_box_px;
    return PriorFromDetections(dets, layout_for(layout, int(cls.size())), cls, opt);
  }, "detections"_a, "layout"_a, "classes"_a = py::none(), "floor_prob"_a = DetectionPriorOptions{}.floor_prob,
        "max_box_px"_a = DetectionPriorOptions{}.max_box_px,
        "Detections (Detection or {class, score, bbox}) → Prior; layout = PyramidLayout or Camera; "
        "classes default to the detections' classes.");
  m.def("detections_to_raw_pyramid", [layout_for](py::handle detections, py::handle layout, const std::vector<std::string>& classes,
                                                  double floor_prob, double max_box_px) {
    DetectionPriorOptions opt;
    opt.floor_prob = floor_prob, opt.max_box_px = max_box_px;
    const auto raw = DetectionsToRawPyramid(DetectionsFrom(detections), layout_for(layout, int(classes.size())), classes, opt);
    return py::array_t<float>(py::ssize_t(raw.size()), raw.data());
  }, "detections"_a, "layout"_a, "classes"_a, "floor_prob"_a = DetectionPriorOptions{}.floor_prob,
        "max_box_px"_a = DetectionPriorOptions{}.max_box_px);
  m.def("post_process_pyramid", [layout_for](py::handle raw, py::handle layout, const std::vector<std::string>& classes, double max_box_px) {
    const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(raw);
    if (!a) Fail("raw: expected an array of float32");
    PostProcessOptions opt;
    opt.max_box_px = max_box_px;
    return PostProcessPyramid(std::vector<float>(a.data(), a.data() + a.size()), layout_for(layout, int(classes.size())), classes, opt);
  }, "raw"_a, "layout"_a, "classes"_a, "max_box_px"_a = PostProcessOptions{}.max_box_px,
        "Raw pyramid (cells x (classes + 5) float32, thesis layout) → Prior (eq. 7.1–7.2).");
  m.def("read_raw_pyramid", [layout_for](const std::string& path, py::handle layout, const std::vector<std::string>& classes) {
    const auto raw = ReadRawPyramid(path, layout_for(layout, int(classes.size())));
    return py::array_t<float>(py::ssize_t(raw.size()), raw.data());
  }, "path"_a, "layout"_a, "classes"_a);
  m.def("uniform_prior", [layout_for](py::handle layout, const std::vector<std::string>& classes) {
    return UniformPrior(layout_for(layout, int(classes.size())), classes);
  }, "layout"_a, "classes"_a);
  m.def("read_detections_json", [](const std::string& path, bool allow_empty) { return ReadDetectionsJson(path, allow_empty); },
        "path"_a, "allow_empty"_a = false);
  m.def("write_detections_json", [](py::handle detections, const std::string& path) {
    WriteDetectionsJson(DetectionsFrom(detections), path);
  }, "detections"_a, "path"_a);
  m.def("ycbv_class_names", &YcbVideoClassNames);

  // The initialisation's importance sampling (thesis §7.4, eq. 7.3): CDF of the class's cell
  // probabilities and `n` cells drawn from it with the filter's CDF sampler and threshold tracker.
  m.def("sample_cells", [](const Prior& prior, py::handle cls, int n, std::uint64_t seed, int tracker_bins,
                           py::handle depth, std::optional<Camera> camera, std::optional<double> depth_scale) {
    const int c = ClassOf(prior, cls);
    if (n < 1) Fail("sample_cells: n must be >= 1");
    if (tracker_bins < 1) Fail("sample_cells: tracker_bins must be >= 1");
    std::vector<double> w(prior.layout.CellCount());
    for (int i = 0; i < prior.layout.CellCount(); ++i) w[i] = prior.Prob(i, c);
    if (!depth.is_none()) {
      // As EstimatePose: a cell without a heuristic volume (too little depth in its box) has no mass.
      if (!camera) Fail("sample_cells: depth needs camera=");
      const auto volumes = ComputeHeuristics(DepthFrom(depth, depth_scale, &*camera, "depth"), *camera, prior.boxes);
      for (std::size_t i = 0; i < w.size(); ++i)
        if (!volumes[i].valid) w[i] = 0;
    }
    filter::CdfSampler sampler(w, tracker_bins);
    Rng rng(seed);
    py::array_t<std::int32_t> cells(n);
    auto* out = cells.mutable_data();
    for (int i = 0; i < n; ++i) out[i] = sampler.Sample(1.0 - rng.Uniform());
    return py::dict("cells"_a = cells, "cdf"_a = ToNumpy(sampler.cdf()), "weights"_a = ToNumpy(w),
                    "reads"_a = sampler.reads(), "reads_linear"_a = sampler.reads_linear());
  }, "prior"_a, "cls"_a, "n"_a, "seed"_a = 1, "tracker_bins"_a = FilterOptions{}.tracker_bins, "depth"_a = py::none(),
        "camera"_a = py::none(), "depth_scale"_a = py::none(),
        "Importance sampling of cells as the filter's initialisation does it (§7.4): → dict(cells, cdf, weights, "
        "reads, reads_linear). With depth and camera, cells without a heuristic volume get no mass.");

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
      .def("__repr__", [](const BatchResult& b) { return "BatchResult(" + std::to_string(b.items.size()) + " objects)"; });

  py::class_<Estimator>(m, "Estimator",
                        "The particle filter with fixed options. Estimator(**options): keyword = FilterOptions field "
                        "(nested: inlier_*, heuristics_*); see Estimator.defaults().")
      .def(py::init([](const py::kwargs& kw) {
        FilterOptions o;
        ApplyKeywords(&o, kw, FilterKeywords(), "Estimator");
        return Estimator(o);
      }))
      .def_property_readonly("options", [](const Estimator& e) { return KeywordDict(e.options(), FilterKeywords()); },
                             "dict of every option")
      .def_static("defaults", [] { return KeywordDict(FilterOptions{}, FilterKeywords()); }, "dict of the default options")
      .def_static("option_names", [] {
        std::vector<std::string> n;
        for (const auto& k : FilterKeywords()) n.push_back(k.name);
        return n;
      })
      .def("estimate", &Estimator::Estimate, "depth"_a, "camera"_a, "mesh"_a, "prior"_a = py::none(), py::kw_only(),
           "obj"_a = py::none(), "depth_scale"_a = py::none(), "progress"_a = py::none(), "mask"_a = py::none(),
           "Pose(s) of mesh (a Mesh → Result; a list of Mesh → BatchResult) in depth (H x W float metres, or "
           "uint16 with depth_scale). prior: None (uniform, or the mask's box), a Prior, a detections JSON path, "
           "or a list of Detection/dicts. obj: prior class name(s), default the meshes' names. mask: the "
           "object's instance mask (H x W, non-zero = the object; one Mesh), scored against. progress(obj, "
           "iteration, best_weight) is called after each iteration. Runs without the GIL.")
      .def("__repr__", [](const Estimator& e) {
        const auto& o = e.options();
        return "Estimator(num_particles=" + std::to_string(o.num_particles) + ", max_iterations=" +
               std::to_string(o.max_iterations) + ", restarts=" + std::to_string(o.restarts) + ", seed=" +
               std::to_string(o.seed) + ", ...)";
      });

  // ---- Synthetic scenes
  py::class_<SynthScene>(m, "SynthScene", "A synthetic scene with ground truth and a stage-1 prior.")
      .def_property_readonly("depth", [](const SynthScene& s) { return ToNumpy(s.depth); }, "H x W float32 metres")
      .def_readonly("camera", &SynthScene::camera)
      .def_readonly("depth_scale", &SynthScene::depth_scale)
      .def_property_readonly("labels", [](const SynthScene& s) {
        py::array_t<std::int32_t> out({py::ssize_t(s.depth.height), py::ssize_t(s.depth.width)});
        std::int32_t* o = out.mutable_data();
        for (std::size_t i = 0; i < s.labels.size(); ++i) o[i] = s.labels[i];
        return out;
      }, "H x W int32: 0 background/table, 1 target, 2 occluder, 3.. clutter")
      .def_property_readonly("gt_poses", [](const SynthScene& s) {
        std::vector<Eigen::Isometry3d> Ts;
        for (const auto& g : s.gt) Ts.push_back(g.T_cam_obj);
        return StackPoses(Ts);
      }, "N x 4 x 4 ground-truth T_cam_obj")
      .def_property_readonly("gt_objs", [](const SynthScene& s) {
        std::vector<std::string> o;
        for (const auto& g : s.gt) o.push_back(g.obj);
        return o;
      })
      .def_readonly("target", &SynthScene::target)
      .def_readonly("classes", &SynthScene::classes)
      .def_readonly("detections", &SynthScene::detections)
      .def_readonly("layout", &SynthScene::layout)
      .def_property_readonly("raw_pyramid", [](const SynthScene& s) {
        return py::array_t<float>(py::ssize_t(s.raw_pyramid.size()), s.raw_pyramid.data());
      })
      .def_property_readonly("prior", [](const SynthScene& s) { return PostProcessPyramid(s.raw_pyramid, s.layout, s.classes); },
                             "PostProcessPyramid of raw_pyramid (a new Prior each access)")
      .def_property_readonly("gt_box", [](const SynthScene& s) { return BoxTuple(s.gt_box); })
      .def_readonly("distance_m", &SynthScene::distance_m)
      .def_readonly("table_angle_rad", &SynthScene::table_angle_rad)
      .def_readonly("occlusion_achieved", &SynthScene::occlusion_achieved)
      .def_readonly("target_detected", &SynthScene::target_detected)
      .def("write", [](const SynthScene& s, const std::string& dir) { WriteSynthScene(s, dir); }, "dir"_a,
           "Writes depth.png, camera.json, gt.json, the mesh, detections.json, prior.pyr, ... to dir.")
      .def("__repr__", [](const SynthScene& s) {
        std::ostringstream os;
        os << "SynthScene(target='" << s.target.name << "', distance_m=" << s.distance_m
           << ", occlusion_achieved=" << s.occlusion_achieved << ", " << s.detections.size() << " detections)";
        return os.str();
      });
  m.def("make_synth_scene", &MakeScene, "seed"_a = 0,
        "Synthetic table-top scene (deterministic per seed). Keywords = SynthOptions fields: camera, depth_scale, "
        "target, target_mesh, min_distance_m, max_distance_m, occlusion, clutter, noise_sigma_m, hole_fraction, "
        "missing_edges, box_jitter_px, miss_probability, false_positives.");
  m.def("synth_option_names", [] {
    std::vector<std::string> n;
    for (const auto& k : SynthKeywords()) n.push_back(k.name);
    n.push_back("target_mesh");
    return n;
  });
}
