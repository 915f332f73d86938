#include "filter_cli.h"

#include <unistd.h>

#include <cstdio>

#include "posefilter/error.h"

namespace posefilter::cli {

void AddFilterOptions(CLI::App& app, FilterOptions* o) {
  app.add_option("--engine", o->engine, "scoring engine")->capture_default_str()->check(CLI::IsMember({"reference"}));
  app.add_option("--particles", o->num_particles, "number of particles N")->capture_default_str();
  app.add_option("--iterations", o->max_iterations, "maximum iterations")->capture_default_str();
  app.add_option("--confidence", o->confidence, "stop when the best weight reaches this")->capture_default_str();
  app.add_option("--alpha", o->alpha, "weight of I/N_raster (eq. 7.4)")->capture_default_str();
  app.add_option("--beta", o->beta, "weight of I/N_depth (eq. 7.4)")->capture_default_str();
  app.add_option("--gamma", o->gamma, "weight of the stage-1 probability (eq. 7.4)")->capture_default_str();
  app.add_option("--inlier-thr", o->inlier.thr1_m, "soft inlier: chi = 1 up to this, 0 from twice it (m)")->capture_default_str();
  app.add_flag("--hard-inlier", o->inlier.hard, "hard inlier (chi = 1 iff d <= 5 mm) instead of the soft ramp");
  app.add_flag("!--no-zbuffer", o->zbuffer, "thesis mode: back-face culling only, no z-buffer");
  app.add_flag("!--no-occlusion-aware", o->occlusion_aware,
               "count occluded rendered pixels in N_raster, as the thesis does");
  app.add_option("--window", o->max_window_px, "maximum window side (pixels)")->capture_default_str();
  app.add_option("--elite", o->num_elite, "best particles kept unchanged each iteration")->capture_default_str();
  app.add_option("--pool", o->resample_pool, "fraction of the sorted set resampled from")->capture_default_str();
  app.add_option("--sigma-t", o->sigma_t0_m, "initial diffusion translation sigma (m)")->capture_default_str();
  app.add_option("--sigma-r", o->sigma_r0_rad, "initial diffusion rotation sigma (rad)")->capture_default_str();
  app.add_option("--seed", o->seed, "random seed (same seed, same poses)")->capture_default_str();
  app.add_option("--threads", o->threads, "scoring threads (0 = all cores)")->capture_default_str();
}

void CheckFilterOptions(const FilterOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error("invalid filter option: " + why);
}

ProgressFn StderrProgress(const std::string& obj, int max_iterations, bool quiet) {
  if (quiet) return nullptr;
  const bool tty = isatty(fileno(stderr));
  return [obj, max_iterations, tty](int it, double w) {
    if (tty) {
      std::fprintf(stderr, "\r%s: iteration %d/%d, best weight %.3f   ", obj.c_str(), it + 1, max_iterations, w);
    } else if ((it + 1) % 10 == 0) {
      std::fprintf(stderr, "%s: iteration %d/%d, best weight %.3f\n", obj.c_str(), it + 1, max_iterations, w);
    }
    std::fflush(stderr);
  };
}

}  // namespace posefilter::cli
