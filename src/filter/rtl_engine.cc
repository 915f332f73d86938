// src/filter/rtl_engine.cc — the `rtl` engine: the hw engine (hw_driver.cc) with the part of
// each weighing that the RTL covers — FT distributor, vertex multiplier, depth distributor, the
// M = 5 raster cores and the weight merger — done by the Verilated accelerator
// (src/hw/rtl/weigh_accel.sv) through the host driver (src/hw/host/weigh_driver.h) and the
// simulated bus (src/hw/host/verilator_transport.h), exactly as a board driver would drive it.
// The rest of the weigh region stays the C model: sample info (GatherSampleInfo) and the FT
// chain before the accelerator, SplitWeights, CollectStats (statistics, depth offsets) and the
// sorter after it; initialisation and update are the hw engine's. Weights, poses and histories
// are therefore bit-identical to `--engine hw` (tests/hw/rtl/rtl_engine_check.cc checks it).
//
// Cycles: each call's CYCLES register (AP_START to AP_DONE, DDR latency kAxiReadLatency per
// read burst and kAxiWriteLatency per write response) is summed in FilterStats::rtl_cycles, and
// the cycle model of the same part in rtl_model_cycles: the longer of the image copy and the
// model copy, plus ComposeRounds over the particles' raster-core work and the rounds' depth
// distributor cycles, or the merger's ρ copy and II if longer (the figure the pipeline's
// co-simulation compares with, docs/HARDWARE.md §12), from a C-model run of the same call.
//
// Transport: the environment variable POSEFILTER_RTL_DEVICE picks what the driver talks to
// (RtlDeviceTransport below): unset, empty or `verilator`, the Verilated accelerator on the
// simulated bus; `uio[:NAME[:UDMABUF]]`, the accelerator on a board through UioTransport
// (src/hw/host/uio_transport.h; Linux builds). Everything else is the same code.
#pragma GCC diagnostic ignored "-Wunknown-pragmas"
#pragma GCC diagnostic ignored "-Wunused-label"

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "filter/hw_weigh.h"
#include "filter/rtl_engine.h"
#include "hw/cycle_model.h"
#include "hw/host/verilator_transport.h"
#include "hw/host/weigh_driver.h"
#if defined(__linux__)
#include "hw/host/uio_transport.h"  // compiled into the library on Linux (cmake/rtl_engine.cmake)
#endif
#include "hw/latency.h"
#include "hw/top.h"
#include "posefilter/error.h"

namespace posefilter::filter {

namespace {

using namespace posefilter::hw;

class RtlWeigh final : public HwWeighStrategy {
 public:
  explicit RtlWeigh(std::unique_ptr<host::Transport> transport)
      : transport_(std::move(transport)), driver_(*transport_), b_(new Buffers) {}

