// src/filter/options.cc — FilterOptions::IsValid: the range check of every filter option
// (include/posefilter/filter.h), shared by all engines.
#include <cmath>
#include <string>

#include "core/threads.h"
#include "filter/driver.h"
#include "posefilter/filter.h"
#include "posefilter/mesh_simplify.h"
#include "render/cpu_kernel.h"

namespace posefilter {

bool FilterOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  filter::Engine parsed;
  if (!filter::ParseEngine(engine, &parsed))
    return fail("engine must be 'cpu', 'reference' or 'hw' (got '" + engine + "')");
  if (cpu_isa != "auto") {
    render::CpuTarget t;
    if (!render::ParseCpuTarget(cpu_isa, &t))
      return fail("cpu_isa must be 'auto', 'avx512', 'avx2' or 'portable' (got '" + cpu_isa + "')");
    if (!render::CpuTargetSupported(t)) {
      std::string supported;
      for (render::CpuTarget c : render::SupportedCpuTargets())
        supported += std::string(supported.empty() ? "" : ", ") + render::CpuTargetName(c);
      return fail("cpu_isa '" + cpu_isa + "' is not supported by this CPU or build (supported: " + supported + ")");
    }
  }
  if (num_particles < 2 || num_particles > 1'000'000) return fail("num_particles must be in [2, 1000000]");
  if (max_iterations < 1 || max_iterations > 100'000) return fail("max_iterations must be in [1, 100000]");
  if (!(confidence > 0 && confidence <= 1)) return fail("confidence must be in (0, 1]");
  for (double v : {alpha, beta, gamma})
    if (!(v >= 0 && v <= 1)) return fail("alpha, beta, gamma must each be in [0, 1]");
  if (std::fabs(alpha + beta + gamma - 1) > 1e-6) return fail("alpha + beta + gamma must equal 1");
  if (!(inlier.thr1_m > 0 && std::isfinite(inlier.thr1_m))) return fail("inlier threshold must be > 0");
  if (!(inlier.hard_thr_m > 0 && std::isfinite(inlier.hard_thr_m))) return fail("hard inlier threshold must be > 0");
  if (!(anneal_start_m >= 0 && std::isfinite(anneal_start_m))) return fail("anneal_start_m must be >= 0");
  if (!(anneal_fraction >= 0 && anneal_fraction <= 1)) return fail("anneal_fraction must be in [0, 1]");
  if (anneal_subsample < 1 || anneal_subsample > 4) return fail("anneal_subsample must be in [1, 4]");
  if (!(min_window_diameters >= 0 && min_window_diameters <= 4)) return fail("min_window_diameters must be in [0, 4]");
  if (max_window_px < 8) return fail("max_window_px must be >= 8");
  if (!(near_m > 0 && std::isfinite(near_m))) return fail("near_m must be > 0");
  if (num_elite < 0 || num_elite >= num_particles) return fail("num_elite must be in [0, num_particles)");
  if (!(fine_particle_fraction > 0 && fine_particle_fraction <= 1))
    return fail("fine_particle_fraction must be in (0, 1]");
  if (!(resample_pool > 0 && resample_pool <= 1)) return fail("resample_pool must be in (0, 1]");
  if (!(region_cap > 0 && region_cap <= 1)) return fail("region_cap must be in (0, 1]");
  if (!(rotation_cap > 0 && rotation_cap <= 1)) return fail("rotation_cap must be in (0, 1]");
  if (!(delta >= 0 && delta <= 1)) return fail("delta must be in [0, 1]");
  if (!(contact >= 0 && contact <= 1)) return fail("contact must be in [0, 1]");
  if (!(stable_start >= 0 && stable_start <= 1)) return fail("stable_start must be in [0, 1]");
  if (!(contact_tolerance_m >= 0 && std::isfinite(contact_tolerance_m))) return fail("contact_tolerance_m must be >= 0");
  if (!(contact_span_m > 0 && std::isfinite(contact_span_m))) return fail("contact_span_m must be > 0");
  if (!(edge_band_m > 0 && std::isfinite(edge_band_m))) return fail("edge_band_m must be > 0");
  if (!(align_band_m > 0 && std::isfinite(align_band_m))) return fail("align_band_m must be > 0");
  if (init_oversample < 1 || init_oversample > 64) return fail("init_oversample must be in [1, 64]");
  if (restarts < 1 || restarts > 100) return fail("restarts must be in [1, 100]");
  if (stall_iterations < 0 || stall_iterations > 1000) return fail("stall_iterations must be in [0, 1000]");
  if (!(stall_gain >= 0 && stall_gain <= 1)) return fail("stall_gain must be in [0, 1]");
  if (lod_max_faces != 0 && lod_max_faces < kMinSimplifyFaces) return fail("lod_max_faces must be 0 (full mesh) or >= 4");
  if (polish_steps < 0 || polish_steps > 100) return fail("polish_steps must be in [0, 100]");
  if (polish_seeds < 1 || polish_seeds > 1000) return fail("polish_seeds must be in [1, 1000]");
  if (polish_climbers < 0 || polish_climbers > 1000) return fail("polish_climbers must be in [0, 1000]");
  if (polish_keep < 1 || polish_keep > 100000) return fail("polish_keep must be in [1, 100000]");
  if (tracker_bins < 1 || tracker_bins > 4096) return fail("tracker_bins must be in [1, 4096]");
  if (!(sigma_t0_m >= 0 && std::isfinite(sigma_t0_m))) return fail("sigma_t0_m must be >= 0");
  if (!(sigma_r0_rad >= 0 && std::isfinite(sigma_r0_rad))) return fail("sigma_r0_rad must be >= 0");
  if (!(min_sigma_fraction >= 0 && min_sigma_fraction <= 1)) return fail("min_sigma_fraction must be in [0, 1]");
  double total = 0;
  for (double p : move_probabilities) {
    if (!(p >= 0 && std::isfinite(p))) return fail("move probabilities must be finite and >= 0");
    total += p;
  }
  if (!(total > 0)) return fail("at least one move probability must be > 0");
  if (threads < 0 || threads > MaxWorkerThreads())
    return fail("threads must be in [0, " + std::to_string(MaxWorkerThreads()) +
                "] (0 = all cores; at most 4 per hardware thread)");
  std::string h;
  if (!heuristics.IsValid(&h)) return fail("heuristics: " + h);
  return true;
}

}  // namespace posefilter
