// core/mesh_scale.cc — mesh units against the scene's depth (mesh_scale.h).
#include "core/mesh_scale.h"

#include <algorithm>
#include <sstream>
#include <vector>

#include "posefilter/error.h"

namespace posefilter {

double MedianValidDepth(const DepthImage& d) {
  std::vector<float> z;
  z.reserve(d.data.size());
  for (float v : d.data)
    if (v > 0) z.push_back(v);
  if (z.empty()) return 0;
  auto mid = z.begin() + std::ptrdiff_t(z.size() / 2);
  std::nth_element(z.begin(), mid, z.end());
  return *mid;
}

bool MedianValidDepthWithin(const DepthImage& d, double lo, double hi) {
  std::size_t valid = 0, below = 0, above = 0;
  for (float v : d.data) {
    if (!(v > 0)) continue;
    ++valid;
    below += double(v) < lo;
    above += double(v) > hi;
  }
  return valid > 0 && below <= valid / 2 && above <= valid - 1 - valid / 2;
}

void CheckMeshScale(const std::string& mesh_name, double diameter, const DepthImage& support) {
  constexpr double kMinObjectToDepth = 1e-3, kMaxObjectToDepth = 10;
  // Accepted: a median depth of diameter / 10 to diameter / 0.001 (the common case, decided in
  // one pass); the median itself is found only for the message.
  if (MedianValidDepthWithin(support, diameter / kMaxObjectToDepth, diameter / kMinObjectToDepth)) return;
  const double median_depth = MedianValidDepth(support);
  if (median_depth <= 0) return;
  if (diameter >= kMinObjectToDepth * median_depth && diameter <= kMaxObjectToDepth * median_depth) return;
  std::ostringstream os;
  os << "mesh '" << mesh_name << "' is " << diameter << " m across, implausible in a scene whose median depth is "
     << median_depth << " m (objects of " << kMinObjectToDepth * median_depth << " to "
     << kMaxObjectToDepth * median_depth
     << " m are accepted): are the mesh units right? (the unit scale, --unit-scale: 0.001 for a millimetre mesh, 1 for "
        "metres)";
  throw Error(os.str());
}

}  // namespace posefilter
