// src/hw/cycle_model.cc — the hw engine's cycle model (see cycle_model.h, docs/HARDWARE.md).
#include "hw/cycle_model.h"

#include <algorithm>

#include "hw/latency.h"

namespace posefilter::hw {

std::uint64_t LoopCycles(const LoopRecord& r) {
  if (r.trips == 0) return 0;
  return r.trips * r.ii + r.depth;
}

std::vector<std::pair<std::string, std::uint64_t>> ModuleCycles(const CycleTrace& trace) {
  std::vector<std::pair<std::string, std::uint64_t>> out;
  for (int i = 0; i < trace.count; ++i) {
    const LoopRecord& r = trace.records[i];
    auto it = std::find_if(out.begin(), out.end(), [&](const auto& m) { return m.first == r.module; });
    if (it == out.end()) {
      out.emplace_back(r.module, 0);
      it = out.end() - 1;
    }
    it->second += LoopCycles(r);
  }
  return out;
}

std::uint64_t ModuleTotal(const CycleTrace& trace, const std::string& module) {
  std::uint64_t s = 0;
  for (int i = 0; i < trace.count; ++i)
    if (module.empty() || module == trace.records[i].module) s += LoopCycles(trace.records[i]);
  return s;
}

std::uint64_t ModuleDepth(const CycleTrace& trace, const std::string& module) {
  std::uint64_t s = 0;
  for (int i = 0; i < trace.count; ++i) {
    const LoopRecord& r = trace.records[i];
    if ((module.empty() || module == r.module) && r.trips > 0) s += r.depth;
  }
  return s;
}

std::uint64_t ModuleMemory(const CycleTrace& trace, const std::string& module) {
  std::uint64_t s = 0;
  for (int i = 0; i < trace.count; ++i) {
    const LoopRecord& r = trace.records[i];
    if ((module.empty() || module == r.module) && r.trips > 0) s += r.memory;
  }
  return s;
}

std::uint64_t LoopTotal(const CycleTrace& trace, const std::string& module, const std::string& loop) {
  std::uint64_t s = 0;
  for (int i = 0; i < trace.count; ++i)
    if (module == trace.records[i].module && loop == trace.records[i].loop) s += LoopCycles(trace.records[i]);
  return s;
}

std::uint64_t LoopTrips(const CycleTrace& trace, const std::string& module, const std::string& loop) {
  std::uint64_t s = 0;
  for (int i = 0; i < trace.count; ++i)
    if (module == trace.records[i].module && loop == trace.records[i].loop) s += trace.records[i].trips;
  return s;
}

std::uint64_t DataflowLatency(const CycleTrace& trace) {
  std::uint64_t slowest = 0, fill = 0;
  for (const auto& [module, cycles] : ModuleCycles(trace)) {
    slowest = std::max(slowest, cycles);
    fill += ModuleDepth(trace, module);
  }
  return slowest + fill;
}

std::uint64_t ParticleWork::Faces() const {
  if (pixel == 0) return vertex;
  return std::max<std::uint64_t>(vertex, pixel + kRcVertexDepth);
}

std::uint64_t ParticleWork::Total() const { return kRcWindowReadCycles + fill + Compute() + kRcOutputCycles; }

ParticleWork ParticleWorkFromTrace(const CycleTrace& trace) {
  ParticleWork w;
  for (int i = 0; i < trace.count; ++i) {
    const LoopRecord& r = trace.records[i];
    if (std::string(r.module) != "raster_core") continue;
    const std::string loop = r.loop;
    const std::uint64_t c = LoopCycles(r);
    if (loop == "RC_DEPTH_FILL") w.fill += c;
    else if (loop == "RC_FT_READ") w.ft += c;
    else if (loop == "RC_VERTICES") w.vertex += c;
    else if (loop == "RC_RASTER") w.pixel += c;
    else if (loop == "RC_ZPASS") w.zpass += c;
  }
  return w;
}

std::uint64_t ComposeRounds(const std::vector<ParticleWork>& particles, const std::vector<std::uint64_t>& round_fill,
                            int cores) {
  if (cores < 1) cores = 1;
  std::uint64_t total = 0;
  const int n = int(particles.size());
  for (int first = 0, r = 0; first < n; first += cores, ++r) {
    std::uint64_t fill = r < int(round_fill.size()) ? round_fill[r] : 0, compute = 0;
    for (int p = first; p < std::min(n, first + cores); ++p) {
      fill = std::max(fill, particles[p].fill);
      compute = std::max(compute, particles[p].Compute());
    }
    total += fill + compute;
  }
  return total;
}

}  // namespace posefilter::hw