  void Weigh(int /*cores: the accelerator's M is fixed*/, int n, const WeighConfig& cfg, const Sample samples[kMaxParticles],
             const Window cell_windows[kNumCells], const prob_t class_prob[kNumCells],
             const depth_t depth[kImageHeight * kImageWidth], const xyz_t vmem[3][kMaxVertices],
             const face_t tri_mem[kMaxFaces], weight_t sorted_w[kMaxParticles], particle_index_t sorted_idx[kMaxParticles],
             RasterCoreOutput stats[kMaxParticles], depth_off_t offsets[kMaxParticles], DepthDistributionCounts* dd_counts,
             CycleTrace* /*trace: the RTL's figure is its cycle counter*/) override {
    Buffers& b = *b_;
    // The scene's buffers (image, model, ρ) are the runner's fixed memories: copied once.
    if (!loaded_) {
      driver_.LoadScene(depth, cfg.img_width, cfg.img_height, vmem, tri_mem, cfg.num_faces, class_prob);
      loaded_ = true;
    }
    // C model before the accelerator: sample info and the FT chain.
    GatherSampleInfo(n, cfg, samples, cell_windows, b.windows, b.cells, b.samples_ft, nullptr);
    hls::stream<ft_t> ft_chain;
    FullTransformChain(n, b.samples_ft, cfg.cam, ft_chain, nullptr);
    for (int i = 0; i < n * kFtElements; ++i) b.ft[i] = ft_chain.read();
    // The accelerator.
    const host::WeighCallCounters c =
        driver_.Weigh(n, cfg.raster, cfg.weight, b.windows, b.ft, b.cells, b.merged, b.core_out);
    // C model after it: the merger's two output streams into SplitWeights, CollectStats, sorter.
    hls::stream<WeightOut> merged;
    hls::stream<RasterCoreOutput> merged_stats;
    hls::stream<weight_t> to_sorter;
    for (int p = 0; p < n; ++p) {
      merged.write(b.merged[p]);
      merged_stats.write(b.core_out[p]);
    }
    SplitWeights(n, merged, to_sorter, nullptr);
    CollectStats(n, merged_stats, stats, offsets, nullptr);
    SortWeights(to_sorter, n, sorted_w, sorted_idx, nullptr);
    if (dd_counts) {
      dd_counts->reads_shared = c.reads_shared;
      dd_counts->reads_unshared = c.reads_unshared;
    }
    ++calls_;
    cycles_ += std::int64_t(c.cycles);
    model_cycles_ += std::int64_t(ModelCycles(n, cfg, depth, vmem, tri_mem));
  }

  void EndRun(FilterStats* stats) override {
    stats->rtl_calls += calls_;
    stats->rtl_cycles += cycles_;
    stats->rtl_model_cycles += model_cycles_;
    calls_ = cycles_ = model_cycles_ = 0;
  }

 private:
  struct Buffers {
    Window windows[kMaxParticles];
    cell_index_t cells[kMaxParticles];
    Sample samples_ft[kMaxParticles];
    ft_t ft[kMaxParticles * kFtElements];
    WeightOut merged[kMaxParticles];
    RasterCoreOutput core_out[kMaxParticles];
    depth_t depth_mem[kImageHeight * kImageWidth];  // DistributeDepth's on-chip copy (model run)
    RasterCoreMemory core_mem;
    CycleTrace trace;
  };

  // The cycle model of the accelerator's part of this call (see the file comment), at the
  // accelerator's M, from the C model's processes on the same inputs.
  std::uint64_t ModelCycles(int n, const WeighConfig& cfg, const depth_t* depth, const xyz_t vmem[3][kMaxVertices],
                            const face_t* tri) {
    Buffers& b = *b_;
    const int M = driver_.cores();
    hls::stream<ft_t> ft_in, ft_core[kMaxRasterCores];
    hls::stream<Vertex> vert_core[kMaxRasterCores];
    hls::stream<Window> info_core[kMaxRasterCores];
    hls::stream<depth_t> depth_core[kMaxRasterCores];
    hls::stream<RasterCoreOutput> out_core[kMaxRasterCores];
    for (int i = 0; i < n * kFtElements; ++i) ft_in.write(b.ft[i]);
    DistributeFT(n, M, ft_in, ft_core, nullptr);
    VertexMultiplier(n, M, cfg.num_faces, vmem, tri, vert_core, nullptr);
    DepthDistributionCounts counts;
    DistributeDepth(n, M, b.windows, depth, cfg.img_width, cfg.img_height, b.depth_mem, info_core, depth_core, &counts,
                    nullptr);
    std::vector<ParticleWork> work(static_cast<std::size_t>(n));
    for (int p = 0; p < n; ++p) {  // one particle per call: its loop records give its work
      const int core = p % M;
      b.trace.Clear();
      RasterCore(1, cfg.num_faces, cfg.raster, info_core[core], depth_core[core], ft_core[core], vert_core[core],
                 out_core[core], b.core_mem, &b.trace);
      work[std::size_t(p)] = ParticleWorkFromTrace(b.trace);
      out_core[core].read();
    }
    std::vector<std::uint64_t> round_fill;
    for (int first = 0; first < n; first += M) {
      const int active = std::min(M, n - first);
      hls::stream<Window> ri[kMaxRasterCores];
      hls::stream<depth_t> rd[kMaxRasterCores];
      DepthDistributionCounts rc;
      b.trace.Clear();
      DistributeDepth(active, M, b.windows + first, depth, cfg.img_width, cfg.img_height, b.depth_mem, ri, rd, &rc,
                      &b.trace);
      for (int c = 0; c < active; ++c) {
        ri[c].read();
        while (!rd[c].empty()) rd[c].read();
      }
      round_fill.push_back(LoopTotal(b.trace, "depth_distributor", "DD_SETUP") +
                           LoopTotal(b.trace, "depth_distributor", "DD_SEGMENTS") +
                           LoopTotal(b.trace, "depth_distributor", "DD_PIXELS"));
    }
    const std::uint64_t copies = std::max<std::uint64_t>(std::uint64_t(cfg.img_width) * std::uint64_t(cfg.img_height),
                                                         std::uint64_t(kMaxVertices) + std::uint64_t(cfg.num_faces));
    return std::max<std::uint64_t>(copies + ComposeRounds(work, round_fill, M),
                                   std::uint64_t(kNumCells) + std::uint64_t(kWmParticlesII) * std::uint64_t(n));
  }

