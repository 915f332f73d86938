#include "cli_util.h"

#include <filesystem>
#include <iostream>

#include "posefilter/error.h"

namespace posefilter::cli {

int RunApp(CLI::App& app, int argc, char** argv, const std::function<void()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
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

std::string NameSynthOption(const std::string& why) {
  static const std::pair<const char*, const char*> kNames[] = {
      {"target_mesh", "--mesh"},          {"target", "--target"},
      {"min_distance_m", "--min-distance"}, {"max_distance_m", "--max-distance"},
      {"occlusion", "--occlusion"},       {"clutter", "--clutter"},
      {"noise_sigma_m", "--noise"},       {"hole_fraction", "--holes"},
      {"box_jitter_px", "--box-jitter"},  {"miss_probability", "--miss-prob"},
      {"false_positives", "--false-positives"}, {"depth_scale", "--depth-scale"}};
  for (const auto& [field, option] : kNames)
    if (why.rfind(field, 0) == 0) return std::string(option) + " (" + field + "): " + why.substr(why.find(' ') + 1);
  return why;
}

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

}  // namespace posefilter::cli
