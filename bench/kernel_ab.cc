// posefilter_kernel_ab — compares two builds of the cpu kernel (its AVX-512 variant, or the AVX2
// one when configured with -DPOSEFILTER_KERNEL_AB_ISA=avx2) in one process,
// alternating them in short rounds, so that a change of a few per cent shows on a machine whose
// speed drifts by more than that between runs (the A/B of separate benchmark runs cannot).
//
// Side A is compiled from POSEFILTER_KERNEL_AB_BASE (a CMake cache path; default: the tree's own
// src/render/cpu_kernel_impl.inc, which measures the noise floor), side B from the tree's file.
// cpu_kernel_impl.inc includes its part files (cpu_kernel_*.inc) from its own folder, so side A
// needs a whole copy of src/render. Both must fit the tree's src/render/cpu_kernel.h
// (CoreScratch, kFastBins, kTriFields). Typical use: `git archive HEAD src/render | tar -x -C
// /tmp/base`, configure with -DPOSEFILTER_BUILD_BENCH=ON
// -DPOSEFILTER_KERNEL_AB_BASE=/tmp/base/src/render/cpu_kernel_impl.inc, edit, rebuild, run.
//
// Each round times A and B (order alternating) on every pose of the workload (kernel_setup.h),
// --reps times; printed: per-weighing µs of each side (median and minimum over rounds) and the
// median with quartiles of the per-round ratio B/A. Before timing, every pose is scored by both
// sides and the results must agree exactly (counts and the inlier and depth-difference sums);
// otherwise the tool names the pose and exits 1. Exit 2: this CPU cannot run the sides' instruction
// set.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "kernel_setup.h"
#include "render/cpu_kernel.h"
#include "render/face_planes.h"

namespace posefilter::render::cpu_detail {
std::int64_t CoreAbA(const ScoreKernelParams& k, const CoreScratch& s, ScoreKernelResult* r);
std::int64_t CoreAbB(const ScoreKernelParams& k, const CoreScratch& s, ScoreKernelResult* r);
}  // namespace posefilter::render::cpu_detail

namespace {

using namespace posefilter;

typedef std::int64_t (*CoreFn)(const ScoreKernelParams&, const render::cpu_detail::CoreScratch&, ScoreKernelResult*);

ScoreKernelResult Score(CoreFn core, const ScoreKernelParams& k, render::CpuWorkspace* ws,
                        const render::FacePlanes* planes) {
  const render::cpu_detail::CoreScratch s = render::cpu_detail::PrepareScratch(k, ws, planes);
  ScoreKernelResult r;
  r.faces_total = k.num_faces;
  core(k, s, &r);
  return r;
}

bool Same(const ScoreKernelResult& a, const ScoreKernelResult& b) {
  return a.n_raster == b.n_raster && a.n_occluded == b.n_occluded && a.faces_front == b.faces_front &&
         a.depth_diff_count == b.depth_diff_count && a.n_edge == b.n_edge && a.n_edge_continued == b.n_edge_continued &&
         a.inlier_sum == b.inlier_sum && a.depth_diff_sum == b.depth_diff_sum;
}

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::size_t(q * double(v.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"A/B of two cpu kernel builds in one process (see bench/kernel_ab.cc)"};
  int rounds = 40, reps = 10, poses = 64, n = 32;
  std::string zbuffer = "on", set = "near";
  bool precull = true;
  app.add_option("--rounds", rounds, "rounds (each times A and B once)")->check(CLI::Range(2, 100000));
  app.add_option("--reps", reps, "passes over the poses per side and round")->check(CLI::Range(1, 100000));
  app.add_option("--poses", poses, "poses in the workload")->check(CLI::Range(1, 100000));
  app.add_option("--n", n, "torus subdivisions (2·n² triangles)")->check(CLI::Range(3, 1000));
  app.add_option("--zbuffer", zbuffer, "z-buffer mode")->check(CLI::IsMember({"on", "off"}));
  app.add_option("--poses-set", set, "near (converging set) or spread (first iteration)")
      ->check(CLI::IsMember({"near", "spread"}));
  app.add_option("--precull", precull, "back-face pre-cull from the face planes, as the filter runs it");
  CLI11_PARSE(app, argc, argv);

#if POSEFILTER_AB_AVX512
  const render::CpuTarget isa = render::CpuTarget::kAvx512;
  const char* isa_name = "AVX-512";
#else
  const render::CpuTarget isa = render::CpuTarget::kAvx2;
  const char* isa_name = "AVX2";
#endif
  if (!render::CpuTargetSupported(isa)) {
    std::fprintf(stderr, "posefilter_kernel_ab: needs a build and a CPU with %s\n", isa_name);
    return 2;
  }
  const KernelSetup setup(n, zbuffer == "on", poses, set == "spread");
  const render::FacePlanes planes = render::BuildFacePlanes(setup.params[0]);
  const render::FacePlanes* pl = precull ? &planes : nullptr;
  const CoreFn sides[2] = {render::cpu_detail::CoreAbA, render::cpu_detail::CoreAbB};
  render::CpuWorkspace ws[2];  // one per side

  for (int i = 0; i < poses; ++i) {
    const ScoreKernelResult a = Score(sides[0], setup.params[i], &ws[0], pl);
    const ScoreKernelResult b = Score(sides[1], setup.params[i], &ws[1], pl);
    if (!Same(a, b)) {
      std::fprintf(stderr,
                   "posefilter_kernel_ab: A and B differ on pose %d (n_raster %lld / %lld, inlier_sum %.17g / %.17g)\n",
                   i, static_cast<long long>(a.n_raster), static_cast<long long>(b.n_raster), a.inlier_sum,
                   b.inlier_sum);
      return 1;
    }
  }

  std::vector<double> us[2], ratio;
  double checksum = 0;
  for (int r = 0; r < rounds; ++r) {
    for (int pass = 0; pass < 2; ++pass) {
      const int side = (r + pass) % 2;  // A first in even rounds, B first in odd ones
      const auto t0 = std::chrono::steady_clock::now();
      for (int q = 0; q < reps; ++q)
        for (const ScoreKernelParams& k : setup.params) checksum += double(Score(sides[side], k, &ws[side], pl).n_raster);
      const std::chrono::duration<double, std::micro> dt = std::chrono::steady_clock::now() - t0;
      us[side].push_back(dt.count() / (double(reps) * poses));
    }
    ratio.push_back(us[1].back() / us[0].back());
  }
  std::printf("%s; workload: torus %d faces, %d %s poses, z-buffer %s, pre-cull %s; %d rounds x %d reps (checksum %.0f)\n",
              isa_name, 2 * n * n, poses, set.c_str(), zbuffer.c_str(), precull ? "on" : "off", rounds, reps, checksum);
  for (int side = 0; side < 2; ++side)
    std::printf("%s: %.2f us/weighing (median), %.2f (min)\n", side ? "B" : "A", Quantile(us[side], 0.5),
                *std::min_element(us[side].begin(), us[side].end()));
  std::printf("B/A: %.3f (median of rounds; quartiles %.3f .. %.3f)\n", Quantile(ratio, 0.5), Quantile(ratio, 0.25),
              Quantile(ratio, 0.75));
  return 0;
}
