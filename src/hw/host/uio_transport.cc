// src/hw/host/uio_transport.cc — UioTransport (uio_transport.h): the weighing accelerator on a
// board through Linux UIO (registers, interrupt) and u-dma-buf (DDR buffers).
#include "hw/host/uio_transport.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "hw/host/weigh_regs.h"
#include "posefilter/error.h"

namespace posefilter::hw::host {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kRegisterBytes = std::size_t(1) << regs::kAddrBits;  // 256: the register map
constexpr std::size_t kMaxWindowBytes = std::size_t(1) << 30;             // sanity bound of a UIO map

std::string Hex(std::uint64_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << v;
  return s.str();
}

std::string Errno() { return std::strerror(errno); }

[[noreturn]] void Fail(const std::string& what) { throw Error("uio transport: " + what); }

// One line of a sysfs attribute, without its trailing newline.
std::string ReadAttr(const fs::path& path) {
  std::ifstream in(path);
  if (!in) Fail(path.string() + ": cannot read (" + Errno() + ")");
  std::string line;
  std::getline(in, line);
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

// A number in a sysfs attribute: decimal, or hexadecimal with 0x (UIO's map size and address,
// u-dma-buf's phys_addr).
std::uint64_t ReadNumber(const fs::path& path) {
  const std::string text = ReadAttr(path);
  if (text.empty()) Fail(path.string() + ": empty, expected a number");
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 0);
  if (errno != 0 || end == text.c_str() || *end != '\0' || text[0] == '-')
    Fail(path.string() + ": '" + text + "' is not a number");
  return v;
}

// Opens `path` and maps `bytes` of it from byte `offset` (read/write, shared). A regular file
// (a test's stand-in) must hold the whole mapping: touching a page past its end would be SIGBUS.
void* MapDevice(const std::string& path, int flags, std::size_t bytes, off_t offset, int* fd_out) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) Fail(path + ": cannot open (" + Errno() + ")");
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const std::string e = Errno();
    ::close(fd);
    Fail(path + ": fstat failed (" + e + ")");
  }
  if (S_ISREG(st.st_mode) && std::uint64_t(st.st_size) < std::uint64_t(offset) + bytes) {
    ::close(fd);
    Fail(path + ": a regular file of " + std::to_string(st.st_size) + " bytes, smaller than the " +
         std::to_string(bytes) + "-byte mapping");
  }
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  if (p == MAP_FAILED) {
    const std::string e = Errno();
    ::close(fd);
    Fail(path + ": mmap of " + std::to_string(bytes) + " bytes failed (" + e + ")");
  }
  *fd_out = fd;
  return p;
}

// Copies that are safe on any memory type the mapping may have (Device memory faults on
// unaligned accesses, which memcpy may make): bytes up to an 8-byte boundary of the device side,
// then aligned 64-bit words, then the remaining bytes.
void CopyTo(volatile std::uint8_t* dst, const std::uint8_t* src, std::size_t n) {
  while (n > 0 && (reinterpret_cast<std::uintptr_t>(dst) & 7u) != 0) {
    *dst++ = *src++;
    --n;
  }
  for (; n >= 8; n -= 8, dst += 8, src += 8) {
    std::uint64_t w;
    std::memcpy(&w, src, 8);
    *reinterpret_cast<volatile std::uint64_t*>(dst) = w;
  }
  while (n-- > 0) *dst++ = *src++;
}
void CopyFrom(std::uint8_t* dst, const volatile std::uint8_t* src, std::size_t n) {
  while (n > 0 && (reinterpret_cast<std::uintptr_t>(src) & 7u) != 0) {
    *dst++ = *src++;
    --n;
  }
  for (; n >= 8; n -= 8, dst += 8, src += 8) {
    const std::uint64_t w = *reinterpret_cast<const volatile std::uint64_t*>(src);
    std::memcpy(dst, &w, 8);
  }
  while (n-- > 0) *dst++ = *src++;
}

}  // namespace

