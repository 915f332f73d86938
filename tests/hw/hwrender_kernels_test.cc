// Tests of the hw render pipeline's small kernels: the full-transformation-matrix chain vs
// PoseToTransform, the vertex multiplier, the FT distributor, the depth fragment distributor
// (exact window contents, one read per shared pixel and round), the weight merger vs the
// double formula of eq. 7.4 [ALGORITHM.md], and the software checks of the kernels' parameters.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "hw/distributor.h"
#include "hw/raster_core.h"
#include "hw/transform.h"
#include "hw/weight_merger.h"
#include "posefilter/pose.h"
#include "posefilter/rng.h"

namespace posefilter::hw {
namespace {

double Quant(double v, int frac_bits) { return std::round(std::ldexp(v, frac_bits)) / std::ldexp(1.0, frac_bits); }
// dst = v (exact before quantization): the host-side conversion of a double.
template <class T>
void Set(T& dst, double v) {
  dst = T(v);
}

// ---- Full transformation matrix chain ----

TEST(HwRenderTransform, ChainMatchesPoseToTransformWithinFormat) {
  Rng rng(7);
  // Camera: the thesis intrinsics and a non-trivial base→camera extrinsic, quantized.
  CameraParams cam;
  const double fx = Quant(542.556, 16), fy = Quant(537.666, 16), cx = Quant(325.065, 16), cy = Quant(224.214, 16);
  Set(cam.fx, fx);
  Set(cam.fy, fy);
  Set(cam.cx, cx);
  Set(cam.cy, cy);
  const Eigen::Matrix3d Rc = (Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const Eigen::Vector3d tc(0.3, -0.2, 0.5);
  Eigen::Matrix4d C = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      C(r, c) = Quant(Rc(r, c), 16);
      Set(cam.rot[3 * r + c], C(r, c));
    }
    C(r, 3) = Quant(tc[r], 20);
    Set(cam.trans[r], C(r, 3));
  }
  Eigen::Matrix<double, 3, 4> K = Eigen::Matrix<double, 3, 4>::Zero();
  K(0, 0) = fx;
  K(0, 2) = cx;
  K(1, 1) = fy;
  K(1, 2) = cy;
  K(2, 2) = 1;
  const Eigen::Matrix<double, 3, 4> PC = K * C;

  const int kSamples = 200;
  std::vector<Sample> samples(kSamples);
  for (auto& s : samples) {
    Set(s.x, Quant(rng.Uniform(-1, 1), 10));
    Set(s.y, Quant(rng.Uniform(-1, 1), 10));
    Set(s.z, Quant(rng.Uniform(0.2, 3), 10));
    Set(s.roll, Quant(rng.Uniform(-M_PI, M_PI), 8));
    Set(s.pitch, Quant(rng.Uniform(-M_PI, M_PI), 8));
    Set(s.yaw, Quant(rng.Uniform(-M_PI, M_PI), 8));
    s.cell = 0;
  }
  hls::stream<ft_t> out;
  CycleTrace trace;
  FullTransformChain(kSamples, samples.data(), cam, out, &trace);
  double worst_rot = 0, worst_trans = 0;
  for (int i = 0; i < kSamples; ++i) {
    const Sample& s = samples[i];
    const Pose6 p{s.x.to_double(), s.y.to_double(), s.z.to_double(), s.roll.to_double(), s.pitch.to_double(),
                  s.yaw.to_double()};
    const Eigen::Matrix<double, 3, 4> ref = PC * PoseToTransform(p).matrix();
    for (int r = 0; r < 3; ++r) {
      // Tolerance from the formats: rotation entries are Σ_k PC[r][k]·R[k][j] with each R
      // entry a product of ≤ 3 sines/cosines (fx_math SinCos ≤ 2^-16 each, products
      // rounded to 2^-17) → ≤ 4·2^-16 per R entry; plus ≤ 8 roundings to ft_t (2^-23 each).
      const double rowsum = PC.row(r).head<3>().cwiseAbs().sum();
      const double tol_rot = rowsum * 4 * std::ldexp(1.0, -16) + 8 * std::ldexp(1.0, -23);
      // Translation: PC·(x, y, z, 1) with exact x, y, z and PC rounded to 2^-23 per entry.
      const double tol_trans = (std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z) + 2) * std::ldexp(1.0, -23);
      for (int c = 0; c < 4; ++c) {
        ASSERT_FALSE(out.empty());
        const double v = out.read().to_double();
        const double err = std::fabs(v - ref(r, c));
        if (c < 3) {
          EXPECT_LE(err, tol_rot) << "sample " << i << " FT(" << r << "," << c << ")";
          worst_rot = std::max(worst_rot, err / rowsum);
        } else {
          EXPECT_LE(err, tol_trans) << "sample " << i << " FT(" << r << ",3)";
          worst_trans = std::max(worst_trans, err);
        }
      }
    }
  }
  EXPECT_TRUE(out.empty());
  // The error must come from the 16-bit sines, not vanish (would mean a float path) nor
  // exceed them.
  EXPECT_GT(worst_rot, 0.0);
  ASSERT_GE(trace.count, 2);
  EXPECT_EQ(trace.records[trace.count - 1].trips, uint64_t(kSamples) * kFtElements);
  std::printf("FT: worst rotation error / row sum %.3g (2^-16 = %.3g), worst translation error %.3g px\n", worst_rot,
              std::ldexp(1.0, -16), worst_trans);
}

