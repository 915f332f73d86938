// The viewer page's writer (src/view/view_html.cc) without a browser: what the page holds
// (three.js and the viewer inlined, the data's layout and sizes), the subsampling and particle
// caps, and the errors on inputs of the wrong size.
#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>
#include <string>

#include "posefilter/error.h"
#include "posefilter/synth.h"
#include "posefilter/view.h"

namespace posefilter {
namespace {

nlohmann::json Data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"posefilter-data\">";
  const std::size_t a = html.find(open), b = html.find("</script>", a);
  const std::string text = html.substr(a + open.size(), b - a - open.size());
  return nlohmann::json::parse(text);
}

// A scene of 64 x 48 pixels, one box with `sets` recorded sets of `n` particles.
ViewScene SmallScene(int sets, int n) {
  ViewScene v;
  v.title = "a </script> title";
  v.camera.width = 64;
  v.camera.height = 48;
  v.camera.fx = v.camera.fy = 60;
  v.camera.cx = 31.5;
  v.camera.cy = 23.5;
  v.depth = DepthImage(64, 48, 0.8f);
  ViewObject o;
  o.name = "box";
  o.mesh = MakeBox(0.1, 0.05, 0.04);
  o.T_cam_obj.translation() = Eigen::Vector3d(0, 0, 0.7);
  o.weight = 0.5;
  for (int s = 0; s < sets; ++s) {
    ParticleSet set;
    set.iteration = s;
    for (int i = 0; i < n; ++i) {
      set.poses.push_back({0.001 * i, 0, 0.7, 0, 0, 0});
      set.weights.push_back(1.0 - double(i) / n);
    }
    o.particles.push_back(set);
  }
  v.objects.push_back(o);
  return v;
}

TEST(ViewHtml, PageHoldsTheScriptsAndTheData) {
  if (!ViewerAvailable()) GTEST_SKIP() << "this build has no viewer (no libjs-three)";
  ViewOptions opt;
  opt.max_points = 64 * 48 / 4;  // stride 2
  const std::string html = ViewHtml(SmallScene(3, 10), opt);
  EXPECT_NE(html.find("REVISION"), std::string::npos) << "three.js is not inlined";
  EXPECT_NE(html.find("posefilter-data"), std::string::npos);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos) << "the page loads something from the network";
  EXPECT_EQ(html.find("a </script> title"), std::string::npos) << "the title ends the data script early";
  const nlohmann::json d = Data(html);
  EXPECT_EQ(d["title"], "a </script> title");
  EXPECT_EQ(d["cloud"]["step"], 2);
  EXPECT_EQ(d["cloud"]["w"], 32);
  EXPECT_EQ(d["cloud"]["h"], 24);
  // base64 of 32 x 24 float32: 4 characters per 3 bytes.
  EXPECT_EQ(d["cloud"]["depth"].get<std::string>().size(), (32 * 24 * 4 + 2) / 3 * 4);
  const nlohmann::json& o = d["objects"][0];
  ASSERT_EQ(o["sets"].size(), 3u);
  EXPECT_EQ(o["sets"][2]["iteration"], 2);
  EXPECT_EQ(o["sets"][0]["count"], 10);
  EXPECT_DOUBLE_EQ(o["sets"][0]["best"].get<double>(), 1.0);
  EXPECT_EQ(o["points"].get<std::string>().size(), std::size_t((3 * 10 * 12 + 2) / 3 * 4));
  EXPECT_EQ(o["top"].get<std::string>().size(), std::size_t((3 * opt.top_poses * 48 + 2) / 3 * 4));
  EXPECT_DOUBLE_EQ(o["estimate"][11].get<double>(), 0.7);  // row 2, column 3: t_z
  EXPECT_TRUE(o["gt"].is_null());
}

TEST(ViewHtml, ParticleCapKeepsTheBestOfEverySet) {
  if (!ViewerAvailable()) GTEST_SKIP() << "this build has no viewer (no libjs-three)";
  ViewOptions opt;
  opt.max_particles = 40;  // of 4 x 20 = 80: half of each set
  const nlohmann::json d = Data(ViewHtml(SmallScene(4, 20), opt));
  for (const auto& s : d["objects"][0]["sets"]) {
    EXPECT_EQ(s["count"], 10);
    EXPECT_EQ(s["total"], 20);
  }
}

TEST(ViewHtml, WrongSizesAndOptionsAreErrors) {
  if (!ViewerAvailable()) {
    EXPECT_THROW(ViewHtml(SmallScene(1, 1)), Error);
    return;
  }
  ViewScene v = SmallScene(1, 4);
  v.rgb = RgbImage(10, 10);
  try {
    ViewHtml(v);
    ADD_FAILURE() << "no error for a 10x10 RGB image";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("RGB image is 10x10 but the camera is 64x48"), std::string::npos) << e.what();
  }
  v = SmallScene(1, 4);
  v.depth = DepthImage(32, 48);
  EXPECT_THROW(ViewHtml(v), Error);
  v = SmallScene(1, 4);
  v.objects[0].particles[0].weights.pop_back();
  EXPECT_THROW(ViewHtml(v), Error);
  ViewOptions bad;
  bad.max_points = 0;
  EXPECT_THROW(ViewHtml(SmallScene(1, 1), bad), Error);
  EXPECT_THROW(WriteViewHtml(SmallScene(1, 1), "/nonexistent_dir/v.html"), Error);
}

}  // namespace
}  // namespace posefilter
