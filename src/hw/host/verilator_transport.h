// src/hw/host/verilator_transport.h — the Transport (transport.h) of `--engine rtl`: the
// Verilated weighing accelerator (src/hw/rtl/weigh_accel.sv, M = 5, assertions on) clocked one
// cycle at a time, its AXI4-Lite port driven by the register accesses and its AXI4 master port
// served from a simulated DDR. The DDR model: a byte array at device addresses from kDdrBase;
// read bursts answered in order, the first beat `read_latency` clocks after the address, then
// one beat per clock; write responses `write_latency` clocks after a burst's last beat; with
// `random` on (seeded), every ready and valid it drives is low with probability `bubble` per
// clock and each burst's latency grows by a uniform 0 … latency; optionally one read beat or
// write response answers an error (fault_id, for tests). Built when Verilator is
// present (POSEFILTER_RTL_ENGINE); otherwise MakeVerilatorTransport throws that reason.
// Host code (not a kernel).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "hw/host/transport.h"

namespace posefilter::hw::host {

struct VerilatorTransportOptions {
  std::uint64_t ddr_bytes = 4u << 20;  // simulated DDR, bytes
  int read_latency = 64;               // clocks, AR accepted → first R beat (latency.h kAxiReadLatency)
  int write_latency = 64;              // clocks, last W beat → B (latency.h kAxiWriteLatency)
  bool random = false;                 // random bubbles and latencies
  double bubble = 0.3;                 // with random: probability a ready/valid is held low per clock
  std::uint64_t seed = 1;              // with random: the bubbles' and latencies' stream
  // An injected bus error (tests of STATUS and WeighDriver's check): the fault_index-th beat,
  // counted from 0 over the transport's life, of the reads with ID fault_id (0 … 5: the readers
  // IMG, WIN, FT, MODEL, PROB, CELL) comes back with RRESP = fault_resp, or with fault_id 6 (the
  // writer's AWID) the fault_index-th write response with BRESP = fault_resp. The data still
  // flows, as from a DDR controller that flags a beat. fault_id -1: none.
  int fault_id = -1;               // AXI ID, -1 … 6
  std::uint64_t fault_index = 0;   // beat (read) or response (write) of that ID, from 0
  int fault_resp = 2;              // AXI RESP: 1 EXOKAY, 2 SLVERR, 3 DECERR
};

// The device address of the simulated DDR's first byte (ZynqMP's high DDR, so the address
// registers' upper words are exercised).
constexpr std::uint64_t kDdrBase = 0x8'0000'0000ull;

// Whether this build has the Verilated accelerator; *why (may be null) says what is missing.
bool VerilatorTransportBuilt(std::string* why);
// A new simulated accelerator (out of reset). Throws Error when the build has none.
std::unique_ptr<Transport> MakeVerilatorTransport(const VerilatorTransportOptions& options);

}  // namespace posefilter::hw::host
