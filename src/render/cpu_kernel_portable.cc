// The cpu kernel compiled for the baseline instruction set (SSE2 on x86-64; any target).
#define POSEFILTER_CPU_NS cpu_portable
#define POSEFILTER_CPU_ENTRY CorePortable
#define POSEFILTER_CPU_LANES 2
#include "render/cpu_kernel_impl.inc"
