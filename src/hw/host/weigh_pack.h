// src/hw/host/weigh_pack.h — the byte images of the weighing accelerator's DDR buffers
// (weigh_accel.sv; the layouts are in src/hw/rtl/weigh_regs.json and docs/HARDWARE.md §16):
// little endian, elements back to back from the buffer's base. Where a buffer holds a type that
// crosses an HLS top's m_axi port too (depth_t, Window, ft_t, prob_t, cell_index_t,
// RasterCoreOutput), its element is that type as axi_pack.h lays it out. Host code (not a
// kernel), header only.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "hw/host/axi_pack.h"
#include "hw/host/weigh_regs.h"
#include "hw/top.h"

namespace posefilter::hw::host {

// Output record (64 bytes): RasterCoreOutput at 0 (48 bytes, axi_pack), weight at 48, index at 52.
constexpr int kOutRecordBytes = regs::kOutElementBytes;
constexpr int kOutWeightByte = 48;
constexpr int kOutIndexByte = 52;
// Whether weigh_regs.json's element sizes are axi_pack's (the layouts are computed at run time);
// WeighDriver checks it once.
inline bool LayoutsAgree() {
  return axi::PackedBytes<RasterCoreOutput>() == kOutWeightByte && axi::PackedBytes<depth_t>() == regs::kImgElementBytes &&
         axi::PackedBytes<Window>() == regs::kWinElementBytes && axi::PackedBytes<ft_t>() == regs::kFtElementBytes &&
         axi::PackedBytes<prob_t>() == regs::kProbElementBytes && axi::PackedBytes<cell_index_t>() == regs::kCellElementBytes;
}

// IMG: the first width·height pixels of the depth memory (row-major, stride width).
inline std::vector<uint8_t> PackImage(const depth_t* depth, int width, int height) {
  return axi::Pack(depth, width * height);
}
// WIN: n windows.
inline std::vector<uint8_t> PackWindows(const Window* windows, int n) { return axi::Pack(windows, n); }
// FT: 12 elements per particle (row-major 3 × 4), n particles.
inline std::vector<uint8_t> PackFt(const ft_t* ft, int n) { return axi::Pack(ft, n * kFtElements); }
// MODEL: kMaxVertices vertex words {x, y, z} (13-bit raw each, x high), then num_faces face
// words (face_t), each in 8 bytes.
inline std::vector<uint8_t> PackModel(const xyz_t vmem[3][kMaxVertices], const face_t* tri, int num_faces) {
  std::vector<uint8_t> out(std::size_t(kMaxVertices + num_faces) * regs::kModelElementBytes, 0);
  auto put = [&](int i, uint64_t w) {
    for (int b = 0; b < 8; ++b) out[std::size_t(i) * 8 + std::size_t(b)] = uint8_t(w >> (8 * b));
  };
  for (int i = 0; i < kMaxVertices; ++i) {
    uint64_t w = 0;
    for (int a = 0; a < 3; ++a) w = (w << 13) | (axi::RawBits(vmem[a][i]) & 0x1fff);
    put(i, w);
  }
  for (int f = 0; f < num_faces; ++f) put(kMaxVertices + f, axi::RawBits(tri[f]));
  return out;
}
// PROB: kNumCells class probabilities.
inline std::vector<uint8_t> PackProb(const prob_t* prob) { return axi::Pack(prob, kNumCells); }
// CELL: n cell indices.
inline std::vector<uint8_t> PackCells(const cell_index_t* cells, int n) { return axi::Pack(cells, n); }

// OUT: n records → the merger's (weight, index) words and forwarded core outputs.
inline void UnpackOut(const std::vector<uint8_t>& bytes, int n, WeightOut* weights, RasterCoreOutput* stats) {
  for (int p = 0; p < n; ++p) {
    const uint8_t* r = bytes.data() + std::size_t(p) * kOutRecordBytes;
    axi::Unpack(r, 1, &stats[p]);
    uint32_t w = 0, idx = 0;
    for (int b = 0; b < 4; ++b) w |= uint32_t(r[kOutWeightByte + b]) << (8 * b);
    for (int b = 0; b < 2; ++b) idx |= uint32_t(r[kOutIndexByte + b]) << (8 * b);
    axi::SetRawBits(weights[p].weight, w);
    axi::SetRawBits(weights[p].index, idx);
  }
}

}  // namespace posefilter::hw::host
