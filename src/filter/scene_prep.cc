// src/filter/scene_prep.cc — support-plane removal and mask shift of the scored depth
// (scene_prep.h), and the prepared frame that shares the first between estimates
// (posefilter/prepared_frame.h).
#include "filter/scene_prep.h"

#include <algorithm>
#include <atomic>
#include <sstream>

#include "posefilter/error.h"
#include "posefilter/option_table.h"

namespace posefilter {
namespace {

std::atomic<std::uint64_t> frames_prepared{0};

}  // namespace

namespace filter {

PreparedScene FrameScene(const SceneInput& frame, bool support_plane) {
  PreparedScene p;
  p.scoring.camera = frame.camera;
  p.scoring.depth = frame.depth;
  std::vector<float>& z = p.scoring.depth.data;
  if (support_plane) {
    p.surfaces = FindSupportSurfaces(frame.depth, frame.camera);
    if (p.surfaces.supports > 0) p.plane = p.surfaces.patches[0].plane;
    const std::vector<int> on = SupportSurfacePixels(frame.depth, frame.camera, p.surfaces);
    p.removed_by.assign(z.size(), 0);
    for (std::size_t i = 0; i < z.size(); ++i)
      if (on[i] && z[i] > 0) {
        z[i] = 0;
        p.removed_by[i] = std::uint16_t(on[i]);  // FindSupportSurfaces keeps far fewer than 2^16 patches
        ++p.plane_pixels;
      }
  }
  p.valid_pixels = frame.depth.CountValid();
  p.support = p.scoring.depth;
  ++frames_prepared;
  return p;
}

PreparedScene WithObject(PreparedScene p, const std::vector<std::uint8_t>& mask, const std::vector<PoseSeed>& seeds,
                         const FilterOptions& options) {
  p.scoring.seeds = seeds;
  if (!mask.empty()) {
    std::vector<float>& z = p.scoring.depth.data;
    // Further than any inlier ramp (2·thr1 at the annealing's start) and the align and edge
    // bands reach: a fragment on a shifted pixel is never an inlier, never aligned to it.
    const double thr = std::max(options.anneal.start_m, double(options.score.inlier.thr1_m));
    p.mask_shift_m = 2 * std::max({2 * thr, options.diffusion.align_band_m, options.score.edge_band_m});
    for (std::size_t i = 0; i < z.size(); ++i) {
      if (mask[i]) continue;
      p.support.data[i] = 0;
      // A pixel nearer than the shift stays valid with a tiny depth: in front of everything.
      if (z[i] > 0) z[i] = std::max(z[i] - float(p.mask_shift_m), 1e-3f);
    }
  }
  return p;
}

std::vector<std::size_t> ThinRelief(const PreparedScene& frame, const DepthImage& depth, double thickness_m) {
  std::vector<std::size_t> out;
  if (!(thickness_m > 0 && thickness_m < kThinObjectM) || frame.removed_by.empty()) return out;
  const SupportSurfaceOptions opt;  // as FrameScene finds the surfaces
  const Camera& cam = frame.scoring.camera;
  for (int v = 0; v < depth.height; ++v)
    for (int u = 0; u < depth.width; ++u) {
      const std::size_t i = std::size_t(v) * depth.width + u;
      const int k = int(frame.removed_by[i]) - 1;
      if (k < 0 || k >= frame.surfaces.supports) continue;  // kept, or structure (a wall)
      const SupportSurface& s = frame.surfaces.patches[std::size_t(k)];
      const double z = depth.data[i];
      const double band = s.Band(z, opt);
      if (band <= 0.5 * thickness_m) continue;  // the object's relief there stands mostly out of the band
      if (s.plane.Height(cam.Backproject(u, v, z)) > std::max(opt.plane.min_band_m, 0.5 * band)) out.push_back(i);
    }
  return out;
}

namespace {

// Puts the pixels `back` of `depth` into p's scoring and support depths.
void PutBack(PreparedScene* p, const DepthImage& depth, const std::vector<std::size_t>& back) {
  for (std::size_t i : back) {
    p->scoring.depth.data[i] = p->support.data[i] = depth.data[i];
    p->removed_by[i] = 0;
  }
}

}  // namespace

std::shared_ptr<const PreparedScene> ForThickness(std::shared_ptr<const PreparedScene> frame, const DepthImage& depth,
                                                  double thickness_m) {
  const std::vector<std::size_t> back = ThinRelief(*frame, depth, thickness_m);
  if (back.empty()) return frame;
  auto p = std::make_shared<PreparedScene>(*frame);
  PutBack(p.get(), depth, back);
  return p;
}

PreparedScene PrepareScene(const SceneInput& scene, const FilterOptions& options, const std::string& what,
                           double thickness_m) {
  ValidateScene(scene, what);
  PreparedScene p = FrameScene(SceneInput{scene.depth, scene.camera}, options.support.plane);
  PutBack(&p, scene.depth, ThinRelief(p, scene.depth, thickness_m));
  return WithObject(std::move(p), scene.mask, scene.seeds, options);
}

std::shared_ptr<const PreparedScene> SceneFor(const PreparedFrame& frame, const ObjectInput& object,
                                              const FilterOptions& options, const std::string& what, double thickness_m) {
  ValidateObjectInput(object.mask, object.seeds, frame.frame().depth.data.size(), what);
  const bool same = frame.support_plane() == options.support.plane;
  std::shared_ptr<const PreparedScene> base =
      same ? frame.scene() : std::make_shared<const PreparedScene>(FrameScene(frame.frame(), options.support.plane));
  base = ForThickness(std::move(base), frame.frame().depth, thickness_m);
  if (object.mask.empty() && object.seeds.empty()) return base;
  return std::make_shared<const PreparedScene>(WithObject(*base, object.mask, object.seeds, options));
}

}  // namespace filter

PreparedFrame::PreparedFrame(SceneInput frame, bool support_plane, std::shared_ptr<const filter::PreparedScene> scene)
    : frame_(std::move(frame)), support_plane_(support_plane), scene_(std::move(scene)) {}

const SupportSurfaces& PreparedFrame::surfaces() const { return scene_->surfaces; }

std::shared_ptr<const PreparedFrame> PrepareFrame(const SceneInput& frame, const FilterOptions& options,
                                                  const std::string& what) {
  ThrowIfInvalid(options, OptionNaming::kField);
  if (!frame.mask.empty() || !frame.seeds.empty())
    throw Error(what + ": a prepared frame holds no mask and no seeds (they are an object's: ObjectInput)");
  ValidateScene(frame, what);
  SceneInput input{frame.depth, frame.camera};
  auto scene = std::make_shared<const filter::PreparedScene>(filter::FrameScene(input, options.support.plane));
  return std::make_shared<const PreparedFrame>(std::move(input), options.support.plane, std::move(scene));
}

std::uint64_t FramesPrepared() { return frames_prepared.load(); }

}  // namespace posefilter
