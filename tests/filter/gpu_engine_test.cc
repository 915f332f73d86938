// The gpu engine end to end: EstimatePose with --engine gpu gives exactly the cpu engine's
// poses and weights (its kernel counts what the reference counts, bit for bit, and its ICP
// weighings run on the cpu kernel), and its failures — no device, a device lost mid-run, a
// batch that never finishes, a mesh too large for the device's buffers — are errors that
// say so, never a hang or a wrong pose. Runs on the machine's Vulkan device (Mesa's lavapipe
// without a GPU); a build without the gpu engine checks its error instead.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <thread>

#include "filter/easy_case.h"
#include "posefilter/error.h"
#include "posefilter/filter.h"
#include "render/gpu_kernel.h"
#include "test_util.h"

namespace posefilter {
namespace {

// Fails (a build with the gpu engine must find a device) or skips (a build without one).
#define REQUIRE_GPU()                                                                    \
  do {                                                                                   \
    if (!render::GpuBuilt()) GTEST_SKIP() << "this build has no gpu engine";            \
    std::string why;                                                                     \
    ASSERT_TRUE(render::GpuAvailable(&why)) << why;                                      \
  } while (0)

// Small budgets (lavapipe runs the shaders on the CPU, far slower than the cpu engine).
FilterOptions Budget(const std::string& engine) {
  FilterOptions o = EasyCase::Small(6);
  o.num_particles = 48;
  o.engine = engine;
  return o;
}

void ExpectSameEstimate(const EstimateResult& cpu, const EstimateResult& gpu, const std::string& what) {
  EXPECT_EQ(cpu.weight, gpu.weight) << what;
  EXPECT_TRUE(cpu.T_cam_obj.isApprox(gpu.T_cam_obj, 0.0)) << what;
  EXPECT_EQ(cpu.best_weight_history, gpu.best_weight_history) << what;
  EXPECT_EQ(cpu.stats.fragments, gpu.stats.fragments) << what;
  EXPECT_EQ(cpu.stats.weighings, gpu.stats.weighings) << what;
  EXPECT_EQ(cpu.stats.faces_front, gpu.stats.faces_front) << what;
}

TEST(GpuEngine, SamePosesAndWeightsAsTheCpuEngine) {
  REQUIRE_GPU();
  for (const char* target : {"lshape", "torus"}) {
    const int errors = render::GpuValidationErrors();
    const EasyCase c(target, 11);
    const EstimateResult cpu = c.Run(Budget("cpu"));
    const EstimateResult gpu = c.Run(Budget("gpu"));
    ExpectSameEstimate(cpu, gpu, target);
    EXPECT_GT(gpu.stats.fragments, 10000) << target;
    EXPECT_EQ(render::GpuValidationErrors(), errors) << render::GpuFirstValidationError();
  }
  // Thesis mode (no z-buffer), annealing on the coarse grid off, and the final polish (ICP
  // weighings on the cpu kernel, the rest on the device).
  const EasyCase c("box", 12);
  FilterOptions o = Budget("cpu");
  o.render.zbuffer = false;
  o.anneal.subsample = 1;
  const EstimateResult cpu = c.Run(o);
  o.engine = "gpu";
  ExpectSameEstimate(cpu, c.Run(o), "box, no z-buffer");
}

// Estimates on several threads share the one device (each owns its buffers and command
// buffers; submissions and uploads are serialised): each gives its sequential result.
TEST(GpuEngine, ConcurrentEstimatesGiveTheSequentialResults) {
  REQUIRE_GPU();
  const EasyCase a("lshape", 16), b("torus", 17);
  const FilterOptions o = Budget("gpu");
  const EstimateResult seq_a = a.Run(o), seq_b = b.Run(o);
  EstimateResult par_a, par_b;
  std::thread ta([&] { par_a = a.Run(o); });
  std::thread tb([&] { par_b = b.Run(o); });
  ta.join();
  tb.join();
  ExpectSameEstimate(seq_a, par_a, "lshape");
  ExpectSameEstimate(seq_b, par_b, "torus");
}

TEST(GpuEngine, ADeviceLostOrHungMidRunIsAnErrorAndTheNextEstimateWorks) {
  REQUIRE_GPU();
  const EasyCase c("box", 13);
  const FilterOptions o = Budget("gpu");
  render::gpu_testing::InjectFault(/*lost=*/true);
  testing_util::ExpectError([&] { c.Run(o); }, {"gpu engine", "lost", "--engine cpu"});
  render::gpu_testing::InjectFault(/*lost=*/false);
  testing_util::ExpectError([&] { c.Run(o); }, {"gpu engine", "did not finish", "--engine cpu"});
  // A new device after the loss: the same answer as the cpu engine.
  FilterOptions cpu = o;
  cpu.engine = "cpu";
  ExpectSameEstimate(c.Run(cpu), c.Run(o), "after the faults");
}

TEST(GpuEngine, AMeshTooLargeForTheDevicesBuffersIsAnErrorNamingTheLimit) {
  REQUIRE_GPU();
  const EasyCase c("torus", 14);  // 1024 vertices: 16 KiB of vertex records per particle
  FilterOptions o = Budget("gpu");
  o.anneal.subsample = 1;  // one level: the full mesh and image
  o.render.lod_face_px = 0;
  ASSERT_EQ(setenv("POSEFILTER_GPU_MAX_BUFFER_BYTES", "8192", 1), 0);
  try {
    testing_util::ExpectError([&] { c.Run(o); }, {"gpu engine", "too large", "vertices", "--engine cpu"});
    ASSERT_EQ(setenv("POSEFILTER_GPU_MAX_BUFFER_BYTES", "12", 1), 0);
    testing_util::ExpectError([&] { c.Run(o); }, {"POSEFILTER_GPU_MAX_BUFFER_BYTES", "12"});
    // Room for the 640×480 depth image and a few particles' records at a time: many small
    // batches, the same result.
    ASSERT_EQ(setenv("POSEFILTER_GPU_MAX_BUFFER_BYTES", "1300000", 1), 0);
    const EstimateResult small = c.Run(o);
    unsetenv("POSEFILTER_GPU_MAX_BUFFER_BYTES");
    FilterOptions cpu = o;
    cpu.engine = "cpu";
    ExpectSameEstimate(c.Run(cpu), small, "batches of a few particles");
  } catch (...) {
    unsetenv("POSEFILTER_GPU_MAX_BUFFER_BYTES");
    throw;
  }
  unsetenv("POSEFILTER_GPU_MAX_BUFFER_BYTES");
}

TEST(GpuEngine, WithoutTheEngineOrADeviceTheErrorSaysSoAndNamesTheCpuEngine) {
  std::string why;
  if (render::GpuBuilt() && render::GpuAvailable(&why)) GTEST_SKIP() << "a device is present (see the CLI test)";
  const EasyCase c("box", 15);
  testing_util::ExpectError([&] { c.Run(Budget("gpu")); }, {"gpu engine", "--engine cpu"});
}

}  // namespace
}  // namespace posefilter
