// src/hw/diffusion.h — the diffusion module of §7.6 (Fig. 7.26): for each particle of the next
// set, read its resampled sample from the input sample memory, apply one move chosen by an
// LFSR, write the output sample memory (ping-pong: the two memories alternate each iteration
// so no sample is overwritten while it is still to be read).
//
// Moves (§7.6; order = posefilter::Move's first 13, so the driver maps probabilities 1:1):
//   0–3   translate x | y | z | all three      by σ_t·Z (Z ~ N(0,1), Box–Muller)
//   4–7   rotate roll | pitch | yaw | all three by σ_r·Z
//   8–10  flip roll | pitch | yaw: add π
//   11    neighbouring cell of the same pyramid level (one of 8, LFSR-chosen)
//   12    the matching cell of another pyramid level (the cell containing this cell's centre)
//   13    ours, optional (probability 0 = thesis): quarter turn ±π/2 about the object's own x
//         axis. With T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll), R·Rx(±π/2) = Rz·Ry·Rx(roll ± π/2): a
//         pure angle add. Quarter turns about the object's y/z axes (the reference engine's
//         kQuarterTurn) need a rotation-matrix → Euler decomposition and are NOT modelled; nor
//         is the reference's ICP move (it needs a 6×6 solve per particle).
//   14    ours, optional (probability 0 = thesis): align depth — shift the position along the
//         camera's viewing ray through the object origin so its depth changes by the mean depth
//         difference Δ = mean(z_s − z_r) the raster core measured for this particle at the last
//         weighing (depth_diff_sum / depth_diff_count, the side-band word of the sample memory,
//         computed by the top's CollectStats). Like the reference's kAlignDepth
//         (src/filter/diffusion.cc): c = C·p + t (camera frame), p' = p + Cᵀ(Δ·c/c_z). Since
//         Cᵀc = p − o with o = −Cᵀt the camera centre in the base frame, the kernel computes
//         v = p − o, c_z = (row 2 of C)·v, k = Δ/c_z (one divider), p' = p + k·v: 6 multiplies and
//         one division; nothing happens when c_z ≤ kMinAlignCzRaw (behind/at the camera).
// Cell moves shift the position by the difference of the two cells' heuristic-volume centres
// and change the cell (like the reference engine); a target off the grid or with an invalid
// volume (ours: a volume is valid iff min ≤ max on all three axes — the driver writes an
// inverted volume for cells without one) leaves the particle unchanged.
// Spread (§7.6, linear decay): σ_t = d·σ_t0, σ_r = d·σ_r0, d = max(1 − w_best, min_fraction)
// (min_fraction = 0 is the thesis's pure linear decay; ours: a floor, like the reference).
// Quantization: the noise is rounded to the sample's LSB (xyz 2^-10 m, angles 2^-8 rad), so a
// σ below ~half an LSB moves most particles by 0 — Table 7.1 [HARDWARE.md]'s resolution. Ours, optional
// (sigma_floor_lsb = 1; 0 = thesis): σ_t and σ_r are raised to at least one LSB of their output
// format (2^-10 m, 2^-8 rad) after the decay, so late diffusion keeps moving: the reference's
// floor 0.05·σ_t0 = 0.5 mm is about half an xyz_t LSB and would otherwise leave ≈ 2/3 of the
// translation draws at 0. One compare and a mux per σ. Translations
// saturate at ±4 m; rotation noise is clamped to ±π, then every angle is wrapped to (−π, π]
// with π = 804·2^-8 (two conditional ±2π steps: exact for any angle_t input).
// The first num_elite particles are copied unchanged.
#pragma once

#include <stdint.h>

#ifndef __SYNTHESIS__
#include <string>
#endif

#include "hw/box_muller.h"
#include "hw/burst.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/lfsr.h"

// HLS loop labels are for the synthesis reports; g++ sees them as unused labels.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"
#endif

