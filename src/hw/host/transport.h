// src/hw/host/transport.h — what a host driver of the weighing accelerator (weigh_accel.sv;
// docs/HARDWARE.md §16) needs from the bus, and nothing else: 32-bit register access on the
// AXI4-Lite port, device memory (DDR the accelerator's AXI4 master reads and writes) and a wait
// for the interrupt. WeighDriver (weigh_driver.h) drives a weighing through it; a board backend
// (UIO/XRT: mmap'ed registers, a CMA buffer, the UIO interrupt fd) and VerilatorTransport
// (verilator_transport.h: the Verilated RTL, clock by clock) implement it. Host code (not a
// kernel).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace posefilter::hw::host {

class Transport {
 public:
  virtual ~Transport() = default;
  // Registers: offset in bytes on s_axi_ctrl (a multiple of 4; weigh_regs.h names them).
  virtual std::uint32_t ReadReg(std::uint32_t offset) = 0;
  virtual void WriteReg(std::uint32_t offset, std::uint32_t value) = 0;
  // Device memory: `bytes` bytes at a device (bus) address aligned to `align` bytes (a power of
  // two); the block lives as long as the transport. Throws Error when there is no room.
  virtual std::uint64_t Alloc(std::size_t bytes, std::size_t align) = 0;
  virtual void CopyToDevice(std::uint64_t addr, const void* src, std::size_t bytes) = 0;
  virtual void CopyFromDevice(std::uint64_t addr, void* dst, std::size_t bytes) = 0;
  // Waits until the interrupt line is high or `timeout_us` microseconds (a board) / clock
  // cycles at 200 MHz equivalent (a simulation: 200 cycles per µs) have passed; true when it
  // is high.
  virtual bool WaitInterrupt(std::uint64_t timeout_us) = 0;
  // What is behind the transport, for messages ("verilator weigh_accel M=5", "uio0").
  virtual std::string Name() const = 0;
};

}  // namespace posefilter::hw::host
