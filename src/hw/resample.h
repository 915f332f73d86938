// src/hw/resample.h — re-sampling with elitism and a threshold tracker (§7.5.4, Fig. 7.22,
// 7.24; the tracker and sampling of §7.4 steps 2–4 applied to the sorted weights).
//
// Input: the sorting network's output (weights descending + relative indices). Steps:
//  1. Pool: the first pool_size sorted entries (thesis: the whole set — the number of macro
//     sorting cells sets how many are kept). Optional (ours, runtime; region_cap = 0 is the
//     thesis): at most region_cap pool entries per hypothesis (a per-cell label the driver
//     loads, e.g. the detection a cell's box came from) — the reference engine's region_cap
//     niching, one counter memory and a compare. Optional (ours, runtime; rotation_cap = 0
//     is the thesis): at most rotation_cap pool entries per (hypothesis, orientation bin) —
//     the reference engine's rotation_cap (particle_filter.cc RotationBin: which signed base
//     axis the object's z axis points along most × which of the 4 remaining signed axes its x
//     axis points along most = the 24 rotations of a cube). The bin is computed from the
//     sample's angles in the pool loop: 3 SinCos (fx_math), 6 multiplies for R's columns 0
//     and 2 (R = Rz·Ry·Rx, eq. 7.6–7.7 [ALGORITHM.md]), |·| compares; a 24-bank counter memory (one bank per
//     bin, cleared with the hypothesis counters in 256 clocks).
//  2. Elitism: out[0 .. num_elite−1] = the head of the pool, unchanged (diffusion copies them).
//  3. CDF of the pool weights (eq. 7.3 [ALGORITHM.md] on the weights): exact running sum, one reciprocal of
//     the total (fx_math Reciprocal on the leading-one-normalised total), c_i = S_i·(1/S) in
//     cdf_t (truncated, saturating), the LAST entry saturated to 1 − 2^-18 so every draw finds
//     an entry, and the FIRST entry set like every other (GRIP's base port never sets it — bug
//     not copied). A pool whose weights are all 0 is sampled uniformly (c_i = (i+1)/pool).
//  4. Threshold tracker (Listing 7.2 [HARDWARE.md], adapted): while the CDF streams out, a register file of
//     2^kTrackerBits entries records, for every threshold b/2^kTrackerBits, the first index
//     whose CDF's top kTrackerBits bits reach b; one CDF entry that jumps several thresholds
//     fills all of them in the same clock (parallel compare, the thesis's adaptive step).
//  5. Draws: u = an LFSR18 word (∈ [2^-18, 1 − 2^-18], never 0); the answer is the first pool
//     entry with c_i ≥ u (importance sampling, §7.4 step 4); the scan starts at the tracker
//     entry of u's top bits instead of 0. Zero-weight entries are never picked unless the
//     whole pool is zero (their CDF equals their predecessor's).
// Counters: CDF reads with the tracker and what a scan from index 0 would have read (the
// thesis: 375 → 8.34 per draw, 45×).
#pragma once

#include <stdint.h>

#ifndef __SYNTHESIS__
#include <string>
#endif

#include "hw/burst.h"
#include "hw/fx_math.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/lfsr.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

constexpr int kTrackerBits = 5;                 // P of §7.4: 32 thresholds (SIZE_ARR_THR)
constexpr int kTrackerSize = 1 << kTrackerBits;
constexpr int kMaxHypotheses = 256;             // ours: labels of the region cap (8 bits)
typedef ap_uint<8> hypothesis_t;                // ours: a cell's hypothesis label

struct ResampleParams {
  int num_particles = kMaxParticles;  // N: draws + elite written to out_idx, 1 … kMaxParticles
  int num_elite = 10;                 // best entries copied unchanged, 0 … pool_size
  int pool_size = kMaxParticles;      // sorted entries the draws choose from, 1 … N (thesis: N)
  int region_cap = 0;                 // ours: max pool entries per hypothesis; 0 = off (thesis)
  int rotation_cap = 0;               // ours: max pool entries per (hypothesis, orientation
                                      // bin); 0 = off (thesis)
#ifndef __SYNTHESIS__
  // Host-side check (the driver turns a false into posefilter::Error naming *why).
  bool IsValid(std::string* why) const {
    if (num_particles < 1 || num_particles > kMaxParticles) return *why = "num_particles must be in [1, 510]", false;
    if (pool_size < 1 || pool_size > num_particles) return *why = "pool_size must be in [1, num_particles]", false;
    if (num_elite < 0 || num_elite > pool_size) return *why = "num_elite must be in [0, pool_size]", false;
    if (region_cap < 0) return *why = "region_cap must be >= 0 (0 = off)", false;
    if (rotation_cap < 0) return *why = "rotation_cap must be >= 0 (0 = off)", false;
    return true;
  }
#endif
};

