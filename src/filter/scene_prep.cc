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
    p.surfaces = FindSupportSurfaces(scene.depth, scene.camera);
    if (p.surfaces.supports > 0) p.plane = p.surfaces.patches[0].plane;
    const std::vector<int> on = SupportSurfacePixels(scene.depth, scene.camera, p.surfaces);
    for (std::size_t i = 0; i < z.size(); ++i)
      if (on[i] && z[i] > 0) {
        z[i] = 0;
        ++p.plane_pixels;
      }
  }
  p.valid_pixels = scene.depth.CountValid();
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

}  // namespace posefilter::filter