  std::unique_ptr<host::Transport> transport_;
  host::WeighDriver driver_;
  std::unique_ptr<Buffers> b_;
  bool loaded_ = false;
  std::int64_t calls_ = 0, cycles_ = 0, model_cycles_ = 0;
};

// The simulated accelerator, or the reason this build has none (before any set-up).
std::unique_ptr<host::Transport> SimulatedTransport(const host::VerilatorTransportOptions& topt) {
  if (std::string why; !host::VerilatorTransportBuilt(&why)) throw Error(why);
  return host::MakeVerilatorTransport(topt);
}

}  // namespace

bool RtlEngineBuilt(std::string* why) { return hw::host::VerilatorTransportBuilt(why); }

std::unique_ptr<hw::host::Transport> RtlDeviceTransport() {
  const char* env = std::getenv(kRtlDeviceEnv);
  const std::string dev = env != nullptr ? env : "";
  if (dev.empty() || dev == "verilator") {
    hw::host::VerilatorTransportOptions topt;
    topt.read_latency = hw::kAxiReadLatency;
    topt.write_latency = hw::kAxiWriteLatency;
    return SimulatedTransport(topt);
  }
  const std::string where = std::string("rtl engine: ") + kRtlDeviceEnv + "=" + dev + ": ";
  if (dev != "uio" && dev.rfind("uio:", 0) != 0)
    throw Error(where + "not a device: give verilator (the simulation, the default) or uio[:NAME[:UDMABUF]] (a board)");
#if defined(__linux__)
  hw::host::UioTransportOptions u;
  if (dev.size() > 4) {  // uio:NAME[:UDMABUF]
    const std::string rest = dev.substr(4);
    const std::size_t colon = rest.find(':');
    u.uio_name = rest.substr(0, colon);
    if (colon != std::string::npos) u.udmabuf = rest.substr(colon + 1);
  }
  try {
    return hw::host::MakeUioTransport(u);
  } catch (const Error& e) {
    throw Error(where + e.what());
  }
#else
  throw Error(where + "this build has no UIO transport (Linux only)");
#endif
}

std::unique_ptr<HwWeighStrategy> MakeRtlWeigh(const hw::host::VerilatorTransportOptions& topt) {
  return std::make_unique<RtlWeigh>(SimulatedTransport(topt));
}

std::unique_ptr<EngineRuns> MakeRtlEngine(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                          const FilterOptions& options, const hw::host::VerilatorTransportOptions& topt) {
  return MakeHwEngineWith(prep, mesh, prior, cls, options, std::make_unique<RtlWeigh>(SimulatedTransport(topt)));
}

std::unique_ptr<EngineRuns> MakeRtlEngine(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                          const FilterOptions& options) {
  return MakeHwEngineWith(prep, mesh, prior, cls, options, std::make_unique<RtlWeigh>(RtlDeviceTransport()));
}

}  // namespace posefilter::filter
