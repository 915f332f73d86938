// posefilter/version.h — the version of this build of posefilter (CMake's PROJECT_VERSION,
// semantic versioning: MAJOR.MINOR.PATCH); the CLI prints it with the git
// revision for `posefilter --version`, Python has them as posefilter.__version__ and
// posefilter.__git_revision__.
#pragma once

namespace posefilter {

// "MAJOR.MINOR.PATCH", e.g. "0.1.0".
const char* Version();

// The commit this library was built from: 12 hex digits, with "-dirty" when tracked files
// differed from it at build time, or "unknown" for a build outside a git checkout.
const char* GitRevision();

}  // namespace posefilter
