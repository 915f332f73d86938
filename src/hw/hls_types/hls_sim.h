// src/hw/hls_types/hls_sim.h — the C-simulation runtime of our HLS types (not part of the
// vendor API; src/hw/dataflow.h and our hls_stream.h use it, and a Vitis build, which has
// neither, runs the vendor's sequential C simulation instead).
//
// Two modes, process-wide, chosen before a top is called (ScopedMode; default sequential):
//   sequential — the vendor's C-simulation model: a stream is an unbounded FIFO and the
//                processes of a DATAFLOW region run one after another in source order.
//   bounded    — what synthesis builds. Inside a DATAFLOW region (dataflow.h) every stream
//                holds at most its declared depth (HW_STREAM; 2, Vitis's default, when
//                undeclared): a write to a full stream blocks, a read of an empty one
//                blocks, and the region's processes run concurrently. A process that reads a
//                ping-pong buffer (HW_PROCESS_AFTER) starts when its producer has returned.
//                Streams made outside a region (a test bench's) stay unbounded.
//
// Concurrency is cooperative: each process is a coroutine with its own stack (ucontext) on
// the caller's thread, and runs until it blocks; then the scheduler resumes the process that
// has waited longest among those whose stream now has data or room. Only one process runs at a
// time, so the schedule — and with it every result and every deadlock report — is the same on
// every run; blocking reads and writes make the results independent of the schedule anyway
// (a Kahn process network), which is why bounded mode must reproduce the sequential model bit
// for bit whenever it does not deadlock.
//
// Deadlock: a process blocks and no process is ready to run. Every process is then blocked on
// a stream, waiting for a producer, or waiting for its region's processes to end, so none can
// ever run again. The scheduler composes a report naming each blocked process and its stream
// ("RasterCore#2/VertexStage: write to 'triangles', full (16 of 16)"), resumes every process
// blocked on a stream or a producer by throwing Deadlock inside it (each unwinds its own
// stack), and the region rethrows the first error to the top's caller once its processes have
// ended. A livelock watchdog covers what this rule cannot see — processes that poll empty()
// or read_nb() forever: kPollLimit failed polls in a row with no stream transfer in between
// are reported the same way.
//
// Not supported under AddressSanitizer (its stack tracking does not follow swapcontext without
// annotations): SetMode(kBounded) aborts with a message in such a build.
#pragma once

#ifndef __SYNTHESIS__

#include <sys/mman.h>
#include <ucontext.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#define POSEFILTER_HLS_SIM 1

#if defined(__SANITIZE_ADDRESS__)
#define POSEFILTER_HLS_SIM_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define POSEFILTER_HLS_SIM_ASAN 1
#endif
#endif

namespace hls {
namespace sim {

enum class Mode { kSequential, kBounded };

inline std::atomic<int>& ModeFlag() {
  static std::atomic<int> flag{0};
  return flag;
}
inline Mode CurrentMode() { return ModeFlag().load(std::memory_order_relaxed) ? Mode::kBounded : Mode::kSequential; }
inline void SetMode(Mode m) {
#ifdef POSEFILTER_HLS_SIM_ASAN
  if (m == Mode::kBounded) {
    std::fprintf(stderr, "hls::sim: bounded mode is not supported under AddressSanitizer (coroutine stacks)\n");
    std::abort();
  }
#endif
  ModeFlag().store(m == Mode::kBounded ? 1 : 0, std::memory_order_relaxed);
}

// Sets the mode for a scope and restores the previous one.
class ScopedMode {
 public:
  explicit ScopedMode(Mode m) : previous_(CurrentMode()) { SetMode(m); }
  ~ScopedMode() { SetMode(previous_); }
  ScopedMode(const ScopedMode&) = delete;
  ScopedMode& operator=(const ScopedMode&) = delete;

 private:
  Mode previous_;
};

// An upper bound on every bounded stream's depth (0 = none): a test that a design still runs,
// only slower, when its FIFOs are shallower than declared (ScopedDepthLimit).
inline std::atomic<int>& DepthLimit() {
  static std::atomic<int> limit{0};
  return limit;
}
class ScopedDepthLimit {
 public:
  explicit ScopedDepthLimit(int limit) : previous_(DepthLimit().load()) { DepthLimit().store(limit); }
  ~ScopedDepthLimit() { DepthLimit().store(previous_); }
  ScopedDepthLimit(const ScopedDepthLimit&) = delete;
  ScopedDepthLimit& operator=(const ScopedDepthLimit&) = delete;

