// tests/hw/rtl/rc_fifo_bram_test.cc — the block-RAM FIFO rc_fifo_bram (src/hw/rtl/rc_fifo.sv,
// verilated with --assert, DEPTH = 16, W = 16) against a reference queue: random legal traffic
// (pushes and pops at random rates, bursts that fill it to DEPTH and drain it) must give every
// word in order, `empty` exactly when no word has reached the head, `count` equal to the
// words held, and no assertion; a popping consumer must be served one word per clock once the
// head is valid (no bubble behind a full RAM), and a word pushed into the empty FIFO must be at
// the head in the next clock (bypass). Then illegal traffic: a push into the full FIFO must fire
// the overflow assertion and a pop from the empty FIFO the underflow assertion (Verilator counts
// the failed assertions instead of stopping).
#include <cstdio>
#include <deque>
#include <random>

#include "Vrc_fifo_bram.h"
#include "rc_fifo_harness.h"

namespace {

constexpr int kDepth = 16;

using Fifo = FifoHarness<Vrc_fifo_bram>;

}  // namespace

// `rc_fifo_test bram` (rc_fifo_tests_main.cc).
int RunRcFifoBramTest() {
  int failures = 0;
  Fifo f;
  std::deque<int> ref;
  std::mt19937 rng(2026);
  int next = 0;
  long words = 0, served = 0, could_serve = 0;
  // Phases of 400 clocks with different push and pop rates (fill, drain, balanced, bursts).
  const double rates[][2] = {{0.9, 0.2}, {0.1, 0.95}, {0.5, 0.5}, {1.0, 1.0}, {1.0, 0.0},
                             {0.0, 1.0}, {0.7, 0.7}, {0.3, 0.3}, {1.0, 0.6}, {0.2, 1.0}};
  for (int rep = 0; rep < 20; ++rep)
    for (const auto& r : rates)
      for (int t = 0; t < 400; ++t) {
        f.m->eval();
        if (int(f.m->count) != int(ref.size())) {
          if (failures < 10) std::printf("count %d, expected %zu\n", int(f.m->count), ref.size());
          ++failures;
        }
        const bool valid = !f.m->empty;
        if (valid && (ref.empty() || int(f.m->head) != ref.front())) {
          if (failures < 10) std::printf("head %d, expected %d\n", int(f.m->head), ref.empty() ? -1 : ref.front());
          ++failures;
        }
        const bool want_pop = std::bernoulli_distribution(r[1])(rng);
        const bool pop = valid && want_pop;
        // A word that has waited a clock must be at the head (the RAM's latency is hidden
        // behind the output FIFO once the consumer pops every clock).
        if (want_pop && !ref.empty()) ++could_serve;
        if (pop) ++served;
        const bool push = int(ref.size()) - int(pop) < kDepth && std::bernoulli_distribution(r[0])(rng);
        const int din = next & 0xffff;
        if (pop) ref.pop_front();
        if (push) ref.push_back(din), ++next, ++words;
        f.Step(push, din, pop);
      }
  std::printf("random traffic: %ld words, %ld pops of %ld wanted with a word held, %d assertion failures\n",
              words, served, could_serve, f.Errors());
  if (f.Errors() != 0) std::printf("an assertion fired on legal traffic\n"), ++failures;

  // Drain, then: a word pushed into the empty FIFO is at the head in the next clock.
  while (!ref.empty()) {
    f.m->eval();
    if (!f.m->empty) ref.pop_front(), f.Step(false, 0, true);
    else f.Step(false, 0, false);
  }
  f.Step(true, 1234, false);
  if (f.m->empty || int(f.m->head) != 1234) std::printf("bypass: the word is not at the head\n"), ++failures;
  f.Step(false, 0, true);
  // Fill to DEPTH, then pop every clock: after the head is valid, one word per clock.
  for (int i = 0; i < kDepth; ++i) f.Step(true, 100 + i, false);
  if (int(f.m->count) != kDepth) std::printf("count %d after filling\n", int(f.m->count)), ++failures;
  for (int i = 0; i < kDepth; ++i) {
    f.m->eval();
    if (f.m->empty || int(f.m->head) != 100 + i) {
      std::printf("drain of a full FIFO: clock %d head %d valid %d\n", i, int(f.m->head), int(!f.m->empty));
      ++failures;
      break;
    }
    f.Step(false, 0, true);
  }
  if (!f.m->empty || f.m->count != 0) std::printf("not empty after draining\n"), ++failures;
  if (f.Errors() != 0) std::printf("an assertion fired on legal traffic (%d)\n", f.Errors()), ++failures;

  // Overflow: DEPTH pushes, then one more without a pop.
  for (int i = 0; i < kDepth; ++i) f.Step(true, i, false);
  const int before_over = f.Errors();
  f.Step(true, 99, false);
  const bool over = f.Errors() > before_over;
  std::printf("push into the full FIFO: overflow assertion %s\n", over ? "fired" : "did NOT fire");
  failures += !over;

  // Underflow: a pop from the empty FIFO (after a reset).
  f.Reset();
  const int before_under = f.Errors();
  f.Step(false, 0, true);
  const bool under = f.Errors() > before_under;
  std::printf("pop from the empty FIFO: underflow assertion %s\n", under ? "fired" : "did NOT fire");
  failures += !under;

  std::printf(failures ? "FAILED\n" : "PASSED\n");
  return failures ? 1 : 0;
}
