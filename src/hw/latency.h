// src/hw/latency.h — the cycle model's hand-set figures in one table: the pipeline depth
// (latency of one iteration, clocks at 200 MHz) of every pipelined loop, and the FIFO depths
// that the model assumes. Everything else in the model (trips, entries, II) is counted by the
// kernels as they run (HW_TRACE in hw_types.h). Each depth says where it comes from: the RTL
// twin of the raster core (src/hw/rtl/, measured in Verilator), or a count of the loop body's
// operators and their register stages. docs/HARDWARE.md "Cycle model".
#pragma once

namespace posefilter::hw {

// ---- Raster core (raster_core.h; RTL twin src/hw/rtl/raster_core.sv) ----
// Fill: stream read (1) + fragment/z-buffer write and valid count (1) + register (1).
constexpr int kRcFillDepth = 3;
// FT read: one register stage.
constexpr int kRcFtReadDepth = 1;
// Vertex stage: the 12 MACs as 3 DSP cascades (4), the 1/W divider (32 stages) in parallel with
// the two snapping dividers (22), guard/near tests (2), face assembly and culling products (2),
// box clip and edge setup products (2), FIFO write (1).
constexpr int kRcVertexDepth = 43;
// Pixel stage: triangle read and edge registers (1), inside test (1), the depth-recovery
// divider (24 stages), χ multiply and round (3), accumulate or z-buffer read-modify-write (2).
constexpr int kRcPixelDepth = 31;
// z pass: memory read (2) + line-buffer read (1) + compare (3) + accumulate (1).
constexpr int kRcZpassDepth = 7;
// The window word before the fill, and the output word after the particle, clocks.
constexpr int kRcWindowReadCycles = 1;
constexpr int kRcOutputCycles = 1;
// Triangle FIFO between the vertex and the pixel stage, entries.
constexpr int kTriangleFifoDepth = 32;

}  // namespace posefilter::hw
