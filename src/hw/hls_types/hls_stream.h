// src/hw/hls_types/hls_stream.h — our own hls::stream<T> for C simulation (same file name and
// API as the vendor header; a Vitis build swaps in the vendor's by include path).
//
// Two models (hls_sim.h chooses; SEMANTICS.md §2):
//   sequential (default) — an unbounded FIFO (std::deque), like the vendor's C-sim model:
//     full() is always false and write_nb() always succeeds. Stricter than the vendor's
//     (which warns and returns T()): a blocking read() of an empty stream prints the stream's
//     name to stderr and aborts.
//   bounded — a stream constructed inside a DATAFLOW region of a bounded simulation holds at
//     most depth() elements (set_depth(), which HW_STREAM calls with the STREAM pragma's value;
//     2, Vitis's default, when never set): a write to a full stream and a read of an empty one
//     block the calling process until another process makes room or data (hls_sim.h), and
//     full()/write_nb() see the depth. Streams constructed elsewhere (a test bench's) stay
//     unbounded.
// A stream destroyed with data left prints its name and the leftover count to stderr. Not
// copyable: pass streams by reference.
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

#include "hls_sim.h"
#endif

namespace hls {

template <typename T, int DEPTH = 0>
class stream {
 public:
  stream() : name_("hls::stream") { Attach(); }
  explicit stream(const char* name) : name_(name ? name : "hls::stream") { Attach(); }
  explicit stream(const std::string& name) : name_(name) { Attach(); }
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
  // empty()/full(): in a bounded simulation a true answer is a failed poll (the process yields;
  // hls_sim.h's livelock watchdog counts them).
  bool empty() const {
    const bool e = fifo_.empty();
#ifndef __SYNTHESIS__
    if (e && sched_) sched_->FailedPoll("empty()", &name_);
#endif
    return e;
  }
  bool full() const {
#ifndef __SYNTHESIS__
    if (sched_ && fifo_.size() >= Capacity()) {
      sched_->FailedPoll("full()", &name_);
      return true;
    }
#endif
    return false;  // unbounded in sequential C simulation (as the vendor's)
  }
  size_t size() const { return fifo_.size(); }
  const char* name() const { return name_.c_str(); }
  // The FIFO depth the hardware has (the STREAM pragma's value); 2 when never set (Vitis).
  int depth() const { return depth_ > 0 ? depth_ : (DEPTH > 0 ? DEPTH : 2); }
  void set_depth(int d) { depth_ = d; }
  void set_name(const std::string& n) { name_ = n; }
  // true when a bounded simulation holds this stream to its depth.
  bool bounded() const {
#ifndef __SYNTHESIS__
    return sched_ != nullptr;
#else
    return false;
#endif
  }

  // ---- blocking access ----
  void write(const T& v) { push(v, 0); }
  T read() { return pop(nullptr); }
  void read(T& out) { out = pop(nullptr); }
  void operator<<(const T& v) { write(v); }
  void operator>>(T& out) { read(out); }

  // ---- non-blocking access ----
  // read_nb: false (and `out` = T()) when empty; write_nb: false when full (bounded), always
  // succeeds in sequential C simulation.
  bool read_nb(T& out) {
    if (fifo_.empty()) {
#ifndef __SYNTHESIS__
      if (sched_) sched_->FailedPoll("read_nb()", &name_);
#endif
      out = T();
      return false;
    }
    out = pop(nullptr);
    return true;
  }
  bool write_nb(const T& v) {
#ifndef __SYNTHESIS__
    if (sched_ && fifo_.size() >= Capacity()) {
      sched_->FailedPoll("write_nb()", &name_);
      return false;
    }
#endif
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
#ifndef __SYNTHESIS__
  void Attach() { sched_ = ::hls::sim::BoundedScheduler(); }
  size_t Capacity() const {
    const int limit = ::hls::sim::DepthLimit().load(std::memory_order_relaxed);
    return static_cast<size_t>(limit > 0 && limit < depth() ? limit : depth());
  }
  // Blocks the running process until `ready` holds; `slot` is this stream's waiter of that side.
  template <typename Pred>
  void Await(Pred ready, ::hls::sim::Process** slot, const char* op, const char* state) {
    while (!ready()) {
      *slot = sched_->Running();
      struct Clear {
        ::hls::sim::Process** s;
        ~Clear() { *s = nullptr; }
      } clear{slot};
      ::hls::sim::Wait w;
      w.op = op;
      w.name = &name_;
      w.state = state;
      w.fill = fifo_.size();
      w.capacity = Capacity();
      sched_->Block(w, true);
    }
  }
#else
  void Attach() {}
#endif
  void push(const T& v, uint64_t cycle) {
#ifndef __SYNTHESIS__
    if (sched_) {
      Await([this] { return fifo_.size() < Capacity(); }, &writer_waiting_, "write to", "full");
      sched_->Progress();
    }
#endif
    fifo_.emplace_back(v, cycle);
    if (fifo_.size() > high_water_) high_water_ = fifo_.size();
#ifndef __SYNTHESIS__
    if (sched_ && reader_waiting_) sched_->Ready(reader_waiting_);
#endif
  }
  T pop(uint64_t* cycle) {
#ifndef __SYNTHESIS__
    if (sched_) {
      Await([this] { return !fifo_.empty(); }, &reader_waiting_, "read from", "empty");
      sched_->Progress();
    }
#endif
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
#ifndef __SYNTHESIS__
    if (sched_ && writer_waiting_) sched_->Ready(writer_waiting_);
#endif
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
  int depth_ = 0;  // set_depth(); 0 = DEPTH, else Vitis's default 2
#ifndef __SYNTHESIS__
  ::hls::sim::Scheduler* sched_ = nullptr;         // bounded simulation, else nullptr
  ::hls::sim::Process* reader_waiting_ = nullptr;  // blocked on empty
  ::hls::sim::Process* writer_waiting_ = nullptr;  // blocked on full
#endif
};

}  // namespace hls
