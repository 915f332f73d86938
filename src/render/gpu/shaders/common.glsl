// common.glsl — what the gpu engine's three compute passes share (src/render/gpu/gpu_kernel.cc
// records them): bindings, push constants, exact float helpers, 64-bit accumulation.
//
// Exactness (the rules of posefilter/render.h and src/render/raster.h, which every float engine
// obeys bit for bit):
//   - every float expression that the reference evaluates is marked `precise`, so that the
//     compiler neither contracts a·b + c into an FMA nor reorders it;
//   - Vulkan rounds OpFAdd, OpFSub and OpFMul correctly but allows 2.5 ulp for OpFDiv: a float
//     quotient is therefore taken in double and rounded once to float (DivRN). A double
//     quotient within a few double ulps of a/b rounds to the correctly rounded float a/b,
//     because a/b of two floats never lies within 2^-49 (relative) of a float midpoint, and an
//     FMA correction step makes the double quotient that close;
//   - edge functions are exact int64, as in the reference.
// Sums are fixed point in int64 (order-independent, hence deterministic): χ in units of 2^-23
// (every χ is 0, 1 or 2 − d·(1/thr1) with d·(1/thr1) in (1, 2), a multiple of 2^-23, so the
// sum is exact), depth differences in units of 2^-32 m (truncated toward zero).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

// Storage buffers (gpu_kernel.cc, kBinding*). Vertex/face/depth buffers hold one pixel level's
// model and scene, uploaded once per estimate.
layout(std430, set = 0, binding = 0) readonly buffer Vertices { float vertices[]; };   // V × 3, object frame, m
layout(std430, set = 0, binding = 1) readonly buffer Faces { uint faces[]; };          // F × 3 vertex indices
layout(std430, set = 0, binding = 2) readonly buffer Depth { float depth[]; };         // W × H, m, 0 = none
// Per particle kParticleWords words: R row-major (9 floats), t (3 floats, m), window u0, v0,
// width, height (ints), the offset of its window in the z-buffer (pixels), 3 unused.
layout(std430, set = 0, binding = 3) readonly buffer Particles { uint particles[]; };
// Per particle and vertex: snapped x, y (1/256 px), float bits of 1/z (1/m), 1 = usable.
layout(std430, set = 0, binding = 4) buffer VertexRecords { ivec4 vrec[]; };
// Per particle, window-sized: float bits of the largest 1/z of the pixel (0 = empty).
layout(std430, set = 0, binding = 5) buffer ZBuffer { uint zbuf[]; };
// Per particle kResultWords words: kNumSums int64 sums as (low, high) uint pairs.
layout(std430, set = 0, binding = 6) buffer Results { uint results[]; };
// Triangles too large to raster in one invocation (raster.comp → raster_big.comp): jobs[0] is
// their count, then (face, particle) pairs.
layout(std430, set = 0, binding = 7) buffer Jobs { uint jobs[]; };
// The indirect dispatch of raster_big.comp (x, y, z workgroups), written by jobs.comp.
layout(std430, set = 0, binding = 8) buffer JobGroups { uint job_groups[]; };

const uint kParticleWords = 20u;
const uint kResultWords = 16u;
// The sums, in result order.
const uint kInlier = 0u;        // Σ χ, units of 2^-23
const uint kRaster = 1u;        // counted fragments
const uint kOccluded = 2u;      // χ = 0 and the scene in front
const uint kDiffSum = 3u;       // Σ (z_s − z_r) within the align band, units of 2^-32 m
const uint kDiffCount = 4u;
const uint kEdge = 5u;          // silhouette edge samples (z-buffer mode)
const uint kEdgeContinued = 6u;
const uint kFront = 7u;         // faces past the near-plane test and culling
const uint kNumSums = 8u;

layout(push_constant) uniform Push {
  float fx, fy, cx, cy;       // pinhole intrinsics of the level, pixels
  float near_m;               // triangles with a vertex closer are skipped, m
  float thr1_m;               // soft inlier: χ = 1 up to here, m
  float inv_thr1;             // 1/thr1 rounded to float once (as the reference)
  float hard_thr_m;           // hard inlier threshold, m
  float align_band_m;         // depth differences entering the align sums, m
  float edge_band_m;          // silhouette "no depth step" band, m
  int num_vertices, num_faces, num_particles;
  int depth_width, depth_height;
  uint flags;                 // bit 0: z-buffer mode; bit 1: hard inlier
} pc;

