// src/hw/host/weigh_driver.h — the host driver of the weighing accelerator (weigh_accel.sv,
// docs/HARDWARE.md §16): one weighing exactly as a board driver does it, over a Transport
// (transport.h): the DDR buffers allocated once, the scene's buffers (depth image, model, class
// probabilities) copied when the scene is loaded, and per call the particles' buffers (windows,
// FT matrices, cells) copied, the registers written (weigh_regs.h, generated from
// src/hw/rtl/weigh_regs.json), AP_START set, the interrupt waited for, ISR and CTRL
// acknowledged, STATUS checked for bus errors, the counters and the output records read back. Host code (not a kernel).
#pragma once

#include <cstdint>
#include <string>

#include "hw/host/transport.h"
#include "hw/top.h"

namespace posefilter::hw::host {

// What one call reports besides its outputs.
struct WeighCallCounters {
  std::uint64_t cycles = 0;  // CYCLES: clocks from AP_START to AP_DONE
  std::uint32_t reads_shared = 0, reads_unshared = 0;  // the depth distributor's (DD_READS_*)
};

class WeighDriver {
 public:
  // Checks the ID register, reads CORES and clears STATUS's sticky error bits; allocates every
  // buffer at its largest size.
  // Throws Error naming the transport when the device does not answer as weigh_accel.
  explicit WeighDriver(Transport& transport);

  int cores() const { return cores_; }

  // The buffers that stay fixed while a scene is weighed: the depth image (width·height
  // pixels of `depth`, row-major), the model (vmem, num_faces faces of tri) and the class
  // probabilities (kNumCells).
  void LoadScene(const depth_t* depth, int img_width, int img_height, const xyz_t vmem[3][kMaxVertices],
                 const face_t* tri, int num_faces, const prob_t* class_prob);

  // One call of n particles (1 … kMaxParticles): per particle its window, its 12 FT elements
  // (ft[12p …]) and its cell; raster and weight parameters as WeighConfig holds them. Gives
  // the merger's words in particle order: weights[p] (weight, index) and stats[p] (the core's
  // counters). Throws Error when the accelerator does not finish within `timeout_us`, or when
  // STATUS shows a bus error of the call (RD_ERR/WR_ERR, a non-OKAY RRESP or BRESP on
  // m_axi_gmem: the message names the bit, the buffer and the response; STATUS is cleared first,
  // so the next call can run).
  WeighCallCounters Weigh(int n, const RasterParams& raster, const WeightParams& weight, const Window* windows,
                          const ft_t* ft, const cell_index_t* cells, WeightOut* weights, RasterCoreOutput* stats,
                          std::uint64_t timeout_us = 60'000'000);

 private:
  Transport& t_;
  int cores_ = 0;
  int img_width_ = 0, img_height_ = 0, num_faces_ = 0;
  bool loaded_ = false;
  std::uint64_t img_ = 0, win_ = 0, ft_ = 0, model_ = 0, prob_ = 0, cell_ = 0, out_ = 0;  // device addresses
};

}  // namespace posefilter::hw::host
