// The score kernels' set-up and inputs: the cpu engine's dispatch list, the back-face
// pre-cull turning itself off outside its proof (with the kernel's result unchanged), the cpu
// and gpu kernels' input errors, the valid-depth summed-area table, and (with the gpu engine)
// that the Vulkan validation layer's error count moves on invalid usage. The kernels' results
// against the reference kernel: cpu_kernel_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "posefilter/error.h"
#include "posefilter/render.h"
#include "posefilter/rng.h"
#include "posefilter/synth.h"
#include "render/cpu_kernel.h"
#include "render/gpu_kernel.h"
#ifdef POSEFILTER_HAS_VULKAN
#include "render/gpu/vulkan_device.h"
#endif
#include "render/kernel_test_util.h"
#include "test_util.h"

namespace posefilter {
namespace {

using testing_util::At;
using testing_util::PinholeCamera;

// fn() must throw posefilter::Error whose message contains every word of `words`.
template <class Fn>
void ExpectThrowsWith(Fn&& fn, std::initializer_list<const char*> words) {
  try {
    fn();
    ADD_FAILURE() << "no posefilter::Error thrown";
  } catch (const Error& e) {
    for (const char* w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

#ifdef POSEFILTER_HAS_VULKAN
// The validation check can fail: with POSEFILTER_VULKAN_VALIDATION=1 (ctest gpu_validation), a
// buffer of size 0 — invalid usage — raises the count the gpu tests compare before and after.
TEST(GpuKernelValidation, TheLayerCountsInvalidUsage) {
  if (!render::GpuBuilt() || std::getenv("POSEFILTER_VULKAN_VALIDATION") == nullptr)
    GTEST_SKIP() << "validation off (the ctest gpu_validation runs this with it on)";
  std::string why;
  ASSERT_TRUE(render::GpuAvailable(&why)) << why;
  const auto dev = render::gpu::VulkanDevice::Shared();
  ASSERT_TRUE(dev->validation());
  const int before = dev->ValidationErrors();
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = 0;  // VUID-VkBufferCreateInfo-size-00912
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer b = VK_NULL_HANDLE;
  if (vkCreateBuffer(dev->device(), &bci, nullptr, &b) == VK_SUCCESS && b != VK_NULL_HANDLE)
    vkDestroyBuffer(dev->device(), b, nullptr);
  EXPECT_GT(dev->ValidationErrors(), before);
}
#endif

TEST(CpuKernel, DispatchListsPortableFirstAndTheBestVariantIsSupported) {
  const auto targets = render::SupportedCpuTargets();
  ASSERT_FALSE(targets.empty());
  EXPECT_EQ(targets.front(), render::CpuTarget::kPortable);
  EXPECT_TRUE(render::CpuTargetSupported(render::BestCpuTarget()));
  EXPECT_EQ(targets.back(), render::BestCpuTarget());
  EXPECT_STREQ(render::CpuTargetName(render::CpuTarget::kAvx512), "avx512");
}

TEST(CpuKernel, PreCullTurnsItselfOffOutsideItsProof) {
  // PreCullConstants must decline (the kernel then sends every face to the face pass) whenever
  // an assumption of its margin fails, and the kernel's result must not change either way.
  const Mesh torus = MakeTorus(0.06, 0.025, 16, 12);
  const Camera cam = PinholeCamera(525, 525);
  const DepthImage depth(640, 480, 0.8f);
  ScoreKernelParams k = kernel_test::SceneParams(torus, At(0.01, 0, 0.7), cam, depth, PixelRect{0, 0, 640, 480});
  const render::FacePlanes planes = render::BuildFacePlanes(k);
  float c[3], k1, k0;
  ASSERT_TRUE(render::PreCullConstants(k, planes, c, &k1, &k0));
  EXPECT_GT(k1, 0.f);
  EXPECT_GT(k0, 0.f);
  EXPECT_NEAR(c[2], -0.7f, 1e-6f);  // the camera centre in the object frame (R = I)
  auto declines = [&](ScoreKernelParams p, const char* what) {
    EXPECT_FALSE(render::PreCullConstants(p, planes, c, &k1, &k0)) << what;
    RenderWorkspace rws;
    render::CpuWorkspace ws;
    const ScoreKernelResult ref = ScoreReference(p, &rws);
    kernel_test::ExpectSame(ref, render::ScoreCpu(p, &ws, &planes), what);
    EXPECT_EQ(ws.faces_preculled, 0) << what;
  };
  ScoreKernelParams p = k;
  p.t[2] = 0.05f;  // the object reaches behind the camera
  declines(p, "object around the camera");
  p = k;
  p.R[0] = 1.05f;  // not a rotation
  declines(p, "R scaled");
  p = k;
  p.R[0] = -1;  // a reflection (det < 0)
  declines(p, "R reflects");
  p = k;
  p.fx = -525;
  declines(p, "negative focal length");
  p = k;
  p.t[0] = std::nanf("");
  declines(p, "NaN translation");
  // A mesh with a non-finite vertex: the table's radius is infinite, the pre-cull off.
  Mesh bad = torus;
  bad.vertices[3].x() = std::numeric_limits<float>::infinity();
  const ScoreKernelParams kb = kernel_test::SceneParams(bad, At(0.01, 0, 0.7), cam, depth, PixelRect{0, 0, 640, 480});
  const render::FacePlanes pb = render::BuildFacePlanes(kb);
  EXPECT_FALSE(render::PreCullConstants(kb, pb, c, &k1, &k0));
}

TEST(CpuKernel, BadInputsThrowNamingTheProblem) {
  const Mesh box = MakeBox(0.1, 0.1, 0.1);
  const Camera cam = PinholeCamera(500, 500);
  DepthImage depth(640, 480, 1.0f);
  render::CpuWorkspace ws;
  auto params = [&] { return kernel_test::SceneParams(box, At(0, 0, 1), cam, depth, PixelRect{0, 0, 640, 480}); };
  ScoreKernelParams k = params();
  k.window = PixelRect{600, 0, 50, 10};  // sticks out of the image
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws); }, {"window", "640x480"});
  k = params();
  k.window = PixelRect{-1, 0, 10, 10};
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws); }, {"window"});
  k = params();
  k.depth = nullptr;
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws); }, {"depth"});
  Mesh broken = box;
  broken.faces[5][1] = 8;  // one past the last vertex
  k = kernel_test::SceneParams(broken, At(0, 0, 1), cam, depth, PixelRect{0, 0, 640, 480});
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws); }, {"face 5", "out of range"});
  for (render::CpuTarget t : render::SupportedCpuTargets())
    ExpectThrowsWith([&] { render::ScoreCpuWith(t, k, &ws); }, {"face 5"});
  k.near_m = 0;  // the fallback path checks indices too
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws); }, {"face 5"});
  k = params();
  k.num_faces = 3;
  k.faces = nullptr;
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws); }, {"faces"});
  // Face planes: built from another mesh, or from a mesh with a bad index.
  const Mesh other = MakeBox(0.1, 0.1, 0.1);
  const ScoreKernelParams ko = MakeKernelParams(other, At(0, 0, 1), cam);
  const render::FacePlanes planes = render::BuildFacePlanes(ko);
  k = params();
  ExpectThrowsWith([&] { render::ScoreCpu(k, &ws, &planes); }, {"face planes", "another mesh"});
  const ScoreKernelParams kb = kernel_test::SceneParams(broken, At(0, 0, 1), cam, depth, PixelRect{0, 0, 640, 480});
  ExpectThrowsWith([&] { render::BuildFacePlanes(kb); },
                   {"face 5", "out of range"});
}