const uint kFlagZBuffer = 1u;
const uint kFlagHard = 2u;

// The exact product of two int32 (|a|, |b| < 2^31) as int64, from 16-bit limbs and 32-bit
// unsigned products only: Mesa's lavapipe (LLVM 15) returns wrong high halves for some 64-bit
// products of sign-extended 32-bit values (int64 × int64 and imulExtended alike).
int64_t Mul64(int a, int b) {
  const uint ua = uint(abs(a)), ub = uint(abs(b));
  const uint ah = ua >> 16, al = ua & 0xffffu, bh = ub >> 16, bl = ub & 0xffffu;
  const uint64_t p = (uint64_t(ah * bh) << 32) + (uint64_t(ah * bl + al * bh) << 16) + uint64_t(al * bl);
  return (a < 0) != (b < 0) ? -int64_t(p) : int64_t(p);
}

// The correctly rounded float a/b (a, b finite, b ≠ 0, the quotient a normal float or 0).
float DivRN(float a, float b) {
  precise double ad = double(a), bd = double(b);
  precise double q = ad / bd;
  precise double r = fma(-bd, q, ad);  // exact remainder of the double quotient
  q = fma(r, 1.0lf / bd, q);
  return float(q);
}

// Round half away from zero, as std::llround, of x = u·256 (|x| < 2^28): exact in float.
int RoundHalfAway(float x) {
  precise float a = abs(x);
  if (a >= 8388608.0) return int(x);  // ≥ 2^23: already an integer
  precise float r = floor(a + 0.5);    // a + 0.5 is exact below 2^23
  return x < 0.0 ? -int(r) : int(r);
}

// The particle's window: u0, v0, width, height.
ivec4 ParticleWindow(uint p) {
  const uint b = p * kParticleWords + 12u;
  return ivec4(int(particles[b]), int(particles[b + 1u]), int(particles[b + 2u]), int(particles[b + 3u]));
}
uint ZOffset(uint p) { return particles[p * kParticleWords + 16u]; }

// χ of a depth difference |d| (posefilter::SoftInlier).
float SoftInlier(float d) {
  if ((pc.flags & kFlagHard) != 0u) return d <= pc.hard_thr_m ? 1.0 : 0.0;
  if (d <= pc.thr1_m) return 1.0;
  precise float two_thr = 2.0 * pc.thr1_m;
  if (d >= two_thr) return 0.0;
  precise float chi = 2.0 - d * pc.inv_thr1;
  return chi;
}

// Adds v to the 64-bit sum k of particle p: two 32-bit atomics with a carry (mod 2^64).
void AtomicAdd64(uint p, uint k, int64_t v) {
  const uint64_t u = uint64_t(v);
  const uint lo = uint(u & 0xffffffffUL), hi = uint(u >> 32);
  if (lo == 0u && hi == 0u) return;
  const uint base = p * kResultWords + 2u * k;
  const uint old = atomicAdd(results[base], lo);
  const uint carry = (old + lo < old) ? 1u : 0u;
  if (hi + carry != 0u) atomicAdd(results[base + 1u], hi + carry);
}

// One fragment at pixel (u, v) of the level, rendered depth z (m), against the scene: adds
// to the sums s (the reference's Compare without the ICP sums).
void CompareFragment(int u, int v, float z, inout int64_t s[kNumSums]) {
  s[kRaster] += 1;
  const float zs = depth[uint(v) * uint(pc.depth_width) + uint(u)];
  if (zs <= 0.0) return;
  precise float d = zs - z;
  const float chi = SoftInlier(abs(d));
  s[kInlier] += int64_t(chi * 8388608.0);  // exact: χ·2^23 is an integer
  if (chi == 0.0 && d < 0.0) s[kOccluded] += 1;
  if (abs(d) > pc.align_band_m) return;
  s[kDiffSum] += int64_t(d * 4294967296.0);
  s[kDiffCount] += 1;
}
