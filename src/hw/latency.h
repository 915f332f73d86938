// src/hw/latency.h — the cycle model's hand-set figures in one table: the pipeline depth
// (latency of one iteration, clocks at 200 MHz) of every pipelined loop that a kernel records
// (HW_TRACE in hw_types.h), the loops' II where it is not 1 and the per-iteration overheads of
// the non-pipelined outer loops, the latencies of the fx_math.h operators (and postprocess.h's
// ExpRom/WideReciprocal) that those depths add up, and the FIFO depths that the model assumes.
// Everything else in the model (trips, entries) is counted by the kernels as they run; a
// pipelined loop's II of 1 is written as a literal 1 at its HW_TRACE (it is the loop's
// `#pragma HLS PIPELINE II = 1`).
//
// Where the values come from: the raster core's are measured on its RTL twin (src/hw/rtl/, in
// Verilator; the co-simulation compares the RTL's cycles with this model). All the others are
// estimates from an operator count of the loop body — each of its operators and register
// stages (a BRAM read 1–2, a DSP multiply 2–3, a divider or square root one stage per result
// bit, …) — given in the comment above each constant; derived values are written as the sum.
// docs/HARDWARE.md "Cycle model".
//
// This header includes nothing, so every kernel header (and fx_math.h) can include it. One
// depth depends on a structural size and is therefore not in the table: SORT_INSERT's depth is
// kSortCells (sorter.h, one clock per macro cell of the insertion chain), written at its call
// site.
#pragma once

