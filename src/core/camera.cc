// core/camera.cc — validation of the pinhole camera (include/posefilter/camera.h).
#include "posefilter/camera.h"

#include <cmath>
#include <sstream>

#include "core/option_check.h"

namespace posefilter {

namespace {

// Largest accepted image side, pixels. Real sensors are far below; the bound keeps
// width·height (and the images allocated from a camera file) from overflowing.
constexpr int kMaxImageSide = 100000;

// Tolerance on base_to_camera's rotation block: max |RᵀR − I| and |det R − 1|. Loose enough for
// matrices typed with 4–6 decimals in a JSON file, tight enough to catch a scale or a shear.
constexpr double kRotationTolerance = 1e-3;

// Plausible field of view along each image axis, degrees: a focal length outside this range
// (fx = 1e300, or fx in millimetres for a 640-pixel image) is a unit or typing error, not a
// lens. fov = 2·atan(side / (2·f)), so f must lie in [side / (2·tan(max/2)), side / (2·tan(min/2))].
constexpr double kMinFovDeg = 0.5;
constexpr double kMaxFovDeg = 175.0;

// The principal point may lie outside a cropped image, but not further than one image side
// beyond either edge: cx in [−width, 2·width], cy in [−height, 2·height].
constexpr double kPrincipalPointMargin = 1.0;

bool FocalIsPlausible(const char* name, double f, int side, std::string* why) {
  constexpr double kPi = 3.14159265358979323846;
  const double lo = side / (2.0 * std::tan(kMaxFovDeg * kPi / 360.0));
  const double hi = side / (2.0 * std::tan(kMinFovDeg * kPi / 360.0));
  if (f >= lo && f <= hi) return true;
  if (why != nullptr) {
    std::ostringstream os;
    os << name << " = " << f << " pixels gives a field of view outside [" << kMinFovDeg << ", "
       << kMaxFovDeg << "] degrees for a " << side << "-pixel side; " << name << " must be in ["
       << lo << ", " << hi << "] (focal length in pixels, not millimetres)";
    *why = os.str();
  }
  return false;
}

bool PrincipalPointIsPlausible(const char* name, double c, int side, std::string* why) {
  const double lo = -kPrincipalPointMargin * side, hi = (1.0 + kPrincipalPointMargin) * side;
  if (c >= lo && c <= hi) return true;
  if (why != nullptr) {
    std::ostringstream os;
    os << name << " = " << c << " pixels is more than one image side outside a " << side
       << "-pixel image; " << name << " must be in [" << lo << ", " << hi << "]";
    *why = os.str();
  }
  return false;
}

}  // namespace

bool Camera::IsValid(std::string* why) const {
  if (width <= 0 || width > kMaxImageSide) {
    return Fail(why, "width must be in [1, " + std::to_string(kMaxImageSide) + "] pixels (got " +
                         std::to_string(width) + ")");
  }
  if (height <= 0 || height > kMaxImageSide) {
    return Fail(why, "height must be in [1, " + std::to_string(kMaxImageSide) +
                         "] pixels (got " + std::to_string(height) + ")");
  }
  if (!std::isfinite(fx) || fx <= 0) return Fail(why, "fx must be finite and > 0");
  if (!std::isfinite(fy) || fy <= 0) return Fail(why, "fy must be finite and > 0");
  if (!std::isfinite(cx)) return Fail(why, "cx must be finite");
  if (!std::isfinite(cy)) return Fail(why, "cy must be finite");
  if (!FocalIsPlausible("fx", fx, width, why) || !FocalIsPlausible("fy", fy, height, why) ||
      !PrincipalPointIsPlausible("cx", cx, width, why) ||
      !PrincipalPointIsPlausible("cy", cy, height, why)) {
    return false;
  }

  const Eigen::Matrix4d& m = base_to_camera.matrix();
  if (!m.allFinite()) return Fail(why, "base_to_camera must be finite");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
    return Fail(why, "base_to_camera's last row must be [0, 0, 0, 1]");
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double ortho_err = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = r.determinant();
  if (ortho_err > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance) {
    std::ostringstream os;
    os << "base_to_camera's 3x3 block must be a rotation (max |R^T R - I| = " << ortho_err
       << ", det = " << det << ", tolerance " << kRotationTolerance << ")";
    return Fail(why, os.str());
  }
  return true;
}

}  // namespace posefilter
