// tools/hls_lint/hls_lint.cc — the HLS kernel lint's tree lookup, its clang-query part (the
// synthesizable subset) and the tokenizer and function finder of its source-level part
// (top_lint.cc). hls_lint.h states the rules.
#include "hls_lint.h"

#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>

namespace posefilter::hls_lint {

namespace {

// Host-side files of src/hw/ that are not kernels (STL allowed): the cycle model.
const char* const kHostHeaders[] = {"cycle_model.h"};

// The `let`s of the query script: `inhw` restricts a matcher to the kernel files, `notce` keeps
// it out of constexpr functions and variables (compile-time ROM generators).
const char* const kQueryLets = R"(let inhw isExpansionInFileMatching("src/hw/([^/]+[.]h|tops[.]cc)$")
let notce unless(anyOf(hasAncestor(functionDecl(isConstexpr())), hasAncestor(varDecl(isConstexpr()))))
)";

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  return out.good();
}

std::string Quoted(const fs::path& p) { return "'" + p.string() + "'"; }

}  // namespace

std::string Format(const Finding& f) {
  return f.file + ":" + std::to_string(f.line) + ": " + f.rule + ": " + f.message;
}

std::string Joined(const std::vector<Finding>& findings) {
  std::string s;
  for (const Finding& f : findings) s += Format(f) + "\n";
  return s;
}

// ---- The tree ---------------------------------------------------------------------------------

std::optional<Tree> FindTree(const fs::path& path, std::string* why) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // a trailing '/'
  Tree tree;
  if (fs::is_directory(p / "src" / "hw", ec)) {
    tree.hw_dir = p / "src" / "hw";
  } else if (fs::is_directory(p, ec) && p.filename() == "hw" && p.parent_path().filename() == "src") {
    tree.hw_dir = p;
  } else {
    *why = path.string() + ": neither a repository root (with src/hw/) nor a src/hw folder";
    return std::nullopt;
  }
  tree.hw_dir = fs::weakly_canonical(tree.hw_dir, ec);
  for (const auto& e : fs::directory_iterator(tree.hw_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".h") continue;
    if (std::find(std::begin(kHostHeaders), std::end(kHostHeaders), name) != std::end(kHostHeaders)) continue;
    tree.headers.push_back(name);
  }
  if (ec) {
    *why = tree.hw_dir.string() + ": cannot list folder: " + ec.message();
    return std::nullopt;
  }
  std::sort(tree.headers.begin(), tree.headers.end());
  if (tree.headers.empty()) {
    *why = tree.hw_dir.string() + ": no kernel headers (*.h)";
    return std::nullopt;
  }
  tree.has_tops = fs::is_regular_file(tree.hw_dir / "tops.cc", ec);
  const fs::path src = tree.hw_dir.parent_path();
  tree.includes = {src, tree.hw_dir / "hls_types", src.parent_path() / "include"};
  return tree;
}

std::string KernelTranslationUnit(const Tree& tree) {
  std::string tu;
  for (const std::string& h : tree.headers) tu += "#include \"hw/" + h + "\"\n";
  if (tree.has_tops) tu += "#include \"hw/tops.cc\"\n";  // the tops' definitions
  return tu;
}

// ---- The synthesizable subset (clang-query) ---------------------------------------------------

