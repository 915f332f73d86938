// scripts/hls/tb/tb_update.cc — C test bench of HwUpdateTop (Vitis csim/cosim:
// scripts/hls/update.tcl; here: ctest hls_tb_update, hls_tb_update_torus). Reads the golden
// samples of the initialisation and the golden sorted set and depth offsets of the weighing,
// writes every memory and register of the top as its AXI byte image and reads it back as the
// top's argument (w_best = the golden sorted_w[0], the sample memory on both read ports), runs
// the top, reads the next sample memory and the resampling counters back through their byte
// images and compares them bit for bit. Usage: tb_update [<vector dir> [<case>]] (case: cube,
// torus).
#include <memory>

#include "hls_case.h"

namespace hls_case {

inline int TbUpdate(const std::string& dir, const std::string& case_name) {
  const CaseSpec* spec = FindCase(case_name);
  if (!spec) return kTbMissingInput;
  const std::string cdir = CaseDir(dir, *spec);
  std::unique_ptr<Case> host(new Case), dev(new Case);
  MakeCase(host.get(), *spec);
  CaseViaAxi(*host, dev.get());
  const int count = spec->particles;
  Sample samples_host[kMaxParticles];
  weight_t w_host[kMaxParticles];
  particle_index_t idx_host[kMaxParticles];
  depth_off_t offsets_host[kMaxParticles];
  if (!ReadVector(VecPath(cdir, "init_samples"), samples_host, count) ||
      !ReadVector(VecPath(cdir, "weigh_sorted_w"), w_host, count) ||
      !ReadVector(VecPath(cdir, "weigh_sorted_idx"), idx_host, count) ||
      !ReadVector(VecPath(cdir, "weigh_offsets"), offsets_host, count))
    return kTbMissingInput;
  // The driver's writes: the buffers, w_best and the LFSR states.
  Sample samples_in[kMaxParticles];
  weight_t sorted_w[kMaxParticles], w_best;
  particle_index_t sorted_idx[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  ViaAxi(samples_host, count, samples_in);
  ViaAxi(w_host, count, sorted_w);
  ViaAxi(idx_host, count, sorted_idx);
  ViaAxi(offsets_host, count, offsets);
  ViaAxi(&w_host[0], 1, &w_best);
  const Lfsr18 resample_rng_host(host->resample_seed);
  const DiffusionRng diffusion_rng_host(host->diffusion_seed);
  Lfsr18 resample_rng;
  DiffusionRng diffusion_rng;
  ViaAxi(&resample_rng_host, 1, &resample_rng);
  ViaAxi(&diffusion_rng_host, 1, &diffusion_rng);
  Sample samples_out[kMaxParticles];
  ResampleCounters rc;
  HwUpdateTop(sorted_w, sorted_idx, w_best, samples_in, samples_in, offsets, dev->hypothesis, dev->rprm, resample_rng,
              dev->dprm, dev->volumes, diffusion_rng, samples_out, &rc);
  // What the driver reads back: the next sample memory and the counter registers.
  Sample got_samples[kMaxParticles];
  ResampleCounters got_rc;
  ViaAxi(samples_out, count, got_samples);
  ViaAxi(&rc, 1, &got_rc);
  int bad = CompareVector(VecPath(cdir, "update_samples"), got_samples, count);
  bad += CompareVector(VecPath(cdir, "update_counters"), &got_rc, 1);
  std::printf("HwUpdateTop (%s): %s\n", spec->name, bad ? "MISMATCH" : "PASS");
  return TbStatus(bad);
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) {
  return hls_case::TbUpdate(argc > 1 ? argv[1] : "vectors", argc > 2 ? argv[2] : "cube");
}
#endif