 private:
  int previous_;
};

// A deadlock (or livelock) of a bounded simulation; what() names every blocked process and its
// stream.
class Deadlock : public std::runtime_error {
 public:
  explicit Deadlock(const std::string& what) : std::runtime_error(what) {}
};

// Stack of one process coroutine (bytes). The raster cores' memories are in the top's frame or
// on the heap; a kernel's own locals are at most its on-chip copies of DDR arrays (≤ 0.2 MB).
constexpr std::size_t kStackBytes = 1024 * 1024;
// Failed polls in a row (empty()/full() true, read_nb/write_nb refused) with no transfer on
// any stream in between that count as a livelock.
constexpr std::uint64_t kPollLimit = 10000000;

class Scheduler;

// What a blocked process waits for, kept as pointers and numbers (a deadlock report formats it;
// a block costs no string work). `name` lives as long as the wait.
struct Wait {
  enum class Kind { kStream, kPoll, kProducer, kJoin };
  Kind kind = Kind::kStream;
  const char* op = "";                // kStream: "write to" / "read from"; kPoll: "empty()" …
  const std::string* name = nullptr;  // the stream's, the producer's or the first pending process's
  const char* state = "";             // kStream: "full" / "empty"
  std::size_t fill = 0, capacity = 0; // kStream: the stream's occupancy and depth when it blocked
  std::string Describe() const {
    const std::string n = name ? *name : std::string("?");
    switch (kind) {
      case Kind::kStream:
        return std::string(op) + " '" + n + "', " + state + " (" + std::to_string(fill) + " of " +
               std::to_string(capacity) + ")";
      case Kind::kPoll:
        return std::string(op) + " of '" + n + "'";
      case Kind::kProducer:
        return "its producer " + n + " to end (a ping-pong buffer)";
      case Kind::kJoin:
        return "its processes to end (" + n + " first)";
    }
    return "";
  }
};

// One simulated process: a coroutine with its own stack, or (owner = true) the thread that
// entered the outermost region.
struct Process {
  enum class State { kReady, kRunning, kBlocked, kDone };
  std::string name;
  State state = State::kReady;
  bool owner = false;
  ucontext_t ctx;
  void* stack = nullptr;
  std::function<void()> body;
  Wait wait;                 // what it is blocked on (the report's line)
  bool stream_wait = false;  // blocked on a stream or a producer (resumed with Deadlock)
  bool abort = false;        // resume by throwing Deadlock
  std::exception_ptr error;  // what the body threw
  Process* after = nullptr;  // the producer this process waits for before it starts
  std::vector<Process*> dependents;  // processes waiting for this one to end
  Process* joiner = nullptr;         // the region owner waiting for this one to end
};

class Scheduler {
 public:
  // The scheduler of the calling thread's current region tree (nullptr outside regions).
  static Scheduler*& Current() {
    static thread_local Scheduler* current = nullptr;
    return current;
  }

  Scheduler() {
    main_.name = "(caller)";
    main_.owner = true;
    main_.state = Process::State::kRunning;
    running_ = &main_;
  }
  ~Scheduler() {
    for (void* s : free_stacks_) munmap(s, kStackBytes + kGuardBytes);
  }
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  Process* Running() const { return running_; }
  bool Deadlocked() const { return deadlocked_; }
  const std::string& Report() const { return report_; }

  // A new process running `body`, ready to run after the processes already ready (after =
  // a producer that must end first, or nullptr). The caller owns the Process.
  std::unique_ptr<Process> Spawn(const std::string& name, std::function<void()> body, Process* after) {
    std::unique_ptr<Process> p(new Process);
    p->name = name;
    p->body = std::move(body);
    p->after = after;
    p->stack = AllocateStack();
    if (getcontext(&p->ctx) != 0) Fatal("getcontext failed");
    p->ctx.uc_stack.ss_sp = static_cast<char*>(p->stack) + kGuardBytes;
    p->ctx.uc_stack.ss_size = kStackBytes;
    p->ctx.uc_link = nullptr;
    makecontext(&p->ctx, &Scheduler::Trampoline, 0);
    p->state = Process::State::kReady;
    ready_.push_back(p.get());
    registry_.push_back(p.get());
    ++alive_;
    return p;
  }

  // Forgets an ended process (its region is done with it) and keeps its stack for reuse.
  void Release(Process* p) {
    for (std::size_t i = 0; i < registry_.size(); ++i)
      if (registry_[i] == p) {
        registry_.erase(registry_.begin() + static_cast<std::ptrdiff_t>(i));
        break;
      }
    if (p->stack) free_stacks_.push_back(p->stack);
    p->stack = nullptr;
  }

  // The running process waits until Ready() is called for it. stream_wait: blocked on a stream
  // or a producer (a deadlock resumes it by throwing). Throws Deadlock when resumed so.
  void Block(const Wait& wait, bool stream_wait) {
    Process* me = running_;
    if (me->owner && stream_wait && alive_ > 0) {
      std::fprintf(stderr, "hls::sim: the caller of a dataflow region blocked on %s while its processes run; "
                           "only processes may use a region's streams\n", wait.Describe().c_str());
      std::abort();
    }
    me->state = Process::State::kBlocked;
    me->wait = wait;
    me->stream_wait = stream_wait;
    Dispatch();
    if (me->abort) {
      me->abort = false;
      throw Deadlock(report_);
    }
  }

  // Makes a blocked process ready again (no effect on any other state).
  void Ready(Process* p) {
    if (p == nullptr || p->state != Process::State::kBlocked) return;
    p->state = Process::State::kReady;
    ready_.push_back(p);
  }

  // A transfer on some stream (resets the livelock watchdog).
  void Progress() { failed_polls_ = 0; }

