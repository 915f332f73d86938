// src/hw/host/verilator_transport_none.cc — VerilatorTransport in a build without the Verilated
// accelerator (POSEFILTER_RTL_ENGINE=OFF: Verilator not found, or the sanitizer presets).
#include "hw/host/verilator_transport.h"
#include "posefilter/error.h"

namespace posefilter::hw::host {

namespace {
const char* const kNoRtl =
    "rtl engine: this build has no Verilated RTL (configure with -DPOSEFILTER_RTL_ENGINE=ON after installing "
    "Verilator, Debian package verilator); use --engine hw";
}  // namespace

bool VerilatorTransportBuilt(std::string* why) {
  if (why) *why = kNoRtl;
  return false;
}

std::unique_ptr<Transport> MakeVerilatorTransport(const VerilatorTransportOptions&) { throw Error(kNoRtl); }

}  // namespace posefilter::hw::host
