// The failure of the prior layer's option checks (its IsValid functions):
// `return Fail(why, "...")`. Internal: not part of the public API.
#pragma once
#include <string>

namespace posefilter::prior {

// Sets *why (may be null) to `msg` and returns false.
inline bool Fail(std::string* why, const std::string& msg) {
  if (why) *why = msg;
  return false;
}

}  // namespace posefilter::prior
