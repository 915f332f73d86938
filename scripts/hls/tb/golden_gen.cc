// scripts/hls/tb/golden_gen.cc — writes the golden vectors of the HLS test benches: runs the C
// model (src/hw/top.h, C simulation) on the case of hls_case.h through the three halves of one
// filter iteration and writes each top's inputs that come from an earlier top and its outputs:
//
//   HwInitTop      → init_samples, init_report (reads, reads_linear, draws, uniform_fallback)
//   HwWeighTop<1>  → weigh_sorted_w, weigh_sorted_idx, weigh_stats, weigh_offsets, weigh_dd
//                    (one raster core: the 5- and 10-core tops must give the same bits)
//   HwUpdateTop    → update_samples, update_counters (draws, cdf_reads, cdf_reads_linear, pool)
//
// Usage: hls_golden <vector dir> [<corrupted copy dir>] — the copy has one bit of the best weight
// flipped (the negative control of the test benches). Built by tests/hls/CMakeLists.txt.
#include <memory>

#include "hls_case.h"

namespace hls_case {

inline int WriteGolden(const std::string& dir, const std::string& bad_dir) {
  std::unique_ptr<Case> c(new Case);
  MakeCase(c.get());
  const int n = kCaseParticles;
  bool ok = true;
  // Initialisation.
  Sample samples0[kMaxParticles];
  InitReport report;
  HwInitTop(c->prob, c->class_sum, c->volumes, c->gen, c->init_opt, samples0, n, report, nullptr);
  const ap_uint<32> init_report[4] = {report.counters.reads, report.counters.reads_linear, report.counters.draws,
                                      ap_uint<32>(report.uniform_fallback ? 1 : 0)};
  ok &= WriteVector(VecPath(dir, "init_samples"), samples0, n);
  ok &= WriteVector(VecPath(dir, "init_report"), init_report, 4);
  // Weighing with one core.
  weight_t sorted_w[kMaxParticles];
  particle_index_t sorted_idx[kMaxParticles];
  RasterCoreOutput stats[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  DepthDistributionCounts dd;
  HwWeighTop<1>(n, c->cfg, samples0, c->cell_windows, c->class_prob, c->depth, c->vmem, c->tri_mem, sorted_w, sorted_idx,
                stats, offsets, &dd, nullptr);
  const ap_uint<32> dd_words[1] = {dd.reads_unshared};  // reads_shared depends on M
  ok &= WriteVector(VecPath(dir, "weigh_sorted_w"), sorted_w, n);
  ok &= WriteVector(VecPath(dir, "weigh_sorted_idx"), sorted_idx, n);
  ok &= WriteVector(VecPath(dir, "weigh_stats"), stats, n);
  ok &= WriteVector(VecPath(dir, "weigh_offsets"), offsets, n);
  ok &= WriteVector(VecPath(dir, "weigh_dd"), dd_words, 1);
  // Update.
  Lfsr18 resample_rng(c->resample_seed);
  DiffusionRng diffusion_rng(c->diffusion_seed);
  Sample samples1[kMaxParticles];
  ResampleCounters rc;
  HwUpdateTop(sorted_w, sorted_idx, sorted_w[0], samples0, samples0, offsets, c->hypothesis, c->rprm, resample_rng, c->dprm,
              c->volumes, diffusion_rng, samples1, &rc, nullptr);
  const ap_uint<32> counters[4] = {rc.draws, rc.cdf_reads, rc.cdf_reads_linear, rc.pool};
  ok &= WriteVector(VecPath(dir, "update_samples"), samples1, n);
  ok &= WriteVector(VecPath(dir, "update_counters"), counters, 4);
  // Non-trivial case: some particle renders the cube.
  std::printf("golden vectors in %s: %d particles, best weight %.6f, pool %u\n", dir.c_str(), n, sorted_w[0].to_double(),
              unsigned(rc.pool));
  if (!bad_dir.empty()) {  // the same vectors with the best weight's lowest bit flipped
    for (const char* name : {"init_samples", "init_report", "weigh_sorted_idx", "weigh_stats", "weigh_offsets", "weigh_dd",
                             "update_samples", "update_counters"}) {
      std::vector<uint64_t> w;
      ok &= ReadWords(VecPath(dir, name), &w);
      ok &= WriteVector(VecPath(bad_dir, name), w.data(), int(w.size()));
    }
    SetBits(sorted_w[0], Bits(sorted_w[0]) ^ 1);
    ok &= WriteVector(VecPath(bad_dir, "weigh_sorted_w"), sorted_w, n);
  }
  if (!ok) std::fprintf(stderr, "writing the vectors failed\n");
  return ok ? 0 : 1;
}

}  // namespace hls_case

#ifndef HLS_TB_NO_MAIN
int main(int argc, char** argv) {
  if (argc < 2) return std::fprintf(stderr, "usage: %s <vector dir> [<corrupted copy dir>]\n", argv[0]), 2;
  return hls_case::WriteGolden(argv[1], argc > 2 ? argv[2] : "");
}
#endif
