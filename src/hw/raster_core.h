// src/hw/raster_core.h — one raster core of the render/score pipeline (thesis §7.5.3 "Raster
// Core (partial inlier)", Fig. 7.20; rasterization eq. 6.12–6.22 [ALGORITHM.md]; soft inlier §7.5.1).
//
// For each of its particles a core: stores the particle's depth fragment (the window's
// pixels, from the depth distributor) and counts its valid pixels (N_depth); reads the
// particle's FT (3×4, from the FT distributor); for each model face (three vertices from the
// vertex multiplier) transforms and projects the vertices, culls back faces (2·Area ≤ 0,
// §6.2), rasterizes the face inside the window with Pineda edge functions in exact integer
// arithmetic (eq. 6.12–6.20), recovers the perspective-correct depth (eq. 6.21–6.22 [ALGORITHM.md] on 1/z)
// and compares it with the scene depth (soft inlier, §7.5.1) — and outputs the numerator and
// denominators of the weight (eq. 7.4 [ALGORITHM.md]) plus our extensions' counters.
//
// It implements exactly the rasterization rules of include/posefilter/render.h (pixel
// centres at integer coordinates, vertices snapped to 1/256 px with round-half-away-from-
// zero, edge ownership A > 0 or (A = 0 and B > 0), triangles with a vertex nearer than
// `near` skipped), so it covers the same pixels as ScoreReference up to the rounding of the
// snapped vertex positions (see docs/HARDWARE.md). Two modes (runtime switch):
//   zbuffer = 0: the thesis's mode: no z-buffer, every front-face fragment is compared
//               directly while rasterizing (§7.5.1);
//   zbuffer = 1: ours: a per-core window z-buffer (kMaxWindow² words); after the faces, one
//               pass over the window compares the nearest fragment of each pixel and counts
//               the silhouette edge samples (n_edge, n_edge_continued).
//
// Number formats (ours; raw integers are the words of the fixed-point value, binary point
// noted as "Fn" = n fractional bits):
//   FT element            ap_int<36>  F22 (ft_t)        vertex coordinate  ap_int<13> F10 (xyz_t)
//   U, V, W (homogeneous)  ap_int<52>  F32 (exact products)
//   screen x, y            ap_int<23>  F8  (1/256 px; guard band ±8192 px)
//   1/W per vertex         ap_uint<32> F26 (1/m; W ≥ 1/64 m)
//   edge functions, 2·Area ap_int<50>  F16 (exact)
//   recovered depth z_r    ap_uint<24> F20 (m, < 16 m)      z-buffer word  ap_uint<18> F16
//   soft inlier χ          ap_uint<11> F10 (0 … 1)          Σχ             ap_ufixed<42,32>
#pragma once

#include "hw/dataflow.h"
#include "hw/distributor.h"
#include "hw/hw_types.h"
#include "hw/latency.h"
#include "hw/transform.h"

#ifndef __SYNTHESIS__
#include <cmath>
#include <string>
#endif