struct ResampleCounters {
  uint32_t draws = 0;
  uint32_t cdf_reads = 0;         // CDF entries read by the scans (with the tracker)
  uint32_t cdf_reads_linear = 0;  // what scans from index 0 would have read
  uint32_t pool = 0;              // entries in the pool (after the region cap)
};

constexpr int kRotationBins = 24;  // ours: orientation bins of the rotation cap

// Orientation bin (0 … 23) of a sample's angles, as the reference's RotationBin: za = the axis
// of the largest |R(·,2)| (first on ties), zs = its sign; xa = the axis ≠ za of the largest
// |R(·,0)|, xs = its sign; bin = (2·za + zs)·4 + 2·slot(xa) + xs, slot = xa minus 1 if xa > za.
// R(·,0) = (cy·cp, sy·cp, −sp), R(·,2) = (cy·sp·cr + sy·sr, sy·sp·cr − cy·sr, cp·cr) with
// c/s of roll (r), pitch (p), yaw (y); products in 2^-32, compared raw.
inline int RotationBinHw(const Sample& s) {
#pragma HLS INLINE
  ap_fixed<18, 2> sr, cr, sp, cp, sy, cy;
  SinCos(s.roll, &sr, &cr);
  SinCos(s.pitch, &sp, &cp);
  SinCos(s.yaw, &sy, &cy);
  typedef ap_int<40> wide_t;  // 2^-32: products, and triple products via sp·cr shifted to 2^-16
  const wide_t spcr = wide_t(RawOf(sp)) * wide_t(RawOf(cr));  // 2^-32
  const wide_t col0[3] = {wide_t(RawOf(cy)) * wide_t(RawOf(cp)), wide_t(RawOf(sy)) * wide_t(RawOf(cp)),
                          -(wide_t(RawOf(sp)) << 16)};
  const wide_t col2[3] = {wide_t(RawOf(cy)) * (spcr >> 16) + wide_t(RawOf(sy)) * wide_t(RawOf(sr)),
                          wide_t(RawOf(sy)) * (spcr >> 16) - wide_t(RawOf(cy)) * wide_t(RawOf(sr)),
                          wide_t(RawOf(cp)) * wide_t(RawOf(cr))};
  wide_t a2[3], a0[3];
ROT_BIN_ABS:
  for (int k = 0; k < 3; ++k) {
#pragma HLS UNROLL
    a2[k] = col2[k] < 0 ? wide_t(-col2[k]) : col2[k];
    a0[k] = col0[k] < 0 ? wide_t(-col0[k]) : col0[k];
  }
  int za = 0;
  if (a2[1] > a2[za]) za = 1;
  if (a2[2] > a2[za]) za = 2;
  int xa = za == 0 ? 1 : 0;
  for (int k = 0; k < 3; ++k) {
#pragma HLS UNROLL
    if (k != za && a0[k] > a0[xa]) xa = k;
  }
  const int zs = col2[za] < 0 ? 1 : 0, xs = col0[xa] < 0 ? 1 : 0;
  const int slot = xa > za ? xa - 1 : xa;
  return (za * 2 + zs) * 4 + slot * 2 + xs;
}

