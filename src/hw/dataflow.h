// src/hw/dataflow.h — how the kernels of src/hw/ write a DATAFLOW region so that C simulation
// can run it the way synthesis builds it (docs/HARDWARE.md §3, "Bounded C simulation").
//
// A region is a function whose body holds `#pragma HLS DATAFLOW`, then:
//
//   HW_DATAFLOW_BEGIN(df, trace);          // first statement (trace: the function's CycleTrace
//                                          // parameter, or nullptr in an untraced function)
//   hls::stream<ft_t> ft("ft");            // channels
//   HW_STREAM(ft, 24);                     // a stream's depth: STREAM pragma + its C++ depth
//   HW_PROCESS(df, Producer(n, ft HW_TRACE_ARG));
//   HW_PROCESS_AFTER(df, "Gather", Consumer(n, buf, ft HW_TRACE_ARG));  // reads Gather's
//                                          // ping-pong buffer buf: starts when Gather returned
//   HW_PROCESS_UNROLL(df, c, M, Core(c, ...));  // M instances (an unrolled loop), c = 0 … M−1
//   HW_DATAFLOW_END(df);                   // last statement
//
// Under __SYNTHESIS__ the macros are the plain calls, the STREAM pragma and an unrolled `for`
// — the canonical region HLS sees (the lint tools/hls_lint/ checks it). In C simulation
// (hls_sim.h):
//   sequential mode — each process runs when its statement is reached (the vendor's model);
//     the instances of HW_PROCESS_UNROLL run in parallel host threads (OpenMP), each with its
//     own CycleTrace, appended in instance order (the same records as one after another);
//   bounded mode — every process is a coroutine that runs concurrently with the others, the
//     streams declared after HW_DATAFLOW_BEGIN hold their depth, HW_DATAFLOW_END waits for all
//     of them and rethrows the first error (hls::sim::Deadlock names the blocked streams).
//     Each process records into its own CycleTrace; END appends them to the region's in
//     statement order, so the trace equals the sequential one.
// With the vendor's headers (no hls_sim.h), C simulation is the vendor's: sequential.
#pragma once

#include "hw/hw_types.h"

#define HW_PRAGMA(x) _Pragma(#x)

#if defined(__SYNTHESIS__) || !defined(POSEFILTER_HLS_SIM)

#define HW_DATAFLOW_BEGIN(df, trace)
#define HW_DATAFLOW_END(df)
#define HW_STREAM(var, depth) HW_PRAGMA(HLS STREAM variable = var depth = depth)
#define HW_PROCESS(df, ...) __VA_ARGS__
#define HW_PROCESS_AFTER(df, producer, ...) __VA_ARGS__
#define HW_PROCESS_UNROLL(df, var, count, ...) \
  for (int var = 0; var < count; ++var) {      \
    HW_PRAGMA(HLS UNROLL)                      \
    __VA_ARGS__;                               \
  }

