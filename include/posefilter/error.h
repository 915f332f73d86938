// posefilter/error.h — the one exception type of the library.
//
// Every failure caused by input (a missing file, a wrong image size, NaN in a JSON, a nonsense
// option) throws posefilter::Error with a one-line message that names the file or option.
// The CLI turns it into "posefilter: error: <message>" and exit status 1.
#pragma once

#include <stdexcept>
#include <string>

namespace posefilter {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace posefilter
