// src/render/cpu_kernel.h — the `cpu` engine's score kernel (internal API).
//
// ScoreCpu computes exactly what ScoreReference computes (include/posefilter/render.h; the
// rasterization rules there are binding), with SIMD and a fused render+inlier pipeline:
//   1. vertex pass: transform + project + snap, 16 vertices per step (bit-identical float ops);
//      1b. optional back-face pre-cull from per-mesh face planes (face_planes.h): faces proven
//      culled are dropped before their corners are loaded;
//   2. face pass: corner loads (16-byte vertex records), back-face cull, window test, setup of
//      edge functions, 16 faces per step in int32; front faces in the window are listed by
//      vector shape;
//   3. raster: per triangle, vectors of 16 pixel centres (AVX-512; 8 AVX2, 4 portable) laid out
//      as 4 rows of 4, 2 rows of 8 or one row of 16 to fit its box; edge functions holding exact
//      integers in float (int32 for larger triangles, double for the largest); float 1/z
//      exactly as raster.h; z-buffer mode keeps the max of 1/z per pixel (a window-sized float
//      buffer in the workspace), z-buffer-free mode keeps the last fragment per pixel there and
//      scores the fragments it displaces from a small buffer;
//   4. one scoring pass over the covered part of the window's buffer (contiguous loads of
//      scene depth and normals per pixel run, no gathers; the silhouette edge test in z-buffer
//      mode).
// Runtime dispatch: one implementation source (cpu_kernel_impl.inc) compiled three times —
// portable (baseline x86-64 / any target), AVX2, AVX-512 — picked by what the CPU supports.
// docs/PERFORMANCE.md ("The cpu engine's kernel") has the design notes and the exactness arguments.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/render.h"
#include "render/face_planes.h"

