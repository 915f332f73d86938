// scripts/hls/tb/tb_init.cc — C test bench of HwInitTop (Vitis csim/cosim: scripts/hls/init.tcl;
// here: ctest hls_tb_init, hls_tb_init_torus). Builds a case of hls_case.h, writes the top's
// memories and registers as their AXI byte images and reads them back as the top's arguments,
// runs the top, reads its samples and report back through their byte images and compares them
// with the golden vectors bit for bit. Usage: tb_init [<vector dir> [<case>]] (case: cube, torus).
#include <memory>

#include "hls_case.h"

namespace hls_case {

inline int TbInit(const std::string& dir, const std::string& case_name) {
  const CaseSpec* spec = FindCase(case_name);
  if (!spec) return kTbMissingInput;
  std::unique_ptr<Case> host(new Case), dev(new Case);
  MakeCase(host.get(), *spec);
  CaseViaAxi(*host, dev.get());
  int n = 0;
  ViaAxi(&spec->particles, 1, &n);
  Sample samples[kMaxParticles];
  InitReport report;
  HwInitTop(dev->prob, dev->class_sum, dev->volumes, dev->gen, dev->init_opt, samples, n, report);
  // What the driver reads back: the sample buffer and the report registers.
  Sample got_samples[kMaxParticles];
  InitReport got_report;
  ViaAxi(samples, n, got_samples);
  ViaAxi(&report, 1, &got_report);
  const std::string cdir = CaseDir(dir, *spec);
  int bad = CompareVector(VecPath(cdir, "init_samples"), got_samples, n);
  bad += CompareVector(VecPath(cdir, "init_report"), &got_report, 1);
  std::printf("HwInitTop (%s): %s\n", spec->name, bad ? "MISMATCH" : "PASS");
  return TbStatus(bad);
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) { return hls_case::TbInit(argc > 1 ? argv[1] : "vectors", argc > 2 ? argv[2] : "cube"); }
#endif
