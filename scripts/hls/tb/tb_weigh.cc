// scripts/hls/tb/tb_weigh.cc — C test bench of HwWeighTop5 / HwWeighTop10 (Vitis csim/cosim:
// scripts/hls/weigh5.tcl, weigh10.tcl with -DHLS_TB_CORES=5 or 10; here: ctest hls_tb_weigh5,
// hls_tb_weigh10). Reads the initialisation's golden samples, runs the top and compares the
// sorted weights and indices, the per-particle counters, the depth offsets and the unshared
// depth-read count with the golden vectors (written with one core) bit for bit.
// Usage: tb_weigh [<vector dir>].
#include <memory>

#include "hls_case.h"

#ifndef HLS_TB_CORES
#define HLS_TB_CORES 5
#endif

namespace hls_case {

inline int TbWeigh(const std::string& dir, int cores) {
  std::unique_ptr<Case> c(new Case);
  MakeCase(c.get());
  const int n = kCaseParticles;
  Sample samples[kMaxParticles];
  if (!ReadVector(VecPath(dir, "init_samples"), samples, n)) return kTbMissingInput;
  weight_t sorted_w[kMaxParticles];
  particle_index_t sorted_idx[kMaxParticles];
  RasterCoreOutput stats[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  DepthDistributionCounts dd;
  if (cores == 10)
    HwWeighTop10(n, c->cfg, samples, c->cell_windows, c->class_prob, c->depth, c->vmem, c->tri_mem, sorted_w, sorted_idx,
                 stats, offsets, &dd);
  else
    HwWeighTop5(n, c->cfg, samples, c->cell_windows, c->class_prob, c->depth, c->vmem, c->tri_mem, sorted_w, sorted_idx,
                stats, offsets, &dd);
  const ap_uint<32> dd_words[1] = {dd.reads_unshared};
  int bad = CompareVector(VecPath(dir, "weigh_sorted_w"), sorted_w, n);
  bad += CompareVector(VecPath(dir, "weigh_sorted_idx"), sorted_idx, n);
  bad += CompareVector(VecPath(dir, "weigh_stats"), stats, n);
  bad += CompareVector(VecPath(dir, "weigh_offsets"), offsets, n);
  bad += CompareVector(VecPath(dir, "weigh_dd"), dd_words, 1);
  if (dd.reads_shared > dd.reads_unshared) ++bad, std::fprintf(stderr, "shared depth reads exceed the unshared\n");
  std::printf("HwWeighTop%d: %s\n", cores, bad ? "MISMATCH" : "PASS");
  return TbStatus(bad);
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) { return hls_case::TbWeigh(argc > 1 ? argv[1] : "vectors", HLS_TB_CORES); }
#endif
