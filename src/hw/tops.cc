// src/hw/tops.cc — the definitions of the four HLS tops declared in tops.h: the functions the
// HLS flow names with set_top (scripts/hls/*.tcl compile this file as the design source), and
// in C simulation a translation unit of the library. They only carry the INTERFACE pragmas and
// call the regions of top.h; top.h explains the design.
#include "hw/tops.h"

#include "hw/top.h"

#ifndef __SYNTHESIS__
#include <cstdio>
#include <cstdlib>
#endif

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

// In C simulation a top records into the trace its caller named for this thread (ScopedTopTrace,
// hw_types.h; none by default); the kernels' HW_TRACE_ARG passes it on.
#ifndef __SYNTHESIS__
#define HW_TOP_TRACE ::posefilter::hw::CycleTrace* const trace = ::posefilter::hw::TopTrace()
#else
#define HW_TOP_TRACE
#endif

namespace posefilter::hw {

// Initialisation (§7.4, Fig. 7.5): n samples of the class whose post-processed probabilities
// are prob[·][0] (one class loaded, NC = 1) and whose sum is class_sum. The sampling memory
// (the CDF, kNumCells × 18 bits, BRAM) is local to the design.
void HwInitTop(const prob_t prob[kNumCells][1], class_sum_t class_sum, const HeuristicVolume volumes[kNumCells],
                      InitGenerators& gen, const InitOptions& opt, Sample samples[kMaxParticles], int n,
                      InitReport& report) {
  HW_TOP_TRACE;
#pragma HLS INTERFACE m_axi port = prob offset = slave bundle = gmem_prob depth = 6300
#pragma HLS INTERFACE m_axi port = volumes offset = slave bundle = gmem_vol depth = 6300
#pragma HLS INTERFACE m_axi port = samples offset = slave bundle = gmem_smp depth = 510
#pragma HLS INTERFACE s_axilite port = class_sum bundle = control
#pragma HLS INTERFACE s_axilite port = gen bundle = control
#pragma HLS INTERFACE s_axilite port = opt bundle = control
#pragma HLS INTERFACE s_axilite port = n bundle = control
#pragma HLS INTERFACE s_axilite port = report bundle = control
#pragma HLS INTERFACE s_axilite port = return bundle = control
  cdf_t cdf_mem[kNumCells];
  InitSamples<1>(prob, 0, class_sum, volumes, cdf_mem, gen, opt, samples, n, report HW_TRACE_ARG);
}

// The weigh tops' interfaces: one m_axi bundle per process that touches memory
// (GatherSampleInfo: samples + cell windows; DistributeDepth: depth; VertexMultiplier: the
// model; MergeWeights: ρ), and one per array where a loop writes two at once (SortWeights:
// sorted_w, sorted_idx; CollectStats: stats, offsets): a bundle moves one word per clock.
#define HW_WEIGH_TOP_INTERFACE                                                                               \
  _Pragma("HLS INTERFACE m_axi port = samples offset = slave bundle = gmem_info depth = 510")               \
  _Pragma("HLS INTERFACE m_axi port = cell_windows offset = slave bundle = gmem_info depth = 6300")         \
  _Pragma("HLS INTERFACE m_axi port = class_prob offset = slave bundle = gmem_prob depth = 6300")           \
  _Pragma("HLS INTERFACE m_axi port = depth offset = slave bundle = gmem_depth depth = 307200")             \
  _Pragma("HLS INTERFACE m_axi port = vmem offset = slave bundle = gmem_model depth = 3072")                \
  _Pragma("HLS INTERFACE m_axi port = tri_mem offset = slave bundle = gmem_model depth = 2048")             \
  _Pragma("HLS INTERFACE m_axi port = sorted_w offset = slave bundle = gmem_sort_w depth = 510")            \
  _Pragma("HLS INTERFACE m_axi port = sorted_idx offset = slave bundle = gmem_sort_idx depth = 510")        \
  _Pragma("HLS INTERFACE m_axi port = stats offset = slave bundle = gmem_stats depth = 510")                \
  _Pragma("HLS INTERFACE m_axi port = offsets offset = slave bundle = gmem_offsets depth = 510")            \
  _Pragma("HLS INTERFACE s_axilite port = n bundle = control")                                              \
  _Pragma("HLS INTERFACE s_axilite port = cfg bundle = control")                                            \
  _Pragma("HLS INTERFACE s_axilite port = dd_counts bundle = control")                                      \
  _Pragma("HLS INTERFACE s_axilite port = return bundle = control")

// The thesis's two designs (§7.7: five and ten raster cores) as HLS tops.
void HwWeighTop5(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                        const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
                        const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
                        const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                        particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                        depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts) {
  HW_TOP_TRACE;
  HW_WEIGH_TOP_INTERFACE
  HwWeighTop<5>(n, cfg, samples, cell_windows, class_prob, depth, vmem, tri_mem, sorted_w, sorted_idx, stats, offsets,
                dd_counts HW_TRACE_ARG);
}

void HwWeighTop10(int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                         const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
                         const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
                         const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                         particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                         depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts) {
  HW_TOP_TRACE;
  HW_WEIGH_TOP_INTERFACE
  HwWeighTop<10>(n, cfg, samples, cell_windows, class_prob, depth, vmem, tri_mem, sorted_w, sorted_idx, stats, offsets,
                 dd_counts HW_TRACE_ARG);
}

#ifndef __SYNTHESIS__
// Host side (C simulation, tops.h): HwWeighTop<M> for a runtime core count (the driver and
// ProfileHw choose M at run time; each M is its own hardware design).
void HwWeighTopCores(int cores, int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
                            const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
                            const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
                            const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles],
                            particle_index_t sorted_idx[kMaxParticles], RasterCoreOutput stats[kMaxParticles],
                            depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts HW_TRACE_PARAM) {
#define HW_WEIGH_CASE(m)                                                                                           \
  case m:                                                                                                          \
    HwWeighTop<m>(n, cfg, samples, cell_windows, class_prob, depth, vmem, tri_mem, sorted_w, sorted_idx, stats,    \
                  offsets, dd_counts HW_TRACE_ARG);                                                                \
    return;
  switch (cores) {
    HW_WEIGH_CASE(1)
    HW_WEIGH_CASE(2)
    HW_WEIGH_CASE(3)
    HW_WEIGH_CASE(4)
    HW_WEIGH_CASE(5)
    HW_WEIGH_CASE(6)
    HW_WEIGH_CASE(7)
    HW_WEIGH_CASE(8)
    HW_WEIGH_CASE(9)
    HW_WEIGH_CASE(10)
    default:
      break;
  }
#undef HW_WEIGH_CASE
  std::fprintf(stderr, "HwWeighTopCores: %d raster cores is outside [1, %d]\n", cores, kMaxRasterCores);
  std::abort();  // the callers validate the core count
}
#endif

