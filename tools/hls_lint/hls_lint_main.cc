// tools/hls_lint/hls_lint_main.cc — `hls_lint`, the HLS kernel lint (hls_lint.h) on a source tree:
//
//   hls_lint [--only subset|top] [--verbose] <repository root | src/hw folder>
//
// Prints one line per finding, "file:line: rule: message" (files relative to the repository
// root). Exit status: 0 clean, 1 findings, 2 a usage error, a tree it cannot lint, a tool
// missing (clang-query for `subset`, c++ for `top`) or a tool that failed (the kernels do not
// parse). --only runs one part; --verbose says on stderr what was checked: the headers, the
// matchers that ran, the tops, the DATAFLOW regions and the function:parameter pairs the memory
// rule followed.
#include <stdlib.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <system_error>
#include <vector>

#include "hls_lint.h"

namespace hl = posefilter::hls_lint;
namespace fs = std::filesystem;

namespace {

constexpr int kClean = 0, kFindings = 1, kError = 2;

int Usage(const std::string& why) {
  if (!why.empty()) std::cerr << "hls_lint: " << why << "\n";
  std::cerr << "usage: hls_lint [--only subset|top] [--verbose] <repository root | src/hw folder>\n"
               "  subset: the synthesizable subset of the kernels (clang-query AST matchers)\n"
               "  top:    the tops' interfaces, the DATAFLOW regions and the m_axi accesses (c++ -E)\n"
               "Prints file:line: rule: message per finding; exit 0 clean, 1 findings, 2 error.\n";
  return kError;
}

// `file` relative to the repository root when it lies under it.
std::string Shown(const std::string& file, const fs::path& root) {
  const fs::path p = fs::path(file).lexically_normal();
  const fs::path rel = p.lexically_relative(root);
  if (p.is_absolute() && !rel.empty() && *rel.begin() != "..") return rel.string();
  return file;
}

// A scratch folder of its own under the system's temporary folder, removed on destruction.
class WorkDir {
 public:
  WorkDir() {
    std::string pattern = (fs::temp_directory_path() / "hls_lint.XXXXXX").string();
    if (::mkdtemp(pattern.data())) path_ = pattern;
  }
  ~WorkDir() {
    std::error_code ec;
    if (!path_.empty()) fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

int main(int argc, char** argv) {
  bool subset = true, top = true, verbose = false;
  std::string tree_arg;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      Usage("");
      return kError;
    } else if (a == "--verbose" || a == "-v") {
      verbose = true;
    } else if (a == "--only" || a.rfind("--only=", 0) == 0) {
      std::string part;
      if (a == "--only") {
        if (i + 1 >= argc) return Usage("--only needs subset or top");
        part = argv[++i];
      } else {
        part = a.substr(7);
      }
      if (part != "subset" && part != "top") return Usage("--only: '" + part + "' is neither subset nor top");
      subset = part == "subset";
      top = part == "top";
    } else if (!a.empty() && a[0] == '-') {
      return Usage("unknown option '" + a + "'");
    } else if (tree_arg.empty()) {
      tree_arg = a;
    } else {
      return Usage("one tree only ('" + tree_arg + "' and '" + a + "')");
    }
  }
  if (tree_arg.empty()) return Usage("no tree given");

  std::string why;
  const std::optional<hl::Tree> tree = hl::FindTree(tree_arg, &why);
  if (!tree) {
    std::cerr << "hls_lint: " << why << "\n";
    return kError;
  }
  const fs::path root = tree->hw_dir.parent_path().parent_path();
  if (subset && !hl::HaveClangQuery()) {
    std::cerr << "hls_lint: clang-query not found (Debian clang-tools); `--only top` runs the rest\n";
    return kError;
  }
  if (top && std::system("c++ --version >/dev/null 2>&1") != 0) {
    std::cerr << "hls_lint: no c++ preprocessor (c++ -E)\n";
    return kError;
  }
  const WorkDir work;
  if (work.path().empty()) {
    std::cerr << "hls_lint: cannot make a scratch folder under " << fs::temp_directory_path() << "\n";
    return kError;
  }
  const fs::path tu = work.path() / "kernels.cc";
  {
    std::FILE* f = std::fopen(tu.c_str(), "wb");
    const std::string text = hl::KernelTranslationUnit(*tree);
    if (!f || std::fwrite(text.data(), 1, text.size(), f) != text.size() || std::fclose(f) != 0) {
      std::cerr << "hls_lint: cannot write " << tu << "\n";
      return kError;
    }
  }
  if (verbose)
    for (const std::string& h : tree->headers) std::cerr << "hls_lint: header hw/" << h << "\n";

  std::vector<hl::Finding> findings;
  if (subset) {
    const hl::SubsetResult r = hl::RunSubsetLint(work.path(), tu, tree->includes);
    const int expected = static_cast<int>(hl::SubsetMatchers().size());
    if (r.exit_code != 0 || r.output.find("error:") != std::string::npos || r.matchers_ran != expected) {
      std::cerr << "hls_lint: clang-query failed (exit " << r.exit_code << ", " << r.matchers_ran << " of " << expected
                << " matchers ran):\n"
                << r.output;
      return kError;
    }
    if (verbose)
      std::cerr << "hls_lint: subset: " << r.matchers_ran << " of " << expected << " matchers ran, " << r.matches
                << " matches\n";
    findings.insert(findings.end(), r.findings.begin(), r.findings.end());
  }
  if (top) {
    const hl::TopLintResult r = hl::RunTopLint(work.path(), tu, tree->includes);
    if (!r.error.empty()) {
      std::cerr << "hls_lint: the preprocessor failed:\n" << r.error;
      return kError;
    }
    if (verbose) {
      for (const std::string& t : r.tops) std::cerr << "hls_lint: top " << t << "\n";
      for (const std::string& g : r.regions) std::cerr << "hls_lint: region " << g << "\n";
      for (const std::string& m : r.memory_followed) std::cerr << "hls_lint: m_axi followed " << m << "\n";
    }
    findings.insert(findings.end(), r.violations.begin(), r.violations.end());
  }
  for (hl::Finding& f : findings) {
    f.file = Shown(f.file, root);
    std::cout << hl::Format(f) << "\n";
  }
  return findings.empty() ? kClean : kFindings;
}
