// scripts/hls/tb/golden_gen.cc — writes the golden vectors of the HLS test benches: runs the C
// model (src/hw/top.h, src/hw/tops.cc; C simulation) on each case of hls_case.h through the
// three halves of one filter iteration and writes, into <vector dir>/<case>/, each top's inputs
// that come from an earlier top and its outputs:
//
//   HwInitTop      → init_samples, init_report (reads, reads_linear, draws, uniform_fallback)
//   HwWeighTop<1>  → weigh_sorted_w, weigh_sorted_idx, weigh_stats, weigh_offsets, weigh_dd
//                    (one raster core: the 5- and 10-core tops must give the same bits)
//   HwUpdateTop    → update_samples, update_counters (draws, cdf_reads, cdf_reads_linear, pool)
//
// The generator passes the values to the tops directly; the benches pass them through the AXI
// byte images (hls_case.h ViaAxi), so the golden vectors also check the packer.
// Usage: hls_golden <vector dir> [<corrupted copy dir>] — both folders must hold a sub-folder per
// case (cube, torus); the copy has one bit of the best weight flipped (the negative control of
// the test benches). Built by tests/hls/CMakeLists.txt.
#include <memory>

#include "hls_case.h"

namespace hls_case {

inline bool WriteGoldenCase(const CaseSpec& spec, const std::string& dir, const std::string& bad_dir) {
  std::unique_ptr<Case> c(new Case);
  MakeCase(c.get(), spec);
  const int n = spec.particles;
  const std::string cdir = CaseDir(dir, spec);
  bool ok = true;
  // Initialisation.
  Sample samples0[kMaxParticles];
  InitReport report;
  HwInitTop(c->prob, c->class_sum, c->volumes, c->gen, c->init_opt, samples0, n, report);
  ok &= WriteVector(VecPath(cdir, "init_samples"), samples0, n);
  ok &= WriteVector(VecPath(cdir, "init_report"), &report, 1);
  // Weighing with one core.
  weight_t sorted_w[kMaxParticles];
  particle_index_t sorted_idx[kMaxParticles];
  RasterCoreOutput stats[kMaxParticles];
  depth_off_t offsets[kMaxParticles];
  DepthDistributionCounts dd;
  HwWeighTop<1>(n, c->cfg, samples0, c->cell_windows, c->class_prob, c->depth, c->vmem, c->tri_mem, sorted_w, sorted_idx,
                stats, offsets, &dd, nullptr);
  const ap_uint<32> dd_words[1] = {dd.reads_unshared};  // reads_shared depends on M
  ok &= WriteVector(VecPath(cdir, "weigh_sorted_w"), sorted_w, n);
  ok &= WriteVector(VecPath(cdir, "weigh_sorted_idx"), sorted_idx, n);
  ok &= WriteVector(VecPath(cdir, "weigh_stats"), stats, n);
  ok &= WriteVector(VecPath(cdir, "weigh_offsets"), offsets, n);
  ok &= WriteVector(VecPath(cdir, "weigh_dd"), dd_words, 1);
  // Update.
  Lfsr18 resample_rng(c->resample_seed);
  DiffusionRng diffusion_rng(c->diffusion_seed);
  Sample samples1[kMaxParticles];
  ResampleCounters rc;
  HwUpdateTop(sorted_w, sorted_idx, sorted_w[0], samples0, samples0, offsets, c->hypothesis, c->rprm, resample_rng, c->dprm,
              c->volumes, diffusion_rng, samples1, &rc);
  ok &= WriteVector(VecPath(cdir, "update_samples"), samples1, n);
  ok &= WriteVector(VecPath(cdir, "update_counters"), &rc, 1);
  // Non-trivial case: some particle renders the model.
  std::printf("golden vectors in %s: %d particles, %d faces, best weight %.6f, pool %u\n", cdir.c_str(), n,
              c->cfg.num_faces, sorted_w[0].to_double(), unsigned(rc.pool));
  if (!bad_dir.empty()) {  // the same vectors with the best weight's lowest bit flipped
    const std::string bdir = CaseDir(bad_dir, spec);
    for (const char* name : {"init_samples", "init_report", "weigh_sorted_idx", "weigh_stats", "weigh_offsets", "weigh_dd",
                             "update_samples", "update_counters"}) {
      std::vector<uint64_t> w;
      ok &= ReadWords(VecPath(cdir, name), &w);
      ok &= WriteVector(VecPath(bdir, name), w.data(), int(w.size()));
    }
    axi::SetRawBits(sorted_w[0], axi::RawBits(sorted_w[0]) ^ 1);
    ok &= WriteVector(VecPath(bdir, "weigh_sorted_w"), sorted_w, n);
  }
  return ok;
}

inline int WriteGolden(const std::string& dir, const std::string& bad_dir) {
  bool ok = true;
  for (const CaseSpec& spec : kCases) ok &= WriteGoldenCase(spec, dir, bad_dir);
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
