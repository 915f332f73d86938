// Tests of the HLS kernel lint (tools/hls_lint/; hls_lint.h states its rules, docs/HARDWARE.md §9
// describes them). Suite HwTopLint:
// - KernelHeadersStayInTheSynthesizableSubset and TopsHaveInterfacesAndRegionsAreCanonical run
//   the program hls_lint on the real src/hw (its two parts, `--only subset` and `--only top`) and
//   check that it saw what it checks: the kernel headers, every matcher, the tops, the regions and
//   each kernel that moves an m_axi argument;
// - EachRuleCatchesABadSnippet (the synthesizable subset), EachTopRuleCatchesABadFixture (rules
//   (a)–(c)) and EachMemoryRuleCatchesABadFixture (rule (d)) run the library on small headers
//   under a temporary src/hw/: every bad one is reported under its rule, the good ones pass.
// Suite HlsLintTool: the program's output lines, exit status and usage errors.
// The clang-query parts skip when clang-query is not installed.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "hls_lint.h"

namespace posefilter::hls_lint {
namespace {

// <system temp dir>/posefilter_<tag>_<pid>, removed if it exists (not created).
fs::path FreshTempPath(const std::string& tag) {
  const fs::path p = fs::temp_directory_path() / ("posefilter_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteFile(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  EXPECT_TRUE(out.good()) << "cannot write " << path;
}

bool HaveCxx() { return std::system("c++ --version >/dev/null 2>&1") == 0; }

// The repository root: the build's source folder, else from this file's path (absolute, or
// relative to the test binary's folder when ccache rewrote it).
fs::path RepoRoot() {
  std::vector<fs::path> candidates = {POSEFILTER_SOURCE_DIR};
  const fs::path file = __FILE__;
  candidates.push_back(file.parent_path().parent_path().parent_path());
  char exe[4096];
  const ssize_t len = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (len > 0) {
    exe[len] = 0;
    candidates.push_back((fs::path(exe).parent_path() / file).parent_path().parent_path().parent_path());
  }
  for (const fs::path& c : candidates) {
    std::error_code ec;
    if (fs::exists(c / "src/hw/hw_types.h", ec)) return fs::weakly_canonical(c);
  }
  return {};
}

// Whether a finding of `rule` has `text` in its line.
bool Reports(const std::vector<Finding>& findings, const std::string& rule, const std::string& text) {
  return std::any_of(findings.begin(), findings.end(),
                     [&](const Finding& f) { return f.rule == rule && Format(f).find(text) != std::string::npos; });
}

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

// The program hls_lint with `args` (shell words); its stdout and stderr in `dir` (existing).
ToolRun RunTool(const fs::path& dir, const std::string& args) {
  const std::string cmd = std::string("'") + HLS_LINT_PATH + "' " + args + " >'" + (dir / "tool.out").string() +
                          "' 2>'" + (dir / "tool.err").string() + "'";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ReadFile(dir / "tool.out"), ReadFile(dir / "tool.err")};
}

// The lines of --verbose's stderr that start with "hls_lint: <prefix> ", without it.
std::set<std::string> Said(const std::string& err, const std::string& prefix) {
  std::set<std::string> out;
  std::istringstream in(err);
  const std::string start = "hls_lint: " + prefix + " ";
  for (std::string line; std::getline(in, line);)
    if (line.rfind(start, 0) == 0) out.insert(line.substr(start.size()));
  return out;
}

TEST(HwTopLint, KernelHeadersStayInTheSynthesizableSubset) {
  if (!HaveClangQuery()) GTEST_SKIP() << "clang-query not installed";
  const fs::path root = RepoRoot();
  ASSERT_FALSE(root.empty()) << "cannot find the repository (src/hw/hw_types.h)";
  const fs::path dir = FreshTempPath("hwtop_lint");
  fs::create_directories(dir);
  const ToolRun r = RunTool(dir, "--only subset --verbose '" + root.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "") << "kernel lint violations:\n" << r.out;
  const std::set<std::string> headers = Said(r.err, "header");
  EXPECT_GE(headers.size(), 10u) << "expected the kernel headers in " << (root / "src/hw") << "\n" << r.err;
  EXPECT_TRUE(headers.count("hw/top.h")) << r.err;
  EXPECT_FALSE(headers.count("hw/cycle_model.h")) << "the host-side cycle model is not a kernel";
  // Every matcher ran ("N matches." per query) and none matched.
  const std::string ran = std::to_string(SubsetMatchers().size());
  EXPECT_TRUE(Said(r.err, "subset:").count(ran + " of " + ran + " matchers ran, 0 matches")) << r.err;
  fs::remove_all(dir);
}

TEST(HwTopLint, TopsHaveInterfacesAndRegionsAreCanonical) {
  if (!HaveCxx()) GTEST_SKIP() << "no c++ preprocessor";
  const fs::path root = RepoRoot();
  ASSERT_FALSE(root.empty()) << "cannot find the repository (src/hw/hw_types.h)";
  const fs::path dir = FreshTempPath("hwtop_toplint");
  fs::create_directories(dir);
  const ToolRun r = RunTool(dir, "--only top --verbose '" + root.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "") << r.out;
  // The lint saw what it checks: the four tops and the three regions.
  const std::set<std::string> tops = Said(r.err, "top"), regions = Said(r.err, "region");
  for (const char* top : {"HwInitTop", "HwWeighTop5", "HwWeighTop10", "HwUpdateTop"}) EXPECT_TRUE(tops.count(top)) << top;
  for (const char* region : {"HwWeighTop", "HwUpdateTop", "InitSamplesRegion"})
    EXPECT_TRUE(regions.count(region)) << region;
  // Rule (d) followed every m_axi argument to the kernel that reads or writes it.
  const std::set<std::string> followed = Said(r.err, "m_axi followed");
  for (const char* use : {"GatherSampleInfo:samples", "BurstLoad:src", "DistributeDepth:depth", "VertexMultiplier:vmem",
                          "VertexMultiplier:tri_mem", "MergeWeights:class_prob", "SortWeights:sorted_w",
                          "SortWeights:sorted_idx", "CollectStats:stats", "CollectStats:offsets", "Resample:sorted_w",
                          "Resample:samples", "Resample:hypothesis", "Diffuse:in_mem", "Diffuse:volumes",
                          "Diffuse:out_mem", "CdfNormalise:prob", "GenSample:heuristics", "GenSample:samples"})
    EXPECT_TRUE(followed.count(use)) << "rule (d) did not reach " << use;
  fs::remove_all(dir);
}

// Rule (d) rejects each bad access pattern of an m_axi argument and passes the good ones.
TEST(HwTopLint, EachMemoryRuleCatchesABadFixture) {
  if (std::system("c++ --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "no c++ preprocessor";
  const fs::path dir = FreshTempPath("hwtop_memlint");
  fs::create_directories(dir / "src/hw");
  WriteFile(dir / "tu.cc", "#include \"hw/kernel.h\"\n");
  const std::string prelude = R"(#pragma once
template <typename T, int N>
void Load(const T src[N], T dst[N], int count) {
  for (int i = 0; i < count; ++i) {
#pragma HLS PIPELINE II = 1
    dst[i] = src[i];
  }
}
inline int Pick(const int a[64], int k) { return a[k]; }
)";
  // A top around a kernel body: in and out are m_axi on bundles gmem_a and gmem_b (or one).
  const auto top = [](const std::string& kernel, const std::string& bundle_out) {
    return kernel + R"(
inline void HwFixtureTop(int n, const int in[64], const int lut[64], int out[64]) {
#pragma HLS INTERFACE m_axi port = in offset = slave bundle = gmem_a depth = 64
#pragma HLS INTERFACE m_axi port = lut offset = slave bundle = gmem_lut depth = 64
#pragma HLS INTERFACE m_axi port = out offset = slave bundle = )" + bundle_out + R"( depth = 64
#pragma HLS INTERFACE s_axilite port = n bundle = control
#pragma HLS INTERFACE s_axilite port = return bundle = control
  Kernel(n, in, lut, out);
}
)";
  };
  const std::vector<fs::path> includes = {dir / "src"};
  const std::vector<std::tuple<std::string, std::string, std::string>> good = {
      {"affine reads and writes", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  const int base = n / 2;
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    out[i] = in[base + 2 * i] + lut[i];
  }
})", "gmem_b"},
      {"a random read of an on-chip copy", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  int copy[64];
  Load<int, 64>(in, copy, 64);
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    out[i] = copy[lut[i] & 63];
  }
})", "gmem_b"},
      {"two arrays of one bundle in a loop of II 2", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 2
    out[i] = in[i];
  }
  (void)lut;
})", "gmem_a"},
      {"a row of a 2-D walk (the outer counter is invariant in the inner loop)",
       R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  for (int r = 0; r < 8; ++r) {
    for (int c = 0; c < n; ++c) {
#pragma HLS PIPELINE II = 1
      out[r * 8 + c] = lut[c];
    }
  }
  (void)in;
})", "gmem_b"},
  };
  for (const auto& [what, kernel, bundle] : good) {
    WriteFile(dir / "src/hw/kernel.h", prelude + top(kernel, bundle));
    const TopLintResult r = RunTopLint(dir, dir / "tu.cc", includes);
    ASSERT_TRUE(r.error.empty()) << what << "\n" << r.error;
    EXPECT_TRUE(r.violations.empty()) << what << ":\n" << Joined(r.violations);
    EXPECT_TRUE(r.memory_followed.count("Kernel:in")) << what;
  }
  const std::vector<std::tuple<std::string, std::string, std::string, std::string>> bad = {
      {"a data-dependent read", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    out[i] = in[lut[i]];
  }
})", "gmem_b", "'in' (in Kernel) indexed by '[' in the index"},
      {"an index computed inside the loop", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  int k = 0;
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    k = (k * 5 + 1) & 63;
    out[i] = in[k];
  }
  (void)lut;
})", "gmem_b", "indexed by 'k', which changes inside the loop"},
      {"a member of a sample as the index", R"(struct S { int cell; };
inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  S s{};
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    s.cell = lut[i];
    out[i] = in[s.cell];
  }
})", "gmem_b", "'in' (in Kernel) indexed by"},
      {"two arrays of one bundle in a loop of II 1", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    out[i] = in[i];
  }
  (void)lut;
})", "gmem_a", "bundle gmem_a takes 2 accesses per iteration (in[i], out[i]) in a loop of II 1"},
      {"three reads of one array at II 2", R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 2
    out[i] = in[i] + in[i + 1] + in[i + 2];
  }
  (void)lut;
})", "gmem_b", "bundle gmem_a takes 3 accesses per iteration"},
      {"an m_axi array handed to a function in a pipelined loop",
       R"(inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    out[i] = Pick(in, lut[i]);
  }
})", "gmem_b", "m_axi argument 'in' (in Kernel) is handed on inside a pipelined loop"},
      {"a random read two calls down", R"(inline void Inner(int n, const int a[64], int out[64]) {
  for (int i = 0; i < n; ++i) {
#pragma HLS PIPELINE II = 1
    out[i] = a[(i * i) & 63];
  }
}
inline void Kernel(int n, const int in[64], const int lut[64], int out[64]) {
  Inner(n, in, out);
  (void)lut;
})", "gmem_b", "'a' (in Inner) indexed by '&' in the index"},
  };
  for (const auto& [what, kernel, bundle, expect] : bad) {
    WriteFile(dir / "src/hw/kernel.h", prelude + top(kernel, bundle));
    const TopLintResult r = RunTopLint(dir, dir / "tu.cc", includes);
    ASSERT_TRUE(r.error.empty()) << what << "\n" << r.error;
    EXPECT_TRUE(Reports(r.violations, "memory", expect))
        << "the memory lint missed: " << what << "\nexpected: " << expect << "\ngot:\n" << Joined(r.violations);
  }
  fs::remove_all(dir);
}

