// Tests of the viewer page in a real browser (suite ViewerBrowser*, ctest LABEL viewer; only
// registered where Chromium is installed, tests/CMakeLists.txt): headless Chromium with its
// software WebGL (SwiftShader) loads a page written by WriteViewHtml for a synthetic scene
// and an estimate with recorded particles.
//   - Page: the interactive page runs to the end (body data-status="ready", no script
//     error) with the object and its recorded sets, the slider at the last set.
//   - CameraPanels: the page drawn from the depth camera's viewpoint and intrinsics
//     (#view=camera), three image-sized panels in one screenshot: the estimate in flat red,
//     which must cover the pixels RenderDepth gives the estimated pose; then the particles at
//     the first and at the last slider position, each lighting the pixels its own set's
//     particles project to, and different from each other.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "posefilter/depth_image.h"
#include "posefilter/filter.h"
#include "posefilter/pose.h"
#include "posefilter/projection.h"
#include "posefilter/render.h"
#include "posefilter/synth.h"
#include "posefilter/view.h"
#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;

class ViewerBrowser : public ::testing::Test {
 protected:
  // One scene, estimate and page for the suite.
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing_util::FreshTempPath("viewer_browser"));
    fs::create_directories(*dir_);
    if (!ViewerAvailable()) return;  // a build without libjs-three: the tests skip
    SynthOptions so;
    so.target = "lshape";
    so.clutter = 0;
    scene_ = new SynthScene(MakeSynthScene(so, 3));
    FilterOptions opt;
    opt.num_particles = 60;
    opt.stop.max_iterations = 5;
    opt.restarts = 1;
    opt.stop.stall_iterations = 0;
    opt.polish.steps = 0;
    opt.record_particles = true;
    const Prior prior = PostProcessPyramid(scene_->raw_pyramid, scene_->layout, scene_->classes);
    result_ = new EstimateResult(EstimatePose({scene_->depth, scene_->camera}, scene_->target, prior,
                                              prior.ClassIndex(scene_->target.name), opt));
    ViewScene v;
    v.title = "viewer test";
    v.depth = scene_->depth;
    v.camera = scene_->camera;
    v.planes.push_back(FindSupportPlane(v.depth, v.camera));
    ViewObject o;
    o.name = scene_->target.name;
    o.mesh = scene_->target;
    o.T_cam_obj = result_->T_cam_obj;
    o.weight = result_->weight;
    o.gt_T_cam_obj = scene_->gt[0].T_cam_obj;
    o.particles = result_->particle_history;
    v.objects.push_back(o);
    WriteViewHtml(v, (*dir_ / "view.html").string());
  }
  void SetUp() override {
    if (!ViewerAvailable()) GTEST_SKIP() << "this build has no viewer (libjs-three was not found)";
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete scene_;
    delete result_;
  }

  // Runs Chromium on the page with `hash`; `mode` is "--dump-dom" (returns the DOM) or
  // "--screenshot=PATH". Window `w` x `h` CSS pixels at scale 1.
  static std::string Chromium(const std::string& mode, const std::string& hash, int w, int h) {
    const std::string out = (*dir_ / "stdout.txt").string();
    const std::string cmd = std::string(POSEFILTER_CHROMIUM) +
                            " --headless=new --use-angle=swiftshader --enable-unsafe-swiftshader --no-sandbox"
                            " --no-first-run --disable-extensions --hide-scrollbars --force-device-scale-factor=1"
                            " --user-data-dir=" + (*dir_ / "profile").string() +
                            " --window-size=" + std::to_string(w) + "," + std::to_string(h) + " " + mode +
                            " 'file://" + (*dir_ / "view.html").string() + "#" + hash + "' >" + out + " 2>/dev/null";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

  static fs::path* dir_;
  static SynthScene* scene_;
  static EstimateResult* result_;
};

