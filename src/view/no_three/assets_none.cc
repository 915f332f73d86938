// src/view/no_three/assets_none.cc — the viewer's assets in a build configured without
// libjs-three: none (ViewerAvailable() is false; `posefilter view` says so).
#include "view/assets.h"

namespace posefilter::view {

std::string_view ThreeJs() { return {}; }
std::string_view ViewerJs() { return {}; }

}  // namespace posefilter::view
