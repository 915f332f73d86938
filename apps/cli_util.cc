#include <algorithm>
#include "cli_util.h"

#include <filesystem>
#include <iostream>
#include <memory>

#include "filter_cli.h"
#include "posefilter/error.h"
#include "posefilter/synth.h"

namespace posefilter::cli {

namespace {

// CLI11's help, with a switch's default said in words: CLI11 prints the value a negated switch
// sets after its name ("--zbuffer,--no-zbuffer{false}"), which reads as the default; here the
// braces go, and a switch whose default is known gets "(default: on)" or "(default: off)".
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_name(const CLI::Option* opt, bool is_positional) const override {
    std::string name = CLI::Formatter::make_option_name(opt, is_positional);
    for (std::size_t a; (a = name.find('{')) != std::string::npos;) {
      const std::size_t b = name.find('}', a);
      if (b == std::string::npos) break;
      name.erase(a, b - a + 1);
    }
    return name;
  }
  std::string make_option_opts(const CLI::Option* opt) const override {
    std::string opts = CLI::Formatter::make_option_opts(opt);
    const std::string shown = "=" + opt->get_default_str();
    if (opt->get_expected_max() == 0 && !opt->get_default_str().empty())  // a switch: its default goes in words
      if (const std::size_t at = opts.find(shown); at != std::string::npos) opts.erase(at, shown.size());
    return opts;
  }
  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string desc = CLI::Formatter::make_option_desc(opt);
    const std::string d = opt->get_default_str();
    if (opt->get_expected_max() == 0 && (d == "true" || d == "false" || d == "1" || d == "0"))  // a switch
      desc += (d == "true" || d == "1") ? " (default: on)" : " (default: off)";
    return desc;
  }
};

}  // namespace

int RunApp(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  app.formatter(std::make_shared<HelpFormatter>());
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help: the help on stdout, exit 0
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // A usage error: one line, prefixed like every other error of the command, exit 2.
    std::cerr << "posefilter " << app.get_name() << ": error: " << e.what() << " (--help lists the options)\n";
    return 2;
  }
  try {
    // A value given as "" (`--out ""`) is an error naming the option: no option of posefilter
    // takes an empty value, and an empty path would otherwise mean "no output" or ".".
    for (const CLI::Option* opt : app.get_options())
      if (opt->count() > 0 && opt->get_expected_max() != 0)  // takes a value (not a switch)
        for (const std::string& v : opt->results())
          if (v.empty()) throw Error(opt->get_name() + ": empty value");
    body();
  } catch (const Error& e) {
    std::cerr << "posefilter " << app.get_name() << ": error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "posefilter " << app.get_name() << ": error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

std::string NameSynthOption(const std::string& why) { return NameOptionRow(SynthOptionTable(), why); }

std::vector<std::pair<std::string, std::string>> ParseNamedPaths(const std::vector<std::string>& args,
                                                                 const std::string& option, bool require_name) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& arg : args) {
    const auto eq = arg.find('=');
    std::string name, path;
    if (eq == std::string::npos) {
      if (require_name) throw Error(option + ": expected NAME=PATH, got '" + arg + "' (no '=')");
      name = std::filesystem::path(arg).stem().string();
      path = arg;
    } else {
      name = arg.substr(0, eq);
      path = arg.substr(eq + 1);
      if (name.empty()) throw Error(option + ": empty NAME in '" + arg + "' (expected NAME=PATH)");
      if (path.empty()) throw Error(option + ": empty PATH in '" + arg + "' (expected NAME=PATH)");
    }
    for (const auto& [seen, seen_path] : out)
      if (seen == name)
        throw Error(option + ": NAME '" + name + "' given twice (" + seen_path + " and " + path +
                    "); give each its own name, NAME=PATH");
    out.emplace_back(name, path);
  }
  return out;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace posefilter::cli