TEST(HwRenderTransform, PackFaceFollowsListing71) {
  const face_t f = PackFace(1, 513, 1023);
  EXPECT_EQ(f.range(9, 0).to_int(), 1);
  EXPECT_EQ(f.range(19, 10).to_int(), 513);
  EXPECT_EQ(f.range(29, 20).to_int(), 1023);
}

TEST(HwRenderTransform, DivFloorIsExactAndFlagsOverflow) {
  Rng rng(3);
  for (int i = 0; i < 2000; ++i) {
    const uint64_t d = 1 + rng.UniformInt(1u << 30);
    const uint64_t n = rng.UniformInt(d << 20);  // quotient < 2^20
    bool of = true;
    const ap_uint<20> q = DivFloor<20>(ap_uint<52>(n), ap_uint<31>(d), &of);
    ASSERT_FALSE(of);
    ASSERT_EQ(q.to_uint64(), n / d) << n << "/" << d;
  }
  bool of = false;
  DivFloor<20>(ap_uint<52>(uint64_t(5) << 20), ap_uint<31>(5), &of);  // quotient 2^20 does not fit
  EXPECT_TRUE(of);
  of = false;
  const ap_uint<20> q0 = DivFloor<20>(ap_uint<52>(7), ap_uint<31>(0), &of);
  EXPECT_TRUE(of);
  EXPECT_EQ(q0.to_uint64(), (1u << 20) - 1);
}

// ---- Vertex multiplier ----

