// src/hw/hls_types/hls_stream.h — our own hls::stream<T> for C simulation (same file name and
// API as the vendor header; a Vitis build swaps in the vendor's by include path).
//
// Model (SEMANTICS.md §2): an unbounded FIFO (std::deque), like the vendor's C-sim model —
// full() is always false and write_nb() always succeeds; the DEPTH parameter is accepted and
// ignored in C simulation. Stricter than the vendor's (which warns and returns T()):
//   * a blocking read() of an empty stream prints the stream's name to stderr and aborts;
//   * a stream destroyed with data left prints its name and the leftover count to stderr.
// Not copyable: pass streams by reference.
//
// Cycle-model timestamps (simulation only, not in the vendor API): each element carries the
// cycle at which it was written — write(v, cycle) stamps it, write(v) stamps 0 — and
// read(&cycle) returns the element and stores its stamp; front_cycle() peeks the head's stamp.
// A dataflow composition uses them so a consumer starts no earlier than its data was produced:
//   uint64_t t; T v = s.read(&t); start = std::max(start, t);
// size_high_water() is the largest occupancy seen (for sizing the FIFO depth in RTL).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <deque>
#include <string>
#include <utility>

#ifndef __SYNTHESIS__
#include <cstdio>
#include <cstdlib>
#endif

namespace hls {

template <typename T, int DEPTH = 0>
class stream {
 public:
  stream() : name_("hls::stream") {}
  explicit stream(const char* name) : name_(name ? name : "hls::stream") {}
  explicit stream(const std::string& name) : name_(name) {}
  stream(const stream&) = delete;
  stream& operator=(const stream&) = delete;

  ~stream() {
#ifndef __SYNTHESIS__
    if (!fifo_.empty()) {
      std::fprintf(stderr, "hls::stream '%s' destroyed with %zu leftover element(s)\n",
                   name_.c_str(), fifo_.size());
    }
#endif
  }

  // ---- status ----
  bool empty() const { return fifo_.empty(); }
  bool full() const { return false; }  // unbounded in C simulation (as the vendor's)
  size_t size() const { return fifo_.size(); }
  const char* name() const { return name_.c_str(); }

  // ---- blocking access ----
  void write(const T& v) { push(v, 0); }
  T read() { return pop(nullptr); }
  void read(T& out) { out = pop(nullptr); }
  void operator<<(const T& v) { write(v); }
  void operator>>(T& out) { read(out); }

  // ---- non-blocking access ----
  // read_nb: false (and `out` = T()) when empty; write_nb: always succeeds in C simulation.
  bool read_nb(T& out) {
    if (fifo_.empty()) {
      out = T();
      return false;
    }
    out = pop(nullptr);
    return true;
  }
  bool write_nb(const T& v) {
    write(v);
    return true;
  }

#ifndef __SYNTHESIS__
  // ---- cycle-model timestamps (simulation only) ----
  // Write `v` produced at `cycle` (any monotonic cycle count of the producer).
  void write(const T& v, uint64_t cycle) { push(v, cycle); }
  // Read the head; its write cycle goes to *cycle (when non-null).
  T read(uint64_t* cycle) { return pop(cycle); }
  // The head's write cycle (aborts when empty, as read()).
  uint64_t front_cycle() const {
    if (fifo_.empty()) die("front_cycle");
    return fifo_.front().second;
  }
  // Largest number of elements held at once since construction.
  size_t size_high_water() const { return high_water_; }
#endif

 private:
  void push(const T& v, uint64_t cycle) {
    fifo_.emplace_back(v, cycle);
    if (fifo_.size() > high_water_) high_water_ = fifo_.size();
  }
  T pop(uint64_t* cycle) {
    if (fifo_.empty()) {
#ifndef __SYNTHESIS__
      die("read");
#else
      if (cycle) *cycle = 0;
      return T();
#endif
    }
    std::pair<T, uint64_t> e = std::move(fifo_.front());
    fifo_.pop_front();
    if (cycle) *cycle = e.second;
    return std::move(e.first);
  }
#ifndef __SYNTHESIS__
  [[noreturn]] void die(const char* what) const {
    std::fprintf(stderr, "hls::stream '%s': %s while empty (a blocking read would hang in RTL)\n",
                 name_.c_str(), what);
    std::fflush(stderr);
    std::abort();
  }
#endif

  std::string name_;
  std::deque<std::pair<T, uint64_t>> fifo_;
  size_t high_water_ = 0;
};

}  // namespace hls
