// src/hw/hw_types.h — the `hw` engine's data types (thesis Table 7.1 [HARDWARE.md], §7.1) and compile-time
// bounds (thesis Ch. 7; docs/HARDWARE.md §1), shared by every kernel of src/hw/.
//
// Synthesizable subset: the kernels of src/hw/ use only these types, fixed-size arrays and
// hls::stream — no heap, no STL containers, no Eigen, no exceptions, no virtuals, no recursion.
// ap_int.h / ap_fixed.h / hls_stream.h are our own (src/hw/hls_types/, semantics of
// shared/hls/SEMANTICS.md); a Vitis user puts the vendor headers on the include path instead.
//
// Thesis notation (§7.1.1) → ours: ufixed<N,I> = ap_ufixed<N,I>, fixed<N,I> = ap_fixed<N,I>
// (I counts the sign bit), uint<N> = ap_uint<N>.
#pragma once

#include <stdint.h>

#include "ap_fixed.h"
#include "ap_int.h"
#include "hls_stream.h"

namespace posefilter::hw {

// ---- Compile-time bounds of the architecture (thesis Ch. 7) ----
constexpr int kMaxParticles = 510;    // N (thesis design)
constexpr int kNumCells = 6300;       // 15×20 + 30×40 + 60×80 pyramid cells
constexpr int kNumClasses = 21;       // YCB-Video classes of the stage-1 network
constexpr int kMaxVertices = 1024;    // model vertices (10-bit vertex index)
constexpr int kMaxFaces = 2048;       // model faces
constexpr int kMaxWindow = 200;       // window side, pixels
constexpr int kImageWidth = 640;      // depth image, pixels
constexpr int kImageHeight = 480;
constexpr int kMaxRasterCores = 10;   // M (results for 1, 5 and 10 cores)

// ---- Data types of Table 7.1 [HARDWARE.md] ----
// Depth pixel, metres: ufixed<12,2> (0 … 4 m − 2^-10, ≈ 1 mm; clipped to 4 m on input).
typedef ap_ufixed<12, 2> depth_t;
// Positions x, y, z (sample memory, heuristic volumes, model vertices), metres: fixed<13,3>
// (−4 … 4 m − 2^-10).
typedef ap_fixed<13, 3> xyz_t;
// Angles roll, pitch, yaw, radians: fixed<12,4> (−8 … 8 − 2^-8; ±π fits).
typedef ap_fixed<12, 4> angle_t;
// Class probability of a cell: ufixed<8,0>.
typedef ap_ufixed<8, 0> prob_t;
// Normalised CDF entry: ufixed<18,0> (last value saturated to 1 − 2^-18).
typedef ap_ufixed<18, 0> cdf_t;
// Bounding box of a cell, 18 bits (packed centre + size fields, Table 7.1 [HARDWARE.md]).
typedef ap_uint<18> bbox_t;
// Absolute cell index (0 … 6299): 13 bits.
typedef ap_uint<13> cell_index_t;
// Relative particle index (0 … N−1).
typedef ap_uint<10> particle_index_t;
// Model vertex index (≤ 1024 vertices) and a face packed as 3 × 10 bits (Listing 7.1 [HARDWARE.md]).
typedef ap_uint<10> vertex_index_t;
typedef ap_uint<30> face_t;

// Particle weight (eq. 7.4 [ALGORITHM.md]) in [0, 1] (ours: not in Table 7.1 [HARDWARE.md]).
typedef ap_ufixed<18, 1> weight_t;

// One particle of the sample memory (ping-pong, 2 × N): position, angles, cell.
struct Sample {
  xyz_t x, y, z;
  angle_t roll, pitch, yaw;
  cell_index_t cell;
};

// Heuristic volume of a cell, robot base frame, metres.
struct HeuristicVolume {
  xyz_t x_min, y_min, z_min;
  xyz_t x_max, y_max, z_max;
};

}  // namespace posefilter::hw

// ---- Software-only cycle instrumentation ----
// In C simulation a kernel records each labelled loop's trip count with its initiation
// interval (II) and pipeline depth, so the cycle model (trips × II + depth per loop, composed
// per module and across the dataflow region) can be computed afterwards. Kernels take
// `HW_TRACE_PARAM` as their last parameter and call HW_TRACE(...) after a loop; under
// __SYNTHESIS__ both vanish and the kernel signature is the synthesizable one.
#ifndef __SYNTHESIS__
namespace posefilter::hw {

struct LoopRecord {
  const char* module;  // kernel name, e.g. "raster_core"
  const char* loop;    // loop label, e.g. "RASTER_ROWS"
  uint64_t trips;      // iterations executed in this call
  uint32_t ii;         // initiation interval, cycles (1 = fully pipelined)
  uint32_t depth;      // pipeline depth (latency of one iteration), cycles
  // Of this record's cycles (trips × II + depth), those spent waiting on DDR through an m_axi
  // port: the burst start latency (latency.h kAxiReadLatency / kAxiWriteLatency) once per
  // burst. Included in the cycles above, reported apart (hw-report's memory latency).
  uint64_t memory = 0;
};

// Fixed-capacity log of loop records (no heap): a kernel call appends one record per loop.
struct CycleTrace {
  static constexpr int kCapacity = 4096;
  LoopRecord records[kCapacity];
  int count = 0;
  bool overflowed = false;
  void Add(const char* module, const char* loop, uint64_t trips, uint32_t ii, uint32_t depth, uint64_t memory = 0) {
    if (count >= kCapacity) {
      overflowed = true;
      return;
    }
    records[count++] = LoopRecord{module, loop, trips, ii, depth, memory};
  }
  void Clear() {
    count = 0;
    overflowed = false;
  }
};

// The trace the tops (tops.h) record into on this thread: their signatures are the synthesized
// ones, so the caller names it for the calls it makes, with ScopedTopTrace. None by default.
inline CycleTrace*& TopTraceSlot() {
  thread_local CycleTrace* trace = nullptr;
  return trace;
}
inline CycleTrace* TopTrace() { return TopTraceSlot(); }
// Names `trace` (may be null) as the tops' trace on this thread until the end of the scope.
class ScopedTopTrace {
 public:
  explicit ScopedTopTrace(CycleTrace* trace) : previous_(TopTraceSlot()) { TopTraceSlot() = trace; }
  ~ScopedTopTrace() { TopTraceSlot() = previous_; }
  ScopedTopTrace(const ScopedTopTrace&) = delete;
  ScopedTopTrace& operator=(const ScopedTopTrace&) = delete;

 private:
  CycleTrace* previous_;
};
}  // namespace posefilter::hw

#define HW_TRACE_PARAM , ::posefilter::hw::CycleTrace* trace
#define HW_TRACE_ARG , trace
#define HW_TRACE(module, loop, trips, ii, depth) \
  do {                                            \
    if (trace) trace->Add(module, loop, trips, ii, depth); \
  } while (0)
// A loop that waits on DDR: `memory` of its cycles are m_axi burst latency (LoopRecord).
#define HW_TRACE_MEM(module, loop, trips, ii, depth, memory) \
  do {                                                      \
    if (trace) trace->Add(module, loop, trips, ii, depth, memory); \
  } while (0)
#else
#define HW_TRACE_PARAM
#define HW_TRACE_ARG
#define HW_TRACE(module, loop, trips, ii, depth) \
  do {                                            \
  } while (0)
#define HW_TRACE_MEM(module, loop, trips, ii, depth, memory) \
  do {                                                      \
  } while (0)
#endif
