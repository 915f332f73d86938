// tests/hw/rtl/rtl_engine_check.cc — `--engine rtl` against `--engine hw` (docs/HARDWARE.md §16):
// the same estimates, once with the C model's weighing and once with the Verilated accelerator
// (src/hw/rtl/weigh_accel.sv through hw::host::WeighDriver and VerilatorTransport), must give
// bit-identical weights, poses, cells, best-weight histories, iteration counts and counters.
// With --bubbles or --words, every weighing of the rtl run is also compared word for word with
// the C model's weigh region on the same inputs (HwWeighTopCores): the sorted weights and
// indices, each particle's core counters and depth offset, the depth distributor's counts.
//
// Per mesh: a synthetic scene (MakeSynthScene; a small image, the thesis camera scaled to it,
// so the runs stay short), its detection prior, and the hw engine's filter (no polish). The
// plain run goes through EstimatePose with engine "rtl" (the CLI's path); --bubbles SEED runs
// the rtl engine on a simulated bus with random latencies and valid/ready bubbles (seeded)
// instead. Prints the simulated clocks per weighing next to the cycle model's.
//
// Usage: rtl_engine_check MESH [--bubbles SEED] [--words] [--particles N] [--iterations K]
//                              [--image WxH] [--restarts R] [--seed S]
//        rtl_engine_check --violate   negative control: a host that writes a parameter register
//                                     while a call runs must fire the top's assertion (the
//                                     simulation stops with "Assertion failed")
//        rtl_engine_check --bus-fault SEED   bus errors reach the host: WeighDriver over a
//                                     VerilatorTransport that answers one read beat SLVERR (the
//                                     buffer and beat picked by SEED) or one write response
//                                     DECERR must throw naming STATUS, the bit, the buffer and
//                                     the response; the next call on the same accelerator must
//                                     give the clean run's words
//   MESH: torus | lshape | box | cylinder (synthetic kinds) | a mesh file (PLY/OBJ, metres);
//         a file that does not exist: prints SKIPPED and exits 0 (the YCB-Video models are
//         optional in shared/)
// Exit 0 when everything is identical, 1 on a difference, 2 on bad arguments.
#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "filter/driver.h"
#include "filter/engine.h"
#include "filter/rtl_engine.h"
#include "filter/scene_prep.h"
#include "filter/hw_weigh.h"
#include "hw/host/axi_pack.h"
#include "hw/host/weigh_driver.h"
#include "hw/host/weigh_regs.h"
#include "posefilter/error.h"
#include "posefilter/file_io.h"
#include "posefilter/filter.h"
#include "posefilter/synth.h"

using namespace posefilter;

