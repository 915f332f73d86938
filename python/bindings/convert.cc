// python/bindings/convert.cc — numpy arrays and Python values ↔ the library's types, checked (shapes, dtypes, finite values).
#include "bindings.h"

namespace posefilter::python {

// ---------------------------------------------------------------- array conversions


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

py::array_t<double> StackPoses(const std::vector<Eigen::Isometry3d>& Ts) {
  py::array_t<double> out({py::ssize_t(Ts.size()), py::ssize_t(4), py::ssize_t(4)});
  auto o = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < Ts.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) o(i, r, c) = Ts[i].matrix()(r, c);
  return out;
}

py::tuple BoxTuple(const Box& b) { return py::make_tuple(b.cx, b.cy, b.w, b.h); }

}  // namespace posefilter::python
