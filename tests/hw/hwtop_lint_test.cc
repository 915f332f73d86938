// Kernel lint: the hw kernels (src/hw/*.h and the tops' src/hw/tops.cc, not src/hw/hls_types/)
// stay in the synthesizable subset (hw_shared conventions): no new/delete/malloc, no std:: containers or other heap
// types, no Eigen, no throw/try, no virtual functions, no recursion, no float/double
// arithmetic (constexpr ROM generators evaluated at compile time excepted). clang-query
// (Debian clang-tools) runs AST matchers over one translation unit that includes every kernel
// header, compiled with -D__SYNTHESIS__ (so the host-only parts under #ifndef __SYNTHESIS__
// drop out, as in HLS). Skipped when clang-query is not installed. Suite HwTopLint.
//
// Top and dataflow lint (pragmas are not in the clang AST, so this part is source level): the
// same translation unit is preprocessed (c++ -E -D__SYNTHESIS__; `#pragma` lines and
// _Pragma(...) from macros survive as `#pragma` lines, host-only code is gone) and the code of
// src/hw/*.h and src/hw/tops.cc is tokenized. Rules:
//   (a) a top — a non-template function definition named Hw<letters>Top[<digits>], the
//       functions scripts/hls names with set_top — has `#pragma HLS INTERFACE … port = p` for
//       every parameter p and for `return`;
//   (b) in a DATAFLOW region — a function whose body holds `#pragma HLS DATAFLOW` — a memory
//       argument (array, pointer, non-const reference, hls::stream) is used by at most one
//       process call and a local channel (any local declared in the region) by at most two
//       (one producer, one consumer);
//   (c) the region's statements are channel declarations (without initialisers other than a
//       stream's name), constexpr declarations, static_asserts, process calls and `for` loops
//       of process calls whose bound is compile-time (a literal, a template parameter, a
//       constexpr name): a process under `if`, a loop with a runtime bound (the `c < M` of a
//       runtime M) or any other statement (a scalar assignment, an initialised scalar) is
//       rejected.
//   (d) memory: an m_axi argument of a top, followed through every call that passes it on, is
//       read or written inside a pipelined loop only at an affine function of the loop's
//       counter (a burst), is not handed to a function inside such a loop, and no loop makes
//       more accesses per iteration to one bundle than its II (MemoryLint below).
// Suites: HwTopLint.TopsHaveInterfacesAndRegionsAreCanonical (the real src/hw),
// HwTopLint.EachTopRuleCatchesABadFixture (one fixture per rule (a)–(c), and good fixtures) and
// HwTopLint.EachMemoryRuleCatchesABadFixture (rule (d): bad and good fixtures).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
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
let inhw isExpansionInFileMatching("src/hw/([^/]+[.]h|tops[.]cc)$")
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
  tu += "#include \"hw/tops.cc\"\n";  // the tops' definitions
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

// ---- Top and dataflow lint (source level, on the preprocessed translation unit) ----

struct Tok {
  enum Kind { kIdent, kNumber, kString, kPunct, kPragma } kind;
  std::string text;  // for kPragma: the pragma line after "#pragma"
  std::string file;
  int line = 0;
};

// Tokens of the preprocessed text that come from files whose path matches `keep` (line
// markers `# N "file"` say where each line comes from).
std::vector<Tok> Tokenize(const std::string& pp, const std::regex& keep) {
  std::vector<Tok> out;
  std::string file;
  int line = 0;
  bool kept = false;
  std::istringstream in(pp);
  std::string text;
  static const std::regex marker_re(R"(^#\s*(\d+)\s+"([^"]*)\".*)");
  const char* const kPunct3[] = {"<<=", ">>=", "...", "->*"};
  const char* const kPunct2[] = {"::", "->", "<<", "<=", ">=", "==", "!=", "&&", "||", "++", "--", "+=", "-=",
                                 "*=", "/=", "%=", "&=", "|=", "^="};
  while (std::getline(in, text)) {
    std::size_t b = text.find_first_not_of(" \t");
    if (b != std::string::npos && text[b] == '#') {
      std::smatch m;
      const std::string rest = text.substr(b);
      if (std::regex_match(rest, m, marker_re)) {
        line = std::stoi(m[1]) - 1;  // the next line has number N
        file = m[2];
        kept = std::regex_search(file, keep);
      } else if (kept && rest.compare(0, 7, "#pragma") == 0) {
        out.push_back({Tok::kPragma, rest.substr(7), file, line + 1});
      }
      ++line;
      continue;
    }
    ++line;
    if (!kept) continue;
    for (std::size_t i = 0; i < text.size();) {
      const char c = text[i];
      if (std::isspace(static_cast<unsigned char>(c))) {
        ++i;
      } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
        std::size_t j = i;
        while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_')) ++j;
        out.push_back({Tok::kIdent, text.substr(i, j - i), file, line});
        i = j;
      } else if (std::isdigit(static_cast<unsigned char>(c))) {
        std::size_t j = i;
        while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '.' || text[j] == '\''))
          ++j;
        out.push_back({Tok::kNumber, text.substr(i, j - i), file, line});
        i = j;
      } else if (c == '"' || c == '\'') {
        std::size_t j = i + 1;
        while (j < text.size() && text[j] != c) j += text[j] == '\\' ? 2 : 1;
        out.push_back({Tok::kString, text.substr(i, j + 1 - i), file, line});
        i = j + 1;
      } else {
        std::string p(1, c);
        for (const char* q : kPunct3)
          if (text.compare(i, 3, q) == 0) p = q;
        if (p.size() == 1)
          for (const char* q : kPunct2)
            if (text.compare(i, 2, q) == 0) p = q;
        out.push_back({Tok::kPunct, p, file, line});
        i += p.size();
      }
    }
  }
  return out;
}

