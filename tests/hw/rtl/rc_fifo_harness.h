// tests/hw/rtl/rc_fifo_harness.h — the clocking of a Verilated FIFO model (rc_fifo or
// rc_fifo_bram: ports clk, rst, push, din, pop, head, empty, count) for the FIFO tests of
// rc_fifo_test. Failed simulation assertions are counted (Errors) instead of stopping the run.
#pragma once

#include <memory>

#include "verilated.h"

template <typename Model>
struct FifoHarness {
  std::unique_ptr<VerilatedContext> ctx;
  std::unique_ptr<Model> m;
  FifoHarness() : ctx(new VerilatedContext), m(new Model(ctx.get())) {
    ctx->fatalOnError(false);
    ctx->errorLimit(1000000);  // count failed assertions, do not stop
    m->clk = 0;
    m->push = m->pop = 0;
    m->din = 0;
    Reset();
  }
  // Two clocks with rst high.
  void Reset() {
    m->rst = 1;
    Clock();
    Clock();
    m->rst = 0;
  }
  // One rising and falling edge.
  void Clock() {
    m->eval();
    m->clk = 1;
    m->eval();
    m->clk = 0;
    m->eval();
  }
  // One clock with the given push/pop; returns the head seen before the edge.
  int Step(bool push, int din, bool pop) {
    m->push = push;
    m->din = din;
    m->pop = pop;
    m->eval();
    const int head = int(m->head);
    Clock();
    m->push = m->pop = 0;
    m->eval();
    return head;
  }
  int Errors() const { return ctx->errorCount(); }
};