#else  // C simulation with our HLS types

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace posefilter::hw {

// A stream's depth (HW_STREAM): the value of its STREAM pragma as a property of the C++
// stream, and its name for reports (arrays: "name[i]").
template <typename T, int D>
void SetStreamDepth(hls::stream<T, D>& s, int depth, const char* name) {
  s.set_depth(depth);
  s.set_name(name);
}
template <typename T, int D, int N>
void SetStreamDepth(hls::stream<T, D> (&a)[N], int depth, const char* name) {
  for (int i = 0; i < N; ++i) {
    a[i].set_depth(depth);
    a[i].set_name(std::string(name) + "[" + std::to_string(i) + "]");
  }
}

// One DATAFLOW region of a C simulation (see the top of this file).
class DataflowRegion {
 public:
  DataflowRegion(const char* name, CycleTrace* trace) : name_(name), trace_(trace) {
    if (hls::sim::CurrentMode() != hls::sim::Mode::kBounded) return;
    bounded_ = true;
    hls::sim::Scheduler*& current = hls::sim::Scheduler::Current();
    if (current == nullptr) {  // the outermost region of this thread: it owns the scheduler
      owned_.reset(new hls::sim::Scheduler);
      current = owned_.get();
    }
    sched_ = current;
    const hls::sim::Process* owner = sched_->Running();
    prefix_ = owner->owner ? std::string() : owner->name + "/";
  }
  ~DataflowRegion() {
    if (bounded_ && !ended_) {
      for (const Slot& s : slots_)
        if (s.proc->state != hls::sim::Process::State::kDone) {
          std::fprintf(stderr, "dataflow region %s: left without HW_DATAFLOW_END while %s runs\n", name_,
                       s.proc->name.c_str());
          std::abort();
        }
    }
    if (owned_) hls::sim::Scheduler::Current() = nullptr;
  }
  DataflowRegion(const DataflowRegion&) = delete;
  DataflowRegion& operator=(const DataflowRegion&) = delete;

  // A process: `call_text` is the call as written (its function's name names the process);
  // after = the name of an earlier process whose ping-pong buffer it reads, or nullptr.
  void Process(const char* call_text, const std::function<void(CycleTrace*)>& body, const char* after = nullptr) {
    if (!bounded_) {
      body(trace_);
      return;
    }
    Spawn(UniqueName(FunctionName(call_text)), body, after);
  }

  // `count` instances of one process (an unrolled loop over its instance index), named
  // Function#i.
  void Unrolled(const char* call_text, int count, const std::function<void(int, CycleTrace*)>& body) {
    if (bounded_) {
      const std::string base = FunctionName(call_text);
      for (int i = 0; i < count; ++i)
        Spawn(base + "#" + std::to_string(i), [body, i](CycleTrace* t) { body(i, t); }, nullptr);
      return;
    }
    // Sequential: the instances own their streams and memories, so they may run in parallel
    // host threads; their records are appended in instance order.
    std::vector<std::unique_ptr<CycleTrace>> traces(static_cast<std::size_t>(count));
    if (trace_)
      for (auto& t : traces) t.reset(new CycleTrace);
#pragma omp parallel for schedule(dynamic, 1)
    for (int i = 0; i < count; ++i) body(i, traces[static_cast<std::size_t>(i)].get());
    if (trace_)
      for (const auto& t : traces) Append(*t);
  }

  // Waits for every process (bounded), appends their records in statement order and rethrows
  // the first error.
  void End() {
    if (!bounded_ || ended_) return;
    ended_ = true;
    std::vector<hls::sim::Process*> procs;
    for (const Slot& s : slots_) procs.push_back(s.proc.get());
    sched_->JoinAll(procs);
    std::exception_ptr first;
    for (Slot& s : slots_) {
      if (!first && s.proc->error) first = s.proc->error;
      if (trace_ && s.trace) Append(*s.trace);
      sched_->Release(s.proc.get());
    }
    if (first) std::rethrow_exception(first);
  }

 private:
  struct Slot {
    std::string name;
    std::unique_ptr<hls::sim::Process> proc;
    std::unique_ptr<CycleTrace> trace;
  };

  void Spawn(const std::string& name, const std::function<void(CycleTrace*)>& body, const char* after) {
    hls::sim::Process* producer = after ? Find(after) : nullptr;
    Slot slot;
    slot.name = name;
    if (trace_) slot.trace.reset(new CycleTrace);
    CycleTrace* t = slot.trace.get();
    slot.proc = sched_->Spawn(prefix_ + name, [body, t] { body(t); }, producer);
    slots_.push_back(std::move(slot));
  }
  static std::string FunctionName(const char* call_text) {
    std::string s(call_text);
    const std::size_t paren = s.find('(');
    if (paren != std::string::npos) s.erase(paren);
    const std::size_t angle = s.find('<');  // a template's arguments
    if (angle != std::string::npos) s.erase(angle);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\n')) s.pop_back();
    return s;
  }
  // The function's name, with #k for its k-th repeat in this region.
  std::string UniqueName(const std::string& base) {
    int seen = 0;
    for (const Slot& s : slots_)
      if (s.name == base || s.name.rfind(base + "#", 0) == 0) ++seen;
    return seen == 0 ? base : base + "#" + std::to_string(seen);
  }
  hls::sim::Process* Find(const char* name) {
    for (Slot& s : slots_)
      if (s.name == name) return s.proc.get();
    std::fprintf(stderr, "dataflow region %s: HW_PROCESS_AFTER names '%s', which is no earlier process\n", name_,
                 name);
    std::abort();
  }
  void Append(const CycleTrace& t) {
    for (int r = 0; r < t.count; ++r) {
      const LoopRecord& rec = t.records[r];
      trace_->Add(rec.module, rec.loop, rec.trips, rec.ii, rec.depth);
    }
    if (t.overflowed) trace_->overflowed = true;
  }

  const char* name_;
  CycleTrace* trace_;
  bool bounded_ = false, ended_ = false;
  hls::sim::Scheduler* sched_ = nullptr;
  std::unique_ptr<hls::sim::Scheduler> owned_;
  std::string prefix_;  // "Owner/" for a region inside a process
  std::vector<Slot> slots_;
};

}  // namespace posefilter::hw

#define HW_DATAFLOW_BEGIN(df, trace) ::posefilter::hw::DataflowRegion df(__func__, trace)
#define HW_DATAFLOW_END(df) df.End()
#define HW_STREAM(var, depth)                     \
  HW_PRAGMA(HLS STREAM variable = var depth = depth) \
  ::posefilter::hw::SetStreamDepth(var, depth, #var)
#define HW_PROCESS(df, ...) \
  df.Process(#__VA_ARGS__, [&](::posefilter::hw::CycleTrace* trace) { (void)trace; __VA_ARGS__; })
#define HW_PROCESS_AFTER(df, producer, ...) \
  df.Process(#__VA_ARGS__, [&](::posefilter::hw::CycleTrace* trace) { (void)trace; __VA_ARGS__; }, producer)
#define HW_PROCESS_UNROLL(df, var, count, ...) \
  df.Unrolled(#__VA_ARGS__, (count), [&](int var, ::posefilter::hw::CycleTrace* trace) { (void)trace; __VA_ARGS__; })

#endif
