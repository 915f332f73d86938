#include "cli_util.h"

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

}  // namespace posefilter::cli
