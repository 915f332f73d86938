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

}  // namespace posefilter::cli