struct Function {
  std::string name;
  std::vector<std::string> template_params;  // names; empty for a non-template
  bool is_template = false;
  std::size_t params_begin = 0, params_end = 0;  // tokens inside the parameter list's ( )
  std::size_t body_begin = 0, body_end = 0;      // tokens inside the body's { }
};

bool Is(const Tok& t, const char* s) { return t.kind != Tok::kString && t.kind != Tok::kPragma && t.text == s; }

// Index of the token that closes the bracket opened at `open` ("(", "[", "{"; "<" counts
// only "<" and ">" inside, for template argument lists).
std::size_t MatchClose(const std::vector<Tok>& t, std::size_t open) {
  const std::string o = t[open].text;
  const std::string c = o == "(" ? ")" : o == "[" ? "]" : o == "{" ? "}" : ">";
  int depth = 0;
  for (std::size_t i = open; i < t.size(); ++i) {
    if (t[i].kind != Tok::kPunct) continue;
    if (t[i].text == o) ++depth;
    if (t[i].text == c && --depth == 0) return i;
    if (o == "<" && (t[i].text == ";" || t[i].text == "{")) break;
  }
  return t.size();
}

// Function definitions at namespace or class scope.
std::vector<Function> FindFunctions(const std::vector<Tok>& t) {
  std::vector<Function> fns;
  std::size_t stmt_start = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (Is(t[i], ";") || Is(t[i], "}")) {
      stmt_start = i + 1;
      continue;
    }
    if (t[i].kind == Tok::kPragma) {
      stmt_start = i + 1;
      continue;
    }
    if (!Is(t[i], "{")) continue;
    // `) {`, `) const {`, `) noexcept {`: a function body; anything else (namespace, class,
    // initialiser) is entered.
    std::size_t k = i;
    while (k > stmt_start && (Is(t[k - 1], "const") || Is(t[k - 1], "noexcept") || Is(t[k - 1], "override"))) --k;
    if (k == stmt_start || !Is(t[k - 1], ")")) {
      stmt_start = i + 1;
      continue;
    }
    // The parameter list: the "(" matching t[k - 1].
    int depth = 0;
    std::size_t open = k - 1;
    for (std::size_t j = k - 1;; --j) {
      if (Is(t[j], ")")) ++depth;
      if (Is(t[j], "(") && --depth == 0) {
        open = j;
        break;
      }
      if (j == stmt_start) break;
    }
    const std::size_t close_body = MatchClose(t, i);
    if (open > stmt_start && t[open - 1].kind == Tok::kIdent) {
      Function f;
      f.name = t[open - 1].text;
      f.params_begin = open + 1;
      f.params_end = k - 1;
      f.body_begin = i + 1;
      f.body_end = close_body;
      if (Is(t[stmt_start], "template") && stmt_start + 1 < t.size() && Is(t[stmt_start + 1], "<")) {
        f.is_template = true;
        const std::size_t tclose = MatchClose(t, stmt_start + 1);
        // Parameter names: the identifier before each top-level "," or the closing ">".
        for (std::size_t j = stmt_start + 2; j < tclose; ++j)
          if ((Is(t[j + 1], ",") || j + 1 == tclose || Is(t[j + 1], "=")) && t[j].kind == Tok::kIdent)
            f.template_params.push_back(t[j].text);
      }
      fns.push_back(f);
    }
    i = close_body;  // skip the body (lambdas and local classes inside are not functions)
    stmt_start = i + 1;
  }
  return fns;
}

