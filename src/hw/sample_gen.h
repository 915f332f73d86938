// src/hw/sample_gen.h — sample generation of the initialisation (thesis §7.4 item 5,
// Listing 7.5 [ALGORITHM.md]; docs/HARDWARE.md §7.1) and the whole initialisation chain (Fig. 7.5) as one dataflow
// region: CDF + normalisation → threshold tracker → bound generator → sampling → sample
// generation, fed by the LFSR generators.
//
// Sample generation (Listing 7.5 [ALGORITHM.md]): for each sampled cell index, read the cell's heuristic
// volume and write a Sample:
//   x = (x_min + x_max)/2, y = (y_min + y_max)/2   (full-precision sum, one shift, truncated
//                                                   to xyz_t: floor to 2^-10, in [min, max])
//   z = z_min + (z_max − z_min)·u_z, u_z ∈ [2^-18, 1) from an LFSR18 (truncated to xyz_t, so
//       z ∈ [z_min, z_max] when z_min ≤ z_max)
//   roll, pitch, yaw from three LFSR15 angle generators (lfsr.h AngleGenerate, Listing 7.6 [HARDWARE.md])
//   cell = the index.
// The thesis also writes the index to two absolute-index memories (Sample_abs_inx and its
// copy for the dataflow); ours keeps it in Sample::cell (hw_types.h).
#pragma once

#include "hw/cdf.h"
#include "hw/dataflow.h"
#include "hw/burst.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/lfsr.h"
#include "hw/sampling.h"
#include "hw/threshold_tracker.h"

namespace posefilter::hw {

// Writes samples[0 … n−1] (n clamped to [0, kMaxParticles]) from n indices, n z draws and n
// angles per axis.
inline void GenSample(hls::stream<cell_index_t>& cells, hls::stream<unif18_t>& rand_z,
                      hls::stream<angle_t>& roll, hls::stream<angle_t>& pitch, hls::stream<angle_t>& yaw,
                      const HeuristicVolume heuristics[kNumCells], Sample samples[kMaxParticles],
                      int n HW_TRACE_PARAM) {
  if (n > kMaxParticles) n = kMaxParticles;
  // The heuristic volume of each drawn cell: an on-chip copy of the DDR array (kNumCells × 78
  // bits, BRAM), one burst per call, before the first draw is read.
  HeuristicVolume volume_mem[kNumCells];
  BurstLoad<HeuristicVolume, kNumCells>(heuristics, volume_mem, kNumCells);
  HW_TRACE_MEM("sample_gen", "GEN_LOAD_VOLUMES", kNumCells, 1, kBurstLoadDepth, kAxiReadLatency);
  int trips = 0;
GEN_SAMPLE:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    cell_index_t c = cells.read();
    unif18_t u = rand_z.read();
    int ci = c.to_int();
    if (ci >= kNumCells) ci = kNumCells - 1;  // 13 bits hold up to 8191
    const HeuristicVolume h = volume_mem[ci];
    Sample s;
    ap_fixed<14, 4> sx = h.x_min + h.x_max;  // exact
    ap_fixed<14, 4> sy = h.y_min + h.y_max;
    s.x = sx >> 1;  // the shift keeps <14,4>: floor to 2^-10, then fits xyz_t
    s.y = sy >> 1;
    ap_fixed<14, 4> dz = h.z_max - h.z_min;  // exact
    s.z = h.z_min + dz * u;                  // truncated to xyz_t
    s.roll = roll.read();
    s.pitch = pitch.read();
    s.yaw = yaw.read();
    s.cell = c;
    samples[i] = s;
    ++trips;
  }
  // Depth: latency.h, + the write latency of the samples' burst to DDR.
  HW_TRACE_MEM("sample_gen", "GEN_SAMPLE", trips, 1, kGenSampleDepth + kAxiWriteLatency, kAxiWriteLatency);
}

// The generators of the initialisation (each module owns its LFSR, §7.4 "random number
// generators"; the caller keeps them between calls). Distinct default seeds (ours): equal
// seeds would make z repeat the sampling draws and the three angles equal.
struct InitGenerators {
  Lfsr18 sampling{0x2A5F3};  // uniform draws of the importance sampling
  Lfsr18 z{0x1B3C7};         // z within the heuristic interval
  Lfsr15 roll{0x5A5A}, pitch{0x3C21}, yaw{0x6E17};
};

// Options of the chain (runtime).
struct InitOptions {
  bool use_tracker = true;    // threshold tracker + bound generator (false: scans from 0)
  bool leap = true;           // LFSR18 leaps kLfsr18Leap steps per draw (false = thesis)
};