namespace posefilter::render {

// Instruction-set variants of the kernel.
enum class CpuTarget { kPortable, kAvx2, kAvx512 };

// "portable", "avx2", "avx512".
const char* CpuTargetName(CpuTarget t);
// The variant called `name` (as CpuTargetName spells it); false for any other name.
bool ParseCpuTarget(const std::string& name, CpuTarget* t);
// Whether this build contains the variant and this CPU can run it (portable: always).
bool CpuTargetSupported(CpuTarget t);
// The variants this machine can run, portable first.
std::vector<CpuTarget> SupportedCpuTargets();
// The fastest supported variant (what ScoreCpu uses).
CpuTarget BestCpuTarget();

// Per-worker scratch memory of the cpu kernel (no global state): grows to the largest mesh
// and window seen, never shrinks. One per thread; not shareable between concurrent calls.
struct CpuWorkspace {
  std::vector<std::int32_t> vrec;     // per vertex 4 int32 (16 bytes): snapped x for the fast path
                                      // (1/256 px, or a marker), y, 1/z (float bits, 1/metres),
                                      // x of any magnitude (1/256 px)
  std::vector<std::int32_t> vok;      // per vertex: 1 = passed the near-plane/off-screen test
  std::vector<std::int32_t> tri;      // setup records of the rastered triangles (see impl)
  std::vector<std::int32_t> fast;     // faces that take the float-exact or int32 raster, by bin
  std::vector<std::int32_t> slow;     // faces that take the exact int64 scalar path
  std::vector<std::int32_t> wide;     // faces that take the double row path
  std::vector<float> zbuffer;         // window-sized 1/z per pixel, 0 = empty: the max (z-buffer
                                      // mode) or the last fragment (z-buffer-free mode); all
                                      // zeros between calls (each call clears what it wrote)
  std::vector<std::int32_t> frag_idx; // fragments waiting to be scored: image index v·width + u,
  std::vector<float> frag_iz;         //   1/z (z-buffer-free mode)
  std::vector<std::int32_t> cand;     // faces kept by the back-face pre-cull (see face_planes.h)
  std::vector<std::uint32_t> covmask; // the scan's coverage bits of three rows of vectors
  std::int64_t faces_preculled = 0;   // last call: faces the pre-cull skipped (0 when off)
  RenderWorkspace reference;          // fallback for parameters outside the fast path's domain
};

namespace cpu_detail {
// Raw views of a CpuWorkspace sized for one call (filled in by cpu_kernel.cc); the variants
// (cpu_kernel_impl.inc) allocate nothing.
inline constexpr int kTriFields = 20;  // fields of a triangle's setup record
inline constexpr int kFastBins = 10;   // raster bins of the fast path
struct CoreScratch {
  std::int32_t* vrec;    // vertex records (CpuWorkspace::vrec), 16-byte aligned: fast-path x
                         // (kBadX marks the others), y, 1/z bits, exact x; 16 records of slack
  std::int32_t* vok;
  std::int32_t* tri;     // kTriFields × tri_cap int32/float words, 64-byte aligned
  std::int64_t tri_cap;  // a multiple of 16, ≥ num_faces + 16
  std::int32_t* fast;    // kFastBins × tri_cap
  std::int32_t* slow;
  std::int32_t* wide;
  float* zb;             // z-buffer row 0, column 0 (≥ 16 floats of slack before and 32 after
  std::int64_t zb_stride;//   each row, 4 spare rows)
  std::int32_t* frag_idx;  // fragment buffer: image index v·width + u and 1/z, frag_cap + 16 each
  float* frag_iz;
  int frag_cap;
  // Back-face pre-cull (face_planes.h), off when pc_nx is null: the table's per-face arrays
  // (padded to 16), the camera centre in the object frame (metres) and the margin: a face
  // with d − N·c > k1·len + k0 is skipped. The faces kept are listed in cand: vertex indices
  // i0, i1, i2 and the face's index, tri_cap + 16 entries each.
  const float *pc_nx, *pc_ny, *pc_nz, *pc_d, *pc_len;
  const std::uint32_t *pc_i0, *pc_i1, *pc_i2;
  float pc_c[3], pc_k1, pc_k0;
  std::int32_t* cand;        // 4 × (tri_cap + 16)
  std::uint32_t* covmask;    // 3 × (window width / 4 + 8): per vector of a scanned row, its covered lanes
  std::int64_t* preculled;   // out: faces the pre-cull skipped
};
// The views of `ws` for one call with k (grows its buffers; `planes` as for ScoreCpuWith, used
// when its pre-cull constants are finite). k must lie in the fast path's domain (ScoreCpuWith
// checks it first). Throws when `planes` was built from another mesh.
CoreScratch PrepareScratch(const ScoreKernelParams& k, CpuWorkspace* ws, const FacePlanes* planes);
// Each returns −1, or the index of a face with an out-of-range vertex index (nothing scored).
std::int64_t CorePortable(const ScoreKernelParams& k, const CoreScratch& s, ScoreKernelResult* r);
std::int64_t CoreAvx2(const ScoreKernelParams& k, const CoreScratch& s, ScoreKernelResult* r);
std::int64_t CoreAvx512(const ScoreKernelParams& k, const CoreScratch& s, ScoreKernelResult* r);
// Whether the variant was compiled with its instruction set (false on non-x86 builds).
bool BuiltAvx2();
bool BuiltAvx512();
}  // namespace cpu_detail

// Scores with the best supported variant. Same contract and result as ScoreReference; throws
// posefilter::Error when the window does not lie inside the depth image, the depth (or mesh)
// pointers are missing, or a face index is out of range. `planes` (optional, built from the
// same mesh arrays, else Error) lets the kernel skip faces proven back-facing before their
// vertices are loaded; the result is the same with or without it.
ScoreKernelResult ScoreCpu(const ScoreKernelParams& params, CpuWorkspace* ws, const FacePlanes* planes = nullptr);
// Scores with a given variant; throws posefilter::Error if this machine cannot run it.
ScoreKernelResult ScoreCpuWith(CpuTarget target, const ScoreKernelParams& params, CpuWorkspace* ws,
                               const FacePlanes* planes = nullptr);

// The pre-cull's per-call constants (double arithmetic; proof in docs/PERFORMANCE.md, "Why the
// counts are exact"): the camera centre c in the object frame and the margin k1·len + k0 (metres³)
// beyond which s = d − N·c proves a face culled after snapping. False when the pose or camera lies
// outside the proof's assumptions (R not a rotation to 1 %, a vertex possibly at z ≤ 0, fx or
// fy ≤ 0, anything not finite): the pre-cull is then not used.
bool PreCullConstants(const ScoreKernelParams& params, const FacePlanes& planes, float c[3], float* k1, float* k0);

// Summed-area table of the valid-depth mask (depth > 0): the number of valid depth pixels in
// any rectangle in O(1) (N_depth of eq. 7.4 [ALGORITHM.md]).
class ValidDepthSat {
 public:
  ValidDepthSat() = default;
  // depth: row-major, width × height, metres (0 = missing). Throws Error on negative sizes or a
  // null pointer with a non-empty size.
  ValidDepthSat(const float* depth, int width, int height);
  // Valid pixels in r ∩ image (an empty intersection gives 0).
  std::int64_t Count(const PixelRect& r) const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<std::int64_t> sat_;  // (width+1) × (height+1), sat_(u, v) = count in [0,u)×[0,v)
};

}  // namespace posefilter::render
