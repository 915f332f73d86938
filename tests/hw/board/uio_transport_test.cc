// tests/hw/board/uio_transport_test.cc — UioTransport (src/hw/host/uio_transport.h) without a
// board: a fake /dev and /sys tree in a temporary folder (the transport's `root`), regular files
// standing in for the UIO register window and the u-dma-buf (mmap of a file), and a
// pseudo-terminal standing in for the interrupt node (it carries the UIO protocol's 4-byte
// unmask write and 4-byte event count). What it cannot check here: the PL's registers answering,
// the GIC interrupt, the buffer's cache attributes and the accelerator's DMA; those are the board
// test plan's (docs/HARDWARE.md §17).
//
// The last two tests run WeighDriver (the driver `--engine rtl` uses) over UioTransport against
// a fake accelerator: a thread that waits for the interrupt unmask, checks the registers the
// driver wrote, writes output records at the OUT address and raises the interrupt; in the
// second it reports bus errors in STATUS, which the driver must turn into an Error.
#include <fcntl.h>
#include <sys/mman.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "hw/host/uio_transport.h"
#include "hw/host/weigh_driver.h"
#include "hw/host/weigh_pack.h"
#include "hw/host/weigh_regs.h"
#include "posefilter/error.h"

namespace posefilter::hw::host {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kPhys = 0x7000'0000;        // the fake u-dma-buf's bus address (DDR_LOW)
constexpr std::size_t kDmaBytes = 2u << 20;          // 2 MiB: the driver's buffers need 0.7 MiB
constexpr std::size_t kWindowBytes = 0x10000;        // 64 KiB register window (zcu102_bd.tcl ctrl_range)

void WriteText(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}
void WriteZeros(const fs::path& p, std::size_t bytes) {
  fs::create_directories(p.parent_path());
  std::ofstream out(p, std::ios::binary);
  std::vector<char> z(bytes, 0);
  out.write(z.data(), std::streamsize(bytes));
}

// Maps a whole file shared (the test's view of the fake device).
struct FileMap {
  explicit FileMap(const fs::path& p) {
    fd = ::open(p.c_str(), O_RDWR);
    bytes = fs::file_size(p);
    data = static_cast<std::uint8_t*>(::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0));
  }
  ~FileMap() {
    ::munmap(data, bytes);
    ::close(fd);
  }
  std::uint32_t Word(std::size_t off) const {
    std::uint32_t w;
    std::memcpy(&w, data + off, 4);
    return w;
  }
  void SetWord(std::size_t off, std::uint32_t w) { std::memcpy(data + off, &w, 4); }
  int fd;
  std::size_t bytes;
  std::uint8_t* data;
};

// A pseudo-terminal in raw mode: the transport opens the slave as its interrupt node, the test
// plays the kernel on the master.
struct Pty {
  Pty() {
    master = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) return;
    slave_path = ::ptsname(master);
    slave = ::open(slave_path.c_str(), O_RDWR | O_NOCTTY);
    termios t{};
    ::tcgetattr(slave, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(slave, TCSANOW, &t);
  }
  ~Pty() {
    if (slave >= 0) ::close(slave);
    if (master >= 0) ::close(master);
  }
  bool ok() const { return master >= 0 && slave >= 0; }
  // The transport's next 4-byte write (the unmask), or -1.
  long ReadUnmask() const {
    std::uint32_t v = 0;
    std::size_t got = 0;
    while (got < 4) {
      const ssize_t n = ::read(master, reinterpret_cast<char*>(&v) + got, 4 - got);
      if (n <= 0) return -1;
      got += std::size_t(n);
    }
    return long(v);
  }
  void Raise(std::uint32_t count) const { ASSERT_EQ(::write(master, &count, 4), 4); }
  int master = -1, slave = -1;
  std::string slave_path;
};

class UioTransportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/uio_transport_test_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    root_ = tmpl;
    // Two UIO devices: another one first, then the accelerator's.
    WriteText(root_ / "sys/class/uio/uio0/name", "axi_gpio\n");
    WriteText(root_ / "sys/class/uio/uio0/maps/map0/size", "0x00001000\n");
    WriteZeros(root_ / "dev/uio0", 0x1000);
    WriteText(root_ / "sys/class/uio/uio1/name", "weigh_accel\n");
    WriteText(root_ / "sys/class/uio/uio1/maps/map0/addr", "0x00000000a0000000\n");
    WriteText(root_ / "sys/class/uio/uio1/maps/map0/size", "0x00010000\n");
    WriteZeros(root_ / "dev/uio1", kWindowBytes);
    // The u-dma-buf (phys_addr as u-dma-buf prints it, size in decimal).
    WriteText(root_ / "sys/class/u-dma-buf/udmabuf0/phys_addr", "0x0000000070000000\n");
    WriteText(root_ / "sys/class/u-dma-buf/udmabuf0/size", std::to_string(kDmaBytes) + "\n");
    WriteZeros(root_ / "dev/udmabuf0", kDmaBytes);
  }
  void TearDown() override { fs::remove_all(root_); }

  UioTransportOptions Options() const {
    UioTransportOptions o;
    o.root = root_.string();
    return o;
  }
  // The message of the Error that `f` throws ("" if none).
  template <class F>
  static std::string ErrorOf(F&& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }

  fs::path root_;
};

TEST_F(UioTransportTest, RegistersAreTheWordsOfMapZero) {
  FileMap regs(root_ / "dev/uio1");
  regs.SetWord(regs::kId, regs::kIdExpected);
  UioTransport t(Options());
  EXPECT_EQ(t.uio_device(), (root_ / "dev/uio1").string());
  EXPECT_EQ(t.register_window_bytes(), kWindowBytes);
  EXPECT_EQ(t.ReadReg(regs::kId), regs::kIdExpected);
  t.WriteReg(regs::kOutAddrHi, 0x8u);
  t.WriteReg(regs::kNumParticles, 510u);
  EXPECT_EQ(regs.Word(regs::kOutAddrHi), 0x8u);
  EXPECT_EQ(regs.Word(regs::kNumParticles), 510u);
  EXPECT_EQ(t.ReadReg(regs::kNumParticles), 510u);
  EXPECT_NE(t.Name().find("uio1 (weigh_accel)"), std::string::npos) << t.Name();
  EXPECT_NE(t.Name().find("udmabuf0"), std::string::npos) << t.Name();
}

TEST_F(UioTransportTest, RegisterOffsetsOutsideTheMapAreErrorsNamingTheDevice) {
  UioTransport t(Options());
  const std::string dev = (root_ / "dev/uio1").string();
  for (std::uint32_t bad : {0x2u, 0x101u, 0x100u, 0xFFFCu}) {
    const std::string e = ErrorOf([&] { t.ReadReg(bad); });
    EXPECT_NE(e.find(dev), std::string::npos) << e;
    EXPECT_NE(e.find("multiple of 4 below 0x100"), std::string::npos) << e;
    EXPECT_NE(ErrorOf([&] { t.WriteReg(bad, 1); }), "");
  }
  EXPECT_EQ(ErrorOf([&] { t.ReadReg(0xFC); }), "");  // the last register of the 256-byte map
}

