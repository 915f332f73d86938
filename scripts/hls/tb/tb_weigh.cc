// scripts/hls/tb/tb_weigh.cc — C test bench of HwWeighTop5 / HwWeighTop10 (Vitis csim/cosim:
// scripts/hls/weigh5.tcl, weigh10.tcl with -DHLS_TB_CORES=5 or 10; here: ctest hls_tb_weigh5,
// hls_tb_weigh10 and their _torus twins). Reads the initialisation's golden samples, writes
// every memory and register of the top as its AXI byte image and reads it back as the top's
// argument, runs the top, reads the sorted weights and indices, the per-particle counters, the
// depth offsets and the depth-read counts back through their byte images and compares them with
// the golden vectors (written with one core) bit for bit.
// Usage: tb_weigh [<vector dir> [<case>]] (case: cube, torus).
#include <memory>

#include "hls_case.h"

#ifndef HLS_TB_CORES
#define HLS_TB_CORES 5
#endif

namespace hls_case {

inline int TbWeigh(const std::string& dir, const std::string& case_name, int cores) {
  const CaseSpec* spec = FindCase(case_name);
  if (!spec) return kTbMissingInput;
  const std::string cdir = CaseDir(dir, *spec);
  std::unique_ptr<Case> host(new Case), dev(new Case);
  MakeCase(host.get(), *spec);
  CaseViaAxi(*host, dev.get());
  Sample samples_host[kMaxParticles], samples[kMaxParticles];
  if (!ReadVector(VecPath(cdir, "init_samples"), samples_host, spec->particles)) return kTbMissingInput;
  int n = 0;
  ViaAxi(&spec->particles, 1, &n);
  ViaAxi(samples_host, n, samples);
  weight_t sorted_w[kMaxParticles];
  particle_index_t sorted_idx[kMaxParticles];
  RasterCoreOutput stats[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  DepthDistributionCounts dd;
  if (cores == 10)
    HwWeighTop10(n, dev->cfg, samples, dev->cell_windows, dev->class_prob, dev->depth, dev->vmem, dev->tri_mem, sorted_w,
                 sorted_idx, stats, offsets, &dd);
  else
    HwWeighTop5(n, dev->cfg, samples, dev->cell_windows, dev->class_prob, dev->depth, dev->vmem, dev->tri_mem, sorted_w,
                sorted_idx, stats, offsets, &dd);
  // What the driver reads back: four buffers and the depth-read count registers.
  weight_t got_w[kMaxParticles];
  particle_index_t got_idx[kMaxParticles];
  RasterCoreOutput got_stats[kMaxParticles];
  depth_off_t got_offsets[kMaxParticles];
  DepthDistributionCounts got_dd;
  ViaAxi(sorted_w, n, got_w);
  ViaAxi(sorted_idx, n, got_idx);
  ViaAxi(stats, n, got_stats);
  ViaAxi(offsets, n, got_offsets);
  ViaAxi(&dd, 1, &got_dd);
  const ap_uint<32> dd_words[1] = {got_dd.reads_unshared};  // reads_shared depends on M
  int bad = CompareVector(VecPath(cdir, "weigh_sorted_w"), got_w, n);
  bad += CompareVector(VecPath(cdir, "weigh_sorted_idx"), got_idx, n);
  bad += CompareVector(VecPath(cdir, "weigh_stats"), got_stats, n);
  bad += CompareVector(VecPath(cdir, "weigh_offsets"), got_offsets, n);
  bad += CompareVector(VecPath(cdir, "weigh_dd"), dd_words, 1);
  if (got_dd.reads_shared > got_dd.reads_unshared)
    ++bad, std::fprintf(stderr, "shared depth reads exceed the unshared\n");
  std::printf("HwWeighTop%d (%s): %s\n", cores, spec->name, bad ? "MISMATCH" : "PASS");
  return TbStatus(bad);
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) {
  return hls_case::TbWeigh(argc > 1 ? argv[1] : "vectors", argc > 2 ? argv[2] : "cube", HLS_TB_CORES);
}
#endif