namespace posefilter::hw {

enum HwMove {
  kHwTranslateX = 0,
  kHwTranslateY,
  kHwTranslateZ,
  kHwTranslateAll,
  kHwRotateRoll,
  kHwRotatePitch,
  kHwRotateYaw,
  kHwRotateAll,
  kHwFlipRoll,
  kHwFlipPitch,
  kHwFlipYaw,
  kHwNeighbourCell,
  kHwOtherLevel,
  kHwQuarterRoll,  // ours
  kHwAlignDepth,   // ours
  kNumHwMoves
};
constexpr int kNumThesisMoves = 13;

// ours (not in Table 7.1 [HARDWARE.md]): a diffusion σ, metres or radians, ufixed<18,2> (0 … 4, LSB 2^-16).
typedef ap_ufixed<18, 2> sigma_t;

// ours (not in Table 7.1 [HARDWARE.md]): the per-particle mean depth difference Δ = mean(z_s − z_r) of the
// sample memory's side-band, metres, fixed<18,3> (±4 m, LSB 2^-15 m ≈ 0.03 mm; |Δ| ≤ the
// raster core's align_band in practice).
typedef ap_fixed<18, 3> depth_off_t;
// ours: a coefficient of the camera rotation C (row 2, for c_z), fixed<18,2> (LSB 2^-16), and
// the camera centre o in the base frame, metres, fixed<15,5> (±16 m; LSB 2^-10 m = xyz_t's).
typedef ap_fixed<18, 2> ray_coef_t;
typedef ap_fixed<15, 5> cam_pos_t;
// Smallest camera depth c_z (raw 2^-10 m) at which the align-depth move acts: 16 mm.
constexpr int kMinAlignCzRaw = 16;

// Angle constants in angle_t raw units (2^-8 rad).
constexpr int kPiRaw = 804;      // round(π·256)
constexpr int kTwoPiRaw = 1608;  // 2·kPiRaw, so two flips return exactly to the start
constexpr int kHalfPiRaw = 402;

// Defaults = the thesis configuration (ThesisDiffusionParams): the 13 moves equally likely (the
// thesis gives no weights), no quarter turn, the reference engine's σ0, no σ floor.
struct DiffusionParams {
  // Cumulative move thresholds on a 15-bit LFSR word v ∈ [1, 32767]: the move is the first m
  // with v ≤ move_thr[m]. Non-decreasing, move_thr[kNumHwMoves − 1] = 32767 (equal
  // neighbours = probability 0). Set with SetMoveProbabilities on the host.
  ap_uint<15> move_thr[kNumHwMoves] = {2521,  5041,  7562,  10082, 12603, 15123, 17644, 20164,
                                       22685, 25205, 27726, 30246, 32767, 32767, 32767};
  sigma_t sigma_t0 = sigma_t(0.01);       // translation σ at w_best = 0, metres, [0, 4)
  sigma_t sigma_r0 = sigma_t(0.2);        // rotation σ at w_best = 0, radians, [0, 4)
  weight_t min_fraction = weight_t(0.0);  // floor of the decay d, [0, 1] (0 = thesis)
  ap_uint<1> sigma_floor_lsb = 0;         // ours: 1 = σ_t ≥ 2^-10 m, σ_r ≥ 2^-8 rad (0 = thesis)
  // ours, align-depth move geometry (SetAlignDepthCamera): row 2 of C (base → camera) and the
  // camera centre o = −Cᵀt in the base frame. All 0 (the default) = the move never acts.
  ray_coef_t cam_row_z[3] = {ray_coef_t(0), ray_coef_t(0), ray_coef_t(0)};
  cam_pos_t cam_origin[3] = {cam_pos_t(0), cam_pos_t(0), cam_pos_t(0)};
#ifndef __SYNTHESIS__
  // Host-side check (the driver turns a false into posefilter::Error naming *why).
  bool IsValid(std::string* why) const {
    for (int m = 1; m < kNumHwMoves; ++m)
      if (move_thr[m] < move_thr[m - 1]) return *why = "move_thr must be non-decreasing", false;
    if (move_thr[kNumHwMoves - 1] != 32767) return *why = "move_thr's last entry must be 32767", false;
    if (RawOf(min_fraction) > ap_uint<18>(1u << 17)) return *why = "min_fraction must be in [0, 1]", false;
    return true;
  }
#endif
};

// ---- Host-side setup (driver boundary; not synthesized) ----
#ifndef __SYNTHESIS__
// Move thresholds from probabilities (any non-negative scale, normalised here). False, with
// *why, when a probability is negative/not finite or all are 0.
inline bool SetMoveProbabilities(DiffusionParams* p, const double prob[kNumHwMoves], std::string* why) {
  double total = 0;
  for (int m = 0; m < kNumHwMoves; ++m) {
    if (!(prob[m] >= 0) || prob[m] > 1e300) return *why = "move probabilities must be finite and >= 0", false;
    total += prob[m];
  }
  if (!(total > 0)) return *why = "move probabilities must not all be 0", false;
  double acc = 0;
  for (int m = 0; m < kNumHwMoves; ++m) {
    acc += prob[m];
    long t = long(acc / total * 32767.0 + 0.5);
    if (t > 32767) t = 32767;
    p->move_thr[m] = unsigned(t);
  }
  // The last move with non-zero probability must reach the top.
  for (int m = kNumHwMoves - 1; m >= 0; --m) {
    if (prob[m] > 0) {
      for (int k = m; k < kNumHwMoves; ++k) p->move_thr[k] = 32767u;
      break;
    }
  }
  return true;
}
// The thesis configuration (= the defaults of DiffusionParams).
inline DiffusionParams ThesisDiffusionParams() { return DiffusionParams{}; }
// The align-depth geometry from the base→camera extrinsic C (rot row-major, trans metres).
// False, with *why, when the camera centre lies outside ±16 m (cam_pos_t) or a value is not
// finite.
inline bool SetAlignDepthCamera(DiffusionParams* p, const double rot[9], const double trans[3], std::string* why) {
  for (int k = 0; k < 3; ++k) {
    double o = 0;
    for (int r = 0; r < 3; ++r) o -= rot[3 * r + k] * trans[r];  // o = −Cᵀt
    if (!(o > -15.99 && o < 15.99)) return *why = "the camera centre must lie within +-16 m (fixed<15,5>)", false;
    p->cam_origin[k] = cam_pos_t(ap_fixed<15, 5, AP_RND, AP_SAT>(o));
    if (!(rot[6 + k] >= -1.01 && rot[6 + k] <= 1.01)) return *why = "camera rotation entries must lie in [-1, 1]", false;
    p->cam_row_z[k] = ray_coef_t(ap_fixed<18, 2, AP_RND, AP_SAT>(rot[6 + k]));
  }
  return true;
}
#endif

// What one particle's move consumes from the random sources (drawn every clock).
struct MoveDraw {
  int move;        // HwMove
  gauss_t z[3];    // Gaussians (x/y/z or roll/pitch/yaw)
  ap_uint<5> aux;  // bits 2..0: neighbour direction; bit 3: other level; bit 4: quarter sign
};

// The random sources of the module: one LFSR15 for the move, one for the auxiliary bits, two
// Box–Muller units (4 Gaussians per clock, 3 used).
struct DiffusionRng {
  Lfsr15 move_lfsr;
  Lfsr15 aux_lfsr;
  GaussianSource g0, g1;

