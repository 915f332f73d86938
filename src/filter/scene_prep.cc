// src/filter/scene_prep.cc — support-plane removal and mask shift of the scored depth
// (scene_prep.h).
#include "filter/scene_prep.h"

#include <algorithm>
#include <sstream>

#include "posefilter/error.h"

namespace posefilter::filter {

PreparedScene PrepareScene(const SceneInput& scene, const FilterOptions& options, const std::string& what) {
  ValidateScene(scene, what);
  PreparedScene p;
  p.scoring.camera = scene.camera;
  p.scoring.depth = scene.depth;
  p.scoring.seeds = scene.seeds;
  std::vector<float>& z = p.scoring.depth.data;
  if (options.support.plane) {
    p.plane = FindSupportPlane(scene.depth, scene.camera);
    const std::vector<std::uint8_t> on = SupportPlanePixels(scene.depth, scene.camera, p.plane);
    for (std::size_t i = 0; i < z.size(); ++i)
      if (on[i]) z[i] = 0;
  }
  p.support = p.scoring.depth;
  if (!scene.mask.empty()) {
    // Further than any inlier ramp (2·thr1 at the annealing's start) and the align and edge
    // bands reach: a fragment on a shifted pixel is never an inlier, never aligned to it.
    const double thr = std::max(options.anneal.start_m, double(options.score.inlier.thr1_m));
    p.mask_shift_m = 2 * std::max({2 * thr, options.diffusion.align_band_m, options.score.edge_band_m});
    for (std::size_t i = 0; i < z.size(); ++i) {
      if (scene.mask[i]) continue;
      p.support.data[i] = 0;
      // A pixel nearer than the shift stays valid with a tiny depth: in front of everything.
      if (z[i] > 0) z[i] = std::max(z[i] - float(p.mask_shift_m), 1e-3f);
    }
  }
  return p;
}

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

void CheckMeshScale(const std::string& mesh_name, double diameter, const DepthImage& support) {
  constexpr double kMinObjectToDepth = 1e-3, kMaxObjectToDepth = 10;
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

}  // namespace posefilter::filter