TEST(HwRenderVertexMultiplier, CopiesEveryFaceToEveryActiveCorePerRound) {
  std::unique_ptr<xyz_t[][kMaxVertices]> vmem(new xyz_t[3][kMaxVertices]);
  for (int i = 0; i < 8; ++i)
    for (int a = 0; a < 3; ++a) Set(vmem[a][i], Quant(0.01 * (i + 1) * (a + 1), 10));
  const std::vector<face_t> faces = {PackFace(0, 1, 2), PackFace(7, 3, 5), PackFace(6, 6, 4)};
  const int N = 7, M = 3;  // rounds of 3, 3, 1 particles
  hls::stream<Vertex> out[kMaxRasterCores];
  CycleTrace trace;
  VertexMultiplier(N, M, 3, vmem.get(), faces.data(), out, &trace);
  for (int c = 0; c < M; ++c) {
    const int particles = (N - c + M - 1) / M;  // core c renders particles c, c+M, …
    for (int p = 0; p < particles; ++p) {
      for (int f = 0; f < 3; ++f) {
        for (int k = 0; k < 3; ++k) {
          const int idx = faces[f].range(10 * k + 9, 10 * k).to_int();
          ASSERT_FALSE(out[c].empty()) << "core " << c;
          const Vertex v = out[c].read();
          EXPECT_EQ(v.x.to_double(), vmem[0][idx].to_double());
          EXPECT_EQ(v.y.to_double(), vmem[1][idx].to_double());
          EXPECT_EQ(v.z.to_double(), vmem[2][idx].to_double());
        }
      }
    }
    EXPECT_TRUE(out[c].empty()) << "core " << c << " got more than its particles' faces";
  }
  for (int c = M; c < kMaxRasterCores; ++c) EXPECT_TRUE(out[c].empty());
  // The model's on-chip copy (three coordinate bursts of kMaxVertices words, one of the faces),
  // then the vertex loop.
  ASSERT_EQ(trace.count, 3);
  EXPECT_STREQ(trace.records[0].loop, "VM_LOAD_VERTICES");
  EXPECT_EQ(trace.records[0].trips, uint64_t(3) * kMaxVertices);
  EXPECT_EQ(trace.records[0].memory, uint64_t(3) * kAxiReadLatency);
  EXPECT_EQ(trace.records[1].trips, uint64_t(3));
  EXPECT_EQ(trace.records[2].trips, uint64_t(3) * 3 * 3);  // 3 rounds × 3 faces × 3 vertices: one model read per round
  EXPECT_EQ(trace.records[2].memory, 0u);
}

// ---- FT distributor ----

TEST(HwRenderFtDistributor, SendsEachParticlesMatrixToItsCore) {
  const int N = 11, M = 4;
  hls::stream<ft_t> in;
  for (int p = 0; p < N; ++p)
    for (int e = 0; e < kFtElements; ++e) in.write(ft_t(p * 100 + e));
  hls::stream<ft_t> out[kMaxRasterCores];
  DistributeFT(N, M, in, out, nullptr);
  EXPECT_TRUE(in.empty());
  for (int p = 0; p < N; ++p)
    for (int e = 0; e < kFtElements; ++e) {
      ASSERT_FALSE(out[p % M].empty());
      EXPECT_EQ(out[p % M].read().to_double(), p * 100 + e);
    }
  for (int c = 0; c < kMaxRasterCores; ++c) EXPECT_TRUE(out[c].empty());
}

// ---- Depth fragment & sample-info distributor ----

struct DistCase {
  std::vector<Window> windows;
  int M;
};