  // All six LFSR seeds derived from one 32-bit seed by an integer hash of (seed, k), so they
  // differ from each other for every seed, 0 included (a zero LFSR seed → its default).
  static uint32_t SubSeed(uint32_t seed, uint32_t k) {
    uint32_t h = (seed ^ (k * 0x9E3779B9u)) * 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return h;
  }
  explicit DiffusionRng(uint32_t seed = 1)
      : move_lfsr(SubSeed(seed, 1) & 0x7FFFu),
        aux_lfsr(SubSeed(seed, 2) & 0x7FFFu),
        g0(SubSeed(seed, 3) & 0x3FFFFu, SubSeed(seed, 4) & 0x7FFFu),
        g1(SubSeed(seed, 5) & 0x3FFFFu, SubSeed(seed, 6) & 0x7FFFu) {}

  MoveDraw Draw(const DiffusionParams& p) {
#pragma HLS INLINE
    MoveDraw d;
    const ap_uint<15> v = move_lfsr.Draw();
    // Priority encoder over parallel comparators: the first m with v ≤ move_thr[m].
    int m = kNumHwMoves - 1;
  DIFFUSION_MOVE_SELECT:
    for (int k = kNumHwMoves - 1; k >= 0; --k) {
#pragma HLS UNROLL
      if (v <= p.move_thr[k]) m = k;
    }
    d.move = m;
    d.aux = aux_lfsr.Draw().range(4, 0);
    gauss_t spare;
    g0.Pair(&d.z[0], &d.z[1]);
    g1.Pair(&d.z[2], &spare);
    return d;
  }
};

// ---- Pyramid geometry of the thesis (15×20, 30×40, 60×80; cells row-major, coarse first) ----
struct CellRC {
  int level, row, col;
};
// (Same grid as postprocess.h; guarded so both headers can be included in one TU.)
#ifndef POSEFILTER_HW_PYRAMID_GRID
#define POSEFILTER_HW_PYRAMID_GRID
constexpr int kLevelRows[3] = {15, 30, 60};
constexpr int kLevelCols[3] = {20, 40, 80};
#endif
constexpr int kLevelOffset[3] = {0, 300, 1500};

// cell → (level, row, col): two compares, and a division by cols = 5·2^(level+2) as a shift
// and a multiply by ⌈2^16/5⌉ (exact for the ≤ 300 quotients that occur).
inline CellRC CellToRC(cell_index_t cell) {
#pragma HLS INLINE
  CellRC r;
  const int c = cell.to_int();
  r.level = c < kLevelOffset[1] ? 0 : (c < kLevelOffset[2] ? 1 : 2);
  const int local = c - kLevelOffset[r.level];
  const int q = local >> (r.level + 2);
  r.row = (q * 13108) >> 16;
  r.col = local - r.row * kLevelCols[r.level];
  return r;
}
inline cell_index_t RCToCell(int level, int row, int col) {
#pragma HLS INLINE
  return cell_index_t(kLevelOffset[level] + ((row * 5) << (level + 2)) + col);
}

inline bool VolumeValid(const HeuristicVolume& v) {
#pragma HLS INLINE
  return v.x_min <= v.x_max && v.y_min <= v.y_max && v.z_min <= v.z_max;
}

// The target of a cell move, or −1 (off the grid, invalid volume, not a cell move).
inline int MoveTargetCell(cell_index_t cell, int move, ap_uint<5> aux, const HeuristicVolume volumes[kNumCells]) {
#pragma HLS INLINE
  static constexpr int kDr[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
  static constexpr int kDc[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
  const CellRC rc = CellToRC(cell);
  int target = -1;
  if (move == kHwNeighbourCell) {
    const int k = aux.range(2, 0).to_int();
    const int r = rc.row + kDr[k], c = rc.col + kDc[k];
    if (r >= 0 && r < kLevelRows[rc.level] && c >= 0 && c < kLevelCols[rc.level])
      target = RCToCell(rc.level, r, c).to_int();
  } else if (move == kHwOtherLevel) {
    int other = aux[3] ? 1 : 0;
    if (other >= rc.level) ++other;
    int r, c;
    if (other > rc.level) {  // finer: the cell under this cell's centre (row·2^d + 2^(d−1))
      const int d = other - rc.level;
      r = (rc.row << d) + (1 << (d - 1));
      c = (rc.col << d) + (1 << (d - 1));
    } else {                 // coarser: the cell containing it
      const int d = rc.level - other;
      r = rc.row >> d;
      c = rc.col >> d;
    }
    target = RCToCell(other, r, c).to_int();
  }
  if (target >= 0 && !VolumeValid(volumes[target])) target = -1;
  return target;
}

namespace diffusion_detail {

// Saturating add of a raw delta (2^-10 m) to an xyz_t.
inline xyz_t AddXyz(xyz_t x, ap_int<24> delta) {
#pragma HLS INLINE
  ap_int<25> v = ap_int<25>(RawOf(x)) + ap_int<25>(delta);
  if (v > 4095) v = 4095;
  if (v < -4096) v = -4096;
  return FixedFromRaw<13, 3>(ap_int<13>(v));
}
// Adds a raw delta (2^-8 rad, |delta| ≤ π) to an angle and wraps to (−π, π].
inline angle_t AddAngleWrapped(angle_t a, int delta) {
#pragma HLS INLINE
  int v = RawOf(a).to_int() + delta;
ANGLE_WRAP:
  for (int k = 0; k < 2; ++k) {
#pragma HLS UNROLL
    if (v > kPiRaw) v -= kTwoPiRaw;
    else if (v <= -kPiRaw) v += kTwoPiRaw;
  }
  return FixedFromRaw<12, 4>(ap_int<12>(v));
}
// Noise σ·z: σ raw (2^-16) × z raw (2^-14) = 2^-30, rounded to 2^-shift_to (10 or 8).
inline ap_int<24> ScaledNoise(ap_uint<19> sigma_raw, gauss_t z, int out_frac_bits) {
#pragma HLS INLINE
  ap_int<40> n = ap_int<40>(sigma_raw) * ap_int<40>(RawOf(z));
  const int sh = 30 - out_frac_bits;
  ap_int<40> r = (n + (ap_int<40>(1) << (sh - 1))) >> sh;
  if (r > ap_int<40>(4000000)) r = 4000000;
  if (r < ap_int<40>(-4000000)) r = -4000000;
  return ap_int<24>(r);
}

}  // namespace diffusion_detail

// σ decay d = max(1 − w_best, min_fraction) as a raw 2^-17 word (0 … 2^17).
inline ap_uint<18> DecayRaw(weight_t w_best, weight_t min_fraction) {
#pragma HLS INLINE
  ap_int<20> d = ap_int<20>(1 << 17) - ap_int<20>(RawOf(w_best));
  ap_int<20> floor_raw = ap_int<20>(RawOf(min_fraction));
  if (floor_raw > ap_int<20>(1 << 17)) floor_raw = 1 << 17;
  if (d < floor_raw) d = floor_raw;
  return ap_uint<18>(d);
}

// The align-depth shift of one position (raw 2^-10 m per axis) for a depth offset off:
// v = p − o, c_z = row_z·v, k = off/c_z, shift = k·v (see the header). Returns false (no
// shift) when c_z ≤ kMinAlignCzRaw.
inline bool AlignDepthShift(const Sample& s, depth_off_t off, const DiffusionParams& p, ap_int<24> shift[3]) {
#pragma HLS INLINE
  // v raw 2^-10 m (|v| < 20 m: 16 bits + sign).
  const ap_int<18> v[3] = {ap_int<18>(RawOf(s.x)) - ap_int<18>(RawOf(p.cam_origin[0])),
                           ap_int<18>(RawOf(s.y)) - ap_int<18>(RawOf(p.cam_origin[1])),
                           ap_int<18>(RawOf(s.z)) - ap_int<18>(RawOf(p.cam_origin[2]))};
  // c_z raw 2^-26 (coef 2^-16 × v 2^-10) → 2^-10, rounded.
  ap_int<40> cz26 = 0;
ALIGN_CZ:
  for (int k = 0; k < 3; ++k) {
#pragma HLS UNROLL
    cz26 += ap_int<40>(RawOf(p.cam_row_z[k])) * ap_int<40>(v[k]);
  }
  const ap_int<40> cz = (cz26 + (ap_int<40>(1) << 15)) >> 16;
  shift[0] = shift[1] = shift[2] = 0;
  if (cz <= kMinAlignCzRaw) return false;
  // k raw 2^-20: (off raw 2^-15 << 15) / c_z raw 2^-10 (one signed divider; |k| < 2^13).
  const ap_int<48> num = ap_int<48>(RawOf(off)) << 15;
  const ap_int<48> k20 = num / ap_int<48>(cz);
ALIGN_SHIFT:
  for (int k = 0; k < 3; ++k) {
#pragma HLS UNROLL
    // k·v: 2^-20 × 2^-10 = 2^-30 → 2^-10, rounded half up; clamped like ScaledNoise.
    const ap_int<66> prod = k20 * v[k];
    ap_int<66> t = (prod + (ap_int<66>(1) << 19)) >> 20;
    if (t > ap_int<66>(4000000)) t = 4000000;
    if (t < ap_int<66>(-4000000)) t = -4000000;
    shift[k] = ap_int<24>(t);
  }
  return true;
}

// One move on one sample (pure function of its inputs: what the pipeline does per clock).
// off: the sample's side-band depth offset (read only by the align-depth move).
inline Sample ApplyMove(const Sample& s, const MoveDraw& d, weight_t w_best, const DiffusionParams& p,
                        const HeuristicVolume volumes[kNumCells], depth_off_t off = depth_off_t(0)) {
#pragma HLS INLINE
  using namespace diffusion_detail;
  const ap_uint<18> decay = DecayRaw(w_best, p.min_fraction);
  // σ raw at 2^-16: decay (2^-17) × σ0 (2^-16) >> 17.
  ap_uint<19> st = (ap_uint<36>(decay) * ap_uint<36>(RawOf(p.sigma_t0))) >> 17;
  ap_uint<19> sr = (ap_uint<36>(decay) * ap_uint<36>(RawOf(p.sigma_r0))) >> 17;
  // Ours (optional): σ at least one output LSB — 2^-10 m = 64 and 2^-8 rad = 256 raw 2^-16.
  if (p.sigma_floor_lsb == 1) {
    if (st < 64) st = 64;
    if (sr < 256) sr = 256;
  }
  Sample o = s;
  int rot[3] = {0, 0, 0};  // angle deltas, raw 2^-8
  switch (d.move) {
    case kHwTranslateX: o.x = AddXyz(s.x, ScaledNoise(st, d.z[0], 10)); break;
    case kHwTranslateY: o.y = AddXyz(s.y, ScaledNoise(st, d.z[0], 10)); break;
    case kHwTranslateZ: o.z = AddXyz(s.z, ScaledNoise(st, d.z[0], 10)); break;
    case kHwTranslateAll:
      o.x = AddXyz(s.x, ScaledNoise(st, d.z[0], 10));
      o.y = AddXyz(s.y, ScaledNoise(st, d.z[1], 10));
      o.z = AddXyz(s.z, ScaledNoise(st, d.z[2], 10));
      break;
    case kHwRotateRoll: rot[0] = ScaledNoise(sr, d.z[0], 8).to_int(); break;
    case kHwRotatePitch: rot[1] = ScaledNoise(sr, d.z[0], 8).to_int(); break;
    case kHwRotateYaw: rot[2] = ScaledNoise(sr, d.z[0], 8).to_int(); break;
    case kHwRotateAll:
      rot[0] = ScaledNoise(sr, d.z[0], 8).to_int();
      rot[1] = ScaledNoise(sr, d.z[1], 8).to_int();
      rot[2] = ScaledNoise(sr, d.z[2], 8).to_int();
      break;
    case kHwFlipRoll: rot[0] = kPiRaw; break;
    case kHwFlipPitch: rot[1] = kPiRaw; break;
    case kHwFlipYaw: rot[2] = kPiRaw; break;
    case kHwQuarterRoll: rot[0] = d.aux[4] ? kHalfPiRaw : -kHalfPiRaw; break;
    case kHwAlignDepth: {
      ap_int<24> sh[3];
      if (AlignDepthShift(s, off, p, sh)) {
        o.x = AddXyz(s.x, sh[0]);
        o.y = AddXyz(s.y, sh[1]);
        o.z = AddXyz(s.z, sh[2]);
      }
      break;
    }
    case kHwNeighbourCell:
    case kHwOtherLevel: {
      const int t = MoveTargetCell(s.cell, d.move, d.aux, volumes);
      if (t >= 0) {
        const HeuristicVolume& a = volumes[s.cell.to_int()];
        const HeuristicVolume& b = volumes[t];
        // Δcentre = ((b.min + b.max) − (a.min + a.max)) / 2, rounded half up, raw 2^-10.
        const ap_int<16> dx2 = (ap_int<16>(RawOf(b.x_min)) + RawOf(b.x_max)) - (ap_int<16>(RawOf(a.x_min)) + RawOf(a.x_max));
        const ap_int<16> dy2 = (ap_int<16>(RawOf(b.y_min)) + RawOf(b.y_max)) - (ap_int<16>(RawOf(a.y_min)) + RawOf(a.y_max));
        const ap_int<16> dz2 = (ap_int<16>(RawOf(b.z_min)) + RawOf(b.z_max)) - (ap_int<16>(RawOf(a.z_min)) + RawOf(a.z_max));
        o.x = AddXyz(s.x, ap_int<24>((dx2 + 1) >> 1));
        o.y = AddXyz(s.y, ap_int<24>((dy2 + 1) >> 1));
        o.z = AddXyz(s.z, ap_int<24>((dz2 + 1) >> 1));
        o.cell = t;
      }
      break;
    }
    default: break;
  }
  // Rotation noise clamped to ±π, then every angle wrapped (identity on angles in (−π, π]).
  for (int k = 0; k < 3; ++k) {
#pragma HLS UNROLL
    if (rot[k] > kPiRaw) rot[k] = kPiRaw;
    if (rot[k] < -kPiRaw) rot[k] = -kPiRaw;
  }
  o.roll = AddAngleWrapped(s.roll, rot[0]);
  o.pitch = AddAngleWrapped(s.pitch, rot[1]);
  o.yaw = AddAngleWrapped(s.yaw, rot[2]);
  return o;
}

// The module: out_mem[j] = move(in_mem[selected[j]]) for j ≥ num_elite, a plain copy for
// j < num_elite; n ≤ kMaxParticles particles, II = 1. w_best: the best weight of the set
// just weighed (sorter output [0]). in_off: the sample memory's side-band (per-particle
// depth offsets of the set just weighed, same indices as in_mem).
inline void Diffuse(const Sample in_mem[kMaxParticles], const depth_off_t in_off[kMaxParticles],
                    const particle_index_t selected[kMaxParticles], int n,
                    int num_elite, weight_t w_best, const DiffusionParams& params,
                    const HeuristicVolume volumes[kNumCells], DiffusionRng& rng,
                    Sample out_mem[kMaxParticles] HW_TRACE_PARAM) {
  if (n > kMaxParticles) n = kMaxParticles;
  // The moves read the sample memory at the resampled indices and the heuristic volumes at
  // two cells per particle (its own and the move's target): on-chip copies of the DDR arrays
  // (n × 88 + n × 18 bits, and kNumCells × 78 bits in a dual-port RAM: two reads per clock),
  // one burst each per call.
  Sample sample_mem[kMaxParticles];
  depth_off_t off_mem[kMaxParticles];
  HeuristicVolume volume_mem[kNumCells];
  BurstLoad<Sample, kMaxParticles>(in_mem, sample_mem, n);
  BurstLoad<depth_off_t, kMaxParticles>(in_off, off_mem, n);
  BurstLoad<HeuristicVolume, kNumCells>(volumes, volume_mem, kNumCells);
  HW_TRACE_MEM("diffusion", "DIFFUSION_LOAD_SAMPLES", uint64_t(n > 0 ? n : 0), 1, kBurstLoadDepth, kAxiReadLatency);
  HW_TRACE_MEM("diffusion", "DIFFUSION_LOAD_OFFSETS", uint64_t(n > 0 ? n : 0), 1, kBurstLoadDepth, kAxiReadLatency);
  HW_TRACE_MEM("diffusion", "DIFFUSION_LOAD_VOLUMES", kNumCells, 1, kBurstLoadDepth, kAxiReadLatency);
  int trips = 0;
DIFFUSION_SAMPLES:
  for (int j = 0; j < n; ++j) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    const Sample s = sample_mem[selected[j].to_int()];
    const depth_off_t off = off_mem[selected[j].to_int()];
    const MoveDraw d = rng.Draw(params);  // the sources advance every clock
    out_mem[j] = (j < num_elite) ? s : ApplyMove(s, d, w_best, params, volume_mem, off);
    ++trips;
  }
  // Depth: the align-depth path + the Box–Muller units' latency (latency.h), and out_mem is a
  // write burst to DDR, acknowledged after the write latency.
  HW_TRACE_MEM("diffusion", "DIFFUSION_SAMPLES", trips, 1, kDiffusionDepth + kAxiWriteLatency, kAxiWriteLatency);
}

}  // namespace posefilter::hw

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
