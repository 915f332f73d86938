// src/hw/sorter.h — the online sorting network of §7.5.4 (Fig. 7.23): a chain of macro
// sorting cells that keeps the particle weights sorted (descending) while the weight merger
// emits them, one per clock. Only (weight, relative index) pairs move, never samples (§7.1).
//
// Macro sorting cell (Fig. 7.23a): kSortCellSize registers kept sorted, a shift register with
// conditional insertion. Every register compares the incoming weight with its own in parallel
// (a monotone "greater" vector), takes its upper neighbour's value where the insertion point is
// above it, the incoming value at the insertion point, and keeps its value below; the last
// register's old value (or the incoming value itself, if it is not greater than any stored
// one) leaves the cell and enters the next cell of the chain one clock later (Fig. 7.23b).
// kSortCells cells hold kMaxParticles entries; cells work concurrently on successive arrivals,
// so the chain sorts at II = 1 with a latency of one clock per cell. The C model pushes each
// arrival through the whole chain before the next one, which gives the same final content.
//
// Tie rule (ours; the thesis is silent): equal weights keep arrival order — the same order as
// std::stable_sort with a descending comparator. A new arrival is inserted after the stored
// entries it equals (strict > comparison); an entry pushed out of a cell enters the next cell
// at its head (it is ≥ everything there and arrived before any equal entry there).
#pragma once

#include "hw/hw_types.h"
#include "hw/latency.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

constexpr int kSortCellSize = 30;                         // M registers per macro cell (ours)
constexpr int kSortCells = kMaxParticles / kSortCellSize;  // 17 cells for N = 510
static_assert(kSortCells * kSortCellSize == kMaxParticles, "macro cells must tile kMaxParticles");

struct SortEntry {
  weight_t w;
  particle_index_t idx;  // relative index into the sample memory (= arrival order)
};

// One macro sorting cell: registers reg[0..M−1] (descending, the first `fill` valid).
// Inserts `in` (at its sorted place when is_new, at the head when it was pushed out of the
// previous cell) and returns true with *out set when an entry leaves the cell.
inline bool MacroCellInsert(SortEntry reg[kSortCellSize], int& fill, const SortEntry& in, bool is_new,
                            SortEntry* out) {
#pragma HLS INLINE
  // gt[k]: the incoming entry belongs above register k (or register k is empty).
  bool gt[kSortCellSize];
#pragma HLS ARRAY_PARTITION variable = gt complete
SORT_CELL_COMPARE:
  for (int k = 0; k < kSortCellSize; ++k) {
#pragma HLS UNROLL
    gt[k] = (k >= fill) || !is_new || (in.w > reg[k].w);
  }
  const bool full = (fill == kSortCellSize);
  bool leaves = false;
  if (full) {
    if (gt[kSortCellSize - 1]) {
      *out = reg[kSortCellSize - 1];  // the smallest stored entry is pushed out
    } else {
      *out = in;                      // not greater than any stored entry: passes through
    }
    leaves = true;
  }
SORT_CELL_SHIFT:
  for (int k = kSortCellSize - 1; k >= 0; --k) {
#pragma HLS UNROLL
    if (k > 0 && gt[k - 1]) {
      reg[k] = reg[k - 1];  // shift down below the insertion point
    } else if (gt[k]) {
      reg[k] = in;          // the insertion point (first k with gt[k])
    }
  }
  if (!full) ++fill;
  return leaves;
}

// Sorts n ≤ kMaxParticles weights arriving on `weights` (particle i's weight is the i-th
// value) into sorted_w / sorted_idx, descending, ties in arrival order.
inline void SortWeights(hls::stream<weight_t>& weights, int n, weight_t sorted_w[kMaxParticles],
                        particle_index_t sorted_idx[kMaxParticles] HW_TRACE_PARAM) {
  // Registers, every dimension partitioned: the unrolled chain touches every cell and every
  // register of a cell in one clock (a memory of either dimension would serialise them).
  SortEntry cells[kSortCells][kSortCellSize];
#pragma HLS ARRAY_PARTITION variable = cells complete dim = 0
  int fill[kSortCells];
#pragma HLS ARRAY_PARTITION variable = fill complete
  if (n > kMaxParticles) n = kMaxParticles;
  if (n < 0) n = 0;
SORT_RESET:
  for (int c = 0; c < kSortCells; ++c) {
#pragma HLS UNROLL
    fill[c] = 0;
  }
  int trips = 0;
SORT_INSERT:
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    SortEntry carry;
    carry.w = weights.read();
    carry.idx = i;
    bool is_new = true;
    bool valid = true;  // a token travels down the chain until a cell absorbs it
  SORT_CHAIN:
    for (int c = 0; c < kSortCells; ++c) {
#pragma HLS UNROLL
      if (valid) {
        SortEntry out;
        valid = MacroCellInsert(cells[c], fill[c], carry, is_new, &out);
        carry = out;
        // Whatever leaves a cell enters the next at its head, except the new arrival passing
        // through (it still needs its sorted place).
        is_new = is_new && (out.idx == particle_index_t(i));
      }
    }
    ++trips;
  }
  // Depth: one clock per macro cell of the chain (compare + conditional shift in one cycle).
  // The one depth of the cycle model that is not in latency.h: it is the structural size
  // kSortCells (see latency.h, "Sorter").
  HW_TRACE("sorter", "SORT_INSERT", trips, 1, kSortCells);
  int drained = 0;
SORT_DRAIN:
  for (int k = 0; k < n; ++k) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    const SortEntry& e = cells[k / kSortCellSize][k % kSortCellSize];
    sorted_w[k] = e.w;
    sorted_idx[k] = e.idx;
    ++drained;
  }
  // Depth 2: register mux + write (latency.h); sorted_w and sorted_idx are two write bursts to
  // DDR on their own m_axi bundles (one word each per clock), acknowledged after the write
  // latency.
  HW_TRACE_MEM("sorter", "SORT_DRAIN", drained, 1, kSortDrainDepth + kAxiWriteLatency, kAxiWriteLatency);
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