// Each rule rejects a small header under <tmp>/src/hw/ that breaks it; the good headers pass.
TEST(HwTopLint, EachTopRuleCatchesABadFixture) {
  if (std::system("c++ --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "no c++ preprocessor";
  const fs::path dir = FreshTempPath("hwtop_toplint_bad");
  fs::create_directories(dir / "src/hw");
  WriteFile(dir / "tu.cc", "#include \"hw/kernel.h\"\n");
  // Shared by the fixtures: a stream type and three processes.
  const std::string prelude = R"(#pragma once
namespace hls { template <typename T> struct stream { stream() {} explicit stream(const char*) {} }; }
inline void Produce(int n, const int in[64], hls::stream<int>& out) { (void)n; (void)in; (void)out; }
inline void Consume(int n, hls::stream<int>& in, int out[64]) { (void)n; (void)in; (void)out; }
inline void Pass(int n, hls::stream<int>& in, hls::stream<int>& out) { (void)n; (void)in; (void)out; }
constexpr int kLanes = 4;
)";
  const std::string good_top = R"(
inline void HwGoodTop(int n, const int in[64], int out[64]) {
#pragma HLS INTERFACE m_axi port = in offset = slave bundle = gmem_in depth = 64
#pragma HLS INTERFACE m_axi port = out offset = slave bundle = gmem_out depth = 64
#pragma HLS INTERFACE s_axilite port = n bundle = control
#pragma HLS INTERFACE s_axilite port = return bundle = control
#pragma HLS DATAFLOW
  hls::stream<int> s("s");
  Produce(n, in, s);
  Consume(n, s, out);
}
#define IFACE _Pragma("HLS INTERFACE m_axi port = in offset = slave bundle = gmem depth = 64") \
  _Pragma("HLS INTERFACE s_axilite port = return bundle = control")
inline void HwMacroTop2(const int in[64]) {
  IFACE
  (void)in;
}
template <int M>
void Lanes(int n, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  constexpr int kDepth = 2;
  hls::stream<int> a, b[M];
  hls::stream<int> c[kLanes];
  Produce(n, in, a);
LANES:
  for (int k = 0; k < M; ++k) {
#pragma HLS UNROLL
    Pass(n, a, b[k]);
  }
  for (int k = 0; k < kLanes; ++k) Pass(n + kDepth, b[k], c[k]);
  Consume(n, c[0], out);
}
)";
  const std::vector<fs::path> includes = {dir / "src"};
  // The good fixture passes.
  WriteFile(dir / "src/hw/kernel.h", prelude + good_top);
  const TopLintResult ok = RunTopLint(dir, dir / "tu.cc", includes);
  ASSERT_TRUE(ok.error.empty()) << ok.error;
  EXPECT_TRUE(ok.violations.empty()) << Joined(ok.violations);
  EXPECT_EQ(ok.tops, (std::set<std::string>{"HwGoodTop", "HwMacroTop2"}));
  EXPECT_EQ(ok.regions, (std::set<std::string>{"HwGoodTop", "Lanes"}));

  const std::vector<std::tuple<std::string, std::string, std::string>> bad = {
      {"(a) a top without INTERFACE pragmas", "inline void HwBareTop(int n, int out[64]) { (void)n; (void)out; }",
       "no #pragma HLS INTERFACE for 'n'"},
      {"(a) a top without `return`", R"(inline void HwNoReturnTop(int out[64]) {
#pragma HLS INTERFACE m_axi port = out offset = slave bundle = gmem depth = 64
  (void)out;
})", "no #pragma HLS INTERFACE for 'return'"},
      {"(a) an argument missing", R"(inline void HwHalfTop(int n, int out[64]) {
#pragma HLS INTERFACE m_axi port = out offset = slave bundle = gmem depth = 64
#pragma HLS INTERFACE s_axilite port = return bundle = control
  (void)n; (void)out;
})", "no #pragma HLS INTERFACE for 'n'"},
      {"(b) an argument read by two processes", R"(inline void Region(int n, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  hls::stream<int> s, t;
  Produce(n, in, s);
  Produce(n, in, t);
  Pass(n, t, s);
  Consume(n, s, out);
})", "argument 'in' is used by 2 processes"},
      {"(b) a local stream read by two processes", R"(inline void Region(int n, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  hls::stream<int> s, t;
  Produce(n, in, s);
  Pass(n, s, t);
  Pass(n, s, t);
})", "channel 's' is used by 3 processes"},
      {"(c) a process under if", R"(inline void Region(int n, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  hls::stream<int> s;
  Produce(n, in, s);
  if (n > 0) Consume(n, s, out);
})", "a process called under 'if'"},
      {"(c) the runtime-bounded core loop", R"(inline void Region(int n, int m, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  hls::stream<int> s, t[kLanes];
  Produce(n, in, s);
  for (int c = 0; c < kLanes; ++c) {
#pragma HLS UNROLL
    if (c < m) Pass(n, s, t[c]);
  }
  Consume(n, t[0], out);
})", "a process called under 'if'"},
      {"(c) a runtime loop bound", R"(inline void Region(int n, int m, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  hls::stream<int> s, t[kLanes];
  Produce(n, in, s);
  for (int c = 0; c < m; ++c) Pass(n, s, t[c]);
  Consume(n, t[0], out);
})", "bound is not a compile-time constant"},
      {"(c) a scalar statement", R"(inline void Region(int n, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  hls::stream<int> s;
  if (n > 64) n = 64;
  Produce(n, in, s);
  Consume(n, s, out);
})", "a scalar 'if' statement"},
      {"(c) an assignment", R"(inline void Region(int n, const int in[64], int out[64], int& count) {
#pragma HLS DATAFLOW
  hls::stream<int> s;
  Produce(n, in, s);
  Consume(n, s, out);
  count = n;
})", "a scalar statement between the processes"},
      {"(c) an initialised scalar", R"(inline void Region(int n, const int in[64], int out[64]) {
#pragma HLS DATAFLOW
  const int m = n / 2;
  hls::stream<int> s;
  Produce(m, in, s);
  Consume(m, s, out);
})", "initialised declaration of 'm'"},
  };
  for (const auto& [what, code, expect] : bad) {
    WriteFile(dir / "src/hw/kernel.h", prelude + code + "\n");
    const TopLintResult r = RunTopLint(dir, dir / "tu.cc", includes);
    ASSERT_TRUE(r.error.empty()) << what << "\n" << r.error;
    // The rule named by the fixture's "(a)", "(b)" or "(c)".
    const char* rule = what[1] == 'a' ? "interface" : what[1] == 'b' ? "dataflow-channel" : "dataflow-statement";
    EXPECT_TRUE(Reports(r.violations, rule, expect))
        << "the lint missed: " << what << "\nexpected: " << expect << "\ngot:\n" << Joined(r.violations);
  }
  // The rules are about src/hw/*.h only: the same top elsewhere is not reported.
  fs::create_directories(dir / "other");
  WriteFile(dir / "other/host.h", "#pragma once\ninline void HwBareTop(int n) { (void)n; }\n");
  WriteFile(dir / "tu2.cc", "#include \"host.h\"\n");
  const TopLintResult other = RunTopLint(dir, dir / "tu2.cc", {dir / "other"});
  EXPECT_TRUE(other.violations.empty()) << Joined(other.violations);
  EXPECT_TRUE(other.tops.empty());
  fs::remove_all(dir);
}