void CheckDistribution(const std::vector<Window>& windows, int M, uint64_t* shared, uint64_t* unshared) {
  const int W = 64, H = 48;  // a small image (row stride W), distinct value per pixel
  std::vector<depth_t> depth(std::size_t(kImageWidth) * kImageHeight);
  for (int i = 0; i < W * H; ++i) Set(depth[i], Quant(0.001 * (1 + i % 3000), 10));
  const int N = int(windows.size());
  hls::stream<Window> info[kMaxRasterCores];
  hls::stream<depth_t> frag[kMaxRasterCores];
  DepthDistributionCounts counts;
  CycleTrace trace;
  std::vector<depth_t> depth_mem(depth.size());
  DistributeDepth(N, M, windows.data(), depth.data(), W, H, depth_mem.data(), info, frag, &counts, &trace);
  uint64_t expect_shared = 0, expect_unshared = 0;
  for (int first = 0; first < N; first += M) {
    std::set<std::pair<int, int>> pixels;  // distinct pixels of the round
    for (int c = 0; c < M && first + c < N; ++c) {
      const Window& w = windows[first + c];
      ASSERT_FALSE(info[c].empty());
      const Window got = info[c].read();
      EXPECT_EQ(got.u0.to_int(), w.u0.to_int());
      EXPECT_EQ(got.height.to_int(), w.height.to_int());
      for (int v = w.v0.to_int(); v < w.v0.to_int() + w.height.to_int(); ++v)
        for (int u = w.u0.to_int(); u < w.u0.to_int() + w.width.to_int(); ++u) {
          ASSERT_FALSE(frag[c].empty()) << "core " << c << " missing pixel " << u << "," << v;
          EXPECT_EQ(frag[c].read().to_double(), depth[v * W + u].to_double()) << "pixel " << u << "," << v;
          pixels.insert({u, v});
        }
      expect_unshared += uint64_t(w.width.to_int()) * w.height.to_int();
    }
    expect_shared += pixels.size();
  }
  for (int c = 0; c < kMaxRasterCores; ++c) EXPECT_TRUE(frag[c].empty() && info[c].empty()) << "core " << c;
  EXPECT_EQ(counts.reads_shared.to_uint64(), expect_shared);
  EXPECT_EQ(counts.reads_unshared.to_uint64(), expect_unshared);
  // The pixel loop's trace record counts the reads.
  bool found = false;
  for (int i = 0; i < trace.count; ++i)
    if (std::string(trace.records[i].loop) == "DD_PIXELS") {
      found = true;
      EXPECT_EQ(trace.records[i].trips, expect_shared);
    }
  EXPECT_TRUE(found);
  *shared = expect_shared;
  *unshared = expect_unshared;
}

Window Win(int u0, int v0, int w, int h) {
  Window x;
  x.u0 = u0;
  x.v0 = v0;
  x.width = w;
  x.height = h;
  return x;
}

TEST(HwRenderDepthDistributor, IdenticalWindowsAreReadOncePerRound) {
  uint64_t shared = 0, unshared = 0;
  const std::vector<Window> w(5, Win(10, 5, 20, 16));
  CheckDistribution(w, 5, &shared, &unshared);
  EXPECT_EQ(shared, 20u * 16u);
  EXPECT_EQ(unshared, 5u * 20u * 16u);
}

TEST(HwRenderDepthDistributor, OverlappingDisjointAndPartialRounds) {
  uint64_t shared = 0, unshared = 0;
  // Round 1: overlapping, nested, touching and disjoint windows; round 2 partial (2 of 4).
  const std::vector<Window> w = {Win(0, 0, 20, 10),  Win(10, 5, 20, 10), Win(12, 6, 4, 2),
                                 Win(30, 0, 5, 30),  Win(50, 40, 14, 8), Win(50, 40, 14, 8)};
  CheckDistribution(w, 4, &shared, &unshared);
  EXPECT_LT(shared, unshared);
}

TEST(HwRenderDepthDistributor, RandomWindowsDeliverExactFragments) {
  Rng rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const int M = 1 + int(rng.UniformInt(kMaxRasterCores));
    const int N = 1 + int(rng.UniformInt(25));
    std::vector<Window> w(N);
    for (auto& x : w) {
      const int ww = 1 + int(rng.UniformInt(40)), hh = 1 + int(rng.UniformInt(30));
      const int v0 = int(rng.UniformInt(48)), u0 = int(rng.UniformInt(64));  // one draw per statement, as GCC ordered them
      x = SaturatedWindow(u0, v0, ww, hh, 64, 48);
    }
    uint64_t shared = 0, unshared = 0;
    SCOPED_TRACE(::testing::Message() << "trial " << trial << " M=" << M << " N=" << N);
    CheckDistribution(w, M, &shared, &unshared);
    EXPECT_LE(shared, unshared);
    if (M == 1) EXPECT_EQ(shared, unshared);
  }
}

