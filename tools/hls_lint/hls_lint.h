// tools/hls_lint/hls_lint.h — the lint of the HLS kernels (src/hw/*.h and the tops'
// src/hw/tops.cc, not src/hw/hls_types/); docs/HARDWARE.md §9 states its rules. Two parts:
//
// * The synthesizable subset (RunSubsetLint): clang-query (Debian clang-tools) runs AST matchers
//   over one translation unit that includes every kernel header, compiled with -D__SYNTHESIS__
//   (the host-only parts under #ifndef __SYNTHESIS__ drop out, as in HLS). No new/delete/malloc,
//   no std:: containers or other heap types, no Eigen, no throw/try, no virtual functions, no
//   recursion, no float/double arithmetic (constexpr ROM generators evaluated at compile time
//   excepted).
// * Tops, dataflow regions and memory (RunTopLint): pragmas are not in the clang AST, so this part
//   is source level. The same translation unit is preprocessed (c++ -E -D__SYNTHESIS__: `#pragma`
//   lines and _Pragma(...) from macros survive as `#pragma` lines, host-only code is gone) and the
//   code of the kernel files is tokenized. Rules:
//   (a) `interface`: a top — a non-template function definition named Hw<letters>Top[<digits>],
//       the functions scripts/hls names with set_top — has `#pragma HLS INTERFACE … port = p`
//       for every parameter p and for `return`;
//   (b) `dataflow-channel`: in a DATAFLOW region — a function whose body holds
//       `#pragma HLS DATAFLOW` — a memory argument (array, pointer, non-const reference,
//       hls::stream) is used by at most one process call and a local channel (any local declared
//       in the region) by at most two (one producer, one consumer);
//   (c) `dataflow-statement`: the region's statements are channel declarations (without
//       initialisers other than a stream's name), constexpr declarations, static_asserts,
//       process calls and `for` loops of process calls whose bound is compile-time (a literal, a
//       template parameter, a constexpr name): a process under `if`, a loop with a runtime bound
//       or any other statement (a scalar assignment, an initialised scalar) is rejected;
//   (d) `memory`: an m_axi argument of a top, followed through every call that passes it on, is
//       read or written inside a pipelined loop only at an affine function of the loop's counter
//       (a burst), is not handed to a function inside such a loop, and no loop makes more
//       accesses per iteration to one bundle than its II.
//
// The command-line program (hls_lint_main.cc, target hls_lint) runs both on a source tree.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace posefilter::hls_lint {

namespace fs = std::filesystem;

// One finding, printed as "file:line: rule: message".
struct Finding {
  std::string file;
  int line = 0;
  std::string rule;
  std::string message;
};
std::string Format(const Finding& f);
// One Format(f) per line.
std::string Joined(const std::vector<Finding>& findings);

// ---- The tree ---------------------------------------------------------------------------------

// The kernel files, as paths end: src/hw/<name>.h and src/hw/tops.cc.
inline constexpr const char* kKernelFiles = "src/hw/([^/]+[.]h|tops[.]cc)$";

// A source tree to lint: its src/hw folder, the kernel headers in it (sorted; the host-side
// headers, cycle_model.h, left out) and the include path of the kernels.
struct Tree {
  fs::path hw_dir;
  std::vector<std::string> headers;  // names in hw_dir
  bool has_tops = false;             // hw_dir/tops.cc exists (the tops' definitions)
  std::vector<fs::path> includes;    // <src>, <src>/hw/hls_types, <root>/include
};
// `path` is a repository root (it has src/hw/) or a folder .../src/hw; nullopt (and why) if not.
std::optional<Tree> FindTree(const fs::path& path, std::string* why);
// The translation unit both parts lint: `#include "hw/<header>"` for each header, then
// `#include "hw/tops.cc"` if the tree has it.
std::string KernelTranslationUnit(const Tree& tree);

// ---- The synthesizable subset (clang-query) ---------------------------------------------------

struct Matcher {
  const char* rule;   // e.g. "no-heap-type"
  const char* what;   // the finding's message
  const char* query;  // the clang-query matcher
};
// The matchers, in the order the query script runs them.
const std::vector<Matcher>& SubsetMatchers();
// The clang-query script: `set output diag`, the `let`s, then `match <query>` per matcher.
std::string SubsetQueries();
bool HaveClangQuery();

struct SubsetResult {
  int exit_code = -1;    // clang-query's
  int matches = 0;       // the sum of its "N match(es)." lines
  int matchers_ran = 0;  // how many "N match(es)." lines it printed
  std::string output;    // clang-query's stdout and stderr
  std::vector<Finding> findings;  // one per match, at its "root" binding
};
// Runs the matchers over `tu` with the include path `includes`; `work_dir` (existing) holds the
// query script and clang-query's output.
SubsetResult RunSubsetLint(const fs::path& work_dir, const fs::path& tu, const std::vector<fs::path>& includes);

// ---- Tokens and functions ---------------------------------------------------------------------

struct Tok {
  enum Kind { kIdent, kNumber, kString, kPunct, kPragma } kind;
  std::string text;  // for kPragma: the pragma line after "#pragma"
  std::string file;
  int line = 0;
};
// Tokens of the preprocessed text `pp` that come from files whose path matches `keep` (line
// markers `# N "file"` say where each line comes from).
std::vector<Tok> Tokenize(const std::string& pp, const std::regex& keep);
// Whether `t` is the identifier, number or punctuator `s`.
bool Is(const Tok& t, const char* s);
// Index of the token that closes the bracket opened at `open` ("(", "[", "{"; "<" counts only
// "<" and ">" inside, for template argument lists); t.size() if none.
std::size_t MatchClose(const std::vector<Tok>& t, std::size_t open);

struct Function {
  std::string name;
  std::vector<std::string> template_params;  // names; empty for a non-template
  bool is_template = false;
  std::size_t params_begin = 0, params_end = 0;  // tokens inside the parameter list's ( )
  std::size_t body_begin = 0, body_end = 0;      // tokens inside the body's { }
};
// Function definitions at namespace or class scope.
std::vector<Function> FindFunctions(const std::vector<Tok>& t);

struct Param {
  std::string name;
  bool channel = false;  // array, pointer, non-const reference or stream
};
std::vector<Param> Params(const std::vector<Tok>& t, const Function& f);
// Hw<letters>Top[<digits>].
bool IsTopName(const std::string& name);

// ---- Tops, dataflow regions and memory --------------------------------------------------------

struct TopLintResult {
  std::vector<Finding> violations;
  std::set<std::string> tops, regions;
  std::set<std::string> memory_followed;  // "function:parameter" pairs rule (d) walked, all tops
  std::string error;                      // the preprocessor's complaint, if any
};
// Applies rules (a)–(d) to tokens `t`.
TopLintResult LintTokens(const std::vector<Tok>& t);
// Preprocesses `tu` (c++ -E -std=c++20 -D__SYNTHESIS__, include path `includes`; output in
// `work_dir`, existing) and applies rules (a)–(d) to the code of files whose path matches `keep`.
TopLintResult RunTopLint(const fs::path& work_dir, const fs::path& tu, const std::vector<fs::path>& includes,
                         const std::string& keep = kKernelFiles);

}  // namespace posefilter::hls_lint