// The gpu kernel's inputs: every misuse is an Error naming it (a build without the engine
// has none to test: its error is tested by the CLI and filter tests).
TEST(GpuKernel, BadInputsThrowNamingTheProblem) {
  if (!render::GpuBuilt()) GTEST_SKIP() << "this build has no gpu engine";
  std::string why;
  ASSERT_TRUE(render::GpuAvailable(&why)) << why;
  const Mesh box = MakeBox(0.1, 0.1, 0.1);
  const Camera cam = PinholeCamera(500, 500);
  DepthImage depth(640, 480, 1.0f), other_depth(640, 480, 1.0f);
  auto params = [&] { return kernel_test::SceneParams(box, At(0, 0, 1), cam, depth, PixelRect{0, 0, 640, 480}); };
  Mesh broken = box;
  broken.faces[5][1] = 8;  // one past the last vertex
  ExpectThrowsWith(
      [&] { render::GpuKernel(kernel_test::SceneParams(broken, At(0, 0, 1), cam, depth, PixelRect{0, 0, 640, 480})); },
      {"gpu engine", "face 5", "out of range"});
  ScoreKernelParams k = params();
  k.depth = nullptr;
  ExpectThrowsWith([&] { render::GpuKernel kernel(k); }, {"gpu engine", "depth"});
  render::GpuKernel kernel(params());
  std::vector<ScoreKernelResult> out;
  k = params();
  k.window = PixelRect{600, 0, 50, 10};  // sticks out of the image
  ExpectThrowsWith([&] { kernel.Score({params(), k}, &out); }, {"gpu engine", "window of particle 1"});
  k = params();
  k.depth = other_depth.data.data();
  ExpectThrowsWith([&] { kernel.Score({k}, &out); }, {"gpu engine", "another model or image"});
  k = params();
  k.inlier.thr1_m = 0.01f;
  ExpectThrowsWith([&] { kernel.Score({params(), k}, &out); }, {"gpu engine", "mixes", "particle 1"});
  const std::vector<float> normals = ComputeSceneNormals(depth, cam);
  k = params();
  k.scene_normals = normals.data();
  ExpectThrowsWith([&] { kernel.Score({k}, &out); }, {"gpu engine", "ICP"});
  // An empty window renders nothing, as the reference: only faces_total is set.
  k = params();
  k.window = PixelRect{10, 10, 0, 5};
  kernel.Score({k}, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].faces_total, 12);
  EXPECT_EQ(out[0].faces_front, 0);
  EXPECT_EQ(out[0].n_raster, 0);
}