namespace {

int failures = 0;

template <class T>
void Same(const char* what, const T& a, const T& b) {
  if (a == b) return;
  ++failures;
  std::printf("DIFFERENT %s\n", what);
}

void Compare(const EstimateResult& hw, const EstimateResult& rtl) {
  Same("weight", hw.weight, rtl.weight);
  Same("cell", hw.cell, rtl.cell);
  Same("iterations", hw.iterations, rtl.iterations);
  Same("converged", hw.converged, rtl.converged);
  Same("best_weight_history", hw.best_weight_history, rtl.best_weight_history);
  Same("pose x", hw.pose_base.x, rtl.pose_base.x);
  Same("pose y", hw.pose_base.y, rtl.pose_base.y);
  Same("pose z", hw.pose_base.z, rtl.pose_base.z);
  Same("pose roll", hw.pose_base.roll, rtl.pose_base.roll);
  Same("pose pitch", hw.pose_base.pitch, rtl.pose_base.pitch);
  Same("pose yaw", hw.pose_base.yaw, rtl.pose_base.yaw);
  Same("faces_total", hw.stats.faces_total, rtl.stats.faces_total);
  Same("faces_front", hw.stats.faces_front, rtl.stats.faces_front);
  Same("fragments", hw.stats.fragments, rtl.stats.fragments);
  Same("weighings", hw.stats.weighings, rtl.stats.weighings);
  Same("resample_cdf_reads", hw.stats.resample_cdf_reads, rtl.stats.resample_cdf_reads);
}

// The rtl engine's weighing, each call checked against the C model's weigh region.
class CheckedWeigh final : public filter::HwWeighStrategy {
 public:
  explicit CheckedWeigh(const hw::host::VerilatorTransportOptions& topt) : rtl_(filter::MakeRtlWeigh(topt)), ref_(new Ref) {}
  void Weigh(int cores, int n, const hw::WeighConfig& cfg, const hw::Sample samples[hw::kMaxParticles],
             const hw::Window cell_windows[hw::kNumCells], const hw::prob_t class_prob[hw::kNumCells],
             const hw::depth_t depth[hw::kImageHeight * hw::kImageWidth], const hw::xyz_t vmem[3][hw::kMaxVertices],
             const hw::face_t tri_mem[hw::kMaxFaces], hw::weight_t sorted_w[hw::kMaxParticles],
             hw::particle_index_t sorted_idx[hw::kMaxParticles], hw::RasterCoreOutput stats[hw::kMaxParticles],
             hw::depth_off_t offsets[hw::kMaxParticles], hw::DepthDistributionCounts* dd, hw::CycleTrace* trace) override {
    rtl_->Weigh(cores, n, cfg, samples, cell_windows, class_prob, depth, vmem, tri_mem, sorted_w, sorted_idx, stats, offsets,
                dd, trace);
    Ref& r = *ref_;
    // At the library model's M = 5 (the depth distributor's counts depend on M, the rest not).
    hw::HwWeighTopCores(5, n, cfg, samples, cell_windows, class_prob, depth, vmem, tri_mem, r.w, r.idx, r.stats,
                        r.offsets, &r.dd, nullptr);
    namespace axi = hw::axi;
    auto same = [&](const auto* a, const auto* b, int count) { return axi::Pack(a, count) == axi::Pack(b, count); };
    const bool ok = same(sorted_w, r.w, n) && same(sorted_idx, r.idx, n) && same(stats, r.stats, n) &&
                    same(offsets, r.offsets, n) && same(dd, &r.dd, 1);
    ++calls;
    if (!ok) {
      ++mismatches;
      std::printf("DIFFERENT weighing %d: the rtl weighing's words differ from the C model's\n", calls);
    }
  }
  void EndRun(FilterStats* s) override { rtl_->EndRun(s); }
  int calls = 0, mismatches = 0;