struct Param {
  std::string name;
  bool channel = false;  // array, pointer, non-const reference or stream
};

std::vector<Param> Params(const std::vector<Tok>& t, const Function& f) {
  std::vector<Param> out;
  std::vector<std::pair<std::size_t, std::size_t>> pieces;
  int depth = 0;
  std::size_t start = f.params_begin;
  for (std::size_t i = f.params_begin; i <= f.params_end; ++i) {
    if (i == f.params_end || (depth == 0 && Is(t[i], ","))) {
      if (i > start) pieces.push_back({start, i});
      start = i + 1;
      continue;
    }
    if (Is(t[i], "(") || Is(t[i], "[") || Is(t[i], "<") || Is(t[i], "{")) ++depth;
    if (Is(t[i], ")") || Is(t[i], "]") || Is(t[i], ">") || Is(t[i], "}")) --depth;
  }
  for (const auto& [b, e] : pieces) {
    Param p;
    bool is_const = false, ref = false, ptr = false, array = false, stream = false;
    int d = 0;
    for (std::size_t i = b; i < e; ++i) {
      if (d == 0 && Is(t[i], "=")) break;  // default argument
      if (Is(t[i], "<") || Is(t[i], "(")) ++d;
      if (Is(t[i], ">") || Is(t[i], ")")) --d;
      if (d == 0 && Is(t[i], "[")) {
        array = true;
        break;
      }
      if (d == 0 && Is(t[i], "const")) is_const = true;
      if (d == 0 && (Is(t[i], "&") || Is(t[i], "&&"))) ref = true;
      if (d == 0 && Is(t[i], "*")) ptr = true;
      if (Is(t[i], "stream")) stream = true;
      if (d == 0 && t[i].kind == Tok::kIdent && !Is(t[i], "const")) p.name = t[i].text;
    }
    p.channel = array || ptr || stream || (ref && !is_const);
    if (!p.name.empty()) out.push_back(p);
  }
  return out;
}

bool IsTopName(const std::string& name) {
  static const std::regex top_re("^Hw[A-Za-z]*Top[0-9]*$");
  return std::regex_match(name, top_re);
}

std::string Where(const Tok& t) { return t.file + ":" + std::to_string(t.line) + ": "; }

// Rule (a): the tops' INTERFACE pragmas.
void CheckTop(const std::vector<Tok>& t, const Function& f, std::vector<std::string>* bad, std::set<std::string>* tops) {
  if (f.is_template || !IsTopName(f.name)) return;
  tops->insert(f.name);
  std::set<std::string> ports;
  static const std::regex iface_re(R"(^\s*HLS\s+INTERFACE\b.*)", std::regex::icase);
  static const std::regex port_re(R"(\bport\s*=\s*(\w+))", std::regex::icase);
  for (std::size_t i = f.body_begin; i < f.body_end; ++i) {
    if (t[i].kind != Tok::kPragma || !std::regex_match(t[i].text, iface_re)) continue;
    std::smatch m;
    if (std::regex_search(t[i].text, m, port_re)) ports.insert(m[1]);
  }
  std::vector<Param> params = Params(t, f);
  params.push_back({"return", false});
  for (const Param& p : params)
    if (!ports.count(p.name))
      bad->push_back(Where(t[f.body_begin - 1]) + "top " + f.name + ": no #pragma HLS INTERFACE for '" + p.name + "'");
}

// Rules (b) and (c) on one DATAFLOW region.
struct Region {
  const std::vector<Tok>& t;
  const Function& f;
  const std::set<std::string>& constexpr_names;
  std::vector<std::string>* bad;
  std::set<std::string> locals;
  std::vector<std::set<std::string>> calls;  // per process call: the names in its arguments