TEST_F(UioTransportTest, MissingOrWrongDevicesAreNamed) {
  UioTransportOptions o = Options();
  o.uio_name = "nope";
  std::string e = ErrorOf([&] { UioTransport t(o); });
  EXPECT_NE(e.find("no UIO device named 'nope'"), std::string::npos) << e;
  EXPECT_NE(e.find("uio0 (axi_gpio)"), std::string::npos) << e;
  EXPECT_NE(e.find("uio1 (weigh_accel)"), std::string::npos) << e;

  o = Options();
  o.udmabuf = "udmabuf7";
  e = ErrorOf([&] { UioTransport t(o); });
  EXPECT_NE(e.find((root_ / "sys/class/u-dma-buf/udmabuf7").string()), std::string::npos) << e;

  o = Options();
  o.udmabuf = "../udmabuf0";
  EXPECT_NE(ErrorOf([&] { UioTransport t(o); }).find("is not a device name"), std::string::npos);

  o = Options();
  o.irq_path = (root_ / "dev/no_such_irq").string();
  e = ErrorOf([&] { UioTransport t(o); });
  EXPECT_NE(e.find(o.irq_path + ": cannot open the interrupt node"), std::string::npos) << e;

  fs::remove(root_ / "dev/uio1");
  e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find((root_ / "dev/uio1").string() + ": cannot open"), std::string::npos) << e;

  fs::remove_all(root_ / "sys/class/uio");
  e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find((root_ / "sys/class/uio").string() + ": no such folder"), std::string::npos) << e;
}

TEST_F(UioTransportTest, MapsTooSmallOrNotNumbersAreRejected) {
  const fs::path size = root_ / "sys/class/uio/uio1/maps/map0/size";
  WriteText(size, "0x80\n");  // below the 256-byte register map
  std::string e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find(size.string()), std::string::npos) << e;
  EXPECT_NE(e.find("needs 256"), std::string::npos) << e;

  WriteText(size, "sixty-four k\n");
  e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find(size.string() + ": 'sixty-four k' is not a number"), std::string::npos) << e;

  WriteText(size, "0x00010000\n");
  WriteZeros(root_ / "dev/uio1", 0x100);  // the stand-in file shorter than the map
  e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find((root_ / "dev/uio1").string() + ": a regular file of 256 bytes"), std::string::npos) << e;

  WriteZeros(root_ / "dev/uio1", kWindowBytes);
  WriteText(root_ / "sys/class/uio/uio1/maps/map0/offset", "0xff80\n");  // registers past the map's end
  e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find("do not fit"), std::string::npos) << e;
}

TEST_F(UioTransportTest, ARegisterWindowElsewhereIsRefusedUnlessUnchecked) {
  const fs::path addr = root_ / "sys/class/uio/uio1/maps/map0/addr";
  WriteText(addr, "0x00000000a0010000\n");
  const std::string e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find(addr.string() + ": map 0 is at 0xa0010000"), std::string::npos) << e;
  UioTransportOptions o = Options();
  o.register_base = 0;
  EXPECT_EQ(ErrorOf([&] { UioTransport t(o); }), "");
}

TEST_F(UioTransportTest, DmaBufferOutsideTheGmemWindowsIsRejected) {
  const fs::path phys = root_ / "sys/class/u-dma-buf/udmabuf0/phys_addr";
  WriteText(phys, "0x0000000100000000\n");  // 4 GiB: between DDR_LOW and DDR_HIGH
  std::string e = ErrorOf([&] { UioTransport t(Options()); });
  EXPECT_NE(e.find(phys.string()), std::string::npos) << e;
  EXPECT_NE(e.find("outside m_axi_gmem's DDR windows"), std::string::npos) << e;
  WriteText(phys, "0x7ff00000\n");  // starts in DDR_LOW, runs past its end
  EXPECT_NE(ErrorOf([&] { UioTransport t(Options()); }).find("outside"), std::string::npos);
  WriteText(phys, "0x0000000800000000\n");  // DDR_HIGH
  UioTransport t(Options());
  EXPECT_EQ(t.dma_phys(), 0x8'0000'0000ull);
}

