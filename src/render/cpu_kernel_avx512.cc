// The cpu kernel compiled for AVX-512 F/DQ/VL/BW (CMakeLists.txt adds the -m flags and
// -ffp-contract=off to this file on x86-64; elsewhere it compiles to a stub that reports
// "not built").
#include <cstdint>

#include "render/cpu_kernel.h"

#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__) && defined(__AVX512BW__)
// GCC 12's AVX-512 intrinsics (e.g. _mm512_max_pd) pass `_mm512_undefined_pd()`, a
// self-initialised `__Y`, as the unused merge operand; inlined here, -Wmaybe-uninitialized
// flags that idiom (GCC bug 105593; as -Wuninitialized where the intrinsic is inlined into an
// out-of-line helper). No value of ours is involved. (Clang has no such warning group.)
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif
#define POSEFILTER_CPU_NS cpu_avx512
#define POSEFILTER_CPU_ENTRY CoreAvx512
#define POSEFILTER_CPU_LANES 8
#include "render/cpu_kernel_impl.inc"
bool posefilter::render::cpu_detail::BuiltAvx512() { return true; }
#else
bool posefilter::render::cpu_detail::BuiltAvx512() { return false; }
std::int64_t posefilter::render::cpu_detail::CoreAvx512(const ScoreKernelParams&, const CoreScratch&,
                                                        ScoreKernelResult*) {
  return -1;
}
#endif
