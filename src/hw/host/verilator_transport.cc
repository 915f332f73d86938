// src/hw/host/verilator_transport.cc — VerilatorTransport (verilator_transport.h): the
// Verilated weigh_accel (M = 5) and the DDR model serving its AXI4 master port, clock by clock.
#include "hw/host/verilator_transport.h"

#include <cstring>
#include <deque>
#include <random>
#include <vector>

#include "Vweigh_accel.h"
#include "posefilter/error.h"
#include "verilated.h"

namespace posefilter::hw::host {

namespace {

constexpr int kBeatBytes = 16;  // m_axi_gmem: 128-bit data

class VerilatorTransport final : public Transport {
 public:
  explicit VerilatorTransport(const VerilatorTransportOptions& o)
      : o_(o), ctx_(NewContext()), m_(new Vweigh_accel(ctx_.get(), "weigh_accel")), ddr_(o.ddr_bytes, 0),
        rng_(o.seed) {
    if (!(o.read_latency >= 1 && o.write_latency >= 1 && o.bubble >= 0 && o.bubble < 1 && o.ddr_bytes >= (1u << 20)))
      throw Error("rtl transport: latencies must be >= 1, bubble in [0, 1), DDR >= 1 MiB");
    if (o.fault_id < -1 || o.fault_id > 6 || o.fault_resp < 1 || o.fault_resp > 3)
      throw Error("rtl transport: fault_id must be -1 … 6 and fault_resp 1 … 3 (EXOKAY, SLVERR, DECERR)");
    Drive();
    m_->ap_rst_n = 0;
    for (int i = 0; i < 8; ++i) Tick();
    m_->ap_rst_n = 1;
    Tick();
  }
  ~VerilatorTransport() override { m_->final(); }

  std::uint32_t ReadReg(std::uint32_t offset) override {
    m_->s_axi_ctrl_arvalid = 1;
    m_->s_axi_ctrl_araddr = offset;
    m_->s_axi_ctrl_rready = 0;
    bool taken = false;
    for (std::uint64_t guard = 0; !taken; ++guard) {
      Guard(guard, "register read (AR)");
      taken = Tick([&] { return m_->s_axi_ctrl_arvalid && m_->s_axi_ctrl_arready; });
    }
    m_->s_axi_ctrl_arvalid = 0;
    m_->s_axi_ctrl_rready = 1;
    std::uint32_t value = 0;
    bool got = false;
    for (std::uint64_t guard = 0; !got; ++guard) {
      Guard(guard, "register read (R)");
      got = Tick([&] {
        if (m_->s_axi_ctrl_rvalid) value = m_->s_axi_ctrl_rdata;
        return bool(m_->s_axi_ctrl_rvalid);
      });
    }
    m_->s_axi_ctrl_rready = 0;
    return value;
  }

  void WriteReg(std::uint32_t offset, std::uint32_t value) override {
    m_->s_axi_ctrl_awvalid = 1;
    m_->s_axi_ctrl_awaddr = offset;
    m_->s_axi_ctrl_wvalid = 1;
    m_->s_axi_ctrl_wdata = value;
    m_->s_axi_ctrl_wstrb = 0xF;
    m_->s_axi_ctrl_bready = 0;
    bool aw = false, w = false;
    for (std::uint64_t guard = 0; !(aw && w); ++guard) {
      Guard(guard, "register write (AW, W)");
      Tick([&] {
        const bool a = m_->s_axi_ctrl_awvalid && m_->s_axi_ctrl_awready, d = m_->s_axi_ctrl_wvalid && m_->s_axi_ctrl_wready;
        aw = aw || a;
        w = w || d;
        return a || d;
      });
      if (aw) m_->s_axi_ctrl_awvalid = 0;
      if (w) m_->s_axi_ctrl_wvalid = 0;
    }
    m_->s_axi_ctrl_bready = 1;
    bool b = false;
    for (std::uint64_t guard = 0; !b; ++guard) {
      Guard(guard, "register write (B)");
      b = Tick([&] { return bool(m_->s_axi_ctrl_bvalid); });
    }
    m_->s_axi_ctrl_bready = 0;
  }