const std::vector<Matcher>& SubsetMatchers() {
  static const std::vector<Matcher> matchers = {
      {"no-new", "a new-expression (heap)", "cxxNewExpr(inhw)"},
      {"no-delete", "a delete-expression (heap)", "cxxDeleteExpr(inhw)"},
      {"no-malloc", "a call to a C heap function (malloc, calloc, realloc, free, aligned_alloc)",
       R"(callExpr(inhw, callee(functionDecl(hasAnyName("malloc", "calloc", "realloc", "free", "aligned_alloc", "__builtin_malloc", "__builtin_free")))))"},
      {"no-exceptions", "a throw-expression", "cxxThrowExpr(inhw)"},
      {"no-exceptions", "a try block", "cxxTryStmt(inhw)"},
      {"no-virtual", "a virtual method", "cxxMethodDecl(inhw, isVirtual())"},
      {"no-recursion", "a call to the function it is in (recursion)",
       R"(callExpr(inhw, callee(functionDecl().bind("self")), hasAncestor(functionDecl(equalsBoundNode("self")))))"},
      {"no-heap-type", "a std:: container or other heap-allocating type",
       R"(typeLoc(inhw, loc(qualType(hasDeclaration(namedDecl(hasAnyName("::std::vector", "::std::map", "::std::multimap", "::std::set", "::std::multiset", "::std::unordered_map", "::std::unordered_multimap", "::std::unordered_set", "::std::unordered_multiset", "::std::deque", "::std::list", "::std::forward_list", "::std::basic_string", "::std::string", "::std::wstring", "::std::queue", "::std::stack", "::std::priority_queue", "::std::function", "::std::shared_ptr", "::std::unique_ptr")))))))"},
      {"no-eigen", "an Eigen type", R"(typeLoc(inhw, loc(qualType(hasDeclaration(namedDecl(matchesName("^::Eigen::")))))))"},
      {"no-eigen", "a name from namespace Eigen", R"(declRefExpr(inhw, to(namedDecl(matchesName("^::Eigen::")))))"},
      {"no-float", "a binary operator on a floating operand (float/double arithmetic)",
       "binaryOperator(inhw, hasEitherOperand(hasType(realFloatingPointType())), notce)"},
      {"no-float", "a unary operator on a floating operand (float/double arithmetic)",
       "unaryOperator(inhw, hasUnaryOperand(hasType(realFloatingPointType())), notce)"},
      {"no-float", "a floating variable or parameter", "varDecl(inhw, hasType(realFloatingPointType()), notce)"},
      {"no-float", "a floating member", "fieldDecl(inhw, hasType(realFloatingPointType()))"},
      {"no-float", "a call returning a floating value",
       "callExpr(inhw, callee(functionDecl(returns(realFloatingPointType()))), notce)"},
  };
  return matchers;
}

std::string SubsetQueries() {
  std::string q = std::string("set output diag\n") + kQueryLets;
  for (const Matcher& m : SubsetMatchers()) q += std::string("match ") + m.query + "\n";
  return q;
}

bool HaveClangQuery() { return std::system("clang-query --version >/dev/null 2>&1") == 0; }

SubsetResult RunSubsetLint(const fs::path& work_dir, const fs::path& tu, const std::vector<fs::path>& includes) {
  SubsetResult r;
  if (!WriteText(work_dir / "queries.txt", SubsetQueries())) {
    r.output = (work_dir / "queries.txt").string() + ": cannot write";
    return r;
  }
  std::string cmd = "clang-query -f " + Quoted(work_dir / "queries.txt") + " " + Quoted(tu) +
                    " -- -std=c++20 -D__SYNTHESIS__";
  for (const fs::path& inc : includes) cmd += " -I" + Quoted(inc);
  cmd += " >" + Quoted(work_dir / "lint.out") + " 2>&1";
  const int status = std::system(cmd.c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.output = ReadText(work_dir / "lint.out");
  // Each matcher's matches ("file:line:col: note: "root" binds here"), then its "N match(es).".
  static const std::regex count_re(R"(^(\d+) match(es)?\.$)");
  static const std::regex root_re(R"(^(.+):(\d+):(\d+): note: "root" binds here$)");
  const std::vector<Matcher>& matchers = SubsetMatchers();
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, count_re)) {
      r.matches += std::stoi(m[1]);
      ++r.matchers_ran;
    } else if (std::regex_match(line, m, root_re)) {
      const std::size_t k = std::min<std::size_t>(r.matchers_ran, matchers.size() - 1);
      r.findings.push_back({m[1], std::stoi(m[2]), matchers[k].rule, matchers[k].what});
    }
  }
  return r;
}

// ---- Tokens and functions ---------------------------------------------------------------------

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
      if (std::regex_match(rest, m, marker_re)) {  // not a line of the file
        line = std::stoi(m[1]) - 1;                   // the next line has number N
        file = m[2];
        kept = std::regex_search(file, keep);
        continue;
      }
      ++line;
      if (kept && rest.compare(0, 7, "#pragma") == 0) out.push_back({Tok::kPragma, rest.substr(7), file, line});
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

bool Is(const Tok& t, const char* s) { return t.kind != Tok::kString && t.kind != Tok::kPragma && t.text == s; }

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

}  // namespace posefilter::hls_lint