// Resampling (elitism, pool, threshold tracker) and diffusion into samples_out. w_best, the
// best weight that sets the diffusion spread, is the sorter's first output (§7.6): the host
// reads sorted_w[0] for its convergence test anyway and passes it as a register, so sorted_w
// has one reader (Resample). The current sample memory is bound to two read ports,
// samples_in (Diffuse: the samples to move) and samples_in_cells (Resample: the cells of the
// region and rotation caps) — the same buffer, read-only, so each process owns its port (the
// thesis's "copy for the dataflow" of the index memory, §7.1, without the copy). The host
// passes the same memory to both.
void HwUpdateTop(const weight_t sorted_w[kMaxParticles], const particle_index_t sorted_idx[kMaxParticles],
                        weight_t w_best, const Sample samples_in[kMaxParticles],
                        const Sample samples_in_cells[kMaxParticles], const depth_off_t offsets_in[kMaxParticles],
                        const hypothesis_t hypothesis[kNumCells], const ResampleParams& rprm, Lfsr18& resample_rng,
                        const DiffusionParams& dprm, const HeuristicVolume volumes[kNumCells],
                        DiffusionRng& diffusion_rng, Sample samples_out[kMaxParticles],
                        ResampleCounters* counters) {
  HW_TOP_TRACE;
#pragma HLS INTERFACE m_axi port = sorted_w offset = slave bundle = gmem_sort_w depth = 510
#pragma HLS INTERFACE m_axi port = sorted_idx offset = slave bundle = gmem_sort_idx depth = 510
#pragma HLS INTERFACE m_axi port = samples_in_cells offset = slave bundle = gmem_caps depth = 510
#pragma HLS INTERFACE m_axi port = hypothesis offset = slave bundle = gmem_caps depth = 6300
#pragma HLS INTERFACE m_axi port = samples_in offset = slave bundle = gmem_smp depth = 510
#pragma HLS INTERFACE m_axi port = offsets_in offset = slave bundle = gmem_smp depth = 510
#pragma HLS INTERFACE m_axi port = volumes offset = slave bundle = gmem_vol depth = 6300
#pragma HLS INTERFACE m_axi port = samples_out offset = slave bundle = gmem_out depth = 510
#pragma HLS INTERFACE s_axilite port = w_best bundle = control
#pragma HLS INTERFACE s_axilite port = rprm bundle = control
#pragma HLS INTERFACE s_axilite port = resample_rng bundle = control
#pragma HLS INTERFACE s_axilite port = dprm bundle = control
#pragma HLS INTERFACE s_axilite port = diffusion_rng bundle = control
#pragma HLS INTERFACE s_axilite port = counters bundle = control
#pragma HLS INTERFACE s_axilite port = return bundle = control
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, trace);
  particle_index_t selected[kMaxParticles];  // ping-pong buffer: Diffuse starts when Resample has returned
  HW_PROCESS(df, Resample(sorted_w, sorted_idx, samples_in_cells, hypothesis, rprm, resample_rng, selected, counters,
                          nullptr HW_TRACE_ARG));
  HW_PROCESS_AFTER(df, "Resample", Diffuse(samples_in, offsets_in, selected, rprm.num_particles, rprm.num_elite, w_best,
                                           dprm, volumes, diffusion_rng, samples_out HW_TRACE_ARG));
  HW_DATAFLOW_END(df);
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
