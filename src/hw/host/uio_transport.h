// src/hw/host/uio_transport.h — the Transport (transport.h) of a board: the weighing accelerator
// (weigh_accel.sv) in the programmable logic of a Zynq UltraScale+ (scripts/board/zcu102_bd.tcl),
// driven from Linux user space. WeighDriver (weigh_driver.h), the register map (weigh_regs.h)
// and the buffer packer (weigh_pack.h) are the ones `--engine rtl` uses over VerilatorTransport;
// only this class differs.
//
//   registers  the UIO device whose sysfs name is `uio_name` (a device-tree node `weigh_accel`,
//              compatible "generic-uio", bound to uio_pdrv_genirq): its map 0 (/dev/uioN at mmap
//              offset 0, size from /sys/class/uio/uioN/maps/map0/size, ≥ 2^kAddrBits bytes)
//              read and written as 32-bit words.
//   memory     one physically contiguous u-dma-buf (/dev/<udmabuf>, its bus address from
//              /sys/class/u-dma-buf/<udmabuf>/phys_addr and its size in bytes from .../size),
//              opened with O_SYNC (the CPU's cache is off for it, so the accelerator's HP0 port,
//              which does not snoop, and the CPU see the same bytes without cache maintenance).
//              Alloc hands out aligned blocks of it (never freed while the transport lives); the
//              device address of a block is phys_addr + its offset (HP0 sees physical addresses:
//              the SMMU is bypassed, its default), and must lie in one of the DDR windows the
//              block design gives m_axi_gmem (kGmemWindows).
//   interrupt  the UIO protocol: write() of the 32-bit value 1 unmasks the interrupt
//              (uio_pdrv_genirq masks it in its handler: the line is level, high until the driver
//              clears ISR), poll() for POLLIN up to the timeout, read() of the 32-bit event count.
//
// Every failure throws Error naming the device or sysfs path and the reason (errno's text).
// Not tested on a board: the unit test (tests/hw/board/uio_transport_test.cc) runs it over a fake
// /dev and /sys tree (`root`): regular files stand in for the register window and the DMA buffer
// (mmap of a file), and a pseudo-terminal for the interrupt node (irq_path). Host code (not a
// kernel); Linux only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "hw/host/transport.h"

namespace posefilter::hw::host {

struct UioTransportOptions {
  // Prefix of every /dev and /sys path ("/" on a board; a test's fake tree otherwise).
  std::string root = "/";
  // The UIO device: the one whose /sys/class/uio/uioN/name is this (the device-tree node name).
  std::string uio_name = "weigh_accel";
  // The u-dma-buf device name (/dev/<name>, /sys/class/u-dma-buf/<name>/).
  std::string udmabuf = "udmabuf0";
  // The bus address map 0 must have (its sysfs maps/map0/addr): s_axi_ctrl's offset in the
  // block design, so that a stale overlay or another bitstream is refused; 0: not checked.
  std::uint64_t register_base = 0xA000'0000;  // scripts/board/zcu102_bd.tcl ctrl_offset
  // The node whose write()/poll()/read() carry the interrupt, as an absolute path; empty: the
  // register UIO node itself (/dev/uioN, the board's case: one node with reg and interrupts).
  std::string irq_path;
};

// A DDR window of m_axi_gmem's address space: bus addresses [base, base + bytes). They are
// scripts/board/zcu102_bd.tcl's assign_bd_address of HP0_DDR_LOW and HP0_DDR_HIGH
// (board_package_test.py checks that they agree).
struct GmemWindow {
  std::uint64_t base, bytes;
};
inline constexpr GmemWindow kGmemWindows[] = {
    {0x0000'0000ull, 0x8000'0000ull},       // HP0_DDR_LOW: 2 GiB
    {0x8'0000'0000ull, 0x8'0000'0000ull},   // HP0_DDR_HIGH: 32 GiB window (2 GiB populated on a ZCU102)
};

class UioTransport final : public Transport {
 public:
  // Finds and maps the devices. Throws Error naming the path that is missing, unreadable, too
  // small or outside the DDR windows.
  explicit UioTransport(const UioTransportOptions& options);
  ~UioTransport() override;
  UioTransport(const UioTransport&) = delete;
  UioTransport& operator=(const UioTransport&) = delete;

  // Registers: offset a multiple of 4 below 2^kAddrBits (256 bytes; the window above aliases).
  std::uint32_t ReadReg(std::uint32_t offset) override;
  void WriteReg(std::uint32_t offset, std::uint32_t value) override;
  // Device memory in the u-dma-buf; addresses are bus (physical) addresses.
  std::uint64_t Alloc(std::size_t bytes, std::size_t align) override;
  void CopyToDevice(std::uint64_t addr, const void* src, std::size_t bytes) override;
  void CopyFromDevice(std::uint64_t addr, void* dst, std::size_t bytes) override;
  // Unmasks, then waits up to timeout_us µs for an interrupt event; true when one came.
  bool WaitInterrupt(std::uint64_t timeout_us) override;
  // "uio0 (weigh_accel) + udmabuf0".
  std::string Name() const override;

  // What was found (for messages and tests).
  const std::string& uio_device() const { return uio_dev_; }  // e.g. /dev/uio0 under root
  std::size_t register_window_bytes() const { return reg_bytes_; }
  std::uint64_t dma_phys() const { return dma_phys_; }
  std::size_t dma_bytes() const { return dma_bytes_; }
  std::uint32_t interrupts_seen() const { return irq_count_; }  // the last event count read

 private:
  std::uint8_t* Dma(std::uint64_t addr, std::size_t bytes, const char* what);
  void CheckReg(std::uint32_t offset, const char* what) const;
  void Release();  // unmaps and closes what the constructor opened

  std::string root_, uio_name_, uio_dev_, dma_dev_, irq_dev_;
  int uio_fd_ = -1, dma_fd_ = -1, irq_fd_ = -1;
  void* reg_map_ = nullptr;                 // the mapping (page-rounded, reg_map_bytes_ bytes)
  std::size_t reg_map_bytes_ = 0;
  volatile std::uint32_t* regs_ = nullptr;  // map 0's first register (at the map's offset)
  std::size_t reg_bytes_ = 0;               // map 0's size, bytes
  std::uint8_t* dma_ = nullptr;
  std::uint64_t dma_phys_ = 0;
  std::size_t dma_bytes_ = 0, next_ = 0;  // next_: first free byte of the u-dma-buf (offset)
  std::uint32_t irq_count_ = 0;
};

std::unique_ptr<Transport> MakeUioTransport(const UioTransportOptions& options);

}  // namespace posefilter::hw::host