namespace posefilter::hw {

// ---- DDR through m_axi (docs/HARDWARE.md "Memory architecture") ----
// Every memory argument of a top lives in DDR (the PS's DDR4 behind an HP port on the
// Zynq UltraScale+) and is read or written through an m_axi adapter. A pipelined loop whose
// addresses are an affine function of its counter is one burst (the adapter splits it into
// max_read_burst_length-beat requests and keeps up to num_read_outstanding of them in flight,
// so only the first beat waits); every other access pattern reads from an on-chip copy that a
// burst filled (BurstLoad, burst.h). The cycle model charges:
// kAxiReadLatency: clocks from a burst's read request to its first data beat. 64 is the
// `latency` that Vitis HLS schedules an m_axi interface with when the INTERFACE pragma gives
// none (UG1399, "Options for Controlling AXI4 Burst Behavior"): 320 ns at 200 MHz, the order
// of a DDR4 page miss plus the PS interconnect. Paid once per burst.
constexpr int kAxiReadLatency = 64;
// kAxiWriteLatency: clocks from a write burst's last beat to its response (the process ends
// only when its writes are acknowledged). The same default figure; paid once per burst.
constexpr int kAxiWriteLatency = 64;
// A burst load into on-chip RAM (BurstLoad): address/enable (1), then one word per clock; the
// RAM write (1) after the latency.
constexpr int kBurstLoadDepth = kAxiReadLatency + 2;

// ---- Operator latencies (fx_math.h; ExpRom and WideReciprocal in postprocess.h) ----
// Inline building blocks, not kernels: a kernel adds them to its loop's depth.
// SinCos: radian→turn multiply (1 DSP, 2 stages), dual-port ROM read (1), interpolation
// multiply (2), add/round/negate (1).
constexpr int kSinCosDepth = 6;
// SinCosTurns: SinCos without the radian→turn multiply (the phase is the input word): ROM
// read (1), interpolation multiply (2), add/round/negate (1).
constexpr int kSinCosTurnsDepth = 4;
// Log: leading-one detector (1), normalising shift (1), ROM read (1), interpolation multiply
// (2), k·ln2 subtract and round (1).
constexpr int kLogDepth = 6;
// Sqrt of an N-bit radicand: one stage per result bit (N/2), each a compare-subtract.
constexpr int SqrtDepth(int radicand_bits) { return (radicand_bits + 1) / 2; }
// Reciprocal: leading-one (1), shift (1), ROM (1), three NR steps of two 3-stage wide
// multiplies (18), output shift/round (1), correction multiply + compare (4).
constexpr int kReciprocalDepth = 26;
// Divide: one compare-subtract stage per quotient bit.
constexpr int DivideDepth(int quotient_bits) { return quotient_bits; }
// ExpRom (postprocess.h): clamp/round (1), ROM (1), r² and the poly (2), product (2).
constexpr int kExpDepth = 6;
// WideReciprocal (postprocess.h): Reciprocal + leading-one and normalising shift (2).
constexpr int kWideRecipDepth = kReciprocalDepth + 2;

// ---- Post-process (postprocess.h) ----
// PP_CLEAR: the class-sum register write (1).
constexpr int kPpClearDepth = 1;
// PP_READ: stream read, compare-and-select of the running max (2).
constexpr int kPpReadDepth = 2;
// PP_EXP: subtract (1) + ExpRom (kExpDepth) + accumulate (1).
constexpr int kPpExpDepth = kExpDepth + 2;
// PP_SCALE: multiply (2), round/saturate (1), store + class-sum add (1).
constexpr int kPpScaleDepth = 4;
// Per cell outside the loops: (1 + e^c)·Σ (2) then WideReciprocal, loop entry/exit ≈ 3; the
// box decode (two multiplies, an ExpRom, clamps: ≈ 12) runs beside the softmax and is hidden.
constexpr int kPpCellOverhead = 2 + kWideRecipDepth + 3;
// PP_CELLS (the outer, non-pipelined cell loop) is recorded with its per-cell cost as the II:
// the three inner pipelines' fill (their depths) and the reciprocal/loop overhead …
constexpr int kPpCellII = kPpReadDepth + kPpExpDepth + kPpScaleDepth + kPpCellOverhead;
// … and a depth of 1: the last cell's exit.
constexpr int kPpCellsDepth = 1;

// ---- CDF (cdf.h) ----
// CDF_RECIP (once per call) is one WideReciprocal: kWideRecipDepth.
// CDF_NORM: memory read (1), accumulate (1), 57×32 multiply (2), shift and truncate/saturate
// (1), stream write (1).
constexpr int kCdfNormDepth = 6;

// ---- Threshold tracker (threshold_tracker.h) ----
// THR_TRACK: read (1), compare with the last level (1), write both streams (1).
constexpr int kThrTrackDepth = 3;
// THR_PAD: the stream write of a zero word (1).
constexpr int kThrPadDepth = 1;

// ---- LFSR sources (lfsr.h) ----
// LFSR18_GEN: the register update and the stream write happen in the same cycle (1).
constexpr int kLfsr18GenDepth = 1;
// ANGLE_GEN: LFSR step, one DSP multiply (2 stages for 15×18 bits), the write: 3.
constexpr int kAngleGenDepth = 3;

// ---- Uniform source (sampling.h) ----
// UNIFORM_GEN: the (unrolled) register update and the write in one cycle (as LFSR18_GEN).
constexpr int kUniformDepth = 1;

// ---- Bound generator (sampling.h) ----
// BOUND_LOAD: read + store (1).
constexpr int kBoundLoadDepth = 1;
// BOUND_GEN: read, 2^P parallel compares and two priority encoders (2), write (1).
constexpr int kBoundGenDepth = 3;

// ---- Sampling (sampling.h) ----
// SAMPLE_STORE: read + store (1).
constexpr int kSampleStoreDepth = 1;
// SAMPLE_SCAN's pipeline: memory read (1), compare (1), index write (1).
constexpr int kSampleScanDepth = 3;
// Each draw re-enters SAMPLE_SCAN, so its fill is paid per draw, in the draw loop's II (below);
// the SAMPLE_SCAN record itself carries no depth.
constexpr int kSampleScanTraceDepth = 0;
// SAMPLE_DRAWS (non-pipelined, one draw after the other), per draw: the scan's fill
// (kSampleScanDepth) + reading the bounds and writing the index (2) — recorded as the II …
constexpr int kSampleDrawOverhead = kSampleScanDepth + 2;
// … and a depth of 1: the last index write.
constexpr int kSampleDrawsDepth = 1;

// ---- Sample generator (sample_gen.h) ----
// GEN_SAMPLE: index read (1), heuristic memory read (1), (z_max − z_min)·u multiply (2),
// add/truncate and the sample memory write (1).
constexpr int kGenSampleDepth = 5;

// ---- Sample info (top.h, GatherSampleInfo) ----
// GATHER_INFO without growing (II 1, a design without the projection unit, as the thesis's):
// sample read (2) + window memory read (2) + write (1).
constexpr int kGatherInfoDepth = 5;
// Growing (ours): one projection unit, 8 corners per particle → II 8 …
constexpr int kGatherInfoGrowII = 8;
// … depth = sample read (2) + SampleTransform (≈ 18, as the FT chain) + corner MACs (3) + a
// 2^-8 px divider (≈ 40 stages for the 48-bit quotient) + min/max (1) + grow/clip (3) +
// write (1) = 68.
constexpr int kGatherInfoGrowDepth = 2 + 18 + 3 + DivideDepth(40) + 1 + 3 + 1;

// ---- FT chain (transform.h) ----
// PC_ROWS: PC = P·C, 36 MACs once per call, modelled as 12 trips of 3 MACs; depth: the chain
// of 3 MACs (2 stages each).
constexpr int kPcRowsDepth = 6;
// FT_ELEMENTS: sample read (2) + SinCos (kSinCosDepth) + trig product (3) + PC·TrRz (4) +
// ·RyRx (4) + output register (1), from sample read to first element.
constexpr int kFtElementsDepth = 2 + kSinCosDepth + 3 + 4 + 4 + 1;

// ---- FT distributor (distributor.h) ----
// FTD_ELEMENTS: stream read (1) + demultiplexer (1) + stream write (1).
constexpr int kFtdElementsDepth = 3;

// ---- Depth distributor (distributor.h) ----
// DD_SETUP: one comparison/shift of the insertion sorts and the merge per cycle; depth:
// compare (1) + register write (1).
constexpr int kDdSetupDepth = 2;
// DD_PIXELS: address (1) + BRAM read of the on-chip depth image (2) + window compare and
// stream write (1).
constexpr int kDdPixelsDepth = 4;
// Each (row, column interval) segment restarts the pixel pipeline: its fill (kDdPixelsDepth)
// per segment, recorded as DD_SEGMENTS' II …
constexpr int kDdSegmentOverhead = kDdPixelsDepth;
// … with no depth of its own.
constexpr int kDdSegmentsDepth = 0;

// ---- Vertex multiplier (transform.h) ----
// VM_VERTICES: face word read (2) + vertex BRAM read (2) + stream write (1).
constexpr int kVmVerticesDepth = 5;

// ---- Raster core (raster_core.h) ----
// From the RTL twin (src/hw/rtl/raster_core.sv, README "Cycle model"), whose cycles per
// particle the Verilator co-simulation compares with this model (tests/hw/rtl/).
// The window word, and the output word after the particle, clocks.
constexpr int kRcWindowReadCycles = 1;
constexpr int kRcOutputCycles = 1;
// Fill: the state ends in the clock after the last pixel (the memory writes need no drain).
constexpr int kRcFillDepth = 0;
// FT read: 12 words into registers, no drain.
constexpr int kRcFtReadDepth = 0;
// Vertex stage, last vertex → stage empty: input, products, sums, divider operands and the near
// test (4), the 1/W divider (32 stages), its word (1), the face's 1/W words to the FIFO entry F5
// (4), done (1). Beside the 1/W divider: the two 21-stage snapping dividers padded to 30, the
// snapped vertex (1) and the x/y face setup F0–F5 (6: edge differences and box order, area
// products, culling and clipping, edge offsets, edge products, E_k at the box's first pixel).
constexpr int kRcVertexDepth = 42;
// Pixel stage, counted from the vertex stage's first triangle: third vertex → FIFO push → pop
// and last pixel → stage empty (inside test and e' (1), Σe' and the partial products of
// e'·(1/W) (1), the products (1), Σe'·(1/W) (1), the depth divider (24 stages), z_r and the
// memory read (2), the compare (2), done (1)), less the vertex stage's own depth:
// kRcVertexDepth + kRcPixelDepth = 78.
constexpr int kRcPixelDepth = 36;
// z pass: read (1), neighbour registers (1), compare (2), done (1).
constexpr int kRcZpassDepth = 5;
// Triangle FIFO between the vertex and the pixel stage: 16 entries of 446 bits in LUTRAM (the
// vertex pipeline holds ≈ 14 faces; deeper FIFOs measured no faster in co-simulation).
constexpr int kTriangleFifoDepth = 16;
// z-buffer read-modify-write: clocks from a fragment's z-buffer read to the clock its write
// lands (PixelStage's forward registers cover the writes in flight): 1 for the HLS schedule of
// a registered, read-first BRAM written in the clock the next fragment's read is issued. The RTL
// core (src/hw/rtl/README.md) reads through two registers, so its distance is 2 and it forwards
// from two entries; its results are the same, as the forward is exact for any distance. An HLS
// schedule that puts the write later needs this raised to its distance (one more register of
// 34 bits and a comparator per clock).
constexpr int kZbufWriteLag = 1;

// ---- Weight merger (weight_merger.h) ----
// WM_PARTICLES: the one divider takes I/N_raster, I/N_depth and the edge ratio in turn → II 3
// (its `#pragma HLS PIPELINE II = 3`) …
constexpr int kWmParticlesII = 3;
// … depth: stream read (1) + divider (NQ = 50 quotient bits) + 3 MACs (3) + clamp and write (2).
constexpr int kWmParticlesDepth = 1 + DivideDepth(50) + 5;

// ---- Weight split (top.h, SplitWeights) ----
// SPLIT_WEIGHTS: read and write in one cycle (1).
constexpr int kSplitWeightsDepth = 1;

// ---- Stats (top.h, CollectStats) ----
// COLLECT_STATS: read (1) + a pipelined 56/32-bit divider (≈ one stage per quotient bit that
// can be non-zero: 2^17·2^5 / 1 → 24 bits, rounded up to 26) + round/saturate (1) + write (1).
constexpr int kCollectStatsDepth = 1 + DivideDepth(26) + 1 + 1;

// ---- Sorter (sorter.h) ----
// SORT_INSERT: one clock per macro cell of the chain (compare + conditional shift in one
// cycle) = kSortCells, a structural size of sorter.h: written at the call site (see above).
// SORT_DRAIN: register mux + BRAM write (2).
constexpr int kSortDrainDepth = 2;

// ---- Resampling (resample.h) ----
// RESAMPLE_CAP_CLEAR: the counter write (1).
constexpr int kResampleCapClearDepth = 1;
// RESAMPLE_POOL without the cap: index/weight read (1), pool write (1).
constexpr int kResamplePoolDepth = 2;
// With the cap the counter read-modify-write needs 2 clocks (BRAM read latency 1, no
// forwarding) …
constexpr int kResamplePoolCappedII = 2;
// … depth 4 (index read, sample read, label read, counter).
constexpr int kResamplePoolCappedDepth = 4;
// With the rotation cap (ours) the rotation bin runs beside the label read: SinCos
// (kSinCosDepth) + 2 multiply stages (col2's triple product) + compares/encode (2) before the
// counter stage.
constexpr int kResamplePoolRotDepth = kResamplePoolCappedDepth + kSinCosDepth + 2 + 2;
// RESAMPLE_ELITE: pool index read (1), write (1).
constexpr int kResampleEliteDepth = 2;
// RESAMPLE_SUM: weight read (1), add and partial-sum write (1).
constexpr int kResampleSumDepth = 2;
// RESAMPLE_UNIFORM: the partial-sum write (1).
constexpr int kResampleUniformDepth = 1;
// RESAMPLE_NORM: partial-sum read (1), 29×32 multiply (3 DSP stages), shift/saturate (1), CDF
// BRAM write + tracker compare (1); the reciprocal before it adds kReciprocalDepth once.
constexpr int kResampleNormDepth = 6 + kReciprocalDepth;
// RESAMPLE_SCAN: one CDF read per clock; depth: the BRAM read latency (2).
constexpr int kResampleScanDepth = 2;
// RESAMPLE_DRAW (non-pipelined), per draw: LFSR + tracker lookup (1), the BRAM read latency
// (2), the index write (1) — recorded as the II …
constexpr int kResampleDrawOverhead = 4;
// … with no depth of its own.
constexpr int kResampleDrawDepth = 0;

// ---- Box–Muller (box_muller.h) ----
// BOX_MULLER_PAIRS: Log (kLogDepth) → −2·ln (0, a wire shift) → Sqrt of a 31-bit radicand
// (16 stages) → multiply by sin/cos (2) → round (1); SinCos runs in parallel.
constexpr int kBoxMullerDepth = kLogDepth + SqrtDepth(31) + 3;

// ---- Diffusion (diffusion.h) ----
// DIFFUSION_SAMPLES: sample BRAM read (2), move decode + target cell (2), volume reads (2),
// σ multiply (2), noise multiply (2), add/saturate/wrap (1), write (1); the Box–Muller units
// run ahead (free-running) and add their latency once at the start. Ours: the align-depth path
// runs in parallel with the σ/noise path and is longer — v and c_z (3), a pipelined 48/40-bit
// divider (≈ 1 cycle per quotient bit: 33 for |k| < 2^13 at 2^-20), k·v (2) — so it sets the
// depth: 2 + 2 + 3 + 33 + 2 + 1 + 1 = 44 (II stays 1).
constexpr int kDiffusionDepth = 2 + 2 + 3 + DivideDepth(33) + 2 + 1 + 1 + kBoxMullerDepth;

}  // namespace posefilter::hw