// Each forbidden construct in a small kernel header under <tmp>/src/hw/ makes the lint fail,
// and the same header without it passes.
TEST(HwTopLint, EachRuleCatchesABadSnippet) {
  if (!HaveClangQuery()) GTEST_SKIP() << "clang-query not installed";
  const fs::path dir = FreshTempPath("hwtop_lint_bad");
  fs::create_directories(dir / "src/hw");
  fs::create_directories(dir / "fake_eigen/Eigen");
  WriteFile(dir / "fake_eigen/Eigen/Core", "namespace Eigen { struct Matrix3f { float m[9]; }; }\n");
  const std::vector<std::tuple<std::string, std::string, std::string>> bad = {
      {"new", "no-new", "inline int K(int n) { int* p = new int[4]; p[0] = n; int r = p[0]; return r; }"},
      {"delete", "no-delete", "inline void K(int* p) { delete p; }"},
      {"malloc", "no-malloc", "#include <cstdlib>\ninline void* K() { return malloc(16); }"},
      {"vector", "no-heap-type", "#include <vector>\ninline int K() { std::vector<int> v(3); return int(v.size()); }"},
      {"map", "no-heap-type", "#include <map>\ninline int K() { std::map<int, int> m; return int(m.size()); }"},
      {"string", "no-heap-type", "#include <string>\ninline int K() { std::string s = \"x\"; return int(s.size()); }"},
      {"eigen", "no-eigen", "#include <Eigen/Core>\ninline int K() { Eigen::Matrix3f m{}; return int(sizeof(m)); }"},
      {"throw", "no-exceptions", "inline int K(int n) { if (n < 0) throw 1; return n; }"},
      {"try", "no-exceptions", "inline int K(int n) { try { return n; } catch (...) { return 0; } }"},
      {"virtual", "no-virtual", "struct Base { virtual int K() { return 1; } };"},
      {"recursion", "no-recursion", "inline int K(int n) { return n <= 0 ? 0 : 1 + K(n - 1); }"},
      {"template recursion", "no-recursion", "template <int W> int K(int n) { return n <= 0 ? 0 : K<W>(n - 1); }\ninline int U() { return K<3>(2); }"},
      {"double arithmetic", "no-float", "inline int K(int n) { double x = n; return int(x * 0.5); }"},
      {"float parameter", "no-float", "inline int K(float x) { return int(x); }"},
      {"float member", "no-float", "struct K { float gain; };"},
  };
  const std::vector<fs::path> includes = {dir / "src", dir / "fake_eigen"};
  WriteFile(dir / "tu.cc", "#include \"hw/kernel.h\"\n");
  for (const auto& [what, rule, code] : bad) {
    WriteFile(dir / "src/hw/kernel.h", "#pragma once\n" + code + "\n");
    const SubsetResult r = RunSubsetLint(dir, dir / "tu.cc", includes);
    EXPECT_EQ(r.output.find("error:"), std::string::npos) << what << ":\n" << r.output;
    EXPECT_GT(r.matches, 0) << "the lint missed: " << what << "\n" << r.output;
    EXPECT_TRUE(Reports(r.findings, rule, "")) << what << ": no " << rule << " finding:\n" << Joined(r.findings);
  }
  // Allowed: fixed-size arrays, integer arithmetic, a constexpr ROM generator in double.
  WriteFile(dir / "src/hw/kernel.h",
            "#pragma once\nconstexpr double Rom(int i) { return i * 0.5 + 1.0; }\n"
            "constexpr int kRom[2] = {int(Rom(0)), int(Rom(1))};\n"
            "inline int K(const int a[4], int n) { int s = 0; for (int i = 0; i < 4; ++i) s += a[i] * n; return s + kRom[1]; }\n");
  const SubsetResult ok = RunSubsetLint(dir, dir / "tu.cc", includes);
  EXPECT_EQ(ok.matches, 0) << ok.output;
  // The rule is about src/hw/*.h only: the same violation elsewhere is not reported.
  fs::create_directories(dir / "other");
  WriteFile(dir / "other/host.h", "#pragma once\ninline double H(double x) { return x * 2; }\n");
  WriteFile(dir / "tu2.cc", "#include \"host.h\"\n");
  const SubsetResult other = RunSubsetLint(dir, dir / "tu2.cc", {dir / "other"});
  EXPECT_EQ(other.matches, 0) << other.output;
  fs::remove_all(dir);
}