namespace posefilter::hw {

// ---- Formats (ours) ----
typedef ap_ufixed<24, 4> dist_t;      // a distance or depth parameter, metres, F20
typedef ap_ufixed<20, 12> inv_thr_t;  // 1/thr1, 1/metres, F8
typedef ap_ufixed<42, 32> inlier_t;   // Σχ, F10 (up to 2^32 fragments)
typedef ap_fixed<56, 36> diff_sum_t;  // Σ(z_s − z_r), metres, F20
typedef ap_uint<32> count_t;          // fragment / pixel counts
typedef ap_uint<12> face_count_t;     // ≤ kMaxFaces
typedef ap_uint<18> zbuf_word_t;      // z-buffer word: z_r in F16 (15 µm), kZbufEmpty = empty

constexpr int kSubpixelBits = 8;                       // 1/256 px (render.h)
constexpr int kGuardBandSubpixels = 1 << 21;           // |x|, |y| < 8192 px, else skipped
constexpr int kZbufEmpty = (1 << 18) - 1;              // no fragment yet
constexpr int kWindowPixels = kMaxWindow * kMaxWindow;  // depth fragment and z-buffer words

// Runtime parameters of the cores (the host converts and may change them per iteration —
// thr1 is annealed by the host, docs/ALGORITHM.md §9).
struct RasterParams {
  ap_uint<1> zbuffer;   // 1: window z-buffer (default, ours); 0: the thesis's z-buffer-free mode
  ap_uint<1> hard;      // 1: GRIP's hard inlier χ = [d ≤ hard_thr]; 0: soft inlier (default)
  dist_t thr1;          // soft inlier: χ = 1 up to thr1, 0 from 2·thr1 (default 2^-8 m)
  inv_thr_t inv_thr1;   // 1/thr1 (the host's reciprocal: the ramp 2 − d/thr1 is one multiply)
  dist_t hard_thr;      // hard mode threshold (default 0.005 m)
  dist_t align_band;    // |z_s − z_r| band of depth_diff_sum/count (default 0.05 m)
  dist_t edge_band;     // silhouette edge "continued" band (default 0.01 m)
  dist_t near_plane;    // faces with a vertex at W < near are skipped (default 0.05 m, ≥ 1/64)
};

#ifndef __SYNTHESIS__
// Defaults of the reference engine (docs/ALGORITHM.md), for the host and the tests.
inline RasterParams DefaultRasterParams() {
  RasterParams p;
  p.zbuffer = 1;
  p.hard = 0;
  p.thr1 = dist_t(1.0 / 256);
  p.inv_thr1 = inv_thr_t(256.0);
  p.hard_thr = dist_t(0.005);
  p.align_band = dist_t(0.05);
  p.edge_band = dist_t(0.01);
  p.near_plane = dist_t(0.05);
  return p;
}

// Software check for the driver: names the violated constraint in *why.
inline bool RasterParamsAreValid(const RasterParams& p, std::string* why) {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  const double thr1 = p.thr1.to_double(), inv = p.inv_thr1.to_double();
  if (!(thr1 > 0)) return fail("thr1 must be > 0 (at least 2^-20 m)");
  if (!(inv > 0) || std::fabs(inv * thr1 - 1) > 0.01)
    return fail("inv_thr1 must equal 1/thr1 within 1% (thr1 in [2^-12, 8) m)");
  if (!(p.hard_thr.to_double() > 0)) return fail("hard_thr must be > 0");
  if (!(p.edge_band.to_double() > 0)) return fail("edge_band must be > 0");
  if (!(p.near_plane.to_double() >= 1.0 / 64)) return fail("near_plane must be >= 1/64 m");
  return true;
}
#endif

// One core's result for one particle (the numerator and denominators of eq. 7.4 [ALGORITHM.md] and the
// counters of the reference's ScoreKernelResult).
struct RasterCoreOutput {
  inlier_t inlier_sum;         // I = Σχ over counted fragments
  count_t n_raster;            // counted fragments (z-buffer: covered pixels)
  count_t n_occluded;          // counted fragments with χ = 0 and z_s < z_r (occlusion-aware N_raster)
  count_t n_depth;             // valid (non-zero) depth pixels of the window: N_depth
  diff_sum_t depth_diff_sum;   // Σ(z_s − z_r) over fragments with |z_s − z_r| ≤ align_band
  count_t depth_diff_count;
  count_t n_edge;              // z-buffer mode: silhouette edge samples
  count_t n_edge_continued;    // … whose scene depth is within edge_band of the rendering
  face_count_t faces_front;    // faces that passed the near/guard test and culling
  face_count_t faces_total;
};

// Per-core memories: the particle's depth fragment and the window z-buffer, row stride
// kMaxWindow (BRAM: 40000 × 12 bit and 40000 × 18 bit). Owned by the caller (the top keeps
// one per core; in C simulation it is too large for the stack).
struct RasterCoreMemory {
  depth_t frag[kWindowPixels];
  zbuf_word_t zbuf[kWindowPixels];
};

namespace raster_detail {

// A projected vertex: snapped screen position (F8) and 1/W (F26); ok = false when W < near,
// 1/W overflows or the position leaves the guard band (the face is skipped).
struct ScreenVertex {
  ap_int<23> x, y;
  ap_uint<32> iz;
  bool ok;
};

// round(256·num/den) for den > 0, half away from zero (llround of render.h's snapping).
// Returns false outside the guard band.
inline bool SnapRatio(const ap_int<52>& num, const ap_int<52>& den, ap_int<23>* out) {
#pragma HLS INLINE
  const bool neg = num < 0;
  const ap_uint<52> mag = neg ? ap_uint<52>(-num) : ap_uint<52>(num);
  const ap_uint<54> d2 = ap_uint<54>(den) << 1;
  const ap_uint<62> n2 = (ap_uint<62>(mag) << (kSubpixelBits + 1)) + ap_uint<62>(den);
  bool overflow = false;
  const ap_uint<22> q = DivFloor<22>(n2, d2, &overflow);  // floor(|u|·256 + 1/2)
  if (overflow || q >= kGuardBandSubpixels) return false;
  *out = neg ? ap_int<23>(-ap_int<23>(q)) : ap_int<23>(q);
  return true;
}

// Transform (FT·[v;1]), projection and snapping of one vertex.
inline ScreenVertex ProjectVertex(const ap_int<36> ft[kFtElements], const Vertex& v, const ap_int<52>& near_w) {
#pragma HLS INLINE
  const ap_int<13> p[3] = {RawSigned(v.x), RawSigned(v.y), RawSigned(v.z)};
  ap_int<52> h[3];  // U, V, W in F32
  for (int r = 0; r < 3; ++r) {
#pragma HLS UNROLL
    ap_int<52> acc = ap_int<52>(ft[4 * r + 3]) << kXyzFracBits;
    for (int j = 0; j < 3; ++j) acc += ap_int<52>(ft[4 * r + j] * p[j]);
    h[r] = acc;
  }
  ScreenVertex s;
  s.ok = false;
  s.x = 0;
  s.y = 0;
  s.iz = 0;
  if (h[2] < near_w) return s;
  bool overflow = false;
  // 1/W in F26: floor(2^(26+32) / W_raw); overflows for W < 1/64 m.
  s.iz = DivFloor<32>(ap_uint<60>(1) << 58, ap_uint<52>(h[2]), &overflow);
  if (overflow) return s;
  if (!SnapRatio(h[0], h[2], &s.x)) return s;
  if (!SnapRatio(h[1], h[2], &s.y)) return s;
  s.ok = true;
  return s;
}

// Number of significant bits of a positive value (a priority encoder).
inline int BitLength(const ap_int<50>& a) {
#pragma HLS INLINE
  int len = 0;
  for (int i = 0; i < 49; ++i) {
#pragma HLS UNROLL
    if (a[i]) len = i + 1;
  }
  return len;
}

// Depth recovery (§7.5.3, eq. 6.21–6.22 [ALGORITHM.md] applied to 1/z): with the normalised edge values
// e_k' = e_k >> sh (λ_k = e_k' / Σe'), 1/z_r = Σ λ_k/W_k, so z_r = Σe' / Σ(e_k'·(1/W_k)).
// Returns z_r in F20, floor, saturated to 16 m.
inline ap_uint<24> RecoverDepth(const ap_int<50> e[3], int sh, const ap_uint<32> iz[3]) {
#pragma HLS INLINE
  ap_uint<26> sum_e = 0;
  ap_uint<58> sum_ez = 0;  // F26
  for (int k = 0; k < 3; ++k) {
#pragma HLS UNROLL
    const ap_uint<24> en = ap_uint<24>(e[k] >> sh);
    sum_e += en;
    sum_ez += ap_uint<58>(en) * iz[k];
  }
  bool overflow = false;
  // z·2^20 = Σe'·2^(26+20) / Σe'·iz
  const ap_uint<24> z = DivFloor<24>(ap_uint<72>(sum_e) << 46, sum_ez, &overflow);
  return overflow ? ap_uint<24>(~ap_uint<24>(0)) : z;
}

// Accumulators of one particle.
struct Accumulators {
  ap_uint<42> inlier_raw;   // F10
  count_t n_raster, n_occluded, n_depth, diff_count, n_edge, n_edge_continued;
  ap_int<56> diff_raw;      // F20
  face_count_t faces_front, faces_total;
};

// Soft inlier / hard inlier of one counted fragment (§7.5.1, erratum fixed, docs/HARDWARE.md §8:
// continuous ramp χ = 2 − d/thr1 on thr1 < d < 2·thr1) and the occlusion / depth-alignment
// counters. z_r and z_s in F20; z_s = 0 is missing depth (never an inlier, counts nothing).
inline void CompareFragment(const ap_uint<24>& zr, const ap_uint<24>& zs, const RasterParams& prm,
                            Accumulators* acc) {
#pragma HLS INLINE
  if (zs == 0) return;
  const ap_int<26> d = ap_int<26>(zs) - ap_int<26>(zr);  // z_s − z_r, F20
  const ap_uint<25> ad = d < 0 ? ap_uint<25>(-d) : ap_uint<25>(d);
  const ap_uint<24> thr1 = RawUnsigned(prm.thr1);
  ap_uint<11> chi;  // F10
  if (prm.hard == 1) {
    chi = ad <= RawUnsigned(prm.hard_thr) ? 1024 : 0;
  } else if (ad <= thr1) {
    chi = 1024;
  } else if (ad >= (ap_uint<26>(thr1) << 1)) {
    chi = 0;
  } else {
    // (2 − ad·inv) in F28, rounded to F10 and clamped to [0, 1].
    const ap_int<48> ramp = (ap_int<48>(2) << 28) - ap_int<48>(ad * RawUnsigned(prm.inv_thr1));
    ap_int<48> r = (ramp + (ap_int<48>(1) << 17)) >> 18;
    if (r < 0) r = 0;
    if (r > 1024) r = 1024;
    chi = ap_uint<11>(r);
  }
  acc->inlier_raw += chi;
  if (chi == 0 && d < 0) ++acc->n_occluded;
  if (ad <= RawUnsigned(prm.align_band)) {
    acc->diff_raw += d;
    ++acc->diff_count;
  }
}

// Depth pixel (depth_t, F10) → F20.
inline ap_uint<24> DepthF20(const depth_t& z) {
#pragma HLS INLINE
  return ap_uint<24>(RawUnsigned(z)) << (20 - kDepthFracBits);
}

// A front face ready for the pixel stage: the triangle FIFO's entry between the vertex stage and
// the pixel stage of the core's internal dataflow (Fig. 7.20). Positions are relative to the
// window: the clipped bounding box starts at (x0, y0) and is w × h pixels (≥ 1 each).
struct TriangleSetup {
  ap_int<24> A[3], B[3];  // edge steps per pixel column / row, F8 (eq. 6.19–6.20 [ALGORITHM.md])
  ap_int<50> e0[3];       // edge functions at the box's first pixel, F16 (eq. 6.16–6.18 [ALGORITHM.md])
  ap_uint<1> own[3];      // 1: E_k = 0 is inside (owned edge: A > 0, or A = 0 and B > 0)
  ap_uint<32> iz[3];      // 1/W of the vertices, F26
  ap_uint<6> sh;          // normalisation of the barycentric weights (RecoverDepth)
  ap_uint<8> x0, y0;      // box origin in the window, pixels
  ap_uint<8> w, h;        // box size, pixels, 1 … kMaxWindow
  ap_uint<1> last;        // end of the particle's faces (no triangle in this entry)
};

// Vertex stage (Fig. 7.20 "vertex" + triangle setup): 3·num_faces vertices, one per clock across
// faces (flattened), projected (ProjectVertex); per face the near/guard-band test, back-face
// culling (§6.2: 2·Area ≤ 0 is culled), the bounding box clipped to the window (ceil of min,
// floor of max) and the edge setup. Front faces with a non-empty clipped box go to the pixel
// stage; the stream ends with one `last` entry. front = the number of front faces.
inline void VertexStage(int num_faces, const ap_int<36> ft[kFtElements], const ap_int<52>& near_w, const Window& win,
                        hls::stream<Vertex>& vert_in, hls::stream<TriangleSetup>& tri_out, face_count_t& front_faces) {
  const int u0 = win.u0.to_int(), v0 = win.v0.to_int();
  const int ww = win.width.to_int(), wh = win.height.to_int();
  face_count_t front = 0;
  ScreenVertex sv[3];
#pragma HLS ARRAY_PARTITION variable = sv complete
  bool ok = true;
  int k = 0;  // vertex of the current face, 0 … 2
RC_VERTICES:
  for (int i = 0; i < 3 * num_faces; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 36 max = 6144
    sv[k] = ProjectVertex(ft, vert_in.read(), near_w);
    ok = (k == 0 ? true : ok) && sv[k].ok;
    if (k < 2) {
      ++k;
      continue;
    }
    k = 0;
    if (!ok) continue;  // a vertex behind the near plane or outside the guard band
    // Back-face culling (§6.2): 2·Area = (V2x−V0x)(V1y−V0y) − (V2y−V0y)(V1x−V0x) ≤ 0.
    const ap_int<50> area2 = ap_int<50>((sv[2].x - sv[0].x) * (sv[1].y - sv[0].y)) -
                             ap_int<50>((sv[2].y - sv[0].y) * (sv[1].x - sv[0].x));
    if (area2 <= 0) continue;
    ++front;
    ap_int<23> min_x = sv[0].x, max_x = sv[0].x, min_y = sv[0].y, max_y = sv[0].y;
    for (int j = 1; j < 3; ++j) {
#pragma HLS UNROLL
      if (sv[j].x < min_x) min_x = sv[j].x;
      if (sv[j].x > max_x) max_x = sv[j].x;
      if (sv[j].y < min_y) min_y = sv[j].y;
      if (sv[j].y > max_y) max_y = sv[j].y;
    }
    int u_lo = (-((-min_x) >> kSubpixelBits)).to_int(), u_hi = (max_x >> kSubpixelBits).to_int();
    int v_lo = (-((-min_y) >> kSubpixelBits)).to_int(), v_hi = (max_y >> kSubpixelBits).to_int();
    if (u_lo < u0) u_lo = u0;
    if (v_lo < v0) v_lo = v0;
    if (u_hi > u0 + ww - 1) u_hi = u0 + ww - 1;
    if (v_hi > v0 + wh - 1) v_hi = v0 + wh - 1;
    if (u_lo > u_hi || v_lo > v_hi) continue;
    // Edge j opposite vertex j, from Va = V[j+1] to Vb = V[j+2] (eq. 6.13 [ALGORITHM.md]): A = Vb.y − Va.y,
    // B = −(Vb.x − Va.x); E_j at the first pixel (eq. 6.16–6.18 [ALGORITHM.md]).
    TriangleSetup t;
    for (int j = 0; j < 3; ++j) {
#pragma HLS UNROLL
      const int a = (j + 1) % 3, b = (j + 2) % 3;
      t.A[j] = sv[b].y - sv[a].y;
      t.B[j] = sv[a].x - sv[b].x;
      t.e0[j] = ap_int<50>(t.A[j] * ap_int<24>((ap_int<24>(u_lo) << kSubpixelBits) - sv[a].x)) +
                ap_int<50>(t.B[j] * ap_int<24>((ap_int<24>(v_lo) << kSubpixelBits) - sv[a].y));
      t.own[j] = (t.A[j] > 0 || (t.A[j] == 0 && t.B[j] > 0)) ? 1 : 0;
      t.iz[j] = sv[j].iz;
    }
    const int len = BitLength(area2);
    t.sh = len > 24 ? len - 24 : 0;
    t.x0 = u_lo - u0;
    t.y0 = v_lo - v0;
    t.w = u_hi - u_lo + 1;
    t.h = v_hi - v_lo + 1;
    t.last = 0;
    tri_out.write(t);
  }
  TriangleSetup end;
  for (int j = 0; j < 3; ++j) {
    end.A[j] = end.B[j] = 0;
    end.e0[j] = 0;
    end.own[j] = 0;
    end.iz[j] = 0;
  }
  end.sh = 0;
  end.x0 = end.y0 = end.w = end.h = 0;
  end.last = 1;
  tri_out.write(end);
  front_faces = front;
}

// Pixel stage (Fig. 7.20 "pixel"): every pixel of every triangle's clipped box, one pixel per
// clock, rows and triangles back to back (one flattened loop; the next triangle is read in the
// clock after the previous one's last pixel). Inside test on the incremental edge functions
// (+A·256 per column, +B·256 per row, eq. 6.19–6.20), depth recovery (eq. 6.21–6.22 [ALGORITHM.md]), then
// zbuffer = 0: the soft inlier of the fragment (§7.5.1); zbuffer = 1: the z-buffer's
// read-modify-write (min). The z-buffer write of a fragment lands kZbufWriteLag clocks after
// its read (latency.h; the RTL twin: one, a read-first BRAM written in the clock the next
// fragment's read is issued), so a read sees the memory without the writes still in flight and
// takes the newest matching one from the forward registers (the RTL's `lw`): that makes the
// DEPENDENCE pragma's "no inter-iteration dependence through zbuf" true. The C keeps the writes
// in flight too, so a missing forward changes the results (tests/hw/hwrender_raster_test.cc).
// trips += the box pixels visited (the loop's trips).
inline void PixelStage(hls::stream<TriangleSetup>& tri_in, const RasterParams& prm, RasterCoreMemory& mem,
                       Accumulators& acc, uint64_t& trips) {
  const bool zbuffer = prm.zbuffer == 1;
  TriangleSetup t;
#pragma HLS ARRAY_PARTITION variable = t.A complete
  ap_int<50> e[3], row_e[3];
#pragma HLS ARRAY_PARTITION variable = e complete
#pragma HLS ARRAY_PARTITION variable = row_e complete
  // Writes in flight, oldest first: slot k lands k + 1 clocks from now.
  bool fw_valid[kZbufWriteLag];
  ap_uint<16> fw_addr[kZbufWriteLag];
  zbuf_word_t fw_val[kZbufWriteLag];
#pragma HLS ARRAY_PARTITION variable = fw_valid complete
#pragma HLS ARRAY_PARTITION variable = fw_addr complete
#pragma HLS ARRAY_PARTITION variable = fw_val complete
  for (int k = 0; k < kZbufWriteLag; ++k) {
#pragma HLS UNROLL
    fw_valid[k] = false;
    fw_addr[k] = 0;
    fw_val[k] = 0;
  }
  int x = 0, y = 0;
  bool need = true;  // read the next triangle in this clock
  uint64_t visited = 0;
RC_RASTER:
  for (;;) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 100000
#pragma HLS DEPENDENCE variable = mem.zbuf inter false
    if (need) {
      t = tri_in.read();
      if (t.last == 1) break;
      for (int k = 0; k < 3; ++k) e[k] = row_e[k] = t.e0[k];
      x = 0;
      y = 0;
      need = false;
    }
    ++visited;
    bool inside = true;
    for (int k = 0; k < 3; ++k) inside = inside && (e[k] > 0 || (e[k] == 0 && t.own[k] == 1));
    bool write = false;
    int a = 0;
    zbuf_word_t zq_word = 0;
    if (inside) {
      const ap_uint<24> z = RecoverDepth(e, t.sh.to_int(), t.iz);
      a = (t.y0.to_int() + y) * kMaxWindow + t.x0.to_int() + x;
      if (zbuffer) {
        // z-test on the window z-buffer (F16, rounded; the first of equal words wins).
        ap_uint<25> zq = (ap_uint<25>(z) + 8) >> 4;
        if (zq >= kZbufEmpty) zq = kZbufEmpty - 1;
        zbuf_word_t cur = mem.zbuf[a];  // the memory, without the writes in flight
        for (int k = 0; k < kZbufWriteLag; ++k) {
#pragma HLS UNROLL
          if (fw_valid[k] && fw_addr[k] == a) cur = fw_val[k];  // the newest match wins
        }
        write = zq < cur;
        zq_word = zbuf_word_t(zq);
      } else {
        ++acc.n_raster;
        CompareFragment(z, DepthF20(mem.frag[a]), prm, &acc);
      }
    }
    // The oldest write in flight lands; this clock's write enters the forward registers.
    if (fw_valid[0]) mem.zbuf[fw_addr[0].to_int()] = fw_val[0];
    for (int k = 0; k + 1 < kZbufWriteLag; ++k) {
#pragma HLS UNROLL
      fw_valid[k] = fw_valid[k + 1];
      fw_addr[k] = fw_addr[k + 1];
      fw_val[k] = fw_val[k + 1];
    }
    fw_valid[kZbufWriteLag - 1] = write;
    fw_addr[kZbufWriteLag - 1] = a;
    fw_val[kZbufWriteLag - 1] = zq_word;
    if (x + 1 < t.w.to_int()) {
      ++x;
      for (int k = 0; k < 3; ++k) e[k] += ap_int<50>(t.A[k]) << kSubpixelBits;
    } else {
      x = 0;
      ++y;
      for (int k = 0; k < 3; ++k) {
        row_e[k] += ap_int<50>(t.B[k]) << kSubpixelBits;
        e[k] = row_e[k];
      }
      if (y == t.h.to_int()) need = true;
    }
  }
  // The pipeline drains: the writes in flight land.
RC_RASTER_DRAIN:
  for (int k = 0; k < kZbufWriteLag; ++k) {
#pragma HLS UNROLL
    if (fw_valid[k]) mem.zbuf[fw_addr[k].to_int()] = fw_val[k];
  }
  trips += visited;
}

// The face phase of one particle (Fig. 7.20): the vertex stage and the pixel stage as a
// DATAFLOW region joined by the triangle FIFO, so the vertex stage runs ahead by up to
// kTriangleFifoDepth front faces while the pixel stage rasterizes, and the slower of the two
// sets the time (the cycle model's ParticleWork::Faces).
inline void RasterFaces(int num_faces, const ap_int<36> ft[kFtElements], const ap_int<52>& near_w, const Window& win,
                        const RasterParams& prm, hls::stream<Vertex>& vert_in, RasterCoreMemory& mem,
                        face_count_t& front_faces, Accumulators& acc, uint64_t& pixel_trips) {
#pragma HLS DATAFLOW
  HW_DATAFLOW_BEGIN(df, nullptr);
  hls::stream<TriangleSetup> triangles;
  HW_STREAM(triangles, kTriangleFifoDepth);
  HW_PROCESS(df, VertexStage(num_faces, ft, near_w, win, vert_in, triangles, front_faces));
  HW_PROCESS(df, PixelStage(triangles, prm, mem, acc, pixel_trips));
  HW_DATAFLOW_END(df);
}

// One window pixel in the z pass: its z-buffer word and its scene depth.
struct ZPixel {
  zbuf_word_t z;
  depth_t d;
};

// z pass (z-buffer mode, ours): compares the nearest fragment of each covered pixel and counts
// the silhouette edge samples (a covered pixel and an uncovered 4-neighbour inside the window
// with valid scene depth; continued when |z_s(neighbour) − z_r| ≤ edge_band). The window is
// read in raster order, one z-buffer word and one depth word per clock, through two line
// buffers (delay lines of the (z-buffer, depth) pairs): pixel j = i − width is evaluated in
// the clock that reads word i (its lower neighbour); delay line 1 (width − 1 words) yields word
// i − width + 1 (its right neighbour), shifted on into `cen` and `lft`; delay line 2 (width
// words) yields word i − 2·width (its upper neighbour). width·(height + 1) clocks.
inline void ZPass(const Window& win, const RasterParams& prm, const RasterCoreMemory& mem, Accumulators* acc) {
  const int ww = win.width.to_int(), wh = win.height.to_int();
  const ap_uint<24> band = RawUnsigned(prm.edge_band);
  ZPixel line1[kMaxWindow], line2[kMaxWindow];  // delay lines (BRAM or LUTRAM, one read + one write per clock)
#ifndef __SYNTHESIS__
  for (int k = 0; k < kMaxWindow; ++k) {  // C simulation: defined contents (never used before written)
    line1[k].z = line2[k].z = kZbufEmpty;
    line1[k].d = line2[k].d = 0;
  }
#endif
  int p1 = 0, p2 = 0;  // pointers: read the oldest word, write the new one in its place
  ZPixel lft, cen;     // words j − 1 and j
  lft.z = cen.z = kZbufEmpty;
  lft.d = cen.d = 0;
  int x = 0, y = 0;  // the word read in this clock, (x, y); y = height in the flush row
RC_ZPASS:
  for (int i = 0; i < ww * (wh + 1); ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 2 max = 40200
#pragma HLS DEPENDENCE variable = line1 inter false
#pragma HLS DEPENDENCE variable = line2 inter false
    ZPixel dn;  // word i: the lower neighbour of pixel j (none in the flush row)
    dn.z = kZbufEmpty;
    dn.d = 0;
    if (y < wh) {
      dn.z = mem.zbuf[y * kMaxWindow + x];
      dn.d = mem.frag[y * kMaxWindow + x];
    }
    ZPixel rgt = dn;  // word i − width + 1: the right neighbour (a 0-word line for width 1)
    if (ww > 1) {
      rgt = line1[p1];
      line1[p1] = dn;
      p1 = p1 + 1 == ww - 1 ? 0 : p1 + 1;
    }
    const ZPixel up = line2[p2];  // word j − width: the upper neighbour
    line2[p2] = cen;
    p2 = p2 + 1 == ww ? 0 : p2 + 1;
    if (y >= 1 && cen.z != kZbufEmpty) {  // pixel j = (x, y − 1) is covered
      ++acc->n_raster;
      const ap_uint<24> z = ap_uint<24>(cen.z) << 4;
      CompareFragment(z, DepthF20(cen.d), prm, acc);
      const ZPixel nb[4] = {lft, rgt, up, dn};
      const bool in_window[4] = {x > 0, x < ww - 1, y > 1, y < wh};
    RC_EDGE_NEIGHBOURS:
      for (int n = 0; n < 4; ++n) {
#pragma HLS UNROLL
        if (!in_window[n] || nb[n].z != kZbufEmpty) continue;
        const ap_uint<24> zs = DepthF20(nb[n].d);
        ++acc->n_edge;  // a missing reading next to the outline is a discontinuity: not continued
        if (zs == 0) continue;
        const ap_uint<25> diff = zs > z ? ap_uint<25>(zs - z) : ap_uint<25>(z - zs);
        if (diff <= band) ++acc->n_edge_continued;
      }
    }
    lft = cen;
    cen = rgt;
    if (++x == ww) {
      x = 0;
      ++y;
    }
  }
}

}  // namespace raster_detail

