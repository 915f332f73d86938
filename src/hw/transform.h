// src/hw/transform.h — the full-transformation-matrix chain and the vertex multiplier of the
// render/score pipeline (thesis §7.5.2–7.5.3, Fig. 7.15–7.17, Listing 7.1 [HARDWARE.md]), plus the small
// fixed-point helpers the render kernels share (raw-bit views, the restoring divider).
//
// Full transformation (thesis §7.5.2): FT = P·C·(Tr·Rz)·(Ry·Rx), a 3×4 matrix that
// maps a model vertex (object frame, metres, homogeneous [x y z 1]) to homogeneous pixel
// coordinates (U, V, W): u = U/W, v = V/W (pixels, OpenCV convention), W = camera depth z (m).
// P is the pinhole intrinsic matrix K = [fx 0 cx; 0 fy cy; 0 0 1] — the pinhole
// projection of the float engines (docs/ALGORITHM.md §1), used instead of the OpenGL matrix of
// eq. 6.10 (docs/HARDWARE.md §7.2): its third row keeps W
// equal to the metric camera depth, so "depth recovery" (§7.5.3) needs no far/near unmapping.
//
// Fixed-point formats (ours; the thesis gives none for this module):
//   intr_t   fx, fy, cx, cy            ap_ufixed<28,12>  pixels, LSB 2^-16 px, ≤ 4095 px
//   trig_t   sin/cos, C's rotation     ap_fixed<18,2>    LSB 2^-16 (the SinCos output format)
//   ctrans_t C's translation           ap_fixed<24,4>    metres, LSB 2^-20 m ≈ 1 µm, ±8 m
//   ft_t     every FT element          ap_fixed<36,14,AP_RND,AP_SAT>  LSB 2^-22, ±8192
// Why ft_t: row 0/1 entries are fx·r + cx·r' (≤ ~900 px/m for the thesis camera) and the
// translation column fx·t_x + cx·t_z (≤ ~7000 px for |t| ≤ 8 m) need 14 integer bits; 22
// fractional bits keep the row-2 (depth) entries to 2.4e-7, so W is exact to < 1e-6 m and a
// vertex lands within ≪ 1/256 px of the exact projection from FT quantization alone (the
// 16-bit sines dominate: see docs/HARDWARE.md).
#pragma once

#include "hw/burst.h"
#include "hw/fx_math.h"
#include "hw/hw_types.h"
#include "hw/latency.h"