TEST(HwRenderDepthDistributor, SaturatedWindowStaysInsideTheImage) {
  const Window a = SaturatedWindow(5, 470, 200, 100, 640, 480);
  EXPECT_EQ(a.u0.to_int(), 0);
  EXPECT_EQ(a.v0.to_int(), 380);
  EXPECT_EQ(a.width.to_int(), 200);
  const Window b = SaturatedWindow(320, 240, 500, 20, 640, 480);  // clipped to kMaxWindow
  EXPECT_EQ(b.width.to_int(), kMaxWindow);
  EXPECT_EQ(b.u0.to_int(), 220);
  std::string why;
  EXPECT_TRUE(WindowIsValid(a, 640, 480, &why)) << why;
  EXPECT_FALSE(WindowIsValid(Win(500, 0, 200, 10), 640, 480, &why));
  EXPECT_NE(why.find("image width"), std::string::npos) << why;
  EXPECT_FALSE(WindowIsValid(Win(0, 0, 0, 10), 640, 480, &why));
  EXPECT_NE(why.find("width"), std::string::npos) << why;
  EXPECT_FALSE(WindowIsValid(Win(0, 400, 10, 100), 640, 480, &why));
  EXPECT_NE(why.find("image height"), std::string::npos) << why;
}

// ---- Weight merger ----

double ReferenceWeight(const RasterCoreOutput& o, double rho, double a, double b, double g, double d, bool occ) {
  const double I = o.inlier_sum.to_double();
  const double nr = double(o.n_raster.to_uint64()) - (occ ? double(o.n_occluded.to_uint64()) : 0.0);
  const double nd = double(o.n_depth.to_uint64());
  const double r1 = nr > 0 ? std::min(1.0, I / nr) : 0.0;
  const double r2 = nd > 0 ? std::min(1.0, I / nd) : 0.0;
  const double ne = double(o.n_edge.to_uint64());
  const double re = ne > 0 ? double(o.n_edge_continued.to_uint64()) / ne : 0.0;
  return std::max(0.0, a * r1 + b * r2 + g * rho - d * re);
}

TEST(HwRenderWeightMerger, MatchesDoubleFormulaInParticleOrder) {
  Rng rng(21);
  const int N = 23, M = 5;
  std::vector<prob_t> prob(kNumCells);
  for (int i = 0; i < kNumCells; ++i) Set(prob[i], Quant(rng.Uniform(0, 0.996), 8));
  std::vector<cell_index_t> cells(kMaxParticles);
  hls::stream<RasterCoreOutput> core_out[kMaxRasterCores];
  std::vector<RasterCoreOutput> outs(N);
  for (int p = 0; p < N; ++p) {
    RasterCoreOutput& o = outs[p];
    const uint64_t nr = p == 3 ? 0 : rng.UniformInt(40000);  // particle 3: nothing rendered
    o.n_raster = nr;
    o.n_occluded = nr ? rng.UniformInt(nr) : 0;
    Set(o.inlier_sum, Quant(rng.Uniform(0, 1.3) * double(nr), 10));  // > N_raster possible without z-buffer
    o.n_depth = p == 4 ? 0 : rng.UniformInt(40000);
    o.n_edge = p % 3 == 0 ? 0 : rng.UniformInt(800);
    o.n_edge_continued = o.n_edge == 0 ? 0 : rng.UniformInt(o.n_edge.to_uint64() + 1);
    o.depth_diff_sum = 0;
    o.depth_diff_count = 0;
    o.faces_front = 1;
    o.faces_total = 2;
    cells[p] = rng.UniformInt(kNumCells);
    core_out[p % M].write(o);
  }
  for (int variant = 0; variant < 2; ++variant) {
    WeightParams prm = DefaultWeightParams();
    if (variant == 1) {  // the thesis's eq. 7.4 [ALGORITHM.md]: no edge penalty, plain N_raster
      Set(prm.alpha, 0.25);
      Set(prm.beta, 0.25);
      Set(prm.gamma, 0.5);
      prm.delta = 0;
      prm.occlusion_aware = 0;
      for (int p = 0; p < N; ++p) core_out[p % M].write(outs[p]);
    }
    std::string why;
    ASSERT_TRUE(WeightParamsAreValid(prm, &why)) << why;
    hls::stream<WeightOut> weights;
    hls::stream<RasterCoreOutput> stats;
    CycleTrace trace;
    MergeWeights(N, M, prm, core_out, cells.data(), prob.data(), weights, stats, &trace);
    for (int p = 0; p < N; ++p) {
      ASSERT_FALSE(weights.empty());
      const WeightOut w = weights.read();
      EXPECT_EQ(w.index.to_int(), p);
      const double ref = ReferenceWeight(outs[p], prob[cells[p].to_int()].to_double(), prm.alpha.to_double(),
                                         prm.beta.to_double(), prm.gamma.to_double(), prm.delta.to_double(),
                                         prm.occlusion_aware == 1);
      // Three ratios rounded to 2^-18 (fx_math Divide), times coefficients ≤ 1; the weight
      // truncated to 2^-17: |Δ| ≤ 3·2^-18 + 2^-17.
      EXPECT_NEAR(w.weight.to_double(), ref, 3 * std::ldexp(1.0, -18) + std::ldexp(1.0, -17)) << "particle " << p;
      ASSERT_FALSE(stats.empty());
      EXPECT_EQ(stats.read().n_raster.to_uint64(), outs[p].n_raster.to_uint64());
    }
    EXPECT_TRUE(weights.empty());
    for (int c = 0; c < kMaxRasterCores; ++c) EXPECT_TRUE(core_out[c].empty());
    ASSERT_EQ(trace.count, 2);  // ρ's on-chip copy, then the particles
    EXPECT_STREQ(trace.records[0].loop, "WM_PROB_LOAD");
    EXPECT_EQ(trace.records[0].trips, uint64_t(kNumCells));
    EXPECT_EQ(trace.records[1].trips, uint64_t(N));
    EXPECT_EQ(trace.records[1].ii, 3u);
  }
}

