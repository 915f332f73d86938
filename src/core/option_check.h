// src/core/option_check.h — the failure of an option check (an IsValid(std::string* why)
// function and its like): `return Fail(why, "...")` names the violated constraint and returns
// false. Internal: not part of the public API.
#pragma once
#include <string>

namespace posefilter {

// Sets *why (may be null) to `msg` and returns false.
inline bool Fail(std::string* why, const std::string& msg) {
  if (why != nullptr) *why = msg;
  return false;
}

}  // namespace posefilter