// out_idx[j]: the relative sample-memory index of the j-th particle of the next set; the
// first num_elite are the elite (unchanged), the rest are the draws (to be diffused).
// sorted_w/sorted_idx: the sorter's output; samples: the current sample memory (only .cell is
// read, for the region cap); hypothesis: per-cell labels (read only when region_cap > 0).
// cdf_out (optional debug/verification view, may be nullptr in C simulation): the pool's CDF.
inline void Resample(const weight_t sorted_w[kMaxParticles], const particle_index_t sorted_idx[kMaxParticles],
                     const Sample samples[kMaxParticles], const hypothesis_t hypothesis[kNumCells],
                     const ResampleParams& params, Lfsr18& rng, particle_index_t out_idx[kMaxParticles],
                     ResampleCounters* counters, cdf_t* cdf_out HW_TRACE_PARAM) {
  const int n = params.num_particles;
  // ---- 1. Pool (with the optional per-hypothesis cap) ----
  particle_index_t pool_idx[kMaxParticles];
  weight_t pool_w[kMaxParticles];
  ap_uint<10> per_hyp[kMaxHypotheses];
  ap_uint<10> per_niche[kRotationBins][kMaxHypotheses];
#pragma HLS ARRAY_PARTITION variable = per_niche complete dim = 1
  int pool = 0;
  const bool rot_capped = params.rotation_cap > 0;
  const bool capped = params.region_cap > 0 || rot_capped;
  // The caps read the samples and their cells' labels at the sorted indices: on-chip copies
  // (n × 88 bits and kNumCells × 8 bits, BRAM) of the DDR arrays, one burst each per call.
  Sample sample_mem[kMaxParticles];
  hypothesis_t hyp_mem[kNumCells];
  if (capped) {
    BurstLoad<Sample, kMaxParticles>(samples, sample_mem, n);
    BurstLoad<hypothesis_t, kNumCells>(hypothesis, hyp_mem, kNumCells);
    HW_TRACE_MEM("resample", "RESAMPLE_LOAD_SAMPLES", uint64_t(n), 1, kBurstLoadDepth, kAxiReadLatency);
    HW_TRACE_MEM("resample", "RESAMPLE_LOAD_LABELS", kNumCells, 1, kBurstLoadDepth, kAxiReadLatency);
  RESAMPLE_CAP_CLEAR:
    for (int h = 0; h < kMaxHypotheses; ++h) {
#pragma HLS PIPELINE II = 1
      per_hyp[h] = 0;
      for (int b = 0; b < kRotationBins; ++b) {
#pragma HLS UNROLL
        per_niche[b][h] = 0;
      }
    }
    HW_TRACE("resample", "RESAMPLE_CAP_CLEAR", kMaxHypotheses, 1, kResampleCapClearDepth);
  }
  int examined = 0;
RESAMPLE_POOL:
  for (int j = 0; j < n && pool < params.pool_size; ++j) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    ++examined;
    bool take = true;
    if (capped) {
      const Sample& s = sample_mem[sorted_idx[j]];
      const hypothesis_t h = hyp_mem[s.cell];
      const int bin = rot_capped ? RotationBinHw(s) : 0;
      if (params.region_cap > 0 && per_hyp[h] >= ap_uint<10>(params.region_cap)) take = false;
      if (rot_capped && per_niche[bin][h] >= ap_uint<10>(params.rotation_cap)) take = false;
      if (take) {
        per_hyp[h] = per_hyp[h] + 1;
        per_niche[bin][h] = per_niche[bin][h] + 1;
      }
    }
    if (take) {
      pool_idx[pool] = sorted_idx[j];
      pool_w[pool] = sorted_w[j];
      ++pool;
    }
  }
  // II: 1 without the cap; with it the counter read-modify-write needs 2 clocks (BRAM read
  // latency 1, no forwarding), depth 4 (index read, sample read, label read, counter). The
  // rotation bin (ours) runs beside the label read: SinCos (kSinCosDepth) + 2 multiply stages
  // (col2's triple product) + compares/encode (2) before the counter stage. (latency.h.)
  // sorted_w and sorted_idx are read in order: two bursts on their own bundles, whose latency
  // adds to the depth.
  HW_TRACE_MEM("resample", "RESAMPLE_POOL", examined, capped ? kResamplePoolCappedII : 1,
               kAxiReadLatency +
                   (rot_capped ? kResamplePoolRotDepth : (capped ? kResamplePoolCappedDepth : kResamplePoolDepth)),
               kAxiReadLatency);

  // ---- 2. Elite ----
  const int elite = params.num_elite < pool ? params.num_elite : pool;
  int elite_trips = 0;
RESAMPLE_ELITE:
  for (int j = 0; j < elite; ++j) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 0 max = 510
    out_idx[j] = pool_idx[j];
    ++elite_trips;
  }
  HW_TRACE("resample", "RESAMPLE_ELITE", elite_trips, 1, kResampleEliteDepth);

  // ---- 3. CDF: exact sum, one reciprocal, normalise ----
  // Σ of ≤ 510 weights < 2: ufixed<29,11> raw at 2^-17 (weight_t's LSB), exact.
  ap_uint<29> sum = 0;
  ap_uint<29> partial[kMaxParticles];
