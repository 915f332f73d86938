// src/filter/engine_registry.cc — the engine rows (engine_registry.h). A new engine is a row
// here and its own file: a ParticleWeigher (engine_weigh.h) for an engine that weighs the float
// filter's particles, or an EngineRuns (engine.h) for one that runs whole runs of its own.
#include "filter/engine_registry.h"

#include <string>

#include "filter/model_lod.h"
#include "filter/rtl_engine.h"
#include "posefilter/option_table.h"
#include "render/cpu_kernel.h"
#include "render/gpu_kernel.h"

namespace posefilter::filter {
namespace {

// The float filter's runs (particle_filter.cc) on the mesh's level of detail.
std::unique_ptr<EngineRuns> FloatFilterRuns(const EngineInputs& in) {
  return MakeFloatEngine(in.prep, LodFor(in.model, in.mesh, in.options, true, in.prep->plane.found), in.prior, in.cls,
                         in.options);
}
std::unique_ptr<EngineRuns> HwModelRuns(const EngineInputs& in) {
  return MakeHwEngine(*in.prep, in.mesh, in.prior, in.cls, in.options);
}
std::unique_ptr<EngineRuns> RtlModelRuns(const EngineInputs& in) {
  return MakeRtlEngine(*in.prep, in.mesh, in.prior, in.cls, in.options);
}

bool AlwaysAvailable(std::string*) { return true; }
bool ListedByDefault() { return true; }
bool NotListedByDefault() { return false; }
bool GpuIsNotCpuDriver() {
  return render::GpuAvailable(nullptr) && render::GpuDeviceName().find("(cpu)") == std::string::npos;
}
bool GpuEngineAvailable(std::string* why) { return render::GpuAvailable(why); }
bool HwEngineAvailable(std::string* why) { return HwEngineBuilt(why); }
bool HwListedByDefault() { return HwEngineBuilt(nullptr); }
bool RtlEngineAvailable(std::string* why) { return RtlEngineBuilt(why); }

std::string DescribeCpuEngine() {
  std::string s = "instruction sets built: portable";
  if (render::cpu_detail::BuiltAvx2()) s += ", avx2";
  if (render::cpu_detail::BuiltAvx512()) s += ", avx512";
  return s + "; this CPU runs " + render::CpuTargetName(render::BestCpuTarget());
}
std::string DescribeGpuEngine() {
  return render::GpuBuilt() ? "Vulkan compute" : "not built (no Vulkan headers or glslang at build time)";
}
std::string DescribeHwEngine() {
  std::string why;
  return HwEngineBuilt(&why) ? "C simulation of the FPGA design (fixed point)" : "not built (" + why + ")";
}
std::string DescribeRtlEngine() {
  std::string why;
  return RtlEngineBuilt(&why) ? "Verilated RTL of the weighing pipeline (hw engine's results)"
                                                 : "not built (" + why + ")";
}

constexpr EngineRow kEngineRows[] = {
    {"reference", kEngineReference, "scalar float renderer", true, ListedByDefault, FloatFilterRuns, MakeReferenceWeigher,
     AlwaysAvailable, nullptr},
    {"cpu", kEngineCpu, "SIMD float kernel (the reference's results)", true, ListedByDefault, FloatFilterRuns, MakeCpuWeigher,
     AlwaysAvailable, DescribeCpuEngine},
    // Runs of its own (hw_driver.cc); a float context with its options weighs with the reference.
    {"hw", kEngineHw, "C simulation of the FPGA design (fixed point)", false, HwListedByDefault, HwModelRuns, MakeReferenceWeigher,
     HwEngineAvailable, DescribeHwEngine},
    {"gpu", kEngineGpu, "Vulkan compute (the reference's counts)", true, GpuIsNotCpuDriver, FloatFilterRuns, MakeGpuWeigher,
     GpuEngineAvailable, DescribeGpuEngine},
    // The hw engine with its weighing in Verilated RTL (rtl_engine.cc).
    {"rtl", kEngineHw, "Verilated RTL of the weighing pipeline", false, NotListedByDefault, RtlModelRuns, MakeReferenceWeigher,
     RtlEngineAvailable, DescribeRtlEngine},
};

}  // namespace

std::span<const EngineRow> EngineRegistry() { return kEngineRows; }

const EngineRow* FindEngine(std::string_view name) {
  for (const EngineRow& row : kEngineRows)
    if (name == row.name) return &row;
  return nullptr;
}

const EngineRow& DefaultEngine() {
  static const EngineRow* const row = FindEngine(FilterOptions{}.engine);
  return *row;
}

std::string EngineChoices(const char* separator) {
  std::string s = DefaultEngine().name;
  for (const EngineRow& row : kEngineRows)
    if (&row != &DefaultEngine()) s += separator + std::string(row.name);
  return s;
}

}  // namespace posefilter::filter