UioTransport::UioTransport(const UioTransportOptions& o) : root_(o.root), uio_name_(o.uio_name) {
  if (root_.empty()) Fail("the root folder is empty (\"/\" on a board)");
  if (uio_name_.empty()) Fail("no UIO device name given");
  if (o.udmabuf.empty() || o.udmabuf.find('/') != std::string::npos)
    Fail("u-dma-buf name '" + o.udmabuf + "' is not a device name (e.g. udmabuf0)");
  const fs::path root(root_);
  try {
    // The UIO device named uio_name.
    const fs::path uio_class = root / "sys/class/uio";
    std::error_code ec;
    if (!fs::is_directory(uio_class, ec))
      Fail(uio_class.string() + ": no such folder (no UIO devices: is the uio_pdrv_genirq module loaded?)");
    std::vector<std::string> found, names;
    for (const auto& entry : fs::directory_iterator(uio_class, ec)) {
      const std::string n = entry.path().filename().string();
      if (n.rfind("uio", 0) != 0) continue;
      const fs::path name_file = entry.path() / "name";
      std::error_code unreadable;
      if (!fs::exists(name_file, unreadable)) continue;  // not a UIO device folder
      const std::string name = ReadAttr(name_file);
      names.push_back(n + " (" + name + ")");
      if (name == uio_name_) found.push_back(n);
    }
    if (ec) Fail(uio_class.string() + ": cannot list (" + ec.message() + ")");
    if (found.empty()) {
      std::string have;
      for (const auto& n : names) have += (have.empty() ? "" : ", ") + n;
      Fail("no UIO device named '" + uio_name_ + "' in " + uio_class.string() + " (found: " +
           (have.empty() ? "none" : have) +
           "); load the device-tree overlay with the weigh_accel node, compatible \"generic-uio\", and boot with "
           "uio_pdrv_genirq.of_id=generic-uio");
    }
    if (found.size() > 1) Fail("two UIO devices are named '" + uio_name_ + "' in " + uio_class.string() + ": " + found[0] + ", " + found[1]);
    const fs::path map0 = uio_class / found[0] / "maps/map0";
    const std::uint64_t map_bytes = ReadNumber(map0 / "size");
    std::error_code absent;
    const std::uint64_t map_offset = fs::exists(map0 / "offset", absent) ? ReadNumber(map0 / "offset") : 0;
    if (map_bytes < kRegisterBytes || map_bytes > kMaxWindowBytes)
      Fail((map0 / "size").string() + ": " + Hex(map_bytes) + " bytes; the register map needs " +
           std::to_string(kRegisterBytes) + " (weigh_regs.json addr_bits " + std::to_string(regs::kAddrBits) + ")");
    if (map_offset + kRegisterBytes > map_bytes)
      Fail((map0 / "offset").string() + ": the registers at offset " + Hex(map_offset) + " do not fit the " +
           Hex(map_bytes) + "-byte map");
    if (o.register_base != 0 && fs::exists(map0 / "addr", absent)) {
      const std::uint64_t base = ReadNumber(map0 / "addr");
      if (base != o.register_base)
        Fail((map0 / "addr").string() + ": map 0 is at " + Hex(base) + ", the block design puts s_axi_ctrl at " +
             Hex(o.register_base) + " (another bitstream or a stale device-tree overlay?)");
    }
    uio_dev_ = (root / "dev" / found[0]).string();
    // Map N of a UIO device is at mmap offset N · page size; map 0 at 0. The window mapped is
    // the page-rounded map (mmap's length may exceed a map smaller than a page).
    const std::size_t page = std::size_t(::sysconf(_SC_PAGESIZE));
    reg_bytes_ = std::size_t(map_bytes);
    const std::size_t mapped = (std::size_t(map_offset) + reg_bytes_ + page - 1) / page * page;
    void* r = MapDevice(uio_dev_, O_RDWR | O_SYNC, mapped, 0, &uio_fd_);
    regs_ = reinterpret_cast<volatile std::uint32_t*>(static_cast<std::uint8_t*>(r) + map_offset);
    reg_map_bytes_ = mapped;
    reg_map_ = r;

    // The u-dma-buf.
    const fs::path dma_class = root / "sys/class/u-dma-buf" / o.udmabuf;
    if (!fs::is_directory(dma_class, ec))
      Fail(dma_class.string() + ": no such folder (is the u-dma-buf module loaded with a " + o.udmabuf +
           " node in the device tree?)");
    dma_phys_ = ReadNumber(dma_class / "phys_addr");
    const std::uint64_t dma_size = ReadNumber(dma_class / "size");
    if (dma_size == 0) Fail((dma_class / "size").string() + ": 0 bytes");
    bool inside = false;
    for (const GmemWindow& w : kGmemWindows)
      inside = inside || (dma_phys_ >= w.base && dma_size <= w.bytes && dma_phys_ - w.base <= w.bytes - dma_size);
    if (!inside)
      Fail((dma_class / "phys_addr").string() + ": " + Hex(dma_phys_) + " + " + Hex(dma_size) +
           " bytes lies outside m_axi_gmem's DDR windows (" + Hex(kGmemWindows[0].base) + " + " +
           Hex(kGmemWindows[0].bytes) + ", " + Hex(kGmemWindows[1].base) + " + " + Hex(kGmemWindows[1].bytes) + ")");
    dma_bytes_ = std::size_t(dma_size);
    dma_dev_ = (root / "dev" / o.udmabuf).string();
    dma_ = static_cast<std::uint8_t*>(MapDevice(dma_dev_, O_RDWR | O_SYNC, dma_bytes_, 0, &dma_fd_));

    // The interrupt node: the register UIO node itself unless another is named.
    if (o.irq_path.empty()) {
      irq_dev_ = uio_dev_;
      irq_fd_ = uio_fd_;
    } else {
      irq_dev_ = o.irq_path;
      irq_fd_ = ::open(irq_dev_.c_str(), O_RDWR | O_CLOEXEC | O_NOCTTY);
      if (irq_fd_ < 0) Fail(irq_dev_ + ": cannot open the interrupt node (" + Errno() + ")");
    }
  } catch (...) {
    Release();
    throw;
  }
}

