// tests/hw/rtl/rc_fifo_assert_test.cc — negative control of the RTL's simulation assertions:
// rc_fifo (src/hw/rtl/rc_fifo.sv, verilated with --assert, DEPTH = 4, W = 8) is driven first
// legally (fill to full, push and pop together while full, drain; every word must come out in
// order and no assertion may fire), then illegally: a push into the full FIFO must fire the
// overflow assertion and a pop from the empty FIFO the underflow assertion. Verilator counts
// the failed assertions (errorCount) instead of stopping, so the test can check each one.
#include <cstdio>

#include "Vrc_fifo.h"
#include "rc_fifo_harness.h"

namespace {

using Fifo = FifoHarness<Vrc_fifo>;

}  // namespace

// `rc_fifo_test assert` (rc_fifo_tests_main.cc).
int RunRcFifoAssertTest() {
  int failures = 0;
  Fifo f;
  // Legal traffic: 4 pushes (full), push + pop while full, 4 pops.
  for (int i = 0; i < 4; ++i) f.Step(true, 10 + i, false);
  if (f.m->count != 4) std::printf("count %d after 4 pushes, expected 4\n", int(f.m->count)), ++failures;
  int expect = 10;
  if (f.Step(true, 14, true) != expect++) ++failures;
  for (int i = 0; i < 4; ++i)
    if (f.Step(false, 0, true) != expect++) std::printf("wrong word out of the FIFO\n"), ++failures;
  if (f.m->empty != 1) std::printf("FIFO not empty after draining\n"), ++failures;
  if (f.Errors() != 0) std::printf("an assertion fired on legal traffic (%d)\n", f.Errors()), ++failures;
  std::printf("legal traffic: %d assertion failures\n", f.Errors());

  // Overflow: a fifth push without a pop.
  for (int i = 0; i < 4; ++i) f.Step(true, i, false);
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