TEST(CpuKernel, ValidDepthSatCountsAnyRectangle) {
  Rng rng(3);
  const int W = 37, H = 23;
  std::vector<float> d(W * H);
  for (float& z : d) z = rng.Uniform() < 0.3 ? 0.f : float(rng.Uniform(0.5, 2));
  const render::ValidDepthSat sat(d.data(), W, H);
  for (int i = 0; i < 300; ++i) {
    const PixelRect r{int(rng.UniformInt(50)) - 5, int(rng.UniformInt(35)) - 5, int(rng.UniformInt(45)),
                      int(rng.UniformInt(30))};
    std::int64_t brute = 0;
    for (int v = std::max(0, r.v0); v < std::min(H, r.v0 + r.height); ++v)
      for (int u = std::max(0, r.u0); u < std::min(W, r.u0 + r.width); ++u) brute += d[v * W + u] > 0;
    EXPECT_EQ(sat.Count(r), brute) << r.u0 << "," << r.v0 << " " << r.width << "x" << r.height;
  }
  EXPECT_EQ(sat.Count(PixelRect{0, 0, W, H}), std::int64_t(std::count_if(d.begin(), d.end(), [](float z) { return z > 0; })));
  ExpectThrowsWith([] { render::ValidDepthSat(nullptr, 4, 4); }, {"ValidDepthSat"});
  ExpectThrowsWith([] { render::ValidDepthSat(nullptr, -1, 4); }, {"negative"});
}

}  // namespace
}  // namespace posefilter