namespace posefilter::hw {

// ---- Formats of the render pipeline (ours, see above) ----
typedef ap_ufixed<28, 12> intr_t;
typedef ap_fixed<18, 2> trig_t;
typedef ap_fixed<24, 4> ctrans_t;
typedef ap_fixed<36, 14, AP_RND, AP_SAT> ft_t;
constexpr int kFtFracBits = 22;     // fractional bits of ft_t
constexpr int kXyzFracBits = 10;    // fractional bits of xyz_t (Table 7.1 [HARDWARE.md])
constexpr int kDepthFracBits = 10;  // fractional bits of depth_t (Table 7.1 [HARDWARE.md])
constexpr int kFtElements = 12;     // a 3×4 matrix, streamed row-major

// Camera of the chain: intrinsics P and the base→camera extrinsic C (eq. 6.9 [ALGORITHM.md]), host-quantized.
struct CameraParams {
  intr_t fx, fy, cx, cy;   // pixels
  trig_t rot[9];           // C's rotation, row-major
  ctrans_t trans[3];       // C's translation, metres
};

// A model vertex as the vertex multiplier streams it (object frame, metres).
struct Vertex {
  xyz_t x, y, z;
};

// ---- Raw-bit views (a fixed-point value as the integer of its bits) ----
// Raw<W>(x) = x · 2^F as a W-bit two's-complement integer (F = x's fractional bits).
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
inline ap_int<W> RawSigned(const ap_fixed<W, I, Q, O, N>& x) {
#pragma HLS INLINE
  ap_uint<W> bits = x.range(W - 1, 0);
  return ap_int<W>(bits);
}
template <int W, int I, ap_q_mode Q, ap_o_mode O, int N>
inline ap_uint<W> RawUnsigned(const ap_ufixed<W, I, Q, O, N>& x) {
#pragma HLS INLINE
  ap_uint<W> bits = x.range(W - 1, 0);
  return bits;
}

// ---- Restoring divider (one quotient bit per unrolled stage, fully pipelined: II = 1,
// latency QW cycles in hardware). q = floor(n / d) for n < d·2^QW. d = 0 or a quotient that
// does not fit QW bits sets *overflow and returns all ones.
template <int QW, int NW, int DW>
inline ap_uint<QW> DivFloor(const ap_uint<NW>& n, const ap_uint<DW>& d, bool* overflow) {
#pragma HLS INLINE
  static_assert(QW < NW, "quotient must be narrower than the dividend");
  ap_uint<QW> q = 0;
  ap_uint<NW> high = n >> QW;  // must be < d for the quotient to fit QW bits
  if (d == 0 || high >= d) {
    *overflow = true;
    q = ~ap_uint<QW>(0);
    return q;
  }
  *overflow = false;
  ap_uint<DW + 1> r = high;  // invariant r < d
DIV_STEPS:
  for (int i = QW - 1; i >= 0; --i) {
#pragma HLS UNROLL
    r = r << 1;
    r[0] = n[i];
    if (r >= d) {
      r = r - d;
      q[i] = 1;
    }
  }
  return q;
}

// ---- Full transformation matrix (§7.5.2) ----

// PC = P·C (3×4), once per call: "the camera times the projection ... has to be calculated
// only once whereas it is common to all the samples" (§7.5.2).
inline void ProjectionTimesCamera(const CameraParams& cam, ft_t pc[kFtElements]) {
#pragma HLS INLINE
  const intr_t f[2] = {cam.fx, cam.fy};
  const intr_t c[2] = {cam.cx, cam.cy};
PC_ROWS:
  for (int r = 0; r < 2; ++r) {
    for (int j = 0; j < 3; ++j) pc[4 * r + j] = f[r] * cam.rot[3 * r + j] + c[r] * cam.rot[6 + j];
    pc[4 * r + 3] = f[r] * cam.trans[r] + c[r] * cam.trans[2];
  }
  for (int j = 0; j < 3; ++j) pc[8 + j] = cam.rot[6 + j];
  pc[11] = cam.trans[2];
}

// FT of one sample from PC (eq. 7.6–7.7 [ALGORITHM.md]): TrRz needs no multiplication, RyRx four; the
// output is (PC·TrRz) row by row times the columns of RyRx, element by element (Fig. 7.15).
inline void SampleTransform(const Sample& s, const ft_t pc[kFtElements], ft_t ft[kFtElements]) {
#pragma HLS INLINE
  trig_t sx, cx, sy, cy, sz, cz;  // roll (x), pitch (y), yaw (z); fx_math SinCos, ≤ 2^-16
  SinCos(s.roll, &sx, &cx);
  SinCos(s.pitch, &sy, &cy);
  SinCos(s.yaw, &sz, &cz);
  // RyRx (eq. 7.7 [ALGORITHM.md]): [cy, sy·sx, sy·cx; 0, cx, −sx; −sy, cy·sx, cy·cx] — the four products.
  const trig_t sysx = sy * sx, sycx = sy * cx, cysx = cy * sx, cycx = cy * cx;
FT_ROWS:
  for (int r = 0; r < 3; ++r) {
#pragma HLS PIPELINE II = 4
    // M = PC·TrRz (eq. 7.6 [ALGORITHM.md]): columns (c_z, s_z, 0), (−s_z, c_z, 0), (0, 0, 1), (x, y, z, 1).
    const ft_t p0 = pc[4 * r], p1 = pc[4 * r + 1], p2 = pc[4 * r + 2], p3 = pc[4 * r + 3];
    const ft_t m0 = p0 * cz + p1 * sz;
    const ft_t m1 = p1 * cz - p0 * sz;
    const ft_t m3 = p0 * s.x + p1 * s.y + p2 * s.z + p3;
    ft[4 * r + 0] = m0 * cy - p2 * sy;
    ft[4 * r + 1] = m0 * sysx + m1 * cx + p2 * cysx;
    ft[4 * r + 2] = m0 * sycx - m1 * sx + p2 * cycx;
    ft[4 * r + 3] = m3;
  }
}

// The chain: FT of samples[0 … num_samples) streamed element by element (12 per sample,
// row-major) in sample order. One element per cycle (II = 1): the trigonometric products
// of the next sample hide behind the transmission of the current one (§7.5.2, Fig. 7.15).
inline void FullTransformChain(int num_samples, const Sample samples[kMaxParticles],
                               const CameraParams& cam, hls::stream<ft_t>& ft_out HW_TRACE_PARAM) {
  ft_t pc[kFtElements];
#pragma HLS ARRAY_PARTITION variable = pc complete
  ProjectionTimesCamera(cam, pc);
  // 36 MACs once per call: modelled as 12 cycles of 3 MACs (depth: latency.h).
  HW_TRACE("ft_chain", "PC_ROWS", kFtElements, 1, kPcRowsDepth);
FT_SAMPLES:
  for (int i = 0; i < num_samples; ++i) {
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 510
    ft_t ft[kFtElements];
#pragma HLS ARRAY_PARTITION variable = ft complete
    SampleTransform(samples[i], pc, ft);
  FT_ELEMENTS:
    for (int e = 0; e < kFtElements; ++e) {
#pragma HLS PIPELINE II = 1
      ft_out.write(ft[e]);
    }
  }
  // Depth: sample read (2) + SinCos (fx_math, ~6) + trig product (3) + PC·TrRz (4) +
  // ·RyRx (4) + output register (1) ≈ 20 cycles from sample read to first element (latency.h).
  HW_TRACE("ft_chain", "FT_ELEMENTS", uint64_t(num_samples) * kFtElements, 1, kFtElementsDepth);
}

// ---- Vertex multiplier (§7.5.3, Listing 7.1 [HARDWARE.md]) ----

// A face packs its three 10-bit vertex indices: corner k in bits [10k+9 : 10k] (Listing 7.1 [HARDWARE.md]).
inline face_t PackFace(vertex_index_t a, vertex_index_t b, vertex_index_t c) {
  face_t f = 0;
  f.range(9, 0) = a;
  f.range(19, 10) = b;
  f.range(29, 20) = c;
  return f;
}

// Reads the model once per round — per face three vertex reads (the case_select FSM of
// Listing 7.1 [HARDWARE.md]: a face word, then one vertex per cycle) — and writes each vertex to the
// streams of every core that has a particle in that round (num_particles may not be a
// multiple of num_cores: the last round feeds only its active cores). Core c of round r
// renders particle r·num_cores + c.
// vmem and tri_mem are DDR (m_axi): the face words are read in order but the vertices at the
// faces' indices, so the model is first copied on chip (model_v: 3 × kMaxVertices × 13 bits,
// one RAM per coordinate so that the three reads of a vertex take one clock; model_f:
// kMaxFaces × 30 bits), four bursts per call: three of kMaxVertices words and one of the
// num_faces face words.
inline void VertexMultiplier(int num_particles, int num_cores, int num_faces,
                             const xyz_t vmem[3][kMaxVertices], const face_t tri_mem[kMaxFaces],
                             hls::stream<Vertex> vert_out[kMaxRasterCores] HW_TRACE_PARAM) {
  xyz_t model_v[3][kMaxVertices];
#pragma HLS ARRAY_PARTITION variable = model_v complete dim = 1
  face_t model_f[kMaxFaces];
VM_LOAD:
  for (int k = 0; k < 3; ++k) BurstLoad<xyz_t, kMaxVertices>(vmem[k], model_v[k], kMaxVertices);
  BurstLoad<face_t, kMaxFaces>(tri_mem, model_f, num_faces);
  HW_TRACE_MEM("vertex_multiplier", "VM_LOAD_VERTICES", 3 * kMaxVertices, 1, 3 * kBurstLoadDepth, 3 * kAxiReadLatency);
  HW_TRACE_MEM("vertex_multiplier", "VM_LOAD_FACES", uint64_t(num_faces), 1, kBurstLoadDepth, kAxiReadLatency);
  uint64_t trips = 0;
VM_ROUNDS:
  for (int first = 0; first < num_particles; first += num_cores) {
#pragma HLS LOOP_TRIPCOUNT min = 51 max = 510
    const int active = num_particles - first < num_cores ? num_particles - first : num_cores;
    face_t face = 0;
  VM_VERTICES:
    for (int i = 0; i < 3 * num_faces; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 36 max = 6144
      const int corner = i % 3;
      if (corner == 0) face = model_f[i / 3];
      const vertex_index_t idx = face.range(10 * corner + 9, 10 * corner);
      Vertex v;
      v.x = model_v[0][idx];
      v.y = model_v[1][idx];
      v.z = model_v[2][idx];
    VM_COPY:
      for (int c = 0; c < kMaxRasterCores; ++c) {
#pragma HLS UNROLL
        if (c < active) vert_out[c].write(v);
      }
    }
    trips += uint64_t(3) * num_faces;
  }
  // Depth: face word read (2) + vertex BRAM read (2) + stream write (1) (latency.h).
  HW_TRACE("vertex_multiplier", "VM_VERTICES", trips, 1, kVmVerticesDepth);
}

}  // namespace posefilter::hw