void UioTransport::Release() {
  if (irq_fd_ >= 0 && irq_fd_ != uio_fd_) ::close(irq_fd_);
  irq_fd_ = -1;
  if (dma_ != nullptr) ::munmap(dma_, dma_bytes_);
  dma_ = nullptr;
  if (dma_fd_ >= 0) ::close(dma_fd_);
  dma_fd_ = -1;
  if (reg_map_ != nullptr) ::munmap(reg_map_, reg_map_bytes_);
  reg_map_ = nullptr;
  regs_ = nullptr;
  if (uio_fd_ >= 0) ::close(uio_fd_);
  uio_fd_ = -1;
}

UioTransport::~UioTransport() { Release(); }

void UioTransport::CheckReg(std::uint32_t offset, const char* what) const {
  if (offset % 4 != 0 || offset >= kRegisterBytes)
    Fail(uio_dev_ + ": register " + what + " at offset " + Hex(offset) + ": not a multiple of 4 below " +
         Hex(kRegisterBytes) + " (the register map, weigh_regs.h)");
}

std::uint32_t UioTransport::ReadReg(std::uint32_t offset) {
  CheckReg(offset, "read");
  return regs_[offset / 4];
}

void UioTransport::WriteReg(std::uint32_t offset, std::uint32_t value) {
  CheckReg(offset, "write");
  regs_[offset / 4] = value;
}

