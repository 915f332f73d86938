// tests/hw/rtl/rc_fifo_tests_main.cc — the FIFO tests as one program, so that both Verilated
// models share one compiled Verilator runtime: `rc_fifo_test assert` drives rc_fifo
// (rc_fifo_assert_test.cc), `rc_fifo_test bram` drives rc_fifo_bram (rc_fifo_bram_test.cc).
// Exit 0 when the test passed, 1 when it failed, 2 on a usage error.
#include <cstdio>
#include <cstring>

int RunRcFifoAssertTest();
int RunRcFifoBramTest();

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "assert") == 0) return RunRcFifoAssertTest();
  if (argc == 2 && std::strcmp(argv[1], "bram") == 0) return RunRcFifoBramTest();
  std::fprintf(stderr, "usage: rc_fifo_test assert|bram\n");
  return 2;
}
