// src/hw/latency.h — the cycle model's hand-set figures in one table: the pipeline depth
// (latency of one iteration, clocks at 200 MHz) of every pipelined loop, and the FIFO depths
// that the model assumes. Everything else in the model (trips, entries, II) is counted by the
// kernels as they run (HW_TRACE in hw_types.h). Each depth says where it comes from: the RTL
// twin of the raster core (src/hw/rtl/, measured in Verilator), or a count of the loop body's
// operators and their register stages. docs/HARDWARE.md "Cycle model".
#pragma once

namespace posefilter::hw {

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
// test (4), the 1/W divider (32 stages; the two 22-stage snapping dividers are padded to 32 and
// run beside it), the snapped vertex (1), face setup F1–F4 (4: area and box products, culling
// and clipping, edge setup, E_k at the box's first pixel), done (1).
constexpr int kRcVertexDepth = 42;
// Pixel stage, counted from the vertex stage's first triangle: third vertex → FIFO push → pop
// and last pixel → stage empty (inside test and e' (1), Σe' and the e'·(1/W) products (1),
// Σe'·(1/W) (1), the depth divider (24 stages), z_r and the memory read (2), the compare (2),
// done (1)), less the vertex stage's own depth: kRcVertexDepth + kRcPixelDepth = 77.
constexpr int kRcPixelDepth = 35;
// z pass: read (1), neighbour registers (1), compare (2), done (1).
constexpr int kRcZpassDepth = 5;
// Triangle FIFO between the vertex and the pixel stage: 16 entries of 446 bits in LUTRAM (the
// vertex pipeline holds ≈ 14 faces; deeper FIFOs measured no faster in co-simulation).
constexpr int kTriangleFifoDepth = 16;

}  // namespace posefilter::hw
