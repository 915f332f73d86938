// src/filter/scene_pass.cc — RunScenePass (posefilter/scene_pass.h): the per-object estimates
// settled best first against a z-buffer of the objects settled before them.
#include "posefilter/scene_pass.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>

#include "filter/scene_prep.h"
#include "posefilter/error.h"
#include "posefilter/option_table.h"
#include "posefilter/prepared_frame.h"
#include "posefilter/render.h"

namespace posefilter {
namespace {

// The objects settled so far, in their order, rendered with one z-buffer: the pixels they
// explain (mask 0: the nearest settled surface lies within band_m of the measured depth) and
// which of them explained each pixel first (owner, −1 = none).
class Settled {
 public:
  Settled(const DepthImage& z, const Camera& cam, double band_m)
      : z_(z), cam_(cam), band_m_(band_m), depth_(cam.width, cam.height, 0.f),
        free_{std::vector<std::uint8_t>(z.data.size(), 1)}, owner_(z.data.size(), -1) {}
  // Whether rendered depth `rendered` (metres, 0 = empty) explains pixel p's measured depth.
  bool Explains(float rendered, std::size_t p) const {
    return rendered > 0 && z_.data[p] > 0 && std::fabs(rendered - z_.data[p]) < band_m_;
  }
  // Settles object k (its mesh at T_cam_obj): its surface takes the free pixels it explains.
  void Add(std::size_t k, const Mesh& mesh, const Eigen::Isometry3d& T_cam_obj) {
    order_.push_back({k, &mesh, T_cam_obj});
    Render(order_.back());
  }
  // Unsettles object k: the others are settled again from nothing, in their order.
  void Remove(std::size_t k) {
    order_.erase(std::find_if(order_.begin(), order_.end(), [&](const Entry& e) { return e.k == k; }));
    std::fill(depth_.data.begin(), depth_.data.end(), 0.f);
    std::fill(free_.mask.begin(), free_.mask.end(), std::uint8_t{1});
    std::fill(owner_.begin(), owner_.end(), -1);
    for (const Entry& e : order_) Render(e);
  }
  const ObjectInput& Free() const { return free_; }
  bool AnyFree() const { return std::find(free_.mask.begin(), free_.mask.end(), 1) != free_.mask.end(); }
  int Owner(std::size_t p) const { return owner_[p]; }