  void Bad(std::size_t i, const std::string& what) {
    bad->push_back(Where(t[i]) + "DATAFLOW region " + f.name + ": " + what);
  }
  bool CompileTime(const Tok& b) const {
    if (b.kind == Tok::kNumber) return true;
    if (b.kind != Tok::kIdent) return false;
    return std::find(f.template_params.begin(), f.template_params.end(), b.text) != f.template_params.end() ||
           constexpr_names.count(b.text) > 0;
  }
  // End of the statement that starts at i (exclusive): after its ";" or its "}".
  std::size_t StatementEnd(std::size_t i, std::size_t end) const {
    for (std::size_t j = i; j < end; ++j) {
      if (Is(t[j], "(") || Is(t[j], "[")) j = MatchClose(t, j);
      else if (Is(t[j], "{")) return MatchClose(t, j) + 1;
      else if (Is(t[j], ";")) return j + 1;
    }
    return end;
  }
  // Whether [b, e) is `Name[::Name…][<…>](…);` — a process call.
  bool IsCall(std::size_t b, std::size_t e, std::size_t* open) const {
    std::size_t i = b;
    if (t[i].kind != Tok::kIdent) return false;
    ++i;
    while (i + 1 < e && Is(t[i], "::") && t[i + 1].kind == Tok::kIdent) i += 2;
    if (i < e && Is(t[i], "<")) i = MatchClose(t, i) + 1;
    if (i >= e || !Is(t[i], "(")) return false;
    *open = i;
    return MatchClose(t, i) + 2 == e && Is(t[e - 1], ";");
  }
  void RecordCall(std::size_t open, std::size_t close) {
    std::set<std::string> names;
    for (std::size_t i = open + 1; i < close; ++i)
      if (t[i].kind == Tok::kIdent && !(Is(t[i - 1], ".") || Is(t[i - 1], "->") || Is(t[i - 1], "::")))
        names.insert(t[i].text);
    calls.push_back(names);
  }
  bool ContainsCall(std::size_t b, std::size_t e) const {
    for (std::size_t i = b; i + 1 < e; ++i)
      if (t[i].kind == Tok::kIdent && Is(t[i + 1], "(") && !Is(t[i], "if") && !Is(t[i], "for") && !Is(t[i], "while") &&
          !Is(t[i], "switch") && !Is(t[i], "sizeof"))
        return true;
    return false;
  }
  // A declaration `[constexpr|const|static…] Type name[…][("name")], …;`; false if [b, e) is
  // not a declaration. Channel names go to `locals`.
  bool Declaration(std::size_t b, std::size_t e) {
    std::size_t i = b;
    bool is_constexpr = false;
    while (i < e && (Is(t[i], "constexpr") || Is(t[i], "const") || Is(t[i], "static") || Is(t[i], "volatile"))) {
      is_constexpr |= Is(t[i], "constexpr");
      ++i;
    }
    if (i < e && Is(t[i], "::")) ++i;
    if (i >= e || t[i].kind != Tok::kIdent) return false;
    ++i;
    while (i + 1 < e && Is(t[i], "::") && t[i + 1].kind == Tok::kIdent) i += 2;
    if (i < e && Is(t[i], "<")) i = MatchClose(t, i) + 1;
    while (i < e && (Is(t[i], "*") || Is(t[i], "&") || Is(t[i], "const"))) ++i;
    if (i >= e || t[i].kind != Tok::kIdent) return false;  // not `Type name`
    // Declarators.
    while (i < e) {
      if (t[i].kind != Tok::kIdent) return false;
      const std::string name = t[i].text;
      ++i;
      while (i < e && Is(t[i], "[")) i = MatchClose(t, i) + 1;
      if (i < e && (Is(t[i], "(") || Is(t[i], "{"))) {  // constructor arguments: a name only
        const std::size_t c = MatchClose(t, i);
        const bool name_only = c == i + 1 || (c == i + 2 && t[i + 1].kind == Tok::kString);
        if (!name_only && !is_constexpr) Bad(i, "initialised declaration of '" + name + "' (a scalar statement)");
        i = c + 1;
      } else if (i < e && Is(t[i], "=")) {
        if (!is_constexpr) Bad(i, "initialised declaration of '" + name + "' (a scalar statement)");
        int d = 0;
        for (; i < e; ++i) {
          if (Is(t[i], "(") || Is(t[i], "{") || Is(t[i], "[") || Is(t[i], "<")) ++d;
          if (Is(t[i], ")") || Is(t[i], "}") || Is(t[i], "]") || Is(t[i], ">")) --d;
          if (d == 0 && (Is(t[i], ",") || Is(t[i], ";"))) break;
        }
      }
      if (!is_constexpr) locals.insert(name);
      if (i < e && Is(t[i], ",")) {
        ++i;
        continue;
      }
      return i < e && Is(t[i], ";");
    }
    return false;
  }
  // The statements of [b, e); in_loop: inside a process loop's body.
  void Statements(std::size_t b, std::size_t e, bool in_loop) {
    for (std::size_t i = b; i < e;) {
      if (t[i].kind == Tok::kPragma) {
        ++i;
        continue;
      }
      if (t[i].kind == Tok::kIdent && i + 1 < e && Is(t[i + 1], ":")) {  // a loop label
        i += 2;
        continue;
      }
      if (Is(t[i], ";")) {
        ++i;
        continue;
      }
      const std::size_t end = StatementEnd(i, e);
      std::size_t open = 0;
      if (Is(t[i], "static_assert")) {  // compile time
        i = end;
        continue;
      }
      if (Is(t[i], "for") && i + 1 < e && Is(t[i + 1], "(")) {
        const std::size_t hclose = MatchClose(t, i + 1);
        // The condition: the tokens between the header's two top-level ";".
        std::vector<std::size_t> semis;
        for (std::size_t j = i + 2; j < hclose; ++j) {
          if (Is(t[j], "(") || Is(t[j], "[")) j = MatchClose(t, j);
          else if (Is(t[j], ";")) semis.push_back(j);
        }
        const bool bounded = semis.size() == 2 && semis[1] == semis[0] + 4 && t[semis[0] + 1].kind == Tok::kIdent &&
                             (Is(t[semis[0] + 2], "<") || Is(t[semis[0] + 2], "<=")) && CompileTime(t[semis[0] + 3]);
        if (!bounded) Bad(i, "a process loop whose bound is not a compile-time constant");
        std::size_t body_b = hclose + 1, body_e = end;
        if (body_b < e && Is(t[body_b], "{")) {
          body_e = MatchClose(t, body_b);
          ++body_b;
        }
        Statements(body_b, body_e, true);
      } else if (Is(t[i], "if") || Is(t[i], "switch") || Is(t[i], "while") || Is(t[i], "do")) {
        std::size_t stmt_e = end;
        if (Is(t[i], "if")) {  // with its else branches
          while (stmt_e < e && Is(t[stmt_e], "else")) stmt_e = StatementEnd(stmt_e + 1, e);
        }
        if (ContainsCall(i + 1, stmt_e)) Bad(i, "a process called under '" + t[i].text + "'");
        else Bad(i, "a scalar '" + t[i].text + "' statement between the processes");
        i = stmt_e;
        continue;
      } else if (IsCall(i, end, &open)) {
        RecordCall(open, MatchClose(t, open));
      } else if (in_loop || !Declaration(i, end)) {
        Bad(i, "a scalar statement between the processes");
      }
      i = end;
    }
  }
  void Check() {
    Statements(f.body_begin, f.body_end, false);
    std::map<std::string, int> uses;
    for (const auto& names : calls)
      for (const std::string& n : names) ++uses[n];
    for (const Param& p : Params(t, f))
      if (p.channel && uses[p.name] > 1)
        Bad(f.body_begin - 1, "argument '" + p.name + "' is used by " + std::to_string(uses[p.name]) +
                                  " processes (one reader or one writer)");
    for (const std::string& l : locals)
      if (uses[l] > 2)
        Bad(f.body_begin - 1, "channel '" + l + "' is used by " + std::to_string(uses[l]) +
                                  " processes (one producer, one consumer)");
  }
};

