// The cpu kernel compiled for AVX2 (CMakeLists.txt adds -mavx2 … -ffp-contract=off to this file
// on x86-64; elsewhere it compiles to a stub that reports "not built").
#include <cstdint>

#include "render/cpu_kernel.h"

#if defined(__AVX2__) && defined(__FMA__) && defined(__BMI2__) && defined(__POPCNT__)
#define POSEFILTER_CPU_NS cpu_avx2
#define POSEFILTER_CPU_ENTRY CoreAvx2
#define POSEFILTER_CPU_LANES 4
#include "render/cpu_kernel_impl.inc"
bool posefilter::render::cpu_detail::BuiltAvx2() { return true; }
#else
bool posefilter::render::cpu_detail::BuiltAvx2() { return false; }
std::int64_t posefilter::render::cpu_detail::CoreAvx2(const ScoreKernelParams&, const CoreScratch&,
                                                      ScoreKernelResult*) {
  return -1;
}
#endif