RESAMPLE_SUM:
  for (int i = 0; i < pool; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    sum = sum + ap_uint<29>(RawOf(pool_w[i]));
    partial[i] = sum;
  }
  HW_TRACE("resample", "RESAMPLE_SUM", pool, 1, kResampleSumDepth);
  const bool uniform = (sum == 0);
  if (uniform) {
    // Nothing matched: every pool entry counts 1 (raw 1 → the same normalisation below).
  RESAMPLE_UNIFORM:
    for (int i = 0; i < pool; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
      partial[i] = i + 1;
    }
    sum = pool;
    HW_TRACE("resample", "RESAMPLE_UNIFORM", pool, 1, kResampleUniformDepth);
  }
  // 1/sum: sum = 2^e·m (m ∈ [1, 2)); inv = 1/m ∈ (1/2, 1] in ufixed<32,1> (≤ 1 ulp = 2^-31).
  // c_i = partial_i / sum = partial_i·inv·2^-e: raw (2^-18) = partial_i·inv_raw >> (31 + e − 18).
  const int e = fx_detail::LeadingOne<29>(sum);
  ap_uint<29> m_raw = sum << (28 - e);
  ap_ufixed<29, 1> m = UFixedFromRaw<29, 1>(m_raw);
  ap_ufixed<32, 1> inv = Reciprocal<32, 1>(m);
  const ap_uint<32> inv_raw = RawOf(inv);
  const int norm_shift = e + 13;
  cdf_t cdf[kMaxParticles];
  particle_index_t tracker[kTrackerSize];
#pragma HLS ARRAY_PARTITION variable = tracker complete
  tracker[0] = 0;
  int past = 0;
  const ap_uint<18> cdf_max = 0x3FFFF;
RESAMPLE_NORM:
  for (int i = 0; i < pool; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    ap_uint<64> prod = ap_uint<64>(partial[i]) * ap_uint<64>(inv_raw);
    ap_uint<64> c = prod >> norm_shift;
    ap_uint<18> cr = (c > ap_uint<64>(cdf_max) || i == pool - 1) ? cdf_max : ap_uint<18>(c);
    cdf[i] = UFixedFromRaw<18, 0>(cr);
    // Threshold tracker: thresholds past+1 … curr are first reached at index i.
    const int curr = ap_uint<kTrackerBits>(cr >> (18 - kTrackerBits)).to_int();
  RESAMPLE_TRACKER_FILL:
    for (int b = 1; b < kTrackerSize; ++b) {
#pragma HLS UNROLL
      if (b > past && b <= curr) tracker[b] = i;
    }
    if (curr > past) past = curr;
  }
  // Depth: partial-sum read (1), 29×32 multiply (3 DSP stages), shift/saturate (1), CDF BRAM
  // write + tracker compare (1); the reciprocal before it adds kReciprocalDepth once (latency.h).
  HW_TRACE("resample", "RESAMPLE_NORM", pool, 1, kResampleNormDepth);
#ifndef __SYNTHESIS__
  if (cdf_out) {
    for (int i = 0; i < pool; ++i) cdf_out[i] = cdf[i];  // verification view, not hardware
  }
#endif

  // ---- 4./5. Draws with the threshold tracker ----
  uint32_t reads = 0, reads_linear = 0;
  int draws = 0;
RESAMPLE_DRAW:
  for (int j = elite; j < n; ++j) {
#pragma HLS LOOP_TRIPCOUNT min = 0 max = 510
    const ap_uint<18> u = rng.Draw();
    const int b = ap_uint<kTrackerBits>(u >> (18 - kTrackerBits)).to_int();
    const int start = tracker[b].to_int();
    int i = start;
  RESAMPLE_SCAN:
    while (i < pool - 1 && RawOf(cdf[i]) < u) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
      ++i;
    }
    reads += uint32_t(i - start + 1);
    reads_linear += uint32_t(i + 1);
    out_idx[j] = pool_idx[i];
    ++draws;
  }
  // One CDF read per clock while scanning (the scan loop is the pipelined inner loop), plus
  // per draw: LFSR + tracker lookup (1), the BRAM read latency (2), the index write (1),
  // recorded as the draw loop's II (latency.h).
  HW_TRACE("resample", "RESAMPLE_SCAN", reads, 1, kResampleScanDepth);
  HW_TRACE("resample", "RESAMPLE_DRAW", draws, kResampleDrawOverhead, kResampleDrawDepth);
  if (counters) {
    counters->draws += uint32_t(draws);
    counters->cdf_reads += reads;
    counters->cdf_reads_linear += reads_linear;
    counters->pool = uint32_t(pool);
  }
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
