// scripts/hls/tb/tb_init.cc — C test bench of HwInitTop (Vitis csim/cosim: scripts/hls/init.tcl;
// here: ctest hls_tb_init). Builds the case of hls_case.h, runs the top and compares its
// samples and report with the golden vectors bit for bit. Usage: tb_init [<vector dir>].
#include <memory>

#include "hls_case.h"

namespace hls_case {

inline int TbInit(const std::string& dir) {
  std::unique_ptr<Case> c(new Case);
  MakeCase(c.get());
  Sample samples[kMaxParticles];
  InitReport report;
  HwInitTop(c->prob, c->class_sum, c->volumes, c->gen, c->init_opt, samples, kCaseParticles, report);
  const ap_uint<32> words[4] = {report.counters.reads, report.counters.reads_linear, report.counters.draws,
                                ap_uint<32>(report.uniform_fallback ? 1 : 0)};
  int bad = CompareVector(VecPath(dir, "init_samples"), samples, kCaseParticles);
  bad += CompareVector(VecPath(dir, "init_report"), words, 4);
  std::printf("HwInitTop: %s\n", bad ? "MISMATCH" : "PASS");
  return TbStatus(bad);
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) { return hls_case::TbInit(argc > 1 ? argv[1] : "vectors"); }
#endif
