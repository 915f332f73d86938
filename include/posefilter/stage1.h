// posefilter/stage1.h — the stage 1 of an estimate, in one place: from what a front end gives
// (nothing, detections, a raw pyramid, instance masks, or the depth alone: `--prior auto`) to
// what the filter takes — the prior, each object's pose seeds, and with masks one prior and
// mask per instance.
//
//   kind         the prior                                          per object / instance
//   kNone        UniformPrior                                       —
//   kDetections  PriorFromDetections(detections)                    —
//   kPyramid     PostProcessPyramid(raw pyramid)                    —
//   kAuto        PriorFromDetections(ProposeAuto's detections)      pose seeds (auto_prior.h)
//   kMasks       —                                                  per instance of an object's
//                                                                   class: its pixels and the
//                                                                   prior of its box (mask_prior.h)
//
// Every prior is on the thesis pyramid over the camera's image (PyramidLayout::Thesis). Its
// classes are Stage1Options::classes when given (a dataset's or world's full class list), else
// the objects' names, each once, then (kDetections) the detections' other classes
// (ClassesForObjects). Units: metres, pixels. Deterministic.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "posefilter/auto_prior.h"
#include "posefilter/filter.h"
#include "posefilter/mask_prior.h"
#include "posefilter/mesh.h"
#include "posefilter/ppf.h"
#include "posefilter/prior.h"

namespace posefilter {

enum class Stage1Kind { kNone, kDetections, kPyramid, kAuto, kMasks };

// One object the stage 1 is made for.
struct Stage1Object {
  std::string name;               // its class in the prior (and the class of its masks)
  // kAuto: the mesh (metres) whose PPF model is loaded or built when `ppf` is null; its size
  // (with `ppf`: the model's diameter) is checked against the scene's depth first (a unit
  // mistake names the object).
  const Mesh* mesh = nullptr;
  // kAuto: the object's PPF model, made by the caller (LoadOrBuildPpfModel; kept across
  // frames); null: loaded from Stage1Options::cache_dir or built.
  const PpfModel* ppf = nullptr;
  // kAuto: the object's size for the region boxes, metres; 0 = the PPF model's diameter (with
  // auto_ppf off: the mesh's, Mesh::Diameter).
  double diameter_m = 0;
};

struct Stage1Options {
  Stage1Kind kind = Stage1Kind::kNone;
  // The prior's classes (see above); empty = from the objects (and detections). Required for
  // kPyramid (the pyramid's class logits, in order).
  std::vector<std::string> classes;
  // Names the source in errors and warnings: the file or option ("--prior auto", a JSON path).
  std::string what = "prior";
  // kDetections: the detections (class, score, box in pixels).
  std::vector<Detection> detections;
  // kDetections: check them against the objects first (CheckDetectionsForObjects: an Error
  // when no object has one on the image, a warning per box off the image and per object
  // without one, into Stage1::warnings).
  bool check_detections = false;
  // kPyramid: the raw pyramid's values (PostProcessPyramid's layout over the thesis pyramid
  // with `classes`), or, when empty, the raw pyramid file read from pyramid_path.
  std::vector<float> raw_pyramid;
  std::string pyramid_path;
  // kMasks: the instances (MasksFromLabels); each one of an object's class is an instance.
  std::vector<InstanceMask> masks;
  // kAuto: the stage 1's options; its PPF proposals (step 5) are made with auto_ppf on
  // (off: regions only, steps 1–4); the PPF models' cache folder ("" = no cache); whether a
  // scene with no candidate region is an Error ("<what>: no candidates: …") or a uniform-floor
  // prior with Stage1::no_candidates set.
  AutoPriorOptions auto_prior;
  bool auto_ppf = true;
  std::string cache_dir;
  bool require_candidates = true;
  // True when the fields of `kind` are set as above (a pyramid's classes, its values or path,
  // valid auto_prior options); *why (optional) says what is wrong.
  bool IsValid(std::string* why) const;
};

// One estimate of kMasks: an instance of objects[object]'s class.
struct Stage1Instance {
  std::size_t object = 0;              // index into the objects
  std::vector<std::uint8_t> mask;      // width × height, 1 on the instance (SceneInput::mask)
  Prior prior;                         // the prior of its box alone (MaskDetection)
};

struct Stage1 {
  Prior prior;                                 // the objects' shared prior (unset for kMasks)
  std::vector<std::vector<PoseSeed>> seeds;    // per object, in the objects' order (kAuto; else empty lists)
  std::vector<Stage1Instance> instances;       // kMasks: by object, then by mask id; an object of
                                               // no instance has none (the caller decides)
  std::vector<std::string> warnings;           // check_detections' warnings, each starting with `what`
  std::vector<std::string> cache_status;       // kAuto: per object, LoadOrBuildPpfModel's status ("" for a given model)
  bool no_candidates = false;                  // kAuto: no region stood above the support
};

// Makes the stage 1 of `objects` (their names are the prior's classes unless options.classes
// gives them) on `scene`'s depth and camera.
// Throws Error on invalid options, an object without a name (or, for kAuto, without a mesh
// where it needs one), and the errors of the functions above, naming options.what.
Stage1 BuildStage1(const SceneInput& scene, const std::vector<Stage1Object>& objects, const Stage1Options& options);

}  // namespace posefilter