 private:
  struct Ref {
    hw::weight_t w[hw::kMaxParticles];
    hw::particle_index_t idx[hw::kMaxParticles];
    hw::RasterCoreOutput stats[hw::kMaxParticles];
    hw::depth_off_t offsets[hw::kMaxParticles];
    hw::DepthDistributionCounts dd;
  };
  std::unique_ptr<filter::HwWeighStrategy> rtl_;
  std::unique_ptr<Ref> ref_;
};

// A call started on a tiny problem (one particle, a 1 × 1 image, zeroed buffers), then
// NUM_PARTICLES written while it runs: weigh_accel's assertion must stop the simulation.
int Violate() {
  namespace regs = hw::regs;
  const auto t = hw::host::MakeVerilatorTransport({});
  const std::uint32_t addr_regs[] = {regs::kImgAddrLo, regs::kWinAddrLo, regs::kFtAddrLo, regs::kModelAddrLo,
                                     regs::kProbAddrLo, regs::kCellAddrLo, regs::kOutAddrLo};
  for (std::uint32_t lo : addr_regs) {
    const std::uint64_t a = t->Alloc(64 << 10, 4096);
    t->WriteReg(lo, std::uint32_t(a));
    t->WriteReg(lo + 4, std::uint32_t(a >> 32));
  }
  t->WriteReg(regs::kNumParticles, 1);
  t->WriteReg(regs::kNumFaces, 1);
  t->WriteReg(regs::kImgWidth, 1);
  t->WriteReg(regs::kImgHeight, 1);
  t->WriteReg(regs::kCtrl, regs::kCtrlApStart.Put(1));
  t->WriteReg(regs::kNumParticles, 2);  // illegal: a call is running
  t->WaitInterrupt(100);
  std::printf("NO ASSERTION: writing a parameter register during a call went unnoticed\n");
  return 1;
}

// A small call (2 particles, a 16 × 16 image, 4 faces) through WeighDriver: clean, with one
// failed read beat, with one failed write response, and again after each failure.
int BusFault(std::uint64_t seed) {
  using namespace hw;
  constexpr int n = 2, width = 16, height = 16, faces = 4;
  std::vector<depth_t> depth(std::size_t(width) * height);
  for (std::size_t i = 0; i < depth.size(); ++i) axi::SetRawBits(depth[i], 600 + i % 64);
  static xyz_t vmem[3][kMaxVertices];
  for (int v = 0; v < 8; ++v)
    for (int k = 0; k < 3; ++k) axi::SetRawBits(vmem[k][v], (v >> k & 1) ? 40 : 0);
  std::vector<face_t> tri(faces);
  for (int f = 0; f < faces; ++f) axi::SetRawBits(tri[std::size_t(f)], std::uint64_t(f) | std::uint64_t(f + 1) << 10 | std::uint64_t(f + 2) << 20);
  std::vector<prob_t> prob(kNumCells);
  std::vector<Window> win(n);
  std::vector<ft_t> ft(std::size_t(n) * kFtElements);
  std::vector<cell_index_t> cells(n);
  for (int p = 0; p < n; ++p) {
    win[std::size_t(p)].u0 = p;
    win[std::size_t(p)].v0 = p;
    win[std::size_t(p)].width = 12;
    win[std::size_t(p)].height = 12;
    // FT: identity rotation (1.0 = 2^22 raw), translation 0.6 m in z (ft_t raw F22).
    for (int r = 0; r < 3; ++r) axi::SetRawBits(ft[std::size_t(p * kFtElements + r * 4 + r)], 1u << 22);
    axi::SetRawBits(ft[std::size_t(p * kFtElements + 11)], std::uint64_t(0.6 * (1 << 22)));
  }
  // Beats per read buffer of this call (16-byte beats): IMG, WIN, FT, MODEL, PROB, CELL.
  const std::uint64_t beats[6] = {std::uint64_t(width * height * 2 + 15) / 16, 1, std::uint64_t(n * kFtElements * 8 + 15) / 16,
                                  std::uint64_t((kMaxVertices + faces) * 8 + 15) / 16, std::uint64_t(kNumCells + 15) / 16, 1};
  const char* const names[6] = {"IMG", "WIN", "FT", "MODEL", "PROB", "CELL"};
  struct Words {
    std::vector<WeightOut> w = std::vector<WeightOut>(n);
    std::vector<RasterCoreOutput> s = std::vector<RasterCoreOutput>(n);
    bool operator==(const Words& o) const {
      for (int p = 0; p < n; ++p)
        if (axi::RawBits(w[std::size_t(p)].weight) != axi::RawBits(o.w[std::size_t(p)].weight) ||
            axi::RawBits(w[std::size_t(p)].index) != axi::RawBits(o.w[std::size_t(p)].index))
          return false;
      return axi::Pack(s.data(), n) == axi::Pack(o.s.data(), n);
    }
  };
  auto call = [&](host::WeighDriver& d, Words* out) {
    d.Weigh(n, DefaultRasterParams(), DefaultWeightParams(), win.data(), ft.data(), cells.data(), out->w.data(),
            out->s.data(), 1'000'000);
  };
  int bad = 0;
  Words clean;
  {
    const auto t = host::MakeVerilatorTransport({});
    host::WeighDriver d(*t);
    d.LoadScene(depth.data(), width, height, vmem, tri.data(), faces, prob.data());
    call(d, &clean);
  }
  // One faulty call, then the same call again: it must throw a message with every `want`, then
  // give the clean words with STATUS clear.
  auto faulty = [&](const host::VerilatorTransportOptions& topt, const std::vector<std::string>& want) {
    const auto t = host::MakeVerilatorTransport(topt);
    host::WeighDriver d(*t);
    d.LoadScene(depth.data(), width, height, vmem, tri.data(), faces, prob.data());
    Words got;
    std::string msg;
    try {
      call(d, &got);
    } catch (const Error& e) {
      msg = e.what();
    }
    std::printf("fault on AXI ID %d, beat %llu, RESP %d: %s\n", topt.fault_id, (unsigned long long)topt.fault_index,
                topt.fault_resp, msg.empty() ? "no error reported" : msg.c_str());
    for (const std::string& w : want)
      if (msg.find(w) == std::string::npos) ++bad, std::printf("FAILED: the message lacks '%s'\n", w.c_str());
    try {
      call(d, &got);
      if (!(got == clean)) ++bad, std::printf("FAILED: the call after the fault differs from the clean run\n");
      if (t->ReadReg(regs::kStatus) != 0) ++bad, std::printf("FAILED: STATUS not clear after a clean call\n");
    } catch (const Error& e) {
      ++bad;
      std::printf("FAILED: the call after the fault: %s\n", e.what());
    }
  };
  host::VerilatorTransportOptions rd;
  rd.fault_id = int(seed % 6);
  rd.fault_index = (seed / 6) % beats[rd.fault_id];
  rd.fault_resp = 2;
  faulty(rd, {"STATUS reads", "RD_ERR", std::string("the ") + names[rd.fault_id] + " buffer (RID " +
                                            std::to_string(rd.fault_id) + ")", "SLVERR (2)"});
  host::VerilatorTransportOptions wr;
  wr.fault_id = 6;
  wr.fault_index = seed % n;
  wr.fault_resp = 3;
  faulty(wr, {"STATUS reads", "WR_ERR", "OUT buffer", "DECERR (3)"});
  std::printf(bad ? "FAILED\n" : "PASSED: bus faults reported\n");
  return bad ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--violate") return Violate();
  if (argc == 3 && std::string(argv[1]) == "--bus-fault") {
    try {
      return BusFault(std::strtoull(argv[2], nullptr, 10));
    } catch (const Error& e) {
      std::printf("error: %s\nFAILED\n", e.what());
      return 1;
    }
  }
  std::string mesh_arg;
  int particles = 24, iterations = 3, width = 160, height = 120, restarts = 1;
  std::uint64_t seed = 7, bubbles = 0;
  bool random_bus = false, words = false;
  for (int a = 1; a < argc; ++a) {
    const std::string s = argv[a];
    auto next = [&]() -> const char* { return a + 1 < argc ? argv[++a] : ""; };
    if (s == "--bubbles") random_bus = true, bubbles = std::strtoull(next(), nullptr, 10);
    else if (s == "--words") words = true;
    else if (s == "--particles") particles = std::atoi(next());
    else if (s == "--iterations") iterations = std::atoi(next());
    else if (s == "--restarts") restarts = std::atoi(next());
    else if (s == "--seed") seed = std::strtoull(next(), nullptr, 10);
    else if (s == "--image") {
      if (std::sscanf(next(), "%dx%d", &width, &height) != 2) width = 0;
    } else if (mesh_arg.empty() && !s.empty() && s[0] != '-') mesh_arg = s;
    else {
      std::fprintf(stderr, "usage: rtl_engine_check MESH [--bubbles SEED] [--words] [--particles N] [--iterations K] "
                           "[--image WxH] [--restarts R] [--seed S]\n");
      return 2;
    }
  }
  if (mesh_arg.empty() || width < 32 || width > 640 || height < 24 || height > 480) {
    std::fprintf(stderr, "rtl_engine_check: a mesh and an image within 32x24 … 640x480 are needed\n");
    return 2;
  }
  try {
    SynthOptions so;
    so.clutter = 1;
    const double k = double(width) / so.camera.width;
    so.camera.width = width;
    so.camera.height = height;
    so.camera.fx *= k;
    so.camera.fy *= double(height) / 480.0;
    so.camera.cx *= k;
    so.camera.cy *= double(height) / 480.0;
    Mesh file_mesh;
    const bool synthetic = mesh_arg == "torus" || mesh_arg == "lshape" || mesh_arg == "box" || mesh_arg == "cylinder";
    if (synthetic) {
      so.target = mesh_arg;
    } else {
      if (!std::filesystem::exists(mesh_arg)) {
        std::printf("SKIPPED: mesh file %s not found (the YCB-Video models are optional in shared/)\n", mesh_arg.c_str());
        return 0;
      }
      file_mesh = LoadMesh(mesh_arg, 1.0);
      file_mesh.name = std::filesystem::path(mesh_arg).stem().string();
      so.target_mesh = &file_mesh;
    }
    const SynthScene scene = MakeSynthScene(so, seed);
    const Prior prior = PostProcessPyramid(scene.raw_pyramid, scene.layout, scene.classes);
    const int cls = prior.ClassIndex(scene.target.name);
    const SceneInput input{scene.depth, scene.camera, {}};
    FilterOptions o;
    o.engine = "hw";
    o.num_particles = particles;
    o.num_elite = std::min(o.num_elite, std::max(1, particles / 4));  // < N for the small sets
    o.stop.max_iterations = iterations;
    o.restarts = restarts;
    o.polish.steps = 0;
    o.seed = seed;
    o.render.max_window_px = std::min(o.render.max_window_px, std::min(width, height));
    std::printf("mesh %s (%zu faces), image %dx%d, %d particles, %d iterations, %d restart(s), bus: %s\n",
                scene.target.name.c_str(), scene.target.faces.size(), width, height, particles, iterations, restarts,
                random_bus ? ("random latencies and bubbles, seed " + std::to_string(bubbles)).c_str()
                           : "latency.h's DDR latencies, no bubbles");
    const auto t0 = std::chrono::steady_clock::now();
    const EstimateResult hw = EstimatePose(input, scene.target, prior, cls, o);
    const auto t1 = std::chrono::steady_clock::now();
    EstimateResult rtl;
    o.engine = "rtl";
    if (!random_bus && !words) {
      rtl = EstimatePose(input, scene.target, prior, cls, o);  // the CLI's path: engine "rtl"
    } else {
      hw::host::VerilatorTransportOptions topt;
      topt.read_latency = 64;
      topt.write_latency = 64;
      if (random_bus) {
        topt.random = true;
        topt.seed = bubbles;
        topt.bubble = 0.3;
        topt.read_latency = 24;
        topt.write_latency = 12;
      }
      const filter::PreparedScene prep = filter::PrepareScene(input, o);
      auto checked = std::make_unique<CheckedWeigh>(topt);
      CheckedWeigh* check = checked.get();
      const auto runs = filter::MakeHwEngineWith(prep, scene.target, prior, cls, o, std::move(checked));
      rtl = filter::RunRestarts(o, nullptr, [&](Rng& rng, const ProgressFn& p) { return runs->Run(rng, p); });
      std::printf("%d weighings compared word for word with the C model's: %d differ\n", check->calls,
                  check->mismatches);
      failures += check->mismatches;
      if (check->calls != rtl.iterations) ++failures, std::printf("DIFFERENT: %d weighings checked\n", check->calls);
    }
    const auto t2 = std::chrono::steady_clock::now();
    Compare(hw, rtl);
    std::printf("wall time: hw %.2f s, rtl %.2f s\n", std::chrono::duration<double>(t1 - t0).count(),
                std::chrono::duration<double>(t2 - t1).count());
    const FilterStats& s = rtl.stats;
    std::printf("hw: weight %.6f after %d iterations; rtl: weight %.6f after %d iterations\n", hw.weight, hw.iterations,
                rtl.weight, rtl.iterations);
    if (s.rtl_calls != rtl.iterations) {
      ++failures;
      std::printf("DIFFERENT rtl weighings %" PRId64 " vs iterations %d\n", s.rtl_calls, rtl.iterations);
    }
    if (s.rtl_calls > 0) {
      const double ratio = double(s.rtl_cycles) / double(s.rtl_model_cycles);
      std::printf("clocks per weighing (weighing pipeline): simulated %.0f, cycle model %.0f (ratio %.3f)\n",
                  double(s.rtl_cycles) / double(s.rtl_calls), double(s.rtl_model_cycles) / double(s.rtl_calls), ratio);
      // Without bubbles (the bus at latency.h's DDR latencies) the simulated clocks are within
      // 10 % of the cycle model's.
      if (!random_bus && !(ratio >= 0.9 && ratio <= 1.1)) {
        ++failures;
        std::printf("DIFFERENT: simulated clocks %.3f x the cycle model's, outside [0.9, 1.1]\n", ratio);
      }
    } else {
      ++failures;
      std::printf("DIFFERENT: the rtl engine counted no weighing\n");
    }
  } catch (const Error& e) {
    std::printf("error: %s\n", e.what());
    return 1;
  }
  std::printf(failures ? "FAILED\n" : "PASSED: identical\n");
  return failures ? 1 : 0;
}
