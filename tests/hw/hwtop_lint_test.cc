// Kernel lint: the hw kernels (src/hw/*.h, not src/hw/hls_types/) stay in the synthesizable
// subset (hw_shared conventions): no new/delete/malloc, no std:: containers or other heap
// types, no Eigen, no throw/try, no virtual functions, no recursion, no float/double
// arithmetic (constexpr ROM generators evaluated at compile time excepted). clang-query
// (Debian clang-tools) runs AST matchers over one translation unit that includes every kernel
// header, compiled with -D__SYNTHESIS__ (so the host-only parts under #ifndef __SYNTHESIS__
// drop out, as in HLS). Skipped when clang-query is not installed. Suite HwTopLint.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "test_util.h"

namespace posefilter {
namespace {

namespace fs = std::filesystem;
using testing_util::FreshTempPath;
using testing_util::ReadFile;
using testing_util::WriteFile;

// Host-side files of src/hw/ that are not kernels (STL allowed): the cycle model.
const char* const kHostHeaders[] = {"cycle_model.h"};

// The matchers. Each `match` prints "N match(es)."; any match is a violation.
const char* const kQueries = R"(set output diag
let inhw isExpansionInFileMatching("src/hw/[^/]+[.]h$")
let notce unless(anyOf(hasAncestor(functionDecl(isConstexpr())), hasAncestor(varDecl(isConstexpr()))))
match cxxNewExpr(inhw)
match cxxDeleteExpr(inhw)
match callExpr(inhw, callee(functionDecl(hasAnyName("malloc", "calloc", "realloc", "free", "aligned_alloc", "__builtin_malloc", "__builtin_free"))))
match cxxThrowExpr(inhw)
match cxxTryStmt(inhw)
match cxxMethodDecl(inhw, isVirtual())
match callExpr(inhw, callee(functionDecl().bind("self")), hasAncestor(functionDecl(equalsBoundNode("self"))))
match typeLoc(inhw, loc(qualType(hasDeclaration(namedDecl(hasAnyName("::std::vector", "::std::map", "::std::multimap", "::std::set", "::std::multiset", "::std::unordered_map", "::std::unordered_multimap", "::std::unordered_set", "::std::unordered_multiset", "::std::deque", "::std::list", "::std::forward_list", "::std::basic_string", "::std::string", "::std::wstring", "::std::queue", "::std::stack", "::std::priority_queue", "::std::function", "::std::shared_ptr", "::std::unique_ptr"))))))
match typeLoc(inhw, loc(qualType(hasDeclaration(namedDecl(matchesName("^::Eigen::"))))))
match declRefExpr(inhw, to(namedDecl(matchesName("^::Eigen::"))))
match binaryOperator(inhw, hasEitherOperand(hasType(realFloatingPointType())), notce)
match unaryOperator(inhw, hasUnaryOperand(hasType(realFloatingPointType())), notce)
match varDecl(inhw, hasType(realFloatingPointType()), notce)
match fieldDecl(inhw, hasType(realFloatingPointType()))
match callExpr(inhw, callee(functionDecl(returns(realFloatingPointType()))), notce)
)";

bool HaveClangQuery() { return std::system("clang-query --version >/dev/null 2>&1") == 0; }

// The repository root: from this file's path (absolute, or relative to the build's test
// directory when ccache rewrote it) or from POSEFILTER_SHARED_DIR (<root>/../shared).
fs::path RepoRoot() {
  std::vector<fs::path> candidates;
  const fs::path file = __FILE__;
  candidates.push_back(file.parent_path().parent_path().parent_path());
  char exe[4096];
  const ssize_t len = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (len > 0) {
    exe[len] = 0;
    candidates.push_back((fs::path(exe).parent_path() / file).parent_path().parent_path().parent_path());
  }
  const fs::path shared = POSEFILTER_SHARED_DIR;
  candidates.push_back(shared.parent_path() / "main");
  for (const fs::path& c : candidates) {
    std::error_code ec;
    if (fs::exists(c / "src/hw/hw_types.h", ec)) return fs::weakly_canonical(c);
  }
  return {};
}

struct LintResult {
  int exit_code = -1;
  int matches = 0;
  std::string output;
};

// Runs the matchers over `tu` with the include path of the kernels.
LintResult RunLint(const fs::path& dir, const fs::path& tu, const std::vector<fs::path>& includes) {
  WriteFile(dir / "queries.txt", kQueries);
  std::string cmd = "clang-query -f '" + (dir / "queries.txt").string() + "' '" + tu.string() + "' -- -std=c++20 -D__SYNTHESIS__";
  for (const fs::path& inc : includes) cmd += " -I'" + inc.string() + "'";
  cmd += " >'" + (dir / "lint.out").string() + "' 2>&1";
  LintResult r;
  const int status = std::system(cmd.c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.output = ReadFile(dir / "lint.out");
  const std::regex count_re("(\\d+) match(es)?\\.");
  for (auto it = std::sregex_iterator(r.output.begin(), r.output.end(), count_re); it != std::sregex_iterator(); ++it)
    r.matches += std::stoi((*it)[1]);
  return r;
}

int CountQueries() {
  const std::string q = kQueries;
  int n = 0;
  for (std::size_t p = q.find("\nmatch "); p != std::string::npos; p = q.find("\nmatch ", p + 1)) ++n;
  return n;
}

TEST(HwTopLint, KernelHeadersStayInTheSynthesizableSubset) {
  if (!HaveClangQuery()) GTEST_SKIP() << "clang-query not installed";
  const fs::path root = RepoRoot();
  ASSERT_FALSE(root.empty()) << "cannot find the repository (src/hw/hw_types.h)";
  const fs::path dir = FreshTempPath("hwtop_lint");
  fs::create_directories(dir);
  std::vector<std::string> headers;
  for (const auto& e : fs::directory_iterator(root / "src/hw")) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".h") continue;
    if (std::find(std::begin(kHostHeaders), std::end(kHostHeaders), name) != std::end(kHostHeaders)) continue;
    headers.push_back(name);
  }
  std::sort(headers.begin(), headers.end());
  ASSERT_GE(headers.size(), 10u) << "expected the kernel headers in " << (root / "src/hw");
  ASSERT_NE(std::find(headers.begin(), headers.end(), "top.h"), headers.end());
  std::string tu;
  for (const auto& h : headers) tu += "#include \"hw/" + h + "\"\n";
  WriteFile(dir / "kernels.cc", tu);
  const LintResult r = RunLint(dir, dir / "kernels.cc", {root / "src", root / "src/hw/hls_types", root / "include"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("error:"), std::string::npos) << "the kernels do not parse:\n" << r.output;
  // Every matcher ran ("N matches." per query) and none matched.
  std::size_t ran = 0;
  for (std::size_t p = r.output.find("match"); p != std::string::npos; p = r.output.find("match", p + 1))
    ran += r.output.compare(p, 7, "matches") == 0 || r.output.compare(p, 6, "match.") == 0;
  EXPECT_EQ(int(ran), CountQueries()) << r.output;
  EXPECT_EQ(r.matches, 0) << "kernel lint violations:\n" << r.output;
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
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"new", "inline int K(int n) { int* p = new int[4]; p[0] = n; int r = p[0]; return r; }"},
      {"delete", "inline void K(int* p) { delete p; }"},
      {"malloc", "#include <cstdlib>\ninline void* K() { return malloc(16); }"},
      {"vector", "#include <vector>\ninline int K() { std::vector<int> v(3); return int(v.size()); }"},
      {"map", "#include <map>\ninline int K() { std::map<int, int> m; return int(m.size()); }"},
      {"string", "#include <string>\ninline int K() { std::string s = \"x\"; return int(s.size()); }"},
      {"eigen", "#include <Eigen/Core>\ninline int K() { Eigen::Matrix3f m{}; return int(sizeof(m)); }"},
      {"throw", "inline int K(int n) { if (n < 0) throw 1; return n; }"},
      {"try", "inline int K(int n) { try { return n; } catch (...) { return 0; } }"},
      {"virtual", "struct Base { virtual int K() { return 1; } };"},
      {"recursion", "inline int K(int n) { return n <= 0 ? 0 : 1 + K(n - 1); }"},
      {"template recursion", "template <int W> int K(int n) { return n <= 0 ? 0 : K<W>(n - 1); }\ninline int U() { return K<3>(2); }"},
      {"double arithmetic", "inline int K(int n) { double x = n; return int(x * 0.5); }"},
      {"float parameter", "inline int K(float x) { return int(x); }"},
      {"float member", "struct K { float gain; };"},
  };
  const std::vector<fs::path> includes = {dir / "src", dir / "fake_eigen"};
  WriteFile(dir / "tu.cc", "#include \"hw/kernel.h\"\n");
  for (const auto& [what, code] : bad) {
    WriteFile(dir / "src/hw/kernel.h", "#pragma once\n" + code + "\n");
    const LintResult r = RunLint(dir, dir / "tu.cc", includes);
    EXPECT_EQ(r.output.find("error:"), std::string::npos) << what << ":\n" << r.output;
    EXPECT_GT(r.matches, 0) << "the lint missed: " << what << "\n" << r.output;
  }
  // Allowed: fixed-size arrays, integer arithmetic, a constexpr ROM generator in double.
  WriteFile(dir / "src/hw/kernel.h",
            "#pragma once\nconstexpr double Rom(int i) { return i * 0.5 + 1.0; }\n"
            "constexpr int kRom[2] = {int(Rom(0)), int(Rom(1))};\n"
            "inline int K(const int a[4], int n) { int s = 0; for (int i = 0; i < 4; ++i) s += a[i] * n; return s + kRom[1]; }\n");
  const LintResult ok = RunLint(dir, dir / "tu.cc", includes);
  EXPECT_EQ(ok.matches, 0) << ok.output;
  // The rule is about src/hw/*.h only: the same violation elsewhere is not reported.
  fs::create_directories(dir / "other");
  WriteFile(dir / "other/host.h", "#pragma once\ninline double H(double x) { return x * 2; }\n");
  WriteFile(dir / "tu2.cc", "#include \"host.h\"\n");
  const LintResult other = RunLint(dir, dir / "tu2.cc", {dir / "other"});
  EXPECT_EQ(other.matches, 0) << other.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace posefilter