// Rule (d), memory: an m_axi argument of a top (followed through every call that passes it
// on, by parameter position) is, inside a pipelined loop (`#pragma HLS PIPELINE` at the top of
// the loop's body), only indexed by an affine function of the loop's counter: each subscript
// made of the counter, literals, loop-invariant names (assigned nowhere in the loop body) and
// + - * ( ); no subscript inside it, no member, no call, no division. It is not handed to a
// function inside such a loop. And the loop makes at most II distinct accesses per bundle in
// one iteration (a bundle moves one word per clock).
struct MemoryLint {
  const std::vector<Tok>& t;
  const std::vector<Function>& fns;
  std::vector<std::string>* bad;
  std::set<std::string>* checked;  // "function:parameter" pairs followed (also the cycle guard)

  static bool Keyword(const Tok& k) {
    for (const char* w : {"if", "for", "while", "switch", "return", "sizeof", "static_assert", "do", "else"})
      if (Is(k, w)) return true;
    return false;
  }
  // The arguments of the call whose "(" is at `open`: [begin, end) token ranges.
  std::vector<std::pair<std::size_t, std::size_t>> Args(std::size_t open) const {
    std::vector<std::pair<std::size_t, std::size_t>> out;
    const std::size_t close = MatchClose(t, open);
    std::size_t b = open + 1;
    for (std::size_t i = open + 1; i <= close; ++i) {
      if (i == close || Is(t[i], ",")) {
        if (i > b) out.push_back({b, i});
        b = i + 1;
        continue;
      }
      if (Is(t[i], "(") || Is(t[i], "[") || Is(t[i], "{")) i = MatchClose(t, i);
      else if (Is(t[i], "<") && i > 0 && t[i - 1].kind == Tok::kIdent && Is(t[i - 1], "stream")) i = MatchClose(t, i);
    }
    return out;
  }
  struct Loop {
    std::size_t body_b, body_e;
    std::string var;
    int ii;
  };
  // The pipelined `for` loops of [b, e).
  std::vector<Loop> PipelinedLoops(std::size_t b, std::size_t e) const {
    std::vector<Loop> out;
    static const std::regex pipe_re(R"(^\s*HLS\s+PIPELINE\b(.*))", std::regex::icase);
    static const std::regex ii_re(R"(\bII\s*=\s*(\d+))", std::regex::icase);
    for (std::size_t i = b; i + 1 < e; ++i) {
      if (!Is(t[i], "for") || !Is(t[i + 1], "(")) continue;
      const std::size_t hclose = MatchClose(t, i + 1);
      if (hclose + 1 >= e || !Is(t[hclose + 1], "{")) continue;
      Loop l{hclose + 2, MatchClose(t, hclose + 1), "", 0};
      for (std::size_t j = i + 2; j < hclose && !Is(t[j], ";"); ++j)
        if (t[j].kind == Tok::kIdent && Is(t[j + 1], "=")) l.var = t[j].text;
      for (std::size_t j = l.body_b; j < l.body_e && t[j].kind == Tok::kPragma; ++j) {
        std::smatch m;
        if (!std::regex_match(t[j].text, m, pipe_re)) continue;
        std::smatch n;
        const std::string rest = m[1];
        l.ii = std::regex_search(rest, n, ii_re) ? std::stoi(n[1]) : 1;
      }
      if (l.ii > 0) out.push_back(l);
    }
    return out;
  }
  // Names assigned, incremented or declared with an initialiser inside [b, e).
  std::set<std::string> Variant(std::size_t b, std::size_t e) const {
    std::set<std::string> v;
    for (std::size_t i = b; i < e; ++i) {
      if (t[i].kind != Tok::kIdent) continue;
      const bool before_assign = i + 1 < e && (Is(t[i + 1], "=") || Is(t[i + 1], "+=") || Is(t[i + 1], "-=") ||
                                               Is(t[i + 1], "*=") || Is(t[i + 1], "++") || Is(t[i + 1], "--") ||
                                               Is(t[i + 1], "[") || Is(t[i + 1], "("));
      const bool after_incr = i > b && (Is(t[i - 1], "++") || Is(t[i - 1], "--"));
      if ((before_assign && !Is(t[i + 1], "[") && !Is(t[i + 1], "(")) || after_incr) v.insert(t[i].text);
      // A declaration `Type name;` / `Type name[...]` / `Type name(...)` counts as well.
      if (i + 1 < e && i > b && t[i - 1].kind == Tok::kIdent && !Keyword(t[i - 1]) &&
          (Is(t[i + 1], ";") || Is(t[i + 1], "[") || Is(t[i + 1], "(") || Is(t[i + 1], "=") || Is(t[i + 1], ",")))
        if (!Is(t[i - 1], "return")) v.insert(t[i].text);
    }
    return v;
  }
  // Whether subscript [b, e) is affine in `var` with invariants (names outside `variant`).
  bool Affine(std::size_t b, std::size_t e, const std::string& var, const std::set<std::string>& variant,
              std::string* why) const {
    if (b == e) {
      *why = "an empty subscript";
      return false;
    }
    for (std::size_t i = b; i < e; ++i) {
      const Tok& k = t[i];
      if (k.kind == Tok::kNumber) continue;
      if (k.kind == Tok::kIdent) {
        if (i + 1 < e && (Is(t[i + 1], "(") || Is(t[i + 1], "<"))) {
          *why = "a call '" + k.text + "(…)' in the index";
          return false;
        }
        if (k.text != var && variant.count(k.text)) {
          *why = "'" + k.text + "', which changes inside the loop";
          return false;
        }
        continue;
      }
      if (k.kind == Tok::kPunct &&
          (k.text == "+" || k.text == "-" || k.text == "*" || k.text == "(" || k.text == ")" || k.text == "::"))
        continue;
      *why = "'" + k.text + "' in the index (data-dependent or not affine)";
      return false;
    }
    return true;
  }
  // Pipelined-loop accesses of the tracked parameters of `f`; then the calls that pass them on.
  void Follow(const Function& f, const std::map<std::string, std::string>& tracked, const std::string& top) {
    std::map<std::string, std::string> fresh;
    for (const auto& [name, bundle] : tracked)
      if (checked->insert(f.name + ":" + name).second) fresh[name] = bundle;
    if (fresh.empty()) return;
    std::vector<std::pair<std::size_t, std::size_t>> pipelined;
    for (const Loop& l : PipelinedLoops(f.body_begin, f.body_end)) {
      pipelined.push_back({l.body_b, l.body_e});
      const std::set<std::string> variant = Variant(l.body_b, l.body_e);
      std::map<std::string, std::set<std::string>> per_bundle;  // bundle → distinct accesses
      for (std::size_t i = l.body_b; i < l.body_e; ++i) {
        if (t[i].kind != Tok::kIdent || !fresh.count(t[i].text)) continue;
        if (i > 0 && (Is(t[i - 1], ".") || Is(t[i - 1], "->"))) continue;  // a member of the same name
        const std::string& name = t[i].text;
        if (i + 1 >= l.body_e || !Is(t[i + 1], "[")) {
          bad->push_back(Where(t[i]) + "top " + top + ": m_axi argument '" + name + "' (in " + f.name +
                         ") is handed on inside a pipelined loop");
          continue;
        }
        std::string access = name;
        for (std::size_t j = i + 1; j < l.body_e && Is(t[j], "[");) {
          const std::size_t c = MatchClose(t, j);
          std::string why;
          if (!Affine(j + 1, c, l.var, variant, &why))
            bad->push_back(Where(t[i]) + "top " + top + ": m_axi argument '" + name + "' (in " + f.name +
                           ") indexed by " + why + " (a pipelined loop over '" + l.var + "')");
          for (std::size_t q = j; q <= c; ++q) access += t[q].text;
          j = c + 1;
        }
        per_bundle[fresh.at(name)].insert(access);
      }
      for (const auto& [bundle, accesses] : per_bundle)
        if (int(accesses.size()) > l.ii) {
          std::string list;
          for (const auto& a : accesses) list += (list.empty() ? "" : ", ") + a;
          bad->push_back(Where(t[l.body_b]) + "top " + top + ": bundle " + bundle + " takes " +
                         std::to_string(accesses.size()) + " accesses per iteration (" + list + ") in a loop of II " +
                         std::to_string(l.ii) + " (in " + f.name + ")");
        }
    }
    // Calls outside the pipelined loops that pass a tracked argument on.
    for (std::size_t i = f.body_begin; i + 1 < f.body_end; ++i) {
      bool inside = false;
      for (const auto& [b, e] : pipelined) inside |= i >= b && i < e;
      if (inside || t[i].kind != Tok::kIdent || Keyword(t[i])) continue;
      if (i > 0 && (Is(t[i - 1], ".") || Is(t[i - 1], "->"))) continue;
      std::size_t open = i + 1;
      if (Is(t[open], "<")) open = MatchClose(t, open) + 1;
      if (open >= f.body_end || !Is(t[open], "(")) continue;
      const auto args = Args(open);
      for (const Function& g : fns) {
        if (g.name != t[i].text) continue;
        const std::vector<Param> params = Params(t, g);
        std::map<std::string, std::string> passed;
        for (std::size_t a = 0; a < args.size() && a < params.size(); ++a) {
          const Tok& first = t[args[a].first];
          if (first.kind == Tok::kIdent && fresh.count(first.text) &&
              (args[a].second == args[a].first + 1 || Is(t[args[a].first + 1], "[")))
            passed[params[a].name] = fresh.at(first.text);
        }
        if (!passed.empty()) Follow(g, passed, top);
      }
    }
  }
  // The m_axi ports of top `f` (port → bundle) and the walk from it.
  void CheckTop(const Function& f) {
    if (f.is_template || !IsTopName(f.name)) return;
    static const std::regex maxi_re(R"(^\s*HLS\s+INTERFACE\s+m_axi\b.*)", std::regex::icase);
    static const std::regex port_re(R"(\bport\s*=\s*(\w+))", std::regex::icase);
    static const std::regex bundle_re(R"(\bbundle\s*=\s*(\w+))", std::regex::icase);
    std::map<std::string, std::string> ports;
    for (std::size_t i = f.body_begin; i < f.body_end; ++i) {
      if (t[i].kind != Tok::kPragma || !std::regex_match(t[i].text, maxi_re)) continue;
      std::smatch p, b;
      if (std::regex_search(t[i].text, p, port_re))
        ports[p[1]] = std::regex_search(t[i].text, b, bundle_re) ? std::string(b[1]) : std::string("gmem");
    }
    checked->clear();
    Follow(f, ports, f.name);
  }
};