  std::uint64_t Alloc(std::size_t bytes, std::size_t align) override {
    if (align == 0 || (align & (align - 1)) != 0) throw Error("rtl transport: alignment must be a power of two");
    const std::uint64_t at = (next_ + align - 1) / align * align;
    if (at + bytes > ddr_.size())
      throw Error("rtl transport: simulated DDR of " + std::to_string(ddr_.size()) + " bytes is full");
    next_ = at + bytes;
    return kDdrBase + at;
  }
  void CopyToDevice(std::uint64_t addr, const void* src, std::size_t bytes) override {
    std::memcpy(Host(addr, bytes), src, bytes);
  }
  void CopyFromDevice(std::uint64_t addr, void* dst, std::size_t bytes) override {
    std::memcpy(dst, Host(addr, bytes), bytes);
  }
  // The port `interrupt` is a C++ word Verilator renames (__SYM__interrupt).
  bool WaitInterrupt(std::uint64_t timeout_us) override {
    const std::uint64_t limit = timeout_us * 200;  // clocks at 200 MHz
    for (std::uint64_t c = 0; c < limit; ++c) {
      if (m_->__SYM__interrupt) return true;
      Tick();
    }
    return m_->__SYM__interrupt != 0;
  }
  std::string Name() const override { return "verilated weigh_accel (M = 5)"; }

 private:
  // A context whose uninitialised bits start at 0 (the same start on every run), set before
  // the model is built.
  static VerilatedContext* NewContext() {
    auto* c = new VerilatedContext;
    c->randReset(0);
    return c;
  }

  struct Burst {
    std::uint64_t addr;  // device address of the first beat
    int beats, done = 0, id;
    std::uint64_t due;   // clock from which its data (R) or its response (B) may go
  };

  std::uint8_t* Host(std::uint64_t addr, std::size_t bytes) {
    if (addr < kDdrBase || addr - kDdrBase + bytes > ddr_.size())
      throw Error("rtl transport: access of " + std::to_string(bytes) + " bytes at 0x" + Hex(addr) +
                  " outside the simulated DDR");
    return ddr_.data() + (addr - kDdrBase);
  }
  static std::string Hex(std::uint64_t v) {
    char s[24];
    std::snprintf(s, sizeof s, "%llx", (unsigned long long)v);
    return s;
  }
  void Guard(std::uint64_t n, const char* what) {
    if (n > 10'000'000) throw Error(std::string("rtl transport: the accelerator hangs in a ") + what);
  }
  bool Bubble() { return o_.random && std::bernoulli_distribution(o_.bubble)(rng_); }
  std::uint64_t Latency(int base) {
    return std::uint64_t(base) + (o_.random ? std::uniform_int_distribution<std::uint64_t>(0, std::uint64_t(base))(rng_) : 0);
  }

  // The DDR model's outputs for this clock, from its state.
  void Drive() {
    m_->m_axi_gmem_arready = reads_.size() < 16 && !Bubble();
    m_->m_axi_gmem_awready = writes_.size() < 16 && !Bubble();
    m_->m_axi_gmem_wready = !writes_.empty() && !Bubble();
    const bool r = !reads_.empty() && reads_.front().due <= cycle_ && !Bubble();
    m_->m_axi_gmem_rvalid = r;
    if (r) {
      const Burst& b = reads_.front();
      const std::uint8_t* p = Host(b.addr + std::uint64_t(b.done) * kBeatBytes, kBeatBytes);
      for (int k = 0; k < 4; ++k) {
        std::uint32_t w;
        std::memcpy(&w, p + 4 * k, 4);
        m_->m_axi_gmem_rdata[k] = w;
      }
      m_->m_axi_gmem_rid = b.id;
      m_->m_axi_gmem_rlast = b.done + 1 == b.beats;
      m_->m_axi_gmem_rresp = b.id == o_.fault_id && beats_[b.id] == o_.fault_index ? o_.fault_resp : 0;
    }
    const bool bv = !responses_.empty() && responses_.front().due <= cycle_ && !Bubble();
    m_->m_axi_gmem_bvalid = bv;
    m_->m_axi_gmem_bid = bv ? responses_.front().id : 0;
    m_->m_axi_gmem_bresp =
        bv && responses_.front().id == o_.fault_id && beats_[responses_.front().id] == o_.fault_index ? o_.fault_resp : 0;
  }