fs::path* ViewerBrowser::dir_ = nullptr;
SynthScene* ViewerBrowser::scene_ = nullptr;
EstimateResult* ViewerBrowser::result_ = nullptr;

TEST_F(ViewerBrowser, Page) {
  const std::string dom = Chromium("--dump-dom", "", 800, 600);
  const int sets = int(result_->particle_history.size());
  ASSERT_GE(sets, 2);
  EXPECT_NE(dom.find("data-status=\"ready\""), std::string::npos) << dom.substr(0, 2000);
  EXPECT_EQ(dom.find("<div id=\"error\">"), std::string::npos) << "a script error";
  EXPECT_NE(dom.find("data-objects=\"1\""), std::string::npos);
  EXPECT_NE(dom.find("data-sets=\"" + std::to_string(sets) + "\""), std::string::npos);
  EXPECT_NE(dom.find("data-iteration=\"" + std::to_string(sets - 1) + "\""), std::string::npos);
}

TEST_F(ViewerBrowser, CameraPanels) {
  const Camera& cam = scene_->camera;
  const int W = cam.width, H = cam.height;
  const std::string shot = (*dir_ / "panels.png").string();
  Chromium("--screenshot=" + shot, "view=camera&flat=1&panels=est@0;particles@0;particles@-1", W, 3 * H);
  const RgbImage img = LoadRgbPng(shot);
  ASSERT_EQ(img.width, W);
  ASSERT_EQ(img.height, 3 * H);
  auto px = [&](int panel, int u, int v) { return &img.data[(std::size_t(panel * H + v) * W + u) * 3]; };

  // Panel 0: the estimate's red pixels against its rendering at the estimated pose.
  DepthImage rendered(W, H);
  RenderDepth(scene_->target, result_->T_cam_obj, cam, &rendered);
  int both = 0, either = 0, expected = 0;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const std::uint8_t* p = px(0, u, v);
      const bool red = p[0] > 200 && p[1] < 60 && p[2] < 60;
      const bool mesh = rendered.at(u, v) > 0;
      both += red && mesh;
      either += red || mesh;
      expected += mesh;
    }
  ASSERT_GT(expected, 500);
  EXPECT_GT(double(both) / either, 0.93) << both << " of " << either << " pixels agree";

  // Panels 1 and 2: each set's particles light the pixels they project to.
  const std::vector<ParticleSet>& sets = result_->particle_history;
  Eigen::Vector3f lo = scene_->target.vertices[0], hi = lo;
  for (const auto& x : scene_->target.vertices) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const Eigen::Vector3d centre = (0.5f * (lo + hi)).cast<double>();
  auto lit = [&](int panel, int u, int v) {
    const std::uint8_t* p = px(panel, u, v);
    return p[0] > 30 || p[1] > 30 || p[2] > 30;
  };
  auto hits = [&](const ParticleSet& set, int panel) {
    int in = 0, on = 0;
    for (const Pose6& pose : set.poses) {
      const Eigen::Vector3d c = cam.base_to_camera * PoseToTransform(pose) * centre;
      const int u = int(std::lround(cam.fx * c.x() / c.z() + cam.cx)), v = int(std::lround(cam.fy * c.y() / c.z() + cam.cy));
      if (c.z() <= 0 || u < 0 || v < 0 || u >= W || v >= H) continue;
      ++in;
      on += lit(panel, u, v);
    }
    return in ? double(on) / in : 0.0;
  };
  EXPECT_GT(hits(sets.front(), 1), 0.95);
  EXPECT_GT(hits(sets.back(), 2), 0.95);
  int differ = 0, any = 0;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      differ += lit(1, u, v) != lit(2, u, v);
      any += lit(1, u, v) || lit(2, u, v);
    }
  ASSERT_GT(any, 0);
  EXPECT_GT(double(differ) / any, 0.2) << "the slider's first and last sets draw the same pixels";
}

}  // namespace
}  // namespace posefilter
