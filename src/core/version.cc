// src/core/version.cc — posefilter::Version(): the project's version, passed in by CMake
// (POSEFILTER_VERSION = PROJECT_VERSION of the top-level CMakeLists.txt).
#include "posefilter/version.h"

#ifndef POSEFILTER_VERSION
#error "POSEFILTER_VERSION must be defined by the build (CMakeLists.txt)"
#endif

namespace posefilter {

const char* Version() { return POSEFILTER_VERSION; }

}  // namespace posefilter
