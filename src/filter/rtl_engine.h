// src/filter/rtl_engine.h — the rtl engine's factory (rtl_engine.cc): the hw engine whose
// weighings run the FT distributor, vertex multiplier, depth distributor, raster cores and
// weight merger in the Verilated RTL (src/hw/rtl/weigh_accel.sv) through
// hw::host::WeighDriver. Throws Error when the build has no Verilated RTL and the simulation is
// the selected device, or when the selected board device is missing.
#pragma once

#include <memory>

#include "filter/engine.h"
#include "hw/host/transport.h"
#include "hw/host/verilator_transport.h"

namespace posefilter::filter {

// The environment variable that selects the rtl engine's device (docs/HARDWARE.md §16, §17):
//   unset, empty or "verilator"  the Verilated accelerator (M = 5) on the simulated bus of the
//                                cycle model's DDR latencies (latency.h), no bubbles
//   "uio[:NAME[:UDMABUF]]"       the accelerator on a board: UioTransport with the UIO device
//                                whose sysfs name is NAME (default weigh_accel) and the u-dma-buf
//                                UDMABUF (default udmabuf0); Linux builds only
inline constexpr const char* kRtlDeviceEnv = "POSEFILTER_RTL_DEVICE";

// Whether this build can run the rtl engine on the simulation (the hw engine and the Verilated
// RTL are built), else *why (may be null) says why not.
bool RtlEngineBuilt(std::string* why);

// The transport POSEFILTER_RTL_DEVICE selects. Throws Error, one line naming the variable and
// the device or sysfs path, when the value is not a device, the build lacks it or the device is
// missing.
std::unique_ptr<hw::host::Transport> RtlDeviceTransport();

// On the device POSEFILTER_RTL_DEVICE selects (by default the simulation).
std::unique_ptr<EngineRuns> MakeRtlEngine(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                          const FilterOptions& options);
// On a simulated bus of the given latencies, bubbles and faults (the tests' variants), whatever
// POSEFILTER_RTL_DEVICE says.
std::unique_ptr<EngineRuns> MakeRtlEngine(const PreparedScene& prep, const Mesh& mesh, const Prior& prior, int cls,
                                          const FilterOptions& options, const hw::host::VerilatorTransportOptions& topt);

}  // namespace posefilter::filter
