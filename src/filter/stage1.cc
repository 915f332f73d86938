// filter/stage1.cc — the stage 1 of an estimate: prior, pose seeds and instance masks from what
// a front end gives (posefilter/stage1.h).
#include "posefilter/stage1.h"

#include "core/mesh_scale.h"
#include "core/option_check.h"
#include "posefilter/error.h"

namespace posefilter {

bool Stage1Options::IsValid(std::string* why) const {
  if (kind == Stage1Kind::kPyramid) {
    if (classes.empty()) return Fail(why, "a raw pyramid prior needs its class list (classes)");
    if (raw_pyramid.empty() && pyramid_path.empty())
      return Fail(why, "a raw pyramid prior needs raw_pyramid or pyramid_path");
  }
  if (kind == Stage1Kind::kAuto) {
    std::string p;
    if (!auto_prior.IsValid(&p)) return Fail(why, "auto_prior: " + p);
  }
  return true;
}

namespace {

// The class list of the prior: the caller's, else the objects' names and then the detections'
// other classes, each once.
std::vector<std::string> Stage1Classes(const Stage1Options& opt, const std::vector<std::string>& names,
                                       const std::vector<Detection>& detections) {
  return opt.classes.empty() ? ClassesForObjects(names, detections) : opt.classes;
}

PyramidLayout Stage1Layout(const Camera& camera, const std::vector<std::string>& classes) {
  return PyramidLayout::Thesis(camera.width, camera.height, int(classes.size()));
}

// kAuto: the objects' PPF models (the caller's, or loaded/built after every mesh's size is
// checked), ProposeAuto, and the prior of its detections.
void BuildAutoStage1(const SceneInput& scene, const std::vector<Stage1Object>& objects,
                     const std::vector<std::string>& names, const Stage1Options& opt, Stage1* out) {
  const bool load = opt.auto_ppf;  // models to load for the objects without one
  for (const Stage1Object& o : objects) {
    if (load && !o.ppf && !o.mesh)
      throw Error(opt.what + ": object '" + o.name + "' has neither a mesh nor a PPF model");
    // Wrong units fail before any table is built, and with the caller's model of such a mesh
    // (its diameter is the mesh's).
    if (load && o.mesh) CheckMeshScale(o.name, o.ppf ? o.ppf->diameter : o.mesh->Diameter(), scene.depth);
  }
  std::vector<PpfModel> loaded;
  loaded.reserve(objects.size());
  std::vector<const PpfModel*> ppf(objects.size(), nullptr);
  for (std::size_t k = 0; k < objects.size(); ++k) {
    std::string status;
    if (opt.auto_ppf && objects[k].ppf) {
      ppf[k] = objects[k].ppf;
    } else if (load) {
      loaded.push_back(LoadOrBuildPpfModel(*objects[k].mesh, opt.auto_prior.ppf, opt.cache_dir, &status));
      ppf[k] = &loaded.back();
    }
    out->cache_status.push_back(status);
  }
  std::vector<AutoObject> wanted;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Stage1Object& o = objects[k];
    double diameter = o.diameter_m;
    if (!(diameter > 0)) {
      if (ppf[k]) diameter = ppf[k]->diameter;
      else if (o.mesh) diameter = o.mesh->Diameter();
      else throw Error(opt.what + ": object '" + o.name + "' has no size (a mesh or diameter_m)");
    }
    wanted.push_back({o.name, diameter, ppf[k]});
  }
  AutoProposals proposals = ProposeAuto(scene.depth, scene.camera, wanted, opt.auto_prior);
  out->no_candidates = proposals.detections.empty();
  if (out->no_candidates && opt.require_candidates)
    throw Error(opt.what + ": no candidates: no region of the depth image stands above the support plane");
  const std::vector<std::string> classes = Stage1Classes(opt, names, {});
  out->prior = PriorFromDetections(proposals.detections, Stage1Layout(scene.camera, classes), classes);
  out->seeds = std::move(proposals.seeds);
}

}  // namespace

Stage1 BuildStage1(const SceneInput& scene, const std::vector<Stage1Object>& objects, const Stage1Options& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw Error(opt.what + ": invalid stage-1 options: " + why);
  std::vector<std::string> names;
  for (const Stage1Object& o : objects) {
    if (o.name.empty()) throw Error(opt.what + ": an object has no name");
    names.push_back(o.name);
  }
  const Camera& camera = scene.camera;
  Stage1 out;
  switch (opt.kind) {
    case Stage1Kind::kNone: {
      const std::vector<std::string> classes = Stage1Classes(opt, names, {});
      out.prior = UniformPrior(Stage1Layout(camera, classes), classes);
      break;
    }
    case Stage1Kind::kDetections: {
      if (opt.check_detections)
        out.warnings = CheckDetectionsForObjects(opt.detections, names, camera.width, camera.height, opt.what);
      const std::vector<std::string> classes = Stage1Classes(opt, names, opt.detections);
      out.prior = PriorFromDetections(opt.detections, Stage1Layout(camera, classes), classes);
      break;
    }
    case Stage1Kind::kPyramid: {
      const PyramidLayout layout = Stage1Layout(camera, opt.classes);
      out.prior = PostProcessPyramid(opt.raw_pyramid.empty() ? ReadRawPyramid(opt.pyramid_path, layout) : opt.raw_pyramid,
                                     layout, opt.classes);
      break;
    }
    case Stage1Kind::kAuto:
      BuildAutoStage1(scene, objects, names, opt, &out);
      break;
    case Stage1Kind::kMasks: {
      const std::vector<std::string> classes = Stage1Classes(opt, names, {});
      const PyramidLayout layout = Stage1Layout(camera, classes);
      for (std::size_t k = 0; k < objects.size(); ++k)
        for (const InstanceMask& m : opt.masks)
          if (m.cls == objects[k].name)
            out.instances.push_back({k, m.pixels, PriorFromDetections({MaskDetection(m)}, layout, classes)});
      break;
    }
  }
  out.seeds.resize(objects.size());
  return out;
}

}  // namespace posefilter
