// posefilter/version.h — the version of this build of posefilter (CMake's PROJECT_VERSION,
// semantic versioning: MAJOR.MINOR.PATCH); the CLI prints it for `posefilter --version`, Python
// has it as posefilter.__version__.
#pragma once

namespace posefilter {

// "MAJOR.MINOR.PATCH", e.g. "0.1.0".
const char* Version();

}  // namespace posefilter