TEST(HwRenderWeightMerger, ParamChecksNameTheConstraint) {
  WeightParams p = DefaultWeightParams();
  std::string why;
  EXPECT_TRUE(WeightParamsAreValid(p, &why));
  Set(p.alpha, 0.5);  // sum 1.3
  EXPECT_FALSE(WeightParamsAreValid(p, &why));
  EXPECT_NE(why.find("alpha + beta + gamma"), std::string::npos) << why;
  p = DefaultWeightParams();
  Set(p.delta, 1.5);
  EXPECT_FALSE(WeightParamsAreValid(p, &why));
  EXPECT_NE(why.find("delta"), std::string::npos) << why;
  p = DefaultWeightParams();
  Set(p.alpha, 1.5);
  p.beta = 0;
  p.gamma = 0;
  EXPECT_FALSE(WeightParamsAreValid(p, &why));
  EXPECT_NE(why.find("[0, 1]"), std::string::npos) << why;
}

TEST(HwRenderRasterParams, ChecksNameTheConstraint) {
  RasterParams p = DefaultRasterParams();
  std::string why;
  EXPECT_TRUE(RasterParamsAreValid(p, &why)) << why;
  p.inv_thr1 = 100;  // not 1/thr1
  EXPECT_FALSE(RasterParamsAreValid(p, &why));
  EXPECT_NE(why.find("inv_thr1"), std::string::npos) << why;
  p = DefaultRasterParams();
  p.thr1 = 0;
  EXPECT_FALSE(RasterParamsAreValid(p, &why));
  EXPECT_NE(why.find("thr1"), std::string::npos) << why;
  p = DefaultRasterParams();
  Set(p.near_plane, 0.01);
  EXPECT_FALSE(RasterParamsAreValid(p, &why));
  EXPECT_NE(why.find("near_plane"), std::string::npos) << why;
  p = DefaultRasterParams();
  p.edge_band = 0;
  EXPECT_FALSE(RasterParamsAreValid(p, &why));
  EXPECT_NE(why.find("edge_band"), std::string::npos) << why;
}

}  // namespace
}  // namespace posefilter::hw
