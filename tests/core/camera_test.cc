// Tests of Camera::IsValid and the pinhole projection (include/posefilter/camera.h).
#include "posefilter/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace posefilter {
namespace {

TEST(CameraTest, DefaultThesisCameraIsValid) {
  Camera c;
  std::string why = "untouched";
  EXPECT_TRUE(c.IsValid(&why));
  EXPECT_TRUE(c.IsValid(nullptr));
}

TEST(CameraTest, RigidBaseToCameraIsValid) {
  Camera c;
  c.base_to_camera = Eigen::Translation3d(0.1, -0.2, 1.5) *
                     Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
  std::string why;
  EXPECT_TRUE(c.IsValid(&why)) << why;
}

// Each invalid camera must be rejected and the reason must name the violated field.
struct BadCamera {
  const char* label;
  void (*mutate)(Camera&);
  const char* expected_word;
};

class CameraInvalidTest : public ::testing::TestWithParam<BadCamera> {};

TEST_P(CameraInvalidTest, RejectedWithReason) {
  Camera c;
  GetParam().mutate(c);
  std::string why;
  EXPECT_FALSE(c.IsValid(&why));
  EXPECT_NE(why.find(GetParam().expected_word), std::string::npos) << "why = " << why;
  EXPECT_FALSE(c.IsValid(nullptr));  // a null `why` is allowed
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

INSTANTIATE_TEST_SUITE_P(
    All, CameraInvalidTest,
    ::testing::Values(
        BadCamera{"width0", [](Camera& c) { c.width = 0; }, "width"},
        BadCamera{"widthNeg", [](Camera& c) { c.width = -640; }, "width"},
        BadCamera{"widthHuge", [](Camera& c) { c.width = 1 << 30; }, "width"},
        BadCamera{"height0", [](Camera& c) { c.height = 0; }, "height"},
        BadCamera{"fx0", [](Camera& c) { c.fx = 0; }, "fx"},
        BadCamera{"fxNeg", [](Camera& c) { c.fx = -500; }, "fx"},
        BadCamera{"fxNaN", [](Camera& c) { c.fx = kNaN; }, "fx"},
        BadCamera{"fyInf", [](Camera& c) { c.fy = kInf; }, "fy"},
        BadCamera{"cxNaN", [](Camera& c) { c.cx = kNaN; }, "cx"},
        BadCamera{"cyInf", [](Camera& c) { c.cy = -kInf; }, "cy"},
        BadCamera{"extrinsicNaN",
                  [](Camera& c) { c.base_to_camera.matrix()(0, 3) = kNaN; }, "base_to_camera"},
        BadCamera{"extrinsicScaled",
                  [](Camera& c) { c.base_to_camera.linear() *= 2.0; }, "rotation"},
        BadCamera{"extrinsicReflection",
                  [](Camera& c) { c.base_to_camera.matrix()(2, 2) = -1.0; }, "rotation"},
        BadCamera{"extrinsicSheared",
                  [](Camera& c) { c.base_to_camera.matrix()(0, 1) = 0.05; }, "rotation"},
        BadCamera{"extrinsicLastRow",
                  [](Camera& c) { c.base_to_camera.matrix()(3, 0) = 0.5; }, "last row"}),
    [](const ::testing::TestParamInfo<BadCamera>& info) { return std::string(info.param.label); });

TEST(CameraTest, ProjectAndBackprojectAreInverse) {
  Camera c;  // thesis intrinsics
  const Eigen::Vector3d p(0.12, -0.05, 0.83);
  const Eigen::Vector2d uv = c.Project(p);
  // u = fx·x/z + cx (pinhole, OpenCV convention).
  EXPECT_NEAR(uv.x(), 542.556 * 0.12 / 0.83 + 325.065, 1e-9);
  EXPECT_NEAR(uv.y(), 537.666 * -0.05 / 0.83 + 224.214, 1e-9);
  EXPECT_TRUE(c.Backproject(uv.x(), uv.y(), p.z()).isApprox(p, 1e-12));
  // The principal point back-projects onto the optical axis.
  EXPECT_TRUE(c.Backproject(c.cx, c.cy, 2.0).isApprox(Eigen::Vector3d(0, 0, 2.0)));
}

}  // namespace
}  // namespace posefilter