// The program on a tree of its own: one "file:line: rule: message" line per finding (the file
// relative to the root), exit 1; the same header fixed, no output and exit 0; the src/hw folder
// works as the root does; usage errors and a folder that is no tree exit 2.
TEST(HlsLintTool, PrintsOneLinePerFindingAndExitsByTheResult) {
  if (!HaveCxx()) GTEST_SKIP() << "no c++ preprocessor";
  const fs::path dir = FreshTempPath("hls_lint_tool");
  fs::create_directories(dir / "repo/src/hw");
  const std::string bad =
      "#pragma once\n"
      "inline void HwBareTop(int n, int out[64]) {\n"
      "#pragma HLS INTERFACE m_axi port = out offset = slave bundle = gmem depth = 64\n"
      "  (void)n; (void)out;\n"
      "}\n";
  WriteFile(dir / "repo/src/hw/kernel.h", bad);
  const std::string expected =
      "src/hw/kernel.h:2: interface: top HwBareTop: no #pragma HLS INTERFACE for 'n'\n"
      "src/hw/kernel.h:2: interface: top HwBareTop: no #pragma HLS INTERFACE for 'return'\n";
  for (const std::string tree : {"repo", "repo/src/hw", "repo/src/hw/"}) {
    const ToolRun r = RunTool(dir, "--only top '" + (dir / tree).string() + "'");
    EXPECT_EQ(r.exit_code, 1) << tree << "\n" << r.err;
    EXPECT_EQ(r.out, expected) << tree;
  }
  WriteFile(dir / "repo/src/hw/kernel.h",
            "#pragma once\ninline void HwBareTop(int n, int out[64]) {\n"
            "#pragma HLS INTERFACE m_axi port = out offset = slave bundle = gmem depth = 64\n"
            "#pragma HLS INTERFACE s_axilite port = n bundle = control\n"
            "#pragma HLS INTERFACE s_axilite port = return bundle = control\n"
            "  (void)n; (void)out;\n}\n");
  const ToolRun ok = RunTool(dir, "--only=top '" + (dir / "repo").string() + "'");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(ok.out, "");
  if (HaveClangQuery()) {  // both parts (the default): a float member is the subset's
    WriteFile(dir / "repo/src/hw/kernel.h", bad + "struct Gain { float g; };\n");
    const ToolRun both = RunTool(dir, "'" + (dir / "repo").string() + "'");
    EXPECT_EQ(both.exit_code, 1) << both.err;
    EXPECT_NE(both.out.find("src/hw/kernel.h:6:"), std::string::npos) << both.out;
    EXPECT_NE(both.out.find(": no-float: a floating member\n"), std::string::npos) << both.out;
    EXPECT_NE(both.out.find(expected), std::string::npos) << both.out;
  }
  fs::create_directories(dir / "empty");
  for (const std::string args : {std::string(""), std::string("--only all ."), std::string("--frob ."),
                                 std::string("a b"), "'" + (dir / "empty").string() + "'"}) {
    const ToolRun r = RunTool(dir, args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(r.out, "") << args;
    EXPECT_NE(r.err.find("hls_lint: "), std::string::npos) << args;
  }
  fs::remove_all(dir);
}

// The query script is the matchers in order, one `match` line each, after the `let`s.
TEST(HlsLintTool, QueryScriptHasOneMatchPerMatcher) {
  const std::string q = SubsetQueries();
  EXPECT_EQ(q.rfind("set output diag\nlet inhw ", 0), 0u) << q;
  std::size_t n = 0;
  for (std::size_t p = q.find("\nmatch "); p != std::string::npos; p = q.find("\nmatch ", p + 1)) ++n;
  EXPECT_EQ(n, SubsetMatchers().size());
  for (const Matcher& m : SubsetMatchers())
    EXPECT_NE(q.find(std::string("\nmatch ") + m.query + "\n"), std::string::npos) << m.rule;
}

}  // namespace
}  // namespace posefilter::hls_lint
