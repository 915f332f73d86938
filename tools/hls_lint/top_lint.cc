// tools/hls_lint/top_lint.cc — the source-level part of the HLS kernel lint: rules (a)–(d) of
// hls_lint.h (the tops' interfaces, the dataflow regions' channels and statements, the m_axi
// accesses) on the tokens of the preprocessed kernels.
#include "hls_lint.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <utility>

namespace posefilter::hls_lint {

namespace {

Finding At(const Tok& t, const char* rule, std::string message) { return {t.file, t.line, rule, std::move(message)}; }

// Rule (a): the tops' INTERFACE pragmas.
void CheckTop(const std::vector<Tok>& t, const Function& f, std::vector<Finding>* bad, std::set<std::string>* tops) {
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
      bad->push_back(
          At(t[f.body_begin - 1], "interface", "top " + f.name + ": no #pragma HLS INTERFACE for '" + p.name + "'"));
}

// Rules (b) and (c) on one DATAFLOW region.
struct Region {
  const std::vector<Tok>& t;
  const Function& f;
  const std::set<std::string>& constexpr_names;
  std::vector<Finding>* bad;
  std::set<std::string> locals;
  std::vector<std::set<std::string>> calls;  // per process call: the names in its arguments

  // Rule (c) unless `rule` says (b).
  void Bad(std::size_t i, const std::string& what, const char* rule = "dataflow-statement") {
    bad->push_back(At(t[i], rule, "DATAFLOW region " + f.name + ": " + what));
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
                                  " processes (one reader or one writer)",
            "dataflow-channel");
    for (const std::string& l : locals)
      if (uses[l] > 2)
        Bad(f.body_begin - 1, "channel '" + l + "' is used by " + std::to_string(uses[l]) +
                                  " processes (one producer, one consumer)",
            "dataflow-channel");
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
  std::vector<Finding>* bad;
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
          bad->push_back(At(t[i], "memory", "top " + top + ": m_axi argument '" + name + "' (in " + f.name +
                                                  ") is handed on inside a pipelined loop"));
          continue;
        }
        std::string access = name;
        for (std::size_t j = i + 1; j < l.body_e && Is(t[j], "[");) {
          const std::size_t c = MatchClose(t, j);
          std::string why;
          if (!Affine(j + 1, c, l.var, variant, &why))
            bad->push_back(At(t[i], "memory", "top " + top + ": m_axi argument '" + name + "' (in " + f.name +
                                                    ") indexed by " + why + " (a pipelined loop over '" + l.var + "')"));
          for (std::size_t q = j; q <= c; ++q) access += t[q].text;
          j = c + 1;
        }
        per_bundle[fresh.at(name)].insert(access);
      }
      for (const auto& [bundle, accesses] : per_bundle)
        if (int(accesses.size()) > l.ii) {
          std::string list;
          for (const auto& a : accesses) list += (list.empty() ? "" : ", ") + a;
          bad->push_back(At(t[l.body_b], "memory",
                            "top " + top + ": bundle " + bundle + " takes " + std::to_string(accesses.size()) +
                                " accesses per iteration (" + list + ") in a loop of II " + std::to_string(l.ii) +
                                " (in " + f.name + ")"));
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

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TopLintResult LintTokens(const std::vector<Tok>& t) {
  TopLintResult r;
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

TopLintResult RunTopLint(const fs::path& work_dir, const fs::path& tu, const std::vector<fs::path>& includes,
                         const std::string& keep) {
  std::string cmd = "c++ -E -std=c++20 -D__SYNTHESIS__ '" + tu.string() + "'";
  for (const fs::path& inc : includes) cmd += " -I'" + inc.string() + "'";
  cmd += " >'" + (work_dir / "pp.out").string() + "' 2>'" + (work_dir / "pp.err").string() + "'";
  if (std::system(cmd.c_str()) != 0) {
    TopLintResult r;
    r.error = ReadText(work_dir / "pp.err");
    if (r.error.empty()) r.error = "c++ -E failed: " + cmd;
    return r;
  }
  return LintTokens(Tokenize(ReadText(work_dir / "pp.out"), std::regex(keep)));
}

}  // namespace posefilter::hls_lint