// One raster core. Processes `num_particles` particles (its share of the round-robin deal:
// particles c, c + M, c + 2M, … of the iteration), each with `num_faces` faces; reads per
// particle its window (info_in), width·height depth pixels (depth_in, row-major), 12 FT
// elements (ft_in) and 3·num_faces vertices (vert_in); writes one RasterCoreOutput.
// Per particle: (1) the window fill, (2) the FT read, (3) the vertex stage and the pixel
// stage as a dataflow joined by the triangle FIFO (Fig. 7.20), (4) in z-buffer mode the z pass.
// The top instantiates M copies, each with its own RasterCoreMemory.
inline void RasterCore(int num_particles, int num_faces, const RasterParams& prm,
                       hls::stream<Window>& info_in, hls::stream<depth_t>& depth_in,
                       hls::stream<ft_t>& ft_in, hls::stream<Vertex>& vert_in,
                       hls::stream<RasterCoreOutput>& out, RasterCoreMemory& mem HW_TRACE_PARAM) {
  using namespace raster_detail;
  uint64_t fill_trips = 0, vertex_trips = 0, pixel_trips = 0, zpass_trips = 0;
  const ap_int<52> near_w = ap_int<52>(RawUnsigned(prm.near_plane)) << 12;  // F20 → F32
  const bool zbuffer = prm.zbuffer == 1;
RC_PARTICLES:
  for (int p = 0; p < num_particles; ++p) {
#pragma HLS LOOP_TRIPCOUNT min = 51 max = 510
    Accumulators acc;
    acc.inlier_raw = 0;
    acc.n_raster = acc.n_occluded = acc.n_depth = acc.diff_count = acc.n_edge = acc.n_edge_continued = 0;
    acc.diff_raw = 0;
    acc.faces_front = 0;
    acc.faces_total = num_faces;

    // 1. The window and its depth fragment, row by row (column/row counters, no divider);
    // the z-buffer is cleared on the way.
    const Window win = info_in.read();
    const int ww = win.width.to_int(), wh = win.height.to_int();
    int fx = 0, fy = 0;
  RC_DEPTH_FILL:
    for (int i = 0; i < ww * wh; ++i) {
#pragma HLS PIPELINE II = 1
#pragma HLS LOOP_TRIPCOUNT min = 1 max = 40000
      const int a = fy * kMaxWindow + fx;
      const depth_t d = depth_in.read();
      mem.frag[a] = d;
      mem.zbuf[a] = kZbufEmpty;
      if (d != 0) ++acc.n_depth;
      if (++fx == ww) {
        fx = 0;
        ++fy;
      }
    }
    fill_trips += uint64_t(ww) * wh;

    // 2. The particle's FT (raw words, registers).
    ap_int<36> ft[kFtElements];
#pragma HLS ARRAY_PARTITION variable = ft complete
  RC_FT_READ:
    for (int e = 0; e < kFtElements; ++e) {
#pragma HLS PIPELINE II = 1
      ft[e] = RawSigned(ft_in.read());
    }

    // 3. Faces: vertex stage → triangle FIFO → pixel stage (the core's internal dataflow).
    face_count_t front = 0;
    RasterFaces(num_faces, ft, near_w, win, prm, vert_in, mem, front, acc, pixel_trips);
    acc.faces_front = front;
    vertex_trips += uint64_t(3) * num_faces;

    // 4. z-buffer mode: the z pass over the window.
    if (zbuffer) {
      ZPass(win, prm, mem, &acc);
      zpass_trips += uint64_t(ww) * (wh + 1);
    }

    RasterCoreOutput o;
    o.inlier_sum = UFixedFromRaw<42, 32>(acc.inlier_raw);
    o.n_raster = acc.n_raster;
    o.n_occluded = acc.n_occluded;
    o.n_depth = acc.n_depth;
    o.depth_diff_sum = FixedFromRaw<56, 36>(acc.diff_raw);
    o.depth_diff_count = acc.diff_count;
    o.n_edge = acc.n_edge;
    o.n_edge_continued = acc.n_edge_continued;
    o.faces_front = acc.faces_front;
    o.faces_total = acc.faces_total;
    out.write(o);
  }
  // Loop records (trips, II, pipeline depth from latency.h; docs/HARDWARE.md "Cycle model").
#ifndef __SYNTHESIS__
  // Each loop is entered once per particle: its depth counts once per entry.
  const uint32_t entries = uint32_t(num_particles);
#endif
  HW_TRACE("raster_core", "RC_DEPTH_FILL", fill_trips, 1, entries * kRcFillDepth);
  HW_TRACE("raster_core", "RC_FT_READ", uint64_t(num_particles) * kFtElements, 1, entries * kRcFtReadDepth);
  HW_TRACE("raster_core", "RC_VERTICES", vertex_trips, 1, entries * kRcVertexDepth);
  HW_TRACE("raster_core", "RC_RASTER", pixel_trips, 1, entries * kRcPixelDepth);
  HW_TRACE("raster_core", "RC_ZPASS", zpass_trips, 1, (zbuffer ? entries : 0u) * kRcZpassDepth);
}

}  // namespace posefilter::hw