  // A poll that found nothing (empty()/full() true, read_nb/write_nb refused): the running
  // process yields to the ready ones; too many in a row without any transfer is a livelock.
  void FailedPoll(const char* op, const std::string* stream_name) {
    if (++failed_polls_ >= kPollLimit && !deadlocked_) {
      Wait w;
      w.kind = Wait::Kind::kPoll;
      w.op = op;
      w.name = stream_name;
      DeclareDeadlock("livelock: " + std::to_string(kPollLimit) + " polls without a transfer on any stream, last " +
                      running_->name + ": " + w.Describe());
    }
    if (running_->abort) {
      running_->abort = false;
      throw Deadlock(report_);
    }
    if (ready_.empty()) return;
    Process* me = running_;
    me->state = Process::State::kReady;
    ready_.push_back(me);
    Dispatch();
    if (me->abort) {
      me->abort = false;
      throw Deadlock(report_);
    }
  }

  // Called by a region owner: waits until every process of `procs` has ended.
  void JoinAll(const std::vector<Process*>& procs) {
    for (;;) {
      Process* pending = nullptr;
      for (Process* p : procs)
        if (p->state != Process::State::kDone) {
          pending = p;
          break;
        }
      if (!pending) return;
      pending->joiner = running_;
      Wait w;
      w.kind = Wait::Kind::kJoin;
      w.name = &pending->name;
      Block(w, false);
    }
  }

 private:
  static constexpr std::size_t kGuardBytes = 4096;

  [[noreturn]] static void Fatal(const char* what) {
    std::fprintf(stderr, "hls::sim: %s\n", what);
    std::abort();
  }

  void* AllocateStack() {
    if (!free_stacks_.empty()) {
      void* s = free_stacks_.back();
      free_stacks_.pop_back();
      return s;
    }
    void* s = mmap(nullptr, kStackBytes + kGuardBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (s == MAP_FAILED) Fatal("cannot map a coroutine stack");
    mprotect(s, kGuardBytes, PROT_NONE);  // overflow faults instead of corrupting memory
    return s;
  }

  // Entry of every coroutine: waits for its producer, runs the body, ends.
  static void Trampoline() {
    Scheduler* s = Current();
    Process* me = s->running_;
    try {
      if (me->after && me->after->state != Process::State::kDone) {
        me->after->dependents.push_back(me);
        Wait w;
        w.kind = Wait::Kind::kProducer;
        w.name = &me->after->name;
        s->Block(w, true);
      }
      me->body();
    } catch (...) {
      me->error = std::current_exception();
    }
    --s->alive_;
    me->state = Process::State::kDone;
    for (Process* d : me->dependents) s->Ready(d);
    if (me->joiner) s->Ready(me->joiner);
    s->Dispatch();  // never returns: nothing makes a finished process ready again
    Fatal("a finished process was resumed");
  }

  // Runs the next ready process (declaring a deadlock when there is none) and returns when the
  // running one is resumed.
  void Dispatch() {
    Process* me = running_;
    if (ready_.empty()) DeclareDeadlock("deadlock");
    if (ready_.empty()) Fatal("no process can run after a deadlock was declared");
    Process* next = ready_.front();
    ready_.pop_front();
    next->state = Process::State::kRunning;
    running_ = next;
    if (next == me) return;
    if (swapcontext(&me->ctx, &next->ctx) != 0) Fatal("swapcontext failed");
    // Resumed: running_ is me again.
  }

  // Every process blocked on a stream or a producer is resumed by throwing Deadlock, after
  // report_ names them all.
  void DeclareDeadlock(const std::string& kind) {
    if (deadlocked_) return;
    deadlocked_ = true;
    std::string r = "hls::sim " + kind + " in a bounded dataflow simulation; blocked:";
    std::vector<Process*> victims;
    for (Process* p : Blocked()) {
      r += "\n  " + p->name + ": " + p->wait.Describe();
      if (p->stream_wait) victims.push_back(p);
    }
    report_ = r;
    for (Process* p : victims) {
      p->abort = true;
      Ready(p);
    }
    if (running_->state == Process::State::kRunning && kind != "deadlock") running_->abort = true;
  }

  // Every blocked process, in the order they were registered (reporting).
  std::vector<Process*> Blocked() const {
    std::vector<Process*> out;
    for (Process* p : registry_)
      if (p->state == Process::State::kBlocked) out.push_back(p);
    if (main_.state == Process::State::kBlocked) out.push_back(const_cast<Process*>(&main_));
    return out;
  }

 private:
  Process main_;
  Process* running_ = nullptr;
  std::deque<Process*> ready_;
  std::vector<Process*> registry_;  // spawned processes not yet released (reports)
  std::vector<void*> free_stacks_;
  int alive_ = 0;                    // spawned processes that have not ended
  bool deadlocked_ = false;
  std::string report_;
  std::uint64_t failed_polls_ = 0;
};

// The scheduler a stream constructed now belongs to: the current region tree's in bounded
// mode, else none (unbounded).
inline Scheduler* BoundedScheduler() {
  return CurrentMode() == Mode::kBounded ? Scheduler::Current() : nullptr;
}

}  // namespace sim
}  // namespace hls

#endif  // __SYNTHESIS__
