// One side of posefilter_kernel_ab (kernel_ab.cc): the cpu kernel's AVX-512 or AVX2 variant
// (POSEFILTER_KERNEL_AB_ISA) compiled into a namespace of its own, from the implementation file
// CMake names in POSEFILTER_AB_IMPL (side A: POSEFILTER_KERNEL_AB_BASE, e.g. a copy of an older
// cpu_kernel_impl.inc; side B: the tree's). Built with the flags of
// src/render/cpu_kernel_avx512.cc or cpu_kernel_avx2.cc.
#include <cstdint>

#include "render/cpu_kernel.h"

#if !defined(POSEFILTER_AB_NS) || !defined(POSEFILTER_AB_ENTRY) || !defined(POSEFILTER_AB_IMPL)
#error "CMake defines POSEFILTER_AB_NS, POSEFILTER_AB_ENTRY and POSEFILTER_AB_IMPL for each side"
#endif

namespace posefilter::render::cpu_detail {
std::int64_t POSEFILTER_AB_ENTRY(const ScoreKernelParams& k, const CoreScratch& s, ScoreKernelResult* r);
}

#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__) && defined(__AVX512BW__)
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // as in cpu_kernel_avx512.cc
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif
#define POSEFILTER_CPU_LANES 8
#elif defined(__AVX2__) && defined(__FMA__) && defined(__BMI2__) && defined(__POPCNT__)
#define POSEFILTER_CPU_LANES 4
#endif

#if defined(POSEFILTER_CPU_LANES)
#define POSEFILTER_CPU_NS POSEFILTER_AB_NS
#define POSEFILTER_CPU_ENTRY POSEFILTER_AB_ENTRY
#include POSEFILTER_AB_IMPL
#else
std::int64_t posefilter::render::cpu_detail::POSEFILTER_AB_ENTRY(const ScoreKernelParams&, const CoreScratch&,
                                                                 ScoreKernelResult*) {
  return -2;  // not built
}
#endif
