// src/core/version.cc — posefilter::Version(): the project's version, passed in by CMake
// (POSEFILTER_VERSION = PROJECT_VERSION of the top-level CMakeLists.txt); GitRevision(): the
// commit the build came from (generated/git_revision.h, written by cmake/git_revision.cmake).
#include "posefilter/version.h"

#include "git_revision.h"

#ifndef POSEFILTER_VERSION
#error "POSEFILTER_VERSION must be defined by the build (CMakeLists.txt)"
#endif
#ifndef POSEFILTER_GIT_REVISION
#error "POSEFILTER_GIT_REVISION must be defined by generated/git_revision.h (CMakeLists.txt)"
#endif

namespace posefilter {

const char* Version() { return POSEFILTER_VERSION; }

const char* GitRevision() { return POSEFILTER_GIT_REVISION; }

}  // namespace posefilter
