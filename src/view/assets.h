// src/view/assets.h — the scripts the viewer's page inlines (internal).
//
// Both are embedded at build time (CMakeLists.txt, cmake/embed_file.cmake): three.js from
// Debian's libjs-three and the viewer's own script, src/view/viewer.js. In a build configured
// without libjs-three (src/view/no_three/assets_none.cc) both are empty and the viewer
// reports that it is missing.
#pragma once

#include <string_view>

namespace posefilter::view {

std::string_view ThreeJs();   // three.min.js (defines the global THREE)
std::string_view ViewerJs();  // src/view/viewer.js

}  // namespace posefilter::view