  // One clock: the DDR model drives, the inputs settle, the handshakes are taken, the edge.
  // `sample` (may be empty) sees the settled signals before the edge; its result is returned.
  template <class F>
  bool Tick(F&& sample) {
    Drive();
    m_->ap_clk = 0;
    m_->eval();
    const bool result = sample();
    if (m_->m_axi_gmem_arvalid && m_->m_axi_gmem_arready)
      reads_.push_back({m_->m_axi_gmem_araddr, int(m_->m_axi_gmem_arlen) + 1, 0, int(m_->m_axi_gmem_arid),
                        cycle_ + Latency(o_.read_latency)});
    if (m_->m_axi_gmem_rvalid && m_->m_axi_gmem_rready) {
      ++beats_[reads_.front().id];
      if (++reads_.front().done == reads_.front().beats) reads_.pop_front();
    }
    if (m_->m_axi_gmem_awvalid && m_->m_axi_gmem_awready)
      writes_.push_back({m_->m_axi_gmem_awaddr, int(m_->m_axi_gmem_awlen) + 1, 0, int(m_->m_axi_gmem_awid), 0});
    if (m_->m_axi_gmem_wvalid && m_->m_axi_gmem_wready) {
      Burst& b = writes_.front();
      std::uint8_t* p = Host(b.addr + std::uint64_t(b.done) * kBeatBytes, kBeatBytes);
      for (int k = 0; k < kBeatBytes; ++k)
        if ((m_->m_axi_gmem_wstrb >> k) & 1) p[k] = std::uint8_t(m_->m_axi_gmem_wdata[k / 4] >> (8 * (k % 4)));
      if (++b.done == b.beats) {
        if (!m_->m_axi_gmem_wlast) throw Error("rtl transport: WLAST missing on a burst's last beat");
        b.due = cycle_ + Latency(o_.write_latency);
        responses_.push_back(b);
        writes_.pop_front();
      } else if (m_->m_axi_gmem_wlast) {
        throw Error("rtl transport: WLAST before a burst's last beat");
      }
    }
    if (m_->m_axi_gmem_bvalid && m_->m_axi_gmem_bready) {
      ++beats_[responses_.front().id];
      responses_.pop_front();
    }
    m_->ap_clk = 1;
    m_->eval();
    ++cycle_;
    return result;
  }
  void Tick() {
    Tick([] { return false; });
  }

  VerilatorTransportOptions o_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<Vweigh_accel> m_;
  std::vector<std::uint8_t> ddr_;
  std::uint64_t next_ = 0;    // first free DDR byte (offset)
  std::uint64_t cycle_ = 0;
  std::mt19937_64 rng_;
  std::deque<Burst> reads_, writes_, responses_;
  std::uint64_t beats_[8] = {};  // per AXI ID: read beats taken (0 … 5), write responses taken (6)
};

}  // namespace

bool VerilatorTransportBuilt(std::string* why) {
  if (why) why->clear();
  return true;
}

std::unique_ptr<Transport> MakeVerilatorTransport(const VerilatorTransportOptions& options) {
  return std::make_unique<VerilatorTransport>(options);
}

}  // namespace posefilter::hw::host