struct TopLintResult {
  std::vector<std::string> violations;
  std::set<std::string> tops, regions;
  std::set<std::string> memory_followed;  // "function:parameter" pairs rule (d) walked, all tops
  std::string error;  // the preprocessor's complaint, if any
};

// Preprocesses `tu` (-D__SYNTHESIS__) and applies rules (a)–(d) to the code of files whose
// path matches `keep`.
TopLintResult RunTopLint(const fs::path& dir, const fs::path& tu, const std::vector<fs::path>& includes,
                         const std::string& keep = "src/hw/([^/]+[.]h|tops[.]cc)$") {
  TopLintResult r;
  std::string cmd = "c++ -E -std=c++20 -D__SYNTHESIS__ '" + tu.string() + "'";
  for (const fs::path& inc : includes) cmd += " -I'" + inc.string() + "'";
  cmd += " >'" + (dir / "pp.out").string() + "' 2>'" + (dir / "pp.err").string() + "'";
  if (std::system(cmd.c_str()) != 0) {
    r.error = ReadFile(dir / "pp.err");
    return r;
  }
  const std::vector<Tok> t = Tokenize(ReadFile(dir / "pp.out"), std::regex(keep));
  std::set<std::string> constexpr_names;
  for (std::size_t i = 0; i + 1 < t.size(); ++i) {
    if (!Is(t[i], "constexpr")) continue;
    for (std::size_t j = i + 1; j < t.size() && j < i + 12; ++j)
      if (t[j].kind == Tok::kIdent && (Is(t[j + 1], "=") || Is(t[j + 1], "{") || Is(t[j + 1], "["))) {
        constexpr_names.insert(t[j].text);
        break;
      }
  }
  static const std::regex dataflow_re(R"(^\s*HLS\s+DATAFLOW\b.*)", std::regex::icase);
  const std::vector<Function> fns = FindFunctions(t);
  std::set<std::string> followed;
  MemoryLint memory{t, fns, &r.violations, &followed};
  for (const Function& f : fns) {
    memory.CheckTop(f);
    r.memory_followed.insert(followed.begin(), followed.end());
  }
  for (const Function& f : fns) {
    CheckTop(t, f, &r.violations, &r.tops);
    bool dataflow = false;
    for (std::size_t i = f.body_begin; i < f.body_end; ++i)
      dataflow |= t[i].kind == Tok::kPragma && std::regex_match(t[i].text, dataflow_re);
    if (!dataflow) continue;
    r.regions.insert(f.name);
    Region region{t, f, constexpr_names, &r.violations, {}, {}};
    region.Check();
  }
  return r;
}

