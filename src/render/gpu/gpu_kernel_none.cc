// The gpu engine in a build without Vulkan (POSEFILTER_VULKAN=OFF): GpuAvailable says so, and
// making a kernel throws that reason.
#include "posefilter/error.h"
#include "render/gpu_kernel.h"

namespace posefilter::render {

namespace {
const char* const kNoVulkan =
    "gpu engine: this build has no Vulkan support (configure with -DPOSEFILTER_VULKAN=ON after scripts/setup.sh "
    "installs libvulkan-dev and glslang-tools); use --engine cpu";
}  // namespace

struct GpuKernel::Impl {};

bool GpuBuilt() { return false; }
int GpuValidationErrors() { return 0; }
std::string GpuFirstValidationError() { return ""; }

bool GpuAvailable(std::string* why) {
  if (why) *why = kNoVulkan;
  return false;
}
std::string GpuDeviceName() { throw Error(kNoVulkan); }

GpuKernel::GpuKernel(const ScoreKernelParams&) { throw Error(kNoVulkan); }
GpuKernel::~GpuKernel() = default;
void GpuKernel::Score(const std::vector<ScoreKernelParams>&, std::vector<ScoreKernelResult>*, double) {
  throw Error(kNoVulkan);
}

namespace gpu_testing {
void InjectFault(bool) {}
}  // namespace gpu_testing

}  // namespace posefilter::render