TEST_F(UioTransportTest, AllocAlignsInsideTheBufferAndCopiesBothWays) {
  UioTransport t(Options());
  EXPECT_EQ(t.dma_phys(), kPhys);
  EXPECT_EQ(t.dma_bytes(), kDmaBytes);
  const std::uint64_t a = t.Alloc(100, 4096), b = t.Alloc(10, 256), c = t.Alloc(3, 1);
  EXPECT_EQ(a, kPhys);
  EXPECT_EQ(b, kPhys + 256);
  EXPECT_EQ(c, kPhys + 266);
  // Unaligned starts and lengths, so the copies take their byte head, word and byte tail paths.
  std::vector<std::uint8_t> src(37), back(37, 0);
  for (std::size_t i = 0; i < src.size(); ++i) src[i] = std::uint8_t(3 * i + 1);
  t.CopyToDevice(a + 5, src.data(), src.size());
  FileMap dma(root_ / "dev/udmabuf0");
  EXPECT_EQ(std::memcmp(dma.data + 5, src.data(), src.size()), 0);
  EXPECT_EQ(dma.data[4], 0);
  EXPECT_EQ(dma.data[5 + src.size()], 0);
  t.CopyFromDevice(a + 5, back.data(), back.size());
  EXPECT_EQ(back, src);

  const std::string dev = (root_ / "dev/udmabuf0").string();
  std::string e = ErrorOf([&] { t.CopyToDevice(kPhys + kDmaBytes - 4, src.data(), 8); });
  EXPECT_NE(e.find(dev + ": copy to device of 8 bytes"), std::string::npos) << e;
  e = ErrorOf([&] { t.CopyFromDevice(kPhys - 16, back.data(), 8); });
  EXPECT_NE(e.find(dev + ": copy from device"), std::string::npos) << e;
  e = ErrorOf([&] { t.Alloc(kDmaBytes, 4096); });
  EXPECT_NE(e.find(dev + ": no room for"), std::string::npos) << e;
  EXPECT_NE(ErrorOf([&] { t.Alloc(8, 3); }).find("not a power of two"), std::string::npos);
}