// What the chain reports besides the samples.
struct InitReport {
  SamplingCounters counters;
  bool uniform_fallback = false;  // the class had no mass: cells were drawn uniformly
};

// The initialisation (Fig. 7.5) as a DATAFLOW region: n samples (0 … kMaxParticles, the
// caller clamps) of class cls, importance-sampled from the post-processed prior (prob,
// class_sum of cls), placed by the heuristics. cdf_mem is the sampling memory (BRAM,
// kNumCells × 18 bits). P = threshold bits (the thesis's 5). Each generator and each report
// field is its own argument, so that every channel has one producer and one consumer.
template <int NC, int P = kThrBits>
void InitSamplesRegion(const prob_t prob[kNumCells][NC], int cls, class_sum_t class_sum,
                       const HeuristicVolume heuristics[kNumCells], cdf_t cdf_mem[kNumCells], Lfsr18& sampling_rng,
                       Lfsr18& z_rng, Lfsr15& roll_rng, Lfsr15& pitch_rng, Lfsr15& yaw_rng, bool use_tracker, bool leap,
                       Sample samples[kMaxParticles], int n, SamplingCounters& counters,
                       bool& uniform_fallback HW_TRACE_PARAM) {
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, trace);
  constexpr int IB = 13;
  hls::stream<cdf_t> cdf_s, cdf_copy;
  hls::stream<ap_uint<P + IB> > thr_s;
  hls::stream<unif18_t> u_s, z_s;
  hls::stream<SampleBounds<IB, 18> > bounds_s;
  hls::stream<cell_index_t> idx_s;
  hls::stream<angle_t> roll_s, pitch_s, yaw_s;
  HW_STREAM(cdf_s, 2);
  HW_STREAM(cdf_copy, 2);
  HW_STREAM(thr_s, 2);
  HW_STREAM(u_s, 2);
  HW_STREAM(z_s, 2);
  HW_STREAM(bounds_s, 2);
  HW_STREAM(idx_s, 2);
  HW_STREAM(roll_s, 2);
  HW_STREAM(pitch_s, 2);
  HW_STREAM(yaw_s, 2);
  HW_PROCESS(df, CdfNormalise<NC>(prob, cls, class_sum, cdf_s, uniform_fallback HW_TRACE_ARG));
  HW_PROCESS(df, ThresholdTracker<kNumCells, P, IB, 18>(cdf_s, cdf_copy, thr_s, kNumCells HW_TRACE_ARG));
  HW_PROCESS(df, UniformGenerate(sampling_rng, u_s, n, leap HW_TRACE_ARG));
  HW_PROCESS(df, BoundGenerate<kNumCells, P, IB, 18>(thr_s, u_s, bounds_s, kNumCells, n, use_tracker HW_TRACE_ARG));
  HW_PROCESS(df, SampleIndices<kNumCells, IB, 18>(cdf_copy, bounds_s, cdf_mem, idx_s, kNumCells, n, counters HW_TRACE_ARG));
  HW_PROCESS(df, UniformGenerate(z_rng, z_s, n, leap HW_TRACE_ARG));
  HW_PROCESS(df, AngleGenerate(roll_rng, roll_s, n HW_TRACE_ARG));
  HW_PROCESS(df, AngleGenerate(pitch_rng, pitch_s, n HW_TRACE_ARG));
  HW_PROCESS(df, AngleGenerate(yaw_rng, yaw_s, n HW_TRACE_ARG));
  HW_PROCESS(df, GenSample(idx_s, z_s, roll_s, pitch_s, yaw_s, heuristics, samples, n HW_TRACE_ARG));
  HW_DATAFLOW_END(df);
}

// The initialisation chain for n samples (clamped to [0, kMaxParticles]) with the generators
// and options of the caller: InitSamplesRegion on the fields of gen, opt and report.
template <int NC, int P = kThrBits>
void InitSamples(const prob_t prob[kNumCells][NC], int cls, class_sum_t class_sum,
                 const HeuristicVolume heuristics[kNumCells], cdf_t cdf_mem[kNumCells], InitGenerators& gen,
                 const InitOptions& opt, Sample samples[kMaxParticles], int n, InitReport& report
                     HW_TRACE_PARAM) {
  if (n > kMaxParticles) n = kMaxParticles;
  if (n < 0) n = 0;
  InitSamplesRegion<NC, P>(prob, cls, class_sum, heuristics, cdf_mem, gen.sampling, gen.z, gen.roll, gen.pitch, gen.yaw,
                           opt.use_tracker, opt.leap, samples, n, report.counters, report.uniform_fallback HW_TRACE_ARG);
}

}  // namespace posefilter::hw
