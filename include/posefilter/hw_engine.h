// posefilter/hw_engine.h — the `hw` engine: a bit-accurate C simulation of the thesis's FPGA
// architecture (thesis Chapter 7; docs/HARDWARE.md), and its cycle model.
//
// EstimatePose(…) with FilterOptions::engine == "hw" runs it. Its host driver
// (src/filter/hw_driver.cc) converts the inputs to the hardware's fixed-point memories (depth
// clipped to 4 m in ufixed<12,2>, the model reduced to ≤ 1024 vertices / ≤ 2048 faces, camera,
// per-cell windows, heuristic volumes and class probabilities), runs the top functions of
// src/hw/top.h for the configured iterations and restarts, and returns an EstimateResult like
// the float engines. docs/HARDWARE.md describes the modules, the host/hardware split and every
// deviation from the thesis.
//
// Differences from the float engines (all documented in docs/HARDWARE.md; the option table,
// posefilter/option_table.h, lists the options it does not read): at most kHwMaxParticles
// particles, windows of at most kHwMaxWindowPx, a near plane of at least kHwMinNearM
// (FilterOptions::IsValid checks these when engine == "hw"), a 640×480-or-smaller image and the
// thesis's 6300-cell pyramid (Error otherwise). Modelled in fixed point: annealing,
// occlusion-aware N_raster, the edge penalty, grown windows, region and rotation caps, the
// align-depth move and a σ floor of one LSB. Not modelled (float-only): init_oversample, the
// coarse annealing grid, fine sets and the ICP move; the quarter-turn move only about the
// object's x axis. The final polish (polish.steps > 0, the default) runs on the host after the
// hardware runs, in float with the cpu engine's weighing, from each run's best particle; the
// result's weight is then that float weight. polish.steps = 0 returns the hardware's own answer
// and weight.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/filter.h"

namespace posefilter {

// The hardware's limits on the options (src/hw/hw_types.h holds the same numbers).
inline constexpr int kHwMaxParticles = 510;
inline constexpr int kHwMaxWindowPx = 200;
inline constexpr double kHwMinNearM = 1.0 / 64;  // the 1/W format of the transform

// ---- Cycle model report (posefilter hw-report) ----

struct HwProfileOptions {
  std::vector<int> cores = {1, 5, 10};  // raster-core counts M to model, each in [1, 10]
  double clock_mhz = 200;               // clock of the thesis's design, MHz (> 0)
  int profile_every = 1;                // model every k-th iteration (≥ 1; the first always)
  // Raw stage-1 pyramid of the scene (raw layout of prior.h), optional: when non-empty the hw
  // post-process kernel runs on it once and its cycles are reported (part of the first
  // iteration's latency, as in the thesis).
  std::vector<float> raw_pyramid;
  bool IsValid(std::string* why) const;
};

// One module's cycles per iteration: Σ over its loop records of trips × II + depth (its own
// sequential latency, before dataflow overlap), averaged over the modelled iterations.
struct HwModuleCycles {
  std::string module;
  double cycles = 0;
  // Of `cycles`, those spent waiting on DDR: the m_axi burst latency (64 clocks per burst,
  // src/hw/latency.h kAxiReadLatency / kAxiWriteLatency) of the module's reads and writes.
  double memory_cycles = 0;
};

// The model of one core count M, averaged over the modelled iterations.
struct HwCoreModel {
  int cores = 0;
  std::vector<HwModuleCycles> modules;  // weigh + update modules (raster_core: busiest core)
  double depth_distribution_cycles = 0; // Σ over rounds of the depth distributor's fill (Table 7.2 [HARDWARE.md])
  double weigh_cycles = 0;              // the weigh/sort dataflow region (round model)
  double update_cycles = 0;             // resampling + diffusion
  double iteration_cycles = 0;          // weigh + update
  double first_iteration_cycles = 0;    // post-process (if run) + init + the first iteration
  double average_iteration_cycles = 0;  // mean over all iterations, the first included
  double depth_reads_shared = 0;        // depth pixels read per iteration, with window sharing
  double depth_reads_unshared = 0;      // … without (Σ window areas)
  double memory_cycles = 0;             // Σ over modules of memory_cycles (weigh + update)
};

struct HwProfile {
  int num_particles = 0, num_vertices = 0, num_faces = 0, iterations = 0, modelled_iterations = 0;
  double clock_mhz = 200;
  double postprocess_cycles = 0;        // 0 when no raw pyramid was given
  double init_cycles = 0;               // initialisation dataflow region
  std::vector<HwModuleCycles> init_modules;
  double init_reads = 0, init_reads_linear = 0;          // per draw, with / without tracker
  double resample_reads = 0, resample_reads_linear = 0;  // per draw
  double faces_total = 0, faces_front = 0;               // summed over all weighings
  double mean_window_area = 0;          // pixels, over all weighed particles
  std::vector<HwCoreModel> models;      // one per HwProfileOptions::cores
  EstimateResult result;                // the run itself (one restart, options as given)
  double CyclesToMs(double cycles) const { return cycles / (clock_mhz * 1e3); }
};

// Runs the hw engine once (restarts forced to 1) and models its cycles (docs/HARDWARE.md,
// "Cycle model"). Throws Error like EstimatePose with engine "hw", or for invalid profile options.
HwProfile ProfileHw(const SceneInput& scene, const Mesh& mesh, const Prior& prior, int cls,
                    const FilterOptions& options, const HwProfileOptions& profile);

}  // namespace posefilter