TEST_F(UioTransportTest, WaitInterruptUnmasksPollsAndReadsTheCount) {
  Pty pty;
  if (!pty.ok()) GTEST_SKIP() << "no pseudo-terminal to stand in for the interrupt node";
  UioTransportOptions o = Options();
  o.irq_path = pty.slave_path;
  UioTransport t(o);
  std::thread kernel([&] {
    EXPECT_EQ(pty.ReadUnmask(), 1);  // the transport unmasks before it waits
    pty.Raise(7);
  });
  EXPECT_TRUE(t.WaitInterrupt(5'000'000));
  kernel.join();
  EXPECT_EQ(t.interrupts_seen(), 7u);
  // No event: false after the timeout (20 ms), the unmask written all the same.
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(t.WaitInterrupt(20'000));
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(19));
  EXPECT_EQ(pty.ReadUnmask(), 1);
}

// WeighDriver, unchanged from `--engine rtl`, over the board transport: a fake accelerator
// answers one call of 7 particles.
TEST_F(UioTransportTest, WeighDriverRunsACallOverTheBoardTransport) {
  Pty pty;
  if (!pty.ok()) GTEST_SKIP() << "no pseudo-terminal to stand in for the interrupt node";
  FileMap regs(root_ / "dev/uio1");
  regs.SetWord(regs::kId, regs::kIdExpected);
  regs.SetWord(regs::kCores, 5);
  regs.SetWord(regs::kCtrl, regs::kCtrlApIdle.Put(1));
  UioTransportOptions o = Options();
  o.irq_path = pty.slave_path;
  UioTransport t(o);
  WeighDriver driver(t);
  EXPECT_EQ(driver.cores(), 5);

  // A scene and 7 particles (contents do not matter to the fake, only where they land).
  constexpr int n = 7, width = 64, height = 48, faces = 12;
  std::vector<depth_t> depth(std::size_t(width) * height);
  for (std::size_t i = 0; i < depth.size(); ++i) axi::SetRawBits(depth[i], i % 4096);
  static xyz_t vmem[3][kMaxVertices];
  std::vector<face_t> tri(faces);
  std::vector<prob_t> prob(kNumCells);
  driver.LoadScene(depth.data(), width, height, vmem, tri.data(), faces, prob.data());
  std::vector<Window> win(n);
  std::vector<ft_t> ft(std::size_t(n) * kFtElements);
  std::vector<cell_index_t> cells(n);
  for (int p = 0; p < n; ++p) {
    win[std::size_t(p)].u0 = p;
    win[std::size_t(p)].v0 = 2 * p;
    win[std::size_t(p)].width = 10 + p;
    win[std::size_t(p)].height = 20 + p;
    axi::SetRawBits(cells[std::size_t(p)], 100 + p);
  }
  for (std::size_t i = 0; i < ft.size(); ++i) axi::SetRawBits(ft[i], i * 977);

  FileMap dma(root_ / "dev/udmabuf0");
  std::thread accel([&] {
    if (pty.ReadUnmask() != 1) return;  // the driver set AP_START and waits
    auto addr = [&](std::uint32_t lo) { return std::uint64_t(regs.Word(lo)) | (std::uint64_t(regs.Word(lo + 4)) << 32); };
    EXPECT_EQ(regs.Word(regs::kCtrl), regs::kCtrlApStart.Put(1));
    EXPECT_EQ(regs.Word(regs::kNumParticles), std::uint32_t(n));
    EXPECT_EQ(regs.Word(regs::kNumFaces), std::uint32_t(faces));
    EXPECT_EQ(regs.Word(regs::kImgWidth), std::uint32_t(width));
    EXPECT_EQ(regs.Word(regs::kImgHeight), std::uint32_t(height));
    // Every buffer address in the u-dma-buf, 256-byte aligned, and the packed bytes there.
    for (std::uint32_t lo : {regs::kImgAddrLo, regs::kWinAddrLo, regs::kFtAddrLo, regs::kModelAddrLo,
                             regs::kProbAddrLo, regs::kCellAddrLo, regs::kOutAddrLo}) {
      EXPECT_GE(addr(lo), kPhys);
      EXPECT_LT(addr(lo), kPhys + kDmaBytes);
      EXPECT_EQ(addr(lo) % 256, 0u);
    }
    const std::vector<std::uint8_t> wpack = PackWindows(win.data(), n), cpack = PackCells(cells.data(), n);
    EXPECT_EQ(std::memcmp(dma.data + (addr(regs::kWinAddrLo) - kPhys), wpack.data(), wpack.size()), 0);
    EXPECT_EQ(std::memcmp(dma.data + (addr(regs::kCellAddrLo) - kPhys), cpack.data(), cpack.size()), 0);
    // Output records: weight 1000 + p, index p, n_raster 10·p.
    std::uint8_t* out = dma.data + (addr(regs::kOutAddrLo) - kPhys);
    for (int p = 0; p < n; ++p) {
      std::uint8_t* r = out + std::size_t(p) * kOutRecordBytes;
      std::memset(r, 0, kOutRecordBytes);
      const std::uint32_t w = 1000 + p, idx = p, nr = 10 * p;
      std::memcpy(r + 8, &nr, 4);  // n_raster: bytes 8–11 (after the 8-byte inlier_sum)
      std::memcpy(r + kOutWeightByte, &w, 4);
      std::memcpy(r + kOutIndexByte, &idx, 2);
    }
    regs.SetWord(regs::kCyclesLo, 123456);
    regs.SetWord(regs::kCyclesHi, 1);
    regs.SetWord(regs::kDdReadsShared, 3072);
    regs.SetWord(regs::kDdReadsUnshared, 4000);
    regs.SetWord(regs::kIsr, regs::kIsrDone.Put(1));
    regs.SetWord(regs::kCtrl, regs::kCtrlApDone.Put(1) | regs::kCtrlApIdle.Put(1) | regs::kCtrlApReady.Put(1));
    pty.Raise(1);
  });
  std::vector<WeightOut> weights(n);
  std::vector<RasterCoreOutput> stats(n);
  WeighCallCounters c;
  const std::string e = ErrorOf([&] {
    c = driver.Weigh(n, DefaultRasterParams(), DefaultWeightParams(), win.data(), ft.data(), cells.data(),
                     weights.data(), stats.data(), 5'000'000);
  });
  accel.join();
  ASSERT_EQ(e, "");
  EXPECT_EQ(c.cycles, (std::uint64_t(1) << 32) + 123456);
  EXPECT_EQ(c.reads_shared, 3072u);
  EXPECT_EQ(c.reads_unshared, 4000u);
  for (int p = 0; p < n; ++p) {
    EXPECT_EQ(axi::RawBits(weights[std::size_t(p)].weight), std::uint64_t(1000 + p));
    EXPECT_EQ(axi::RawBits(weights[std::size_t(p)].index), std::uint64_t(p));
    EXPECT_EQ(axi::RawBits(stats[std::size_t(p)].n_raster), std::uint64_t(10 * p));
  }
  // The driver acknowledged: ISR.DONE written (toggle on 1).
  EXPECT_EQ(regs.Word(regs::kIsr), regs::kIsrDone.Put(1));
}

// A call whose accelerator reports bus errors in STATUS: the driver throws naming STATUS, both
// bits, the buffer and the responses, after writing the error bits back (W1C).
TEST_F(UioTransportTest, WeighDriverReportsStatusBusErrors) {
  Pty pty;
  if (!pty.ok()) GTEST_SKIP() << "no pseudo-terminal to stand in for the interrupt node";
  FileMap regs(root_ / "dev/uio1");
  regs.SetWord(regs::kId, regs::kIdExpected);
  regs.SetWord(regs::kCores, 10);
  regs.SetWord(regs::kCtrl, regs::kCtrlApIdle.Put(1));
  UioTransportOptions o = Options();
  o.irq_path = pty.slave_path;
  UioTransport t(o);
  WeighDriver driver(t);
  constexpr int n = 1, width = 8, height = 8, faces = 1;
  std::vector<depth_t> depth(std::size_t(width) * height);
  static xyz_t vmem[3][kMaxVertices];
  std::vector<face_t> tri(faces);
  std::vector<prob_t> prob(kNumCells);
  driver.LoadScene(depth.data(), width, height, vmem, tri.data(), faces, prob.data());
  std::vector<Window> win(n);
  std::vector<ft_t> ft(std::size_t(n) * kFtElements);
  std::vector<cell_index_t> cells(n);
  const std::uint32_t status = regs::kStatusRdErr.Put(1) | regs::kStatusWrErr.Put(1) | regs::kStatusRdResp.Put(3) |
                               regs::kStatusWrResp.Put(2) | regs::kStatusRdId.Put(3);
  std::thread accel([&] {
    if (pty.ReadUnmask() != 1) return;
    regs.SetWord(regs::kStatus, status);
    regs.SetWord(regs::kIsr, regs::kIsrDone.Put(1));
    regs.SetWord(regs::kCtrl, regs::kCtrlApDone.Put(1) | regs::kCtrlApIdle.Put(1) | regs::kCtrlApReady.Put(1));
    pty.Raise(1);
  });
  std::vector<WeightOut> weights(n);
  std::vector<RasterCoreOutput> stats(n);
  const std::string e = ErrorOf([&] {
    driver.Weigh(n, DefaultRasterParams(), DefaultWeightParams(), win.data(), ft.data(), cells.data(), weights.data(),
                 stats.data(), 5'000'000);
  });
  accel.join();
  EXPECT_EQ(status, 0x32Fu);
  EXPECT_NE(e.find("STATUS reads 0x0000032F: RD_ERR: a read beat of the MODEL buffer (RID 3) came back DECERR (3); "
                   "WR_ERR: a write response of the OUT buffer came back SLVERR (2)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find(t.uio_device()), std::string::npos) << e;
  // The error bits written back (W1C; the fake's register is a plain word).
  EXPECT_EQ(regs.Word(regs::kStatus), regs::kStatusRdErr.Put(1) | regs::kStatusWrErr.Put(1));
}

}  // namespace
}  // namespace posefilter::hw::host
