// src/hw/cycle_model.h — the cycle model of the hw engine (host code, C simulation only):
// turns the kernels' loop records (hw_types.h CycleTrace: trips, II, depth per labelled loop)
// into module latencies and composes them across the dataflow regions of an iteration.
//
//   loop cycles    = trips × II + depth            (depth counted once, only if trips > 0;
//                                                  DDR burst latency is part of II or depth)
//   module cycles  = Σ over the module's records in one call (its sequential latency)
//   weigh region   = an explicit stage-overlap ("round") model of the render pipeline,
//                    see ComposeRounds; the other modules of the region overlap with it
//   dataflow chain = max over its modules + Σ of their pipeline depths (fill), DataflowLatency
// docs/HARDWARE.md ("Cycle model") explains each choice with the measured quantities.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hw/hw_types.h"

namespace posefilter::hw {

// trips × II + depth (0 for a loop that ran no trip).
std::uint64_t LoopCycles(const LoopRecord& r);

// Per module, in order of first appearance: Σ of LoopCycles over the module's records.
std::vector<std::pair<std::string, std::uint64_t>> ModuleCycles(const CycleTrace& trace);
// Σ of LoopCycles over the records of `module` ("" = every record).
std::uint64_t ModuleTotal(const CycleTrace& trace, const std::string& module);
// Σ of the pipeline depths of the records of `module` that ran (the module's fill latency).
std::uint64_t ModuleDepth(const CycleTrace& trace, const std::string& module);
// Σ of the DDR latency (LoopRecord::memory) of the records of `module` that ran ("" = every
// record): the part of ModuleTotal spent waiting on m_axi bursts.
std::uint64_t ModuleMemory(const CycleTrace& trace, const std::string& module);
// Σ of LoopCycles over the records of one loop of one module.
std::uint64_t LoopTotal(const CycleTrace& trace, const std::string& module, const std::string& loop);
// Σ of trips of one loop of one module.
std::uint64_t LoopTrips(const CycleTrace& trace, const std::string& module, const std::string& loop);

// A dataflow region of modules that stream into each other: the slowest module sets the
// throughput and every module's pipeline depth adds once (fill/drain):
// max_m cycles_m + Σ_m depth_m. `modules` empty → 0.
std::uint64_t DataflowLatency(const CycleTrace& trace);

// One particle's work in a raster core (from the records of a one-particle RasterCore call),
// each loop's trips × II + depth: the window fill, the FT read, the vertex stage (3 clocks per
// face), the pixel stage (1 clock per pixel of each forwarded triangle's clipped box), the z
// pass (0 in the thesis's mode).
struct ParticleWork {
  std::uint64_t fill = 0, ft = 0, vertex = 0, pixel = 0, zpass = 0;
  // The face phase: the vertex and pixel stages run as a dataflow joined by the triangle FIFO,
  // so the slower one sets the time; the pixel stage starts one vertex-stage depth after the
  // first vertex (its first triangle). No pixel work: the vertex stage alone.
  std::uint64_t Faces() const;
  // After the fill: the FT read, the face phase, then the z pass.
  std::uint64_t Compute() const { return ft + Faces() + zpass; }
  // One particle from its window word to its output word (what the RTL twin's testbench
  // counts): window read + fill + Compute() + output.
  std::uint64_t Total() const;
};
ParticleWork ParticleWorkFromTrace(const CycleTrace& trace);

// The render pipeline of one iteration with M cores, particle p on core p mod M in round
// ⌊p/M⌋. A core holds one depth fragment (no ping-pong), so it reads the next window only after
// finishing its particle, and the distributor writes a round's pixels to all its cores in the
// same cycle: round r costs fill_r + max over its particles of Compute(), with
// fill_r = max(distributor cycles of round r, the largest core fill of the round).
// round_fill[r] = the distributor's cycles (DD_SETUP + DD_SEGMENTS + DD_PIXELS) of round r.
std::uint64_t ComposeRounds(const std::vector<ParticleWork>& particles, const std::vector<std::uint64_t>& round_fill,
                            int cores);

}  // namespace posefilter::hw
