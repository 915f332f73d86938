// scripts/hls/tb/tb_update.cc — C test bench of HwUpdateTop (Vitis csim/cosim:
// scripts/hls/update.tcl; here: ctest hls_tb_update). Reads the golden samples of the
// initialisation and the golden sorted set and depth offsets of the weighing, runs the top
// (w_best = the golden sorted_w[0], the sample memory on both read ports) and compares the
// next sample memory and the resampling counters bit for bit. Usage: tb_update [<vector dir>].
#include <memory>

#include "hls_case.h"

namespace hls_case {

inline int TbUpdate(const std::string& dir) {
  std::unique_ptr<Case> c(new Case);
  MakeCase(c.get());
  const int n = kCaseParticles;
  Sample samples_in[kMaxParticles];
  weight_t sorted_w[kMaxParticles];
  particle_index_t sorted_idx[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  if (!ReadVector(VecPath(dir, "init_samples"), samples_in, n) || !ReadVector(VecPath(dir, "weigh_sorted_w"), sorted_w, n) ||
      !ReadVector(VecPath(dir, "weigh_sorted_idx"), sorted_idx, n) || !ReadVector(VecPath(dir, "weigh_offsets"), offsets, n))
    return kTbMissingInput;
  Lfsr18 resample_rng(c->resample_seed);
  DiffusionRng diffusion_rng(c->diffusion_seed);
  Sample samples_out[kMaxParticles];
  ResampleCounters rc;
  HwUpdateTop(sorted_w, sorted_idx, sorted_w[0], samples_in, samples_in, offsets, c->hypothesis, c->rprm, resample_rng,
              c->dprm, c->volumes, diffusion_rng, samples_out, &rc);
  const ap_uint<32> counters[4] = {rc.draws, rc.cdf_reads, rc.cdf_reads_linear, rc.pool};
  int bad = CompareVector(VecPath(dir, "update_samples"), samples_out, n);
  bad += CompareVector(VecPath(dir, "update_counters"), counters, 4);
  std::printf("HwUpdateTop: %s\n", bad ? "MISMATCH" : "PASS");
  return TbStatus(bad);
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) { return hls_case::TbUpdate(argc > 1 ? argv[1] : "vectors"); }
#endif