std::string Joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

TEST(HwTopLint, TopsHaveInterfacesAndRegionsAreCanonical) {
  if (std::system("c++ --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "no c++ preprocessor";
  const fs::path root = RepoRoot();
  ASSERT_FALSE(root.empty()) << "cannot find the repository (src/hw/hw_types.h)";
  const fs::path dir = FreshTempPath("hwtop_toplint");
  fs::create_directories(dir);
  std::string tu;
  for (const auto& e : fs::directory_iterator(root / "src/hw")) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".h") continue;
    if (std::find(std::begin(kHostHeaders), std::end(kHostHeaders), name) != std::end(kHostHeaders)) continue;
    tu += "#include \"hw/" + name + "\"\n";
  }
  tu += "#include \"hw/tops.cc\"\n";  // the tops' definitions
  WriteFile(dir / "kernels.cc", tu);
  const TopLintResult r = RunTopLint(dir, dir / "kernels.cc", {root / "src", root / "src/hw/hls_types", root / "include"});
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_TRUE(r.violations.empty()) << Joined(r.violations);
  // The lint saw what it checks: the four tops and the three regions.
  for (const char* top : {"HwInitTop", "HwWeighTop5", "HwWeighTop10", "HwUpdateTop"}) EXPECT_TRUE(r.tops.count(top)) << top;
  for (const char* region : {"HwWeighTop", "HwUpdateTop", "InitSamplesRegion"})
    EXPECT_TRUE(r.regions.count(region)) << region;
  // Rule (d) followed every m_axi argument to the kernel that reads or writes it.
  for (const char* use : {"GatherSampleInfo:samples", "BurstLoad:src", "DistributeDepth:depth", "VertexMultiplier:vmem",
                          "VertexMultiplier:tri_mem", "MergeWeights:class_prob", "SortWeights:sorted_w",
                          "SortWeights:sorted_idx", "CollectStats:stats", "CollectStats:offsets", "Resample:sorted_w",
                          "Resample:samples", "Resample:hypothesis", "Diffuse:in_mem", "Diffuse:volumes",
                          "Diffuse:out_mem", "CdfNormalise:prob", "GenSample:heuristics", "GenSample:samples"})
    EXPECT_TRUE(r.memory_followed.count(use)) << "rule (d) did not reach " << use;
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
    EXPECT_NE(Joined(r.violations).find(expect), std::string::npos)
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
    EXPECT_NE(Joined(r.violations).find(expect), std::string::npos)
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