std::uint64_t UioTransport::Alloc(std::size_t bytes, std::size_t align) {
  if (align == 0 || (align & (align - 1)) != 0)
    Fail(dma_dev_ + ": alignment " + std::to_string(align) + " is not a power of two");
  const std::uint64_t at = (dma_phys_ + next_ + align - 1) / align * align - dma_phys_;
  if (at > dma_bytes_ || bytes > dma_bytes_ - at)
    Fail(dma_dev_ + ": no room for " + std::to_string(bytes) + " bytes aligned to " + std::to_string(align) + " (" +
         std::to_string(next_) + " of " + std::to_string(dma_bytes_) +
         " bytes in use; give the u-dma-buf node a larger size)");
  next_ = std::size_t(at + bytes);
  return dma_phys_ + at;
}

std::uint8_t* UioTransport::Dma(std::uint64_t addr, std::size_t bytes, const char* what) {
  if (addr < dma_phys_ || addr - dma_phys_ > dma_bytes_ || bytes > dma_bytes_ - (addr - dma_phys_))
    Fail(dma_dev_ + ": " + what + " of " + std::to_string(bytes) + " bytes at " + Hex(addr) + " outside the buffer " +
         Hex(dma_phys_) + " + " + Hex(dma_bytes_));
  return dma_ + (addr - dma_phys_);
}

void UioTransport::CopyToDevice(std::uint64_t addr, const void* src, std::size_t bytes) {
  CopyTo(Dma(addr, bytes, "copy to device"), static_cast<const std::uint8_t*>(src), bytes);
}

void UioTransport::CopyFromDevice(std::uint64_t addr, void* dst, std::size_t bytes) {
  CopyFrom(static_cast<std::uint8_t*>(dst), Dma(addr, bytes, "copy from device"), bytes);
}

bool UioTransport::WaitInterrupt(std::uint64_t timeout_us) {
  const std::uint32_t unmask = 1;
  if (::write(irq_fd_, &unmask, sizeof unmask) != ssize_t(sizeof unmask))
    Fail(irq_dev_ + ": write of 1 (unmask the interrupt) failed (" + Errno() + ")");
  using Clock = std::chrono::steady_clock;
  constexpr std::uint64_t kMaxTimeoutUs = 86'400'000'000ull;  // one day: keeps the deadline in range
  const auto deadline =
      Clock::now() + std::chrono::microseconds(std::int64_t(timeout_us < kMaxTimeoutUs ? timeout_us : kMaxTimeoutUs));
  for (;;) {
    const auto left_us = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
    const long long ms = left_us <= 0 ? 0 : (left_us + 999) / 1000;
    pollfd p{irq_fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, ms > INT_MAX ? INT_MAX : int(ms));
    if (rc < 0) {
      if (errno == EINTR) continue;
      Fail(irq_dev_ + ": poll failed (" + Errno() + ")");
    }
    if (rc == 0) {
      if (Clock::now() < deadline) continue;  // poll's INT_MAX ms cap
      return false;
    }
    if ((p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0 && (p.revents & POLLIN) == 0)
      Fail(irq_dev_ + ": poll reports an error on the interrupt node (revents " + Hex(std::uint64_t(p.revents)) + ")");
    std::uint32_t count = 0;
    const ssize_t n = ::read(irq_fd_, &count, sizeof count);
    if (n < 0 && errno == EINTR) continue;
    if (n != ssize_t(sizeof count))
      Fail(irq_dev_ + ": read of the 4-byte interrupt count gave " + std::to_string(n) + " bytes" +
           (n < 0 ? " (" + Errno() + ")" : std::string()));
    irq_count_ = count;
    return true;
  }
}

std::string UioTransport::Name() const { return uio_dev_ + " (" + uio_name_ + ") + " + dma_dev_; }

std::unique_ptr<Transport> MakeUioTransport(const UioTransportOptions& options) {
  return std::make_unique<UioTransport>(options);
}

}  // namespace posefilter::hw::host