 private:
  struct Entry {
    std::size_t k;
    const Mesh* mesh;
    Eigen::Isometry3d T_cam_obj;
  };
  void Render(const Entry& e) {
    RenderDepth(*e.mesh, e.T_cam_obj, cam_, &depth_);
    for (std::size_t p = 0; p < depth_.data.size(); ++p)
      if (free_.mask[p] && Explains(depth_.data[p], p)) {
        free_.mask[p] = 0;
        owner_[p] = int(e.k);
      }
  }
  const DepthImage& z_;
  const Camera& cam_;
  double band_m_;
  DepthImage depth_;
  ObjectInput free_;
  std::vector<int> owner_;
  std::vector<Entry> order_;
};

}  // namespace

std::vector<ScenePassResult> RunScenePass(const SceneInput& scene, const Prior& prior, const std::vector<SceneObject>& objects,
                                          const FilterOptions& options, const ScenePassOptions& pass) {
  std::string why;
  if (!pass.IsValid(&why)) throw Error("invalid scene pass option: " + why);
  ThrowIfInvalid(options, OptionNaming::kField);
  ValidateScene(scene, "scene pass");
  if (!scene.mask.empty() || !scene.seeds.empty()) throw Error("scene pass: the scene must hold no mask and no seeds");
  // The frame prepared once for every weighing and re-estimate (checked above).
  SceneInput input{scene.depth, scene.camera};
  auto prep = std::make_shared<const filter::PreparedScene>(filter::FrameScene(input, options.support.plane));
  return RunScenePass(PreparedFrame(std::move(input), options.support.plane, std::move(prep)), prior, objects, options,
                      pass);
}

std::vector<ScenePassResult> RunScenePass(const PreparedFrame& frame, const Prior& prior,
                                          const std::vector<SceneObject>& objects, const FilterOptions& options,
                                          const ScenePassOptions& pass) {
  using Clock = std::chrono::steady_clock;
  std::string why;
  if (!pass.IsValid(&why)) throw Error("invalid scene pass option: " + why);
  ThrowIfInvalid(options, OptionNaming::kField);
  const SceneInput& scene = frame.frame();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (!objects[i].mesh) throw Error("scene pass: object " + std::to_string(i) + " has no mesh");
    if (objects[i].cls < 0 || objects[i].cls >= int(prior.classes.size()))
      throw Error("scene pass: object " + std::to_string(i) + "'s class index is out of range");
  }
  const Camera& cam = scene.camera;
  const DepthImage& z = scene.depth;
  std::vector<std::size_t> order(objects.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return objects[a].estimate.weight > objects[b].estimate.weight; });

  Settled settled(z, cam, pass.band_m);
  std::vector<ScenePassResult> out(objects.size());
  // The caller's prepared model of object k, or its mesh prepared for each call.
  auto weigh_of = [&](std::size_t k, const ObjectInput& in, const std::vector<std::pair<Pose6, int>>& poses) {
    const SceneObject& o = objects[k];
    return o.model ? WeighPoses(frame, in, *o.model, prior, o.cls, options, poses)[0]
                   : WeighPoses(frame, in, *o.mesh, prior, o.cls, options, poses)[0];
  };
  // Object k estimated again on `in` (the same options, a seed derived from its index); false
  // where no cell of its class holds free depth.
  auto reestimate = [&](std::size_t k, const ObjectInput& in, EstimateResult* e) {
    FilterOptions o = options;
    o.seed = options.seed ^ (0x9E3779B97F4A7C15ull * (k + 1));
    try {
      *e = objects[k].model ? EstimatePose(frame, in, *objects[k].model, prior, objects[k].cls, o)
                            : EstimatePose(frame, in, *objects[k].mesh, prior, objects[k].cls, o);
    } catch (const Error&) {
      return false;
    }
    return true;
  };
  // With a level of detail by size (render.lod_face_px) an estimate weighed its mesh at its most
  // probable cell's stride; every pose below is weighed at the stride of its own depth instead,
  // so that each comparison weighs one mesh.
  const bool by_size = options.render.lod_face_px > 0;
  std::vector<bool> yielded(objects.size(), false);
  for (std::size_t idx : order) {
    const auto t0 = Clock::now();
    const SceneObject& obj = objects[idx];
    ScenePassResult& r = out[idx];
    r.estimate = obj.estimate;
    const std::vector<std::pair<Pose6, int>> hyp = {{obj.estimate.pose_base, obj.estimate.cell}};
    auto weigh = [&](const ObjectInput& in, const std::vector<std::pair<Pose6, int>>& poses) {
      return weigh_of(idx, in, poses);
    };
    r.weight_alone = by_size ? weigh(ObjectInput{}, hyp) : obj.estimate.weight;
    const bool any_free = settled.AnyFree();
    r.weight_masked = !any_free ? 0.0 : weigh(settled.Free(), hyp);
    const double drop = r.weight_alone - r.weight_masked;
    bool settled_here = false;
    if (any_free && drop > pass.conflict_drop) {
      // Better estimates explain this one's pixels. The settled object that explains most of
      // them (the claimant) yields instead where it lies on this object more than this object
      // lies on it: the claimant's weight without this pose's explained pixels falls by more
      // than this object's fell.
      DepthImage alone(cam.width, cam.height, 0.f);
      RenderDepth(*obj.mesh, obj.estimate.T_cam_obj, cam, &alone);
      std::vector<std::size_t> claimed(objects.size(), 0);
      for (std::size_t p = 0; p < alone.data.size(); ++p)
        if (settled.Owner(p) >= 0 && settled.Explains(alone.data[p], p)) ++claimed[std::size_t(settled.Owner(p))];
      const auto most = std::max_element(claimed.begin(), claimed.end());
      const std::size_t a = std::size_t(most - claimed.begin());
      if (*most > 0 && !yielded[a]) {
        // The claimant's masks: the pixels no other settled object explains, with and without
        // this pose's explained pixels.
        ObjectInput with{std::vector<std::uint8_t>(z.data.size(), 0)};
        ObjectInput without = with;
        for (std::size_t p = 0; p < z.data.size(); ++p) {
          with.mask[p] = settled.Owner(p) < 0 || settled.Owner(p) == int(a) ? 1 : 0;
          without.mask[p] = with.mask[p] && !settled.Explains(alone.data[p], p) ? 1 : 0;
        }
        const std::vector<std::pair<Pose6, int>> hyp_a = {{out[a].estimate.pose_base, out[a].estimate.cell}};
        const double a_without = weigh_of(a, without, hyp_a);
        const double a_drop = weigh_of(a, with, hyp_a) - a_without;
        EstimateResult e;
        if (a_drop > drop && reestimate(a, without, &e)) {
          const double e_weight = by_size ? weigh_of(a, without, {{e.pose_base, e.cell}}) : e.weight;
          if (e_weight > a_without) {
            // The claimant moves, and settles after this object, which keeps its pose.
            yielded[a] = true;
            out[a].reestimated = true;
            out[a].replaced = true;
            out[a].estimate = e;
            out[a].estimate.obj = objects[a].estimate.obj;
            out[a].weight_masked = e_weight;
            settled.Remove(a);
            r.weight_masked = weigh(settled.Free(), hyp);
            settled.Add(idx, *obj.mesh, r.estimate.T_cam_obj);
            settled.Add(a, *objects[a].mesh, e.T_cam_obj);
            settled_here = true;
          }
        }
      }
      if (!settled_here) {
        // Look again where the better estimates leave room.
        r.reestimated = true;
        EstimateResult e;
        if (reestimate(idx, settled.Free(), &e)) {
          const double e_weight = by_size ? weigh(settled.Free(), {{e.pose_base, e.cell}}) : e.weight;
          if (e_weight > r.weight_masked) {
            r.estimate = e;
            r.weight_masked = e_weight;
            r.replaced = true;
          }
        }
        r.estimate.obj = obj.estimate.obj;
      }
    }
    if (!settled_here) settled.Add(idx, *obj.mesh, r.estimate.T_cam_obj);
    r.time_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }
  return out;
}

}  // namespace posefilter
