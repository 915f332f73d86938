// The fast kernels against the reference kernel in the same tests: every dispatch variant of
// the cpu engine this machine can run, and the gpu engine's Vulkan kernel (on the machine's
// Vulkan device: Mesa's lavapipe without a GPU). Many poses (edge-on, partly off-image, at the
// near plane, far off-screen vertices), meshes, windows and both z-buffer modes — counts,
// inlier and depth-difference sums exactly equal, ICP sums within 1e-4 relative (the gpu
// kernel leaves the ICP sums to the cpu kernel: its cases are compared without scene
// normals). The kernels' set-up and input errors: kernel_inputs_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/synth.h"
#include "render/cpu_kernel.h"
#include "render/gpu_kernel.h"
#include "render/kernel_test_util.h"
#include "test_util.h"

namespace posefilter {
namespace {

using kernel_test::ExpectSame;
using kernel_test::SceneParams;
using render::CpuTarget;
using render::CpuWorkspace;
using testing_util::PinholeCamera;

// Random rotation (uniform axis, angle in ±π) and the given translation.
Eigen::Isometry3d RandomPose(Rng& rng, double x, double y, double z) {
  // Draws one per statement, the last coordinate first: C++ leaves the order of a call's
  // argument evaluations open (GCC takes the last first, Clang the first), and these are the
  // cases the tests have always run (GCC's order). The same below.
  const double az = rng.Normal(), ay = rng.Normal(), ax = rng.Normal();
  Eigen::Vector3d axis(ax, ay, az);
  if (axis.norm() < 1e-9) axis = Eigen::Vector3d::UnitZ();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(rng.Uniform(-M_PI, M_PI), axis.normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// A random triangle soup (mixed orientations, self-intersecting, some degenerate faces).
Mesh RandomSoup(Rng& rng, int nv, int nf, double size) {
  Mesh m;
  m.name = "soup";
  for (int i = 0; i < nv; ++i) {
    const double z = rng.Uniform(-size, size), y = rng.Uniform(-size, size), x = rng.Uniform(-size, size);
    m.vertices.emplace_back(float(x), float(y), float(z));
  }
  for (int f = 0; f < nf; ++f) {
    std::array<std::uint32_t, 3> t;
    for (auto& i : t) i = std::uint32_t(rng.UniformInt(std::uint64_t(nv)));
    m.faces.push_back(t);
  }
  return m;
}

// A scene the renderings are compared with: the mesh at a nearby pose (so inliers, ramp and
// occlusions all occur), over a background plane, with per-pixel noise and holes.
DepthImage MakeScene(const Mesh& mesh, const Eigen::Isometry3d& T, const Camera& cam, Rng& rng) {
  DepthImage d(cam.width, cam.height, 0.f);
  Eigen::Isometry3d Ts = T;
  const double dz = rng.Uniform(-0.006, 0.006), dy = rng.Uniform(-0.004, 0.004), dx = rng.Uniform(-0.004, 0.004);
  Ts.translation() += Eigen::Vector3d(dx, dy, dz);
  RenderDepth(mesh, Ts, cam, &d);
  const float plane = float(T.translation().z() + rng.Uniform(-0.05, 0.3));
  for (float& z : d.data) {
    if (z == 0.f) z = plane;
    const double r = rng.Uniform();
    if (r < 0.08) z = 0.f;                                   // holes
    else if (r < 0.12) z -= float(rng.Uniform(0.0, 0.2));    // clutter in front
    else z += float(rng.Uniform(-0.006, 0.006));             // noise across the ramp
    if (z < 0.f) z = 0.f;
  }
  return d;
}

// Windows: full image, ≤ 200×200 around the object, 1-px wide/high, at every border.
std::vector<PixelRect> Windows(const Camera& cam, Rng& rng, const Eigen::Vector2d& centre) {
  const int W = cam.width, H = cam.height;
  auto clip = [&](int u0, int v0, int w, int h) {
    u0 = std::clamp(u0, 0, W - 1);
    v0 = std::clamp(v0, 0, H - 1);
    w = std::clamp(w, 1, W - u0);
    h = std::clamp(h, 1, H - v0);
    return PixelRect{u0, v0, w, h};
  };
  const int cu = int(std::lround(std::clamp(centre.x(), -1e4, 1e4))),
            cv = int(std::lround(std::clamp(centre.y(), -1e4, 1e4)));
  const int s = 100 + int(rng.UniformInt(101));
  return {PixelRect{0, 0, W, H},
          clip(cu - s / 2, cv - s / 2, s, s),
          clip(cu, cv - 60, 1, 120),                 // 1 px wide
          clip(cu - 60, cv, 120, 1),                 // 1 px high
          clip(0, cv - 50, 37, 100),                 // left border
          clip(W - 45, cv - 50, 45, 100),            // right border
          clip(cu - 80, 0, 160, 23),                 // top border
          clip(cu - 80, H - 31, 160, 31),            // bottom border
          clip(W - 200, H - 200, 200, 200)};         // bottom-right corner
}

// Appends to m a vertex that the pose At(0, 0, 1) (object frame = camera frame shifted 1 m
// along the optical axis) puts at pixel (u, v) and depth z, metres; returns its index.
std::uint32_t PixelVertex(Mesh* m, const Camera& cam, double u, double v, double z) {
  m->vertices.emplace_back(float((u - cam.cx) * z / cam.fx), float((v - cam.cy) * z / cam.fy), float(z - 1.0));
  return std::uint32_t(m->vertices.size() - 1);
}

// Tall slivers `w_lo`–`w_hi` px wide whose bounding box (1/256 px) has wx·wy spread evenly in
// log scale over [2^lo_exp, 2^(lo_exp + 4)) (the bound under test at 2^(lo_exp + 2)), clipped
// by the window at the top and bottom; both windings (front and back). Returns how many fall
// below and above the bound.
std::pair<std::int64_t, std::int64_t> AddSliversAroundBound(Mesh* m, const Camera& cam, Rng& rng, int lo_exp,
                                                            double w_lo, double w_hi) {
  std::int64_t below = 0, above = 0;
  auto vertex = [&](double u, double v, double z) { return PixelVertex(m, cam, u, v, z); };
  for (int t = 0; t < 120; ++t) {
    const double w = rng.Uniform(w_lo, w_hi);
    const double wxwy = std::ldexp(1.0, lo_exp) * std::pow(16.0, rng.Uniform());
    const double h = wxwy / (w * 256.0 * 256.0);  // pixels
    (wxwy < std::ldexp(1.0, lo_exp + 2) ? below : above) += 1;
    const double u0 = rng.Uniform(250, 390), vc = rng.Uniform(200, 280), z = rng.Uniform(0.7, 1.3);
    const std::uint32_t a = vertex(u0, vc - h * rng.Uniform(0.3, 0.7), z);
    const double bz = rng.Uniform(0.97, 1.03), bv = rng.Uniform(0.3, 0.7), bu = rng.Uniform(0, 1);
    const std::uint32_t b = vertex(u0 + w * bu, vc + h * bv, z * bz);
    const std::uint32_t c = vertex(u0 + w, vc + rng.Uniform(-20, 20), z);
    m->faces.push_back({a, b, c});
    m->faces.push_back({a, c, b});
  }
  return {below, above};
}

// A kernel under test: a cpu engine variant, or the gpu engine's kernel.
struct Backend {
  bool gpu = false;
  CpuTarget target = CpuTarget::kPortable;
};

class KernelBackend : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    if (gpu()) {
      std::string why;
      // A build with the gpu engine must find a device (setup.sh installs lavapipe): a missing
      // one fails here. A build without it has no gpu kernel to test.
      if (!render::GpuBuilt()) GTEST_SKIP() << "this build has no gpu engine (POSEFILTER_VULKAN=OFF)";
      ASSERT_TRUE(render::GpuAvailable(&why)) << why;
      validation_errors_ = render::GpuValidationErrors();
    } else if (!render::CpuTargetSupported(GetParam().target)) {
      GTEST_SKIP() << "this machine/build cannot run the '" << render::CpuTargetName(GetParam().target)
                   << "' kernel variant";
    }
  }
  void TearDown() override {
    if (gpu() && render::GpuBuilt() && render::GpuAvailable(nullptr))
      EXPECT_EQ(render::GpuValidationErrors(), validation_errors_) << render::GpuFirstValidationError();
  }
  bool gpu() const { return GetParam().gpu; }

  // The kernel under test on k; `planes`: the cpu kernel's back-face pre-cull (its skipped
  // faces added to preculled_).
  ScoreKernelResult Score(const ScoreKernelParams& k, const render::FacePlanes* planes = nullptr) {
    if (gpu()) {
      render::GpuKernel kernel(k);
      std::vector<ScoreKernelResult> out;
      kernel.Score({k}, &out);
      return out.at(0);
    }
    const ScoreKernelResult r = render::ScoreCpuWith(GetParam().target, k, &ws_, planes);
    if (planes) preculled_ += ws_.faces_preculled;
    else EXPECT_EQ(ws_.faces_preculled, 0);
    return r;
  }

  // Compares the kernel under test with ScoreReference on one case in both z-buffer modes;
  // the cpu kernel without and with the back-face pre-cull (face planes of k's mesh). The gpu
  // kernel is compared without scene normals (no ICP sums).
  void Check(ScoreKernelParams k, const std::string& ctx) {
    if (gpu()) k.scene_normals = nullptr;
    const render::FacePlanes planes = render::BuildFacePlanes(k);
    for (bool zb : {true, false}) {
      k.zbuffer = zb;
      RenderWorkspace rws;
      const ScoreKernelResult ref = ScoreReference(k, &rws);
      const ScoreKernelResult got = Score(k);
      ExpectSame(ref, got, ctx + (zb ? " zbuffer" : " no-zbuffer"));
      if (!gpu()) ExpectSame(ref, Score(k, &planes), ctx + (zb ? " zbuffer" : " no-zbuffer") + " pre-cull");
      fragments_ += ref.n_raster;
      edges_ += ref.n_edge;
      icp_ += ref.icp_count;
      occluded_ += ref.n_occluded;
    }
  }

  // Three scenes of slivers around the bound 2^(lo_exp + 2) (AddSliversAroundBound, once per
  // width range), each checked in the full image and in a window that clips them; returns how
  // many slivers fell below and above the bound.
  std::pair<std::int64_t, std::int64_t> CheckSliverScenes(std::uint64_t seed, int lo_exp,
                                                          std::initializer_list<std::pair<double, double>> widths) {
    Rng rng(seed);
    const Camera cam = PinholeCamera(525, 525);
    std::int64_t below = 0, above = 0;
    for (int scene = 0; scene < 3; ++scene) {
      Mesh m;
      m.name = "slivers";
      for (const auto& [w_lo, w_hi] : widths) {
        const auto [b, a] = AddSliversAroundBound(&m, cam, rng, lo_exp, w_lo, w_hi);
        below += b;
        above += a;
      }
      const Eigen::Isometry3d T = testing_util::At(0, 0, 1);
      const DepthImage depth = MakeScene(m, T, cam, rng);
      for (const PixelRect& w : {PixelRect{0, 0, 640, 480}, PixelRect{240, 150, 160, 180}})
        Check(SceneParams(m, T, cam, depth, w),
              "scene " + std::to_string(scene) + " window " + std::to_string(w.u0) + "," + std::to_string(w.v0));
    }
    return {below, above};
  }

  CpuWorkspace ws_;  // shared by all cases: also checks that reuse leaves no stale state
  int validation_errors_ = 0;  // the validation layer's count before the test (gpu)
  std::int64_t fragments_ = 0, edges_ = 0, icp_ = 0, occluded_ = 0, preculled_ = 0;
};

TEST_P(KernelBackend, MatchesReferenceOnRandomPosesMeshesAndWindows) {
  Rng rng(20240611);
  const Camera cam = PinholeCamera(525, 520, 319.5, 239.5);
  std::vector<Mesh> meshes = {MakeBox(0.12, 0.08, 0.16), MakeCylinder(0.04, 0.14, 24), MakeLShape(0.14, 0.05, 0.06),
                              MakeTorus(0.06, 0.025, 24, 16), RandomSoup(rng, 60, 150, 0.08)};
  int cases = 0;
  for (const Mesh& mesh : meshes) {
    for (int p = 0; p < 8; ++p) {
      // Mostly in view; some partly off the image, some straddling the near plane.
      double x = rng.Uniform(-0.15, 0.15), y = rng.Uniform(-0.1, 0.1), z = rng.Uniform(0.4, 1.2);
      if (p == 5) {  // off the side (magnitude drawn first: the operands of * are unsequenced too)
        const double off = rng.Uniform(0.35, 0.5);
        x = off * (rng.Uniform() < 0.5 ? -1 : 1);
      }
      if (p == 6) z = rng.Uniform(0.02, 0.09);                                    // near plane
      const Eigen::Isometry3d T = RandomPose(rng, x, y, z);
      const DepthImage depth = MakeScene(mesh, T, cam, rng);
      const std::vector<float> normals = ComputeSceneNormals(depth, cam);
      const Eigen::Vector3d c = T.translation();
      const Eigen::Vector2d centre(cam.fx * c.x() / std::max(c.z(), 0.05) + cam.cx,
                                   cam.fy * c.y() / std::max(c.z(), 0.05) + cam.cy);
      int wi = 0;
      for (const PixelRect& w : Windows(cam, rng, centre)) {
        ScoreKernelParams k = SceneParams(mesh, T, cam, depth, w, (wi % 3 == 2) ? nullptr : &normals);
        if (wi % 4 == 1) k.inlier.hard = true;
        if (wi % 4 == 3) k.inlier.thr1_m = 0.003f;  // not a power of two
        Check(k, mesh.name + " pose " + std::to_string(p) + " window " + std::to_string(wi));
        ++wi;
        ++cases;
      }
    }
  }
  // The cases must exercise every counted quantity (else the equalities prove little).
  EXPECT_GT(cases, 300);
  EXPECT_GT(fragments_, 100000);
  EXPECT_GT(edges_, 1000);
  if (!gpu()) EXPECT_GT(icp_, 10000);
  EXPECT_GT(occluded_, 1000);
  if (!gpu()) EXPECT_GT(preculled_, 5000);  // the pre-cull ran (and skipped faces) in most cases
}

TEST_P(KernelBackend, MatchesReferenceOnEdgeOnAndPixelAlignedGeometry) {
  const Camera cam = PinholeCamera(500, 500);
  DepthImage depth(640, 480, 1.0f);
  for (int i = 0; i < 640 * 480; i += 7) depth.data[i] = 0.995f;
  // A square exactly on pixel centres (shared-edge ownership), boxes turned edge-on (faces
  // parallel to the viewing rays: 2·Area = 0 → culled), and a box rotated by 45° about z.
  const Mesh sq = testing_util::FrontSquare(0.1f);
  const Mesh box = MakeBox(0.1, 0.1, 0.1);
  std::vector<std::pair<const Mesh*, Eigen::Isometry3d>> cases;
  cases.push_back({&sq, testing_util::At(0, 0, 1)});
  cases.push_back({&sq, testing_util::At(0.0005, -0.0013, 1)});
  for (double a : {M_PI / 2, M_PI, M_PI / 4}) {
    Eigen::Isometry3d T = testing_util::At(0, 0, 0.9);
    T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
    cases.push_back({&box, T});
    T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    cases.push_back({&box, T});
  }
  int i = 0;
  for (const auto& [mesh, T] : cases) {
    for (PixelRect w : {PixelRect{0, 0, 640, 480}, PixelRect{260, 180, 120, 120}, PixelRect{295, 215, 1, 50}}) {
      Check(SceneParams(*mesh, T, cam, depth, w), "case " + std::to_string(i));
    }
    ++i;
  }
  EXPECT_GT(fragments_, 10000);
}

// Without a z-buffer every fragment counts, also where front faces overlap: the fast path
// keeps one fragment per pixel and hands the displaced ones to its fragment buffer, which must
// be scored and refilled many times in one call. Layers of large quads and of small triangles
// (4-, 8- and 16-pixel-wide stamps) stacked at different depths give tens of thousands of
// displaced fragments.
TEST_P(KernelBackend, OverlappingLayersWithoutZBufferMatch) {
  Rng rng(7031);
  const Camera cam = PinholeCamera(525, 525);
  Mesh m;
  m.name = "layers";
  auto tri = [&](double u0, double v0, double u1, double v1, double u2, double v2, double z) {
    const std::uint32_t a = PixelVertex(&m, cam, u0, v0, z), b = PixelVertex(&m, cam, u1, v1, z * rng.Uniform(0.98, 1.02)),
                        c = PixelVertex(&m, cam, u2, v2, z);
    m.faces.push_back({a, b, c});  // both windings: one of them is front-facing
    m.faces.push_back({a, c, b});
  };
  for (int layer = 0; layer < 8; ++layer) {
    const double z = 0.8 + 0.05 * layer, du = rng.Uniform(-6, 6), dv = rng.Uniform(-6, 6);
    tri(250 + du, 180 + dv, 330 + du, 180 + dv, 250 + du, 250 + dv, z);  // a quad of 80 × 70 px
    tri(330 + du, 180 + dv, 330 + du, 250 + dv, 250 + du, 250 + dv, z);
    for (int t = 0; t < 60; ++t) {  // small triangles over the same area
      const double w = rng.Uniform(2, 15), h = rng.Uniform(2, 9), u = rng.Uniform(255, 320), v = rng.Uniform(185, 240);
      tri(u, v, u + w, v + rng.Uniform(0, h), u + rng.Uniform(0, w), v + h, z + rng.Uniform(-0.02, 0.02));
    }
  }
  const Eigen::Isometry3d T = testing_util::At(0, 0, 1);
  const DepthImage depth = MakeScene(m, T, cam, rng);
  const std::vector<float> normals = ComputeSceneNormals(depth, cam);
  for (const PixelRect& w : {PixelRect{0, 0, 640, 480}, PixelRect{270, 190, 50, 45}}) {
    for (bool icp : {false, true}) {
      ScoreKernelParams k = SceneParams(m, T, cam, depth, w, icp ? &normals : nullptr);
      k.zbuffer = true;
      RenderWorkspace rws;
      const std::int64_t nearest = ScoreReference(k, &rws).n_raster;
      k.zbuffer = false;
      const std::int64_t all = ScoreReference(k, &rws).n_raster;
      EXPECT_GT(all - nearest, w.width == 640 ? 30000 : 10000) << "the layers must overlap";
      Check(k, "window " + std::to_string(w.u0) + (icp ? " icp" : ""));
    }
  }
}

TEST_P(KernelBackend, FarOffScreenVerticesTakeTheExactPathAndMatch) {
  // Huge triangles (vertices projecting beyond ±16384 px, still inside ±2^20 px) and vertices
  // beyond ±2^20 px (skipped): the int64 path of the kernel.
  Rng rng(7);
  const Camera cam = PinholeCamera(525, 525);
  DepthImage depth(640, 480, 0.f);
  for (float& z : depth.data) z = float(rng.Uniform(0.5, 3.0));
  Mesh m;
  m.name = "huge";
  for (int i = 0; i < 40; ++i) {
    const double z = rng.Uniform(-0.5, 0.5), y = rng.Uniform(-60, 60), x = rng.Uniform(-60, 60);
    m.vertices.emplace_back(float(x), float(y), float(z));
  }
  m.vertices.emplace_back(1e5f, 0.f, 0.f);  // beyond 2^20 px at z ≈ 1 m
  for (int f = 0; f < 120; ++f) {
    std::array<std::uint32_t, 3> t;
    for (auto& q : t) q = std::uint32_t(rng.UniformInt(m.vertices.size()));
    m.faces.push_back(t);
  }
  for (int p = 0; p < 6; ++p) {
    const Eigen::Isometry3d T = RandomPose(rng, 0, 0, rng.Uniform(0.8, 2.0));
    Check(SceneParams(m, T, cam, depth, p % 2 ? PixelRect{0, 0, 640, 480} : PixelRect{100, 50, 200, 200}),
          "pose " + std::to_string(p));
  }
  EXPECT_GT(fragments_, 10000);
}

TEST_P(KernelBackend, UnusualParametersMatchTheReference) {
  Rng rng(99);
  const Camera cam = PinholeCamera(525, 525);
  const Mesh torus = MakeTorus(0.06, 0.025, 16, 12);
  const Eigen::Isometry3d T = RandomPose(rng, 0.02, 0, 0.7);
  const DepthImage depth = MakeScene(torus, T, cam, rng);
  ScoreKernelParams k = SceneParams(torus, T, cam, depth, PixelRect{0, 0, 640, 480});
  k.near_m = -1.0f;  // outside the fast path's domain: the kernel must fall back, not differ
  Check(k, "near_m <= 0");
  k.near_m = 0.69f;  // cuts through the object
  Check(k, "near plane through the object");
  k.near_m = 0.05f;
  k.window = PixelRect{10, 10, 0, 5};  // empty window: nothing counted, not even front faces
  Check(k, "empty window");
  k.window = PixelRect{0, 0, 640, 480};
  k.align_band_m = 1e-3f;
  k.edge_band_m = 0.05f;
  k.inlier.thr1_m = 0.01f;
  Check(k, "bands");
}

TEST_P(KernelBackend, ImageWidthsWithInexactReciprocalsMatch) {
  // The z-buffer-free mode recovers a fragment's (u, v) for the ICP terms from its image index
  // v·width + u by a float quotient and one correction each way. Widths where that quotient
  // falls short for column 0 in most rows (e.g. 244: 447 of 480 rows) need the correction; a
  // torus across the left border (window from column 0, scene normals nonzero everywhere,
  // also in the border column) exercises it.
  Rng rng(5);
  const Mesh torus = MakeTorus(0.06, 0.025, 24, 16);
  int widths = 0;
  for (int w = 120; w < 800 && widths < 3; ++w) {
    int short_rows = 0;
    for (int v = 0; v < 480; ++v) short_rows += int(float(v * w) * (1.0f / float(w))) < v;
    if (short_rows < 200) continue;
    ++widths;
    Camera cam = PinholeCamera(525, 525, 0.5 * (w - 1), 239.5);
    cam.width = w;
    const Eigen::Isometry3d T = RandomPose(rng, -0.5 * (w - 1) / 525.0 * 0.7, 0, 0.7);  // centred on column 0
    const DepthImage depth = MakeScene(torus, T, cam, rng);
    std::vector<float> normals(3 * depth.data.size());
    for (std::size_t i = 0; i < depth.data.size(); ++i) {
      const double ny = rng.Uniform(-0.3, 0.3), nx = rng.Uniform(-0.3, 0.3);
      const Eigen::Vector3d n = Eigen::Vector3d(nx, ny, -1.0).normalized();
      for (int a = 0; a < 3; ++a) normals[3 * i + a] = float(n[a]);
    }
    for (PixelRect win : {PixelRect{0, 0, w, 480}, PixelRect{0, 140, 90, 200}})
      Check(SceneParams(torus, T, cam, depth, win, &normals), "width " + std::to_string(w));
  }
  EXPECT_EQ(widths, 3);
  if (!gpu()) EXPECT_GT(icp_, 1000);
}

TEST_P(KernelBackend, TinyTrianglesAtTheWindowsBottomRightMatch) {
  // A finely tessellated torus far away: nearly every triangle's box is at most 4×4 px (the
  // kernel's stamp path), placed so that stamps reach past the window's last row and column
  // (the z-buffer's spare rows and row slack) and past the image's bottom-right corner.
  Rng rng(41);
  const Camera cam = PinholeCamera(525, 525);
  const Mesh torus = MakeTorus(0.06, 0.025, 48, 32);
  for (int p = 0; p < 6; ++p) {
    // Centre near the image's bottom-right corner at 1.6–2.4 m (≈ 3200 front faces of ≈ 2 px).
    const double z = rng.Uniform(1.6, 2.4);
    const double dv = rng.Uniform(-30, 10), du = rng.Uniform(-30, 10);
    const Eigen::Isometry3d T = RandomPose(rng, (300.0 + du) * z / 525, (220.0 + dv) * z / 525, z);
    const DepthImage depth = MakeScene(torus, T, cam, rng);
    const std::vector<float> normals = ComputeSceneNormals(depth, cam);
    for (const PixelRect& w : {PixelRect{520, 380, 120, 100}, PixelRect{560, 400, 57, 43}, PixelRect{600, 470, 40, 10}}) {
      Check(SceneParams(torus, T, cam, depth, w, &normals),
            "pose " + std::to_string(p) + " window " + std::to_string(w.u0) + "," + std::to_string(w.v0));
    }
  }
  EXPECT_GT(fragments_, 5000);
  EXPECT_GT(edges_, 500);
}

TEST_P(KernelBackend, TallAndWideSliversMatch) {
  // Slivers in every box shape the raster distinguishes: 1–2 and 3–4 px wide and 5–60 px tall
  // (several rows per vector), 9–16 px wide (two row pieces), at sub-pixel positions and
  // depths 0.6–1.4 m, overlapping, each listed in both windings (one is culled), with
  // windows that clip them on every side.
  Rng rng(77);
  const Camera cam = PinholeCamera(525, 525);
  for (int scene = 0; scene < 4; ++scene) {
    Mesh m;
    m.name = "slivers";
    auto vertex = [&](double u, double v, double z) { return PixelVertex(&m, cam, u, v, z); };
    for (int t = 0; t < 300; ++t) {
      const int shape = t % 3;
      const double w = shape == 0 ? rng.Uniform(0.3, 2.0) : shape == 1 ? rng.Uniform(2.0, 4.0) : rng.Uniform(8.0, 16.0);
      const double h = shape == 2 ? rng.Uniform(1.0, 6.0) : rng.Uniform(5.0, 60.0);
      const double u0 = rng.Uniform(260, 380), v0 = rng.Uniform(180, 300), z = rng.Uniform(0.6, 1.4);
      const std::uint32_t a = vertex(u0, v0, z);
      const double bz = rng.Uniform(0.95, 1.05), bu = rng.Uniform(0, 1);
      const std::uint32_t b = vertex(u0 + w * bu, v0 + h, z * bz), c = vertex(u0 + w, v0 + h * rng.Uniform(0, 1), z);
      m.faces.push_back({a, b, c});
      m.faces.push_back({a, c, b});
    }
    const Eigen::Isometry3d T = testing_util::At(0, 0, 1);
    const DepthImage depth = MakeScene(m, T, cam, rng);
    const std::vector<float> normals = ComputeSceneNormals(depth, cam);
    for (const PixelRect& w : {PixelRect{0, 0, 640, 480}, PixelRect{300, 220, 41, 37}, PixelRect{255, 175, 23, 130},
                               PixelRect{330, 200, 60, 3}}) {
      Check(SceneParams(m, T, cam, depth, w, &normals),
            "scene " + std::to_string(scene) + " window " + std::to_string(w.u0) + "," + std::to_string(w.v0));
    }
  }
  EXPECT_GT(fragments_, 20000);
  if (!gpu()) EXPECT_GT(icp_, 1000);
}

TEST_P(KernelBackend, SliversAroundTheFloatEdgeBoundMatch) {
  // The raster steps edge values in float when a triangle's bounding box (1/256 px) has
  // wx·wy < 2^23 (cpu_kernel_impl.inc: every edge value at a pixel centre of the box is an
  // integer below 2^24), and in int32 above. Slivers 1–30 px wide (narrow boxes and boxes of
  // several row pieces) whose wx·wy spans 2^21 … 2^25 take both paths; a float bound set too
  // high rounds their edge values, and with them the depths, which the bit-identical sums show.
  const auto [below, above] = CheckSliverScenes(2027, 21, {{1.0, 15.5}, {17.0, 30.0}});
  EXPECT_GT(below, 100);
  EXPECT_GT(above, 100);
  EXPECT_GT(fragments_, 20000);
}

TEST_P(KernelBackend, SliversAroundTheInt32EdgeBoundMatch) {
  // The raster steps edge values in int32 when a triangle's bounding box (1/256 px) has
  // 2^23 ≤ wx·wy < 2^30 (cpu_kernel_impl.inc), and in double above. Tall slivers 2–16 px wide
  // whose wx·wy spans 2^28 … 2^32, clipped by the window at the top and bottom, take both
  // paths; an int32 bound set too high overflows their edge values.
  const auto [below, above] = CheckSliverScenes(2026, 28, {{2.0, 15.5}});
  EXPECT_GT(below, 50);
  EXPECT_GT(above, 50);
  EXPECT_GT(fragments_, 20000);
}

TEST_P(KernelBackend, PreCullAtGrazingAnglesMatches) {
  // The back-face pre-cull skips a face when s = N·(v0 − c) exceeds a margin that covers the
  // float transform, the projection and the snapping (PreCullConstants). Faces nearly edge-on
  // to the camera — planes through the viewing ray turned by 10^-7 … 1.4 rad either way, 0.3 to
  // 40 px long, in an object-sized ball under random rotations — lie on both sides of that margin:
  // a face skipped that the reference keeps front changes faces_front (and the fragments).
  Rng rng(31);
  const Camera cam = PinholeCamera(525, 525);
  std::int64_t skipped = 0, faces = 0, front = 0;
  for (int scene = 0; scene < 6; ++scene) {
    const double depth_m = rng.Uniform(0.4, 2.0);
    const double y0 = rng.Uniform(-0.1, 0.1), x0 = rng.Uniform(-0.1, 0.1);
    const Eigen::Isometry3d T = RandomPose(rng, x0, y0, depth_m);
    Mesh m;
    m.name = "grazing";
    for (int f = 0; f < 400; ++f) {
      // Camera frame: a point p of an object-sized ball (0.12 m) around the pose's origin, the
      // ray direction r = p/|p|, a direction w across it.
      Eigen::Vector3d p;
      do {
        const double pz = rng.Uniform(-1, 1), py = rng.Uniform(-1, 1), px = rng.Uniform(-1, 1);
        p = Eigen::Vector3d(px, py, pz);
      } while (p.norm() > 1);
      p = T.translation() + 0.12 * p;
      const double z = p.z();
      const Eigen::Vector3d r = p.normalized();
      const double gz = rng.Normal(), gy = rng.Normal(), gx = rng.Normal();
      Eigen::Vector3d w = r.cross(Eigen::Vector3d(gx, gy, gz)).normalized();
      const double size = rng.Uniform(0.3, 40) * z / cam.fx;  // metres for 0.3 … 40 px
      // The face's plane contains the ray through p (edge-on), then turns about w.
      // Half of them grazing (10^-7 … 0.3 rad), half clearly turned (0.3 … 1.4 rad).
      const double turn = f % 2 ? std::pow(10.0, rng.Uniform(-7, std::log10(0.3))) : rng.Uniform(0.3, 1.4);
      const double angle = (rng.Uniform() < 0.5 ? -1 : 1) * turn;
      const Eigen::Vector3d a = Eigen::AngleAxisd(angle, w) * r;
      // Three corners spread along w (on screen: along the plane's image, a line when edge-on),
      // so that snapping each one independently can flip the sign of a grazing face's area.
      const Eigen::Vector3d q[3] = {p, p + w * size, p + w * size * rng.Uniform(0.2, 0.8) + a * size * rng.Uniform(0.5, 2)};
      std::array<std::uint32_t, 3> idx;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d v = T.inverse() * q[k];  // object frame
        m.vertices.emplace_back(float(v.x()), float(v.y()), float(v.z()));
        idx[k] = std::uint32_t(m.vertices.size() - 1);
      }
      m.faces.push_back(idx);
    }
    DepthImage depth(640, 480, 0.f);
    for (float& d : depth.data) d = float(depth_m * rng.Uniform(0.8, 1.2));
    for (bool zb : {true, false}) {
      ScoreKernelParams k = SceneParams(m, T, cam, depth, PixelRect{0, 0, 640, 480});
      k.zbuffer = zb;
      RenderWorkspace rws;
      const ScoreKernelResult ref = ScoreReference(k, &rws);
      const render::FacePlanes planes = render::BuildFacePlanes(k);
      const std::int64_t before = preculled_;
      const ScoreKernelResult got = Score(k, &planes);
      ExpectSame(ref, got, "scene " + std::to_string(scene) + (zb ? " zbuffer" : " no-zbuffer"));
      skipped += preculled_ - before;
      faces += k.num_faces;
      front += ref.faces_front;
    }
  }
  // Under half the faces are front (the most grazing ones snap to 2·Area ≤ 0); the margin must
  // leave most back faces to the pre-cull, and the grazing ones to the exact test.
  EXPECT_GT(front, faces / 4);
  if (gpu()) return;  // the gpu kernel has no pre-cull
  EXPECT_GT(skipped, faces / 4);
  EXPECT_LT(skipped + front, faces);
}

std::string BackendName(const ::testing::TestParamInfo<Backend>& i) {
  return i.param.gpu ? "gpu" : render::CpuTargetName(i.param.target);
}
INSTANTIATE_TEST_SUITE_P(CpuKernel, KernelBackend,
                         ::testing::Values(Backend{false, CpuTarget::kPortable}, Backend{false, CpuTarget::kAvx2},
                                           Backend{false, CpuTarget::kAvx512}),
                         BackendName);
INSTANTIATE_TEST_SUITE_P(GpuKernel, KernelBackend, ::testing::Values(Backend{true}), BackendName);

}  // namespace
}  // namespace posefilter
