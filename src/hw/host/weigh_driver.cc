// src/hw/host/weigh_driver.cc — WeighDriver (weigh_driver.h): the board driver's sequence of
// register writes and buffer copies for one weighing, over any Transport.
#include "hw/host/weigh_driver.h"

#include <cstdio>
#include <vector>

#include "hw/host/axi_pack.h"
#include "hw/host/weigh_pack.h"
#include "hw/host/weigh_regs.h"
#include "posefilter/error.h"

namespace posefilter::hw::host {

namespace {
constexpr std::size_t kBufferAlign = 4096;  // ≥ the 256 bytes the readers need; a page

// A register word as the register map prints it: 0x and 8 hex digits.
std::string Hex32(std::uint32_t v) {
  char s[16];
  std::snprintf(s, sizeof s, "0x%08X", unsigned(v));
  return s;
}

// An AXI response code's name (RRESP/BRESP, 2 bits).
std::string RespName(std::uint32_t resp) {
  static const char* const kNames[4] = {"OKAY", "EXOKAY", "SLVERR", "DECERR"};
  return std::string(kNames[resp & 3u]) + " (" + std::to_string(resp & 3u) + ")";
}

// The buffer a reader's AXI ID reads (weigh_accel.sv: ARID 0 … 5), with its article.
std::string ReadBufferName(std::uint32_t id) {
  static const char* const kNames[6] = {"IMG", "WIN", "FT", "MODEL", "PROB", "CELL"};
  return id < 6 ? "the " + std::string(kNames[id]) + " buffer" : std::string("no reader's buffer");
}

// STATUS's error bits (RD_ERR, WR_ERR).
constexpr std::uint32_t kStatusErrors = regs::kStatusRdErr.Mask() | regs::kStatusWrErr.Mask();
}  // namespace

WeighDriver::WeighDriver(Transport& transport) : t_(transport) {
  if (!LayoutsAgree())
    throw Error("rtl driver: src/hw/rtl/weigh_regs.json's buffer element sizes differ from axi_pack.h's layouts");
  const std::uint32_t id = t_.ReadReg(regs::kId);
  if (id != regs::kIdExpected)
    throw Error("rtl driver: " + t_.Name() + ": ID register reads " + Hex32(id) + ", not weigh_accel's " +
                Hex32(regs::kIdExpected));
  cores_ = int(regs::kCoresM.Get(t_.ReadReg(regs::kCores)));
  if (cores_ < 1 || cores_ > kMaxRasterCores)
    throw Error("rtl driver: " + t_.Name() + ": CORES register reads " + std::to_string(cores_));
  // Bus errors left from before this driver (STATUS is sticky): cleared, so that a call's check
  // sees only its own.
  if (const std::uint32_t status = t_.ReadReg(regs::kStatus); (status & kStatusErrors) != 0)
    t_.WriteReg(regs::kStatus, status & kStatusErrors);
  img_ = t_.Alloc(std::size_t(kImageWidth) * kImageHeight * regs::kImgElementBytes, kBufferAlign);
  win_ = t_.Alloc(std::size_t(kMaxParticles) * regs::kWinElementBytes, kBufferAlign);
  ft_ = t_.Alloc(std::size_t(kMaxParticles) * kFtElements * regs::kFtElementBytes, kBufferAlign);
  model_ = t_.Alloc(std::size_t(kMaxVertices + kMaxFaces) * regs::kModelElementBytes, kBufferAlign);
  prob_ = t_.Alloc(std::size_t(kNumCells) * regs::kProbElementBytes, kBufferAlign);
  cell_ = t_.Alloc(std::size_t(kMaxParticles) * regs::kCellElementBytes, kBufferAlign);
  out_ = t_.Alloc(std::size_t(kMaxParticles) * regs::kOutElementBytes, kBufferAlign);
}

void WeighDriver::LoadScene(const depth_t* depth, int img_width, int img_height, const xyz_t vmem[3][kMaxVertices],
                            const face_t* tri, int num_faces, const prob_t* class_prob) {
  if (img_width < 1 || img_width > kImageWidth || img_height < 1 || img_height > kImageHeight)
    throw Error("rtl driver: image " + std::to_string(img_width) + "x" + std::to_string(img_height) +
                " outside 1..640 x 1..480");
  if (num_faces < 1 || num_faces > kMaxFaces)
    throw Error("rtl driver: " + std::to_string(num_faces) + " faces outside 1..2048");
  const std::vector<uint8_t> img = PackImage(depth, img_width, img_height);
  const std::vector<uint8_t> model = PackModel(vmem, tri, num_faces);
  const std::vector<uint8_t> prob = PackProb(class_prob);
  t_.CopyToDevice(img_, img.data(), img.size());
  t_.CopyToDevice(model_, model.data(), model.size());
  t_.CopyToDevice(prob_, prob.data(), prob.size());
  img_width_ = img_width;
  img_height_ = img_height;
  num_faces_ = num_faces;
  loaded_ = true;
}

WeighCallCounters WeighDriver::Weigh(int n, const RasterParams& raster, const WeightParams& weight,
                                     const Window* windows, const ft_t* ft, const cell_index_t* cells, WeightOut* weights,
                                     RasterCoreOutput* stats, std::uint64_t timeout_us) {
  if (!loaded_) throw Error("rtl driver: Weigh before LoadScene");
  if (n < 1 || n > kMaxParticles) throw Error("rtl driver: " + std::to_string(n) + " particles outside 1..510");
  if (!regs::kCtrlApIdle.Get(t_.ReadReg(regs::kCtrl)))
    throw Error("rtl driver: " + t_.Name() + " is not idle (AP_IDLE = 0) at the start of a call");
  // The particles' buffers.
  const std::vector<uint8_t> win = PackWindows(windows, n), ftb = PackFt(ft, n), cel = PackCells(cells, n);
  t_.CopyToDevice(win_, win.data(), win.size());
  t_.CopyToDevice(ft_, ftb.data(), ftb.size());
  t_.CopyToDevice(cell_, cel.data(), cel.size());
  // Parameters (raw words of WeighConfig's fields) and addresses.
  auto raw = [](const auto& x) { return std::uint32_t(axi::RawBits(x)); };
  t_.WriteReg(regs::kNumParticles, regs::kNumParticlesN.Put(std::uint32_t(n)));
  t_.WriteReg(regs::kNumFaces, regs::kNumFacesFaces.Put(std::uint32_t(num_faces_)));
  t_.WriteReg(regs::kImgWidth, regs::kImgWidthWidth.Put(std::uint32_t(img_width_)));
  t_.WriteReg(regs::kImgHeight, regs::kImgHeightHeight.Put(std::uint32_t(img_height_)));
  t_.WriteReg(regs::kRasterFlags, regs::kRasterFlagsZbuffer.Put(raw(raster.zbuffer)) | regs::kRasterFlagsHard.Put(raw(raster.hard)));
  t_.WriteReg(regs::kThr1, regs::kThr1Raw.Put(raw(raster.thr1)));
  t_.WriteReg(regs::kInvThr1, regs::kInvThr1Raw.Put(raw(raster.inv_thr1)));
  t_.WriteReg(regs::kHardThr, regs::kHardThrRaw.Put(raw(raster.hard_thr)));
  t_.WriteReg(regs::kAlignBand, regs::kAlignBandRaw.Put(raw(raster.align_band)));
  t_.WriteReg(regs::kEdgeBand, regs::kEdgeBandRaw.Put(raw(raster.edge_band)));
  t_.WriteReg(regs::kNearPlane, regs::kNearPlaneRaw.Put(raw(raster.near_plane)));
  t_.WriteReg(regs::kWeightAb, regs::kWeightAbAlpha.Put(raw(weight.alpha)) | regs::kWeightAbBeta.Put(raw(weight.beta)));
  t_.WriteReg(regs::kWeightGd, regs::kWeightGdGamma.Put(raw(weight.gamma)) | regs::kWeightGdDelta.Put(raw(weight.delta)));
  t_.WriteReg(regs::kWeightFlags, regs::kWeightFlagsOcclusionAware.Put(raw(weight.occlusion_aware)));
  const std::pair<std::uint32_t, std::uint64_t> addrs[] = {{regs::kImgAddrLo, img_},     {regs::kWinAddrLo, win_},
                                                           {regs::kFtAddrLo, ft_},       {regs::kModelAddrLo, model_},
                                                           {regs::kProbAddrLo, prob_},   {regs::kCellAddrLo, cell_},
                                                           {regs::kOutAddrLo, out_}};
  for (const auto& [lo, a] : addrs) {
    t_.WriteReg(lo, std::uint32_t(a));
    t_.WriteReg(lo + 4, std::uint32_t(a >> 32));  // the _HI register follows its _LO
  }
  // Interrupt on done; start; wait; acknowledge (ISR toggles on a written 1; reading CTRL
  // clears AP_DONE).
  t_.WriteReg(regs::kGie, regs::kGieEnable.Put(1));
  t_.WriteReg(regs::kIer, regs::kIerDone.Put(1));
  t_.WriteReg(regs::kCtrl, regs::kCtrlApStart.Put(1));
  if (!t_.WaitInterrupt(timeout_us))
    throw Error("rtl driver: " + t_.Name() + ": no interrupt within " + std::to_string(timeout_us) + " us of AP_START");
  const std::uint32_t isr = t_.ReadReg(regs::kIsr);
  if (!regs::kIsrDone.Get(isr)) throw Error("rtl driver: " + t_.Name() + ": interrupt without ISR.DONE");
  t_.WriteReg(regs::kIsr, regs::kIsrDone.Put(1));
  const std::uint32_t ctrl = t_.ReadReg(regs::kCtrl);
  if (!regs::kCtrlApDone.Get(ctrl) || !regs::kCtrlApIdle.Get(ctrl))
    throw Error("rtl driver: " + t_.Name() + ": interrupt but CTRL reads " + Hex32(ctrl));
  // Bus errors of the call: the outputs are not to be trusted. STATUS is cleared (W1C) so that
  // the next call starts clean, then the call fails naming the response.
  if (const std::uint32_t status = t_.ReadReg(regs::kStatus); (status & kStatusErrors) != 0) {
    t_.WriteReg(regs::kStatus, status & kStatusErrors);
    std::string what;
    if (regs::kStatusRdErr.Get(status))
      what += "RD_ERR: a read beat of " + ReadBufferName(regs::kStatusRdId.Get(status)) + " (RID " +
              std::to_string(regs::kStatusRdId.Get(status)) + ") came back " +
              RespName(regs::kStatusRdResp.Get(status));
    if (regs::kStatusWrErr.Get(status))
      what += std::string(what.empty() ? "" : "; ") + "WR_ERR: a write response of the OUT buffer came back " +
              RespName(regs::kStatusWrResp.Get(status));
    throw Error("rtl driver: " + t_.Name() + ": bus error in the call of " + std::to_string(n) +
                " particles, STATUS reads " + Hex32(status) + ": " + what);
  }
  WeighCallCounters c;
  c.cycles = std::uint64_t(t_.ReadReg(regs::kCyclesLo)) | (std::uint64_t(t_.ReadReg(regs::kCyclesHi)) << 32);
  c.reads_shared = t_.ReadReg(regs::kDdReadsShared);
  c.reads_unshared = t_.ReadReg(regs::kDdReadsUnshared);
  std::vector<uint8_t> out(std::size_t(n) * regs::kOutElementBytes);
  t_.CopyFromDevice(out_, out.data(), out.size());
  UnpackOut(out, n, weights, stats);
  return c;
}

}  // namespace posefilter::hw::host
