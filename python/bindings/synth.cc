// python/bindings/synth.cc — synthetic scenes: make_synth_scene and SynthScene.
#include "bindings.h"

namespace posefilter::python {

// SynthOptions from keywords (skipping `skip`); the target mesh, if any, is kept in *target_mesh.
SynthOptions SynthOptionsFrom(const py::kwargs& kw, const std::string& what, std::set<std::string> skip, Mesh* target_mesh) {
  SynthOptions opt;
  skip.insert("target_mesh");
  ApplyKeywords(&opt, kw, SynthKeywords(), what, skip);
  const py::object tm = kw.contains("target_mesh") ? py::object(kw["target_mesh"]) : py::object(py::none());
  if (!tm.is_none()) {
    if (!py::isinstance<Mesh>(tm)) throw py::type_error(what + ": target_mesh must be a Mesh");
    *target_mesh = tm.cast<Mesh>();
    opt.target_mesh = target_mesh;
  }
  std::string why;
  if (!opt.IsValid(&why)) Fail(what + ": invalid option: " + why);
  return opt;
}

SynthScene MakeScene(std::uint64_t seed, const py::kwargs& kw) {
  Mesh target_mesh;
  const SynthOptions opt = SynthOptionsFrom(kw, "make_synth_scene", {}, &target_mesh);
  py::gil_scoped_release release;
  return MakeSynthScene(opt, seed);
}

std::vector<SynthScene> MakeSequence(int frames, std::uint64_t seed, double speed, double turn, int jump_frame, double jump,
                                     const py::kwargs& kw) {
  Mesh target_mesh;
  const SynthOptions opt = SynthOptionsFrom(kw, "make_synth_sequence", {}, &target_mesh);
  const SynthMotion motion{frames, speed, turn, jump_frame, jump};
  std::string why;
  if (!motion.IsValid(&why)) Fail("make_synth_sequence: invalid motion: " + why);
  py::gil_scoped_release release;
  return MakeSynthSequence(opt, motion, seed);
}


void BindSynth(py::module_& m) {
  // ---- Synthetic scenes
  py::class_<SynthScene>(m, "SynthScene", "A synthetic scene with ground truth and a stage-1 prior.")
      .def_property_readonly("depth", [](const SynthScene& s) { return ToNumpy(s.depth); }, "H x W float32 metres")
      .def_readonly("camera", &SynthScene::camera)
      .def_readonly("depth_scale", &SynthScene::depth_scale)
      .def_property_readonly("labels", [](const SynthScene& s) {
        py::array_t<std::int32_t> out({py::ssize_t(s.depth.height), py::ssize_t(s.depth.width)});
        std::int32_t* o = out.mutable_data();
        for (std::size_t i = 0; i < s.labels.size(); ++i) o[i] = s.labels[i];
        return out;
      }, "H x W int32: 0 background/table, 1 target, 2 occluder, 3.. clutter")
      .def_property_readonly("gt_poses", [](const SynthScene& s) {
        std::vector<Eigen::Isometry3d> Ts;
        for (const auto& g : s.gt) Ts.push_back(g.T_cam_obj);
        return StackPoses(Ts);
      }, "N x 4 x 4 ground-truth T_cam_obj")
      .def_property_readonly("gt_objs", [](const SynthScene& s) {
        std::vector<std::string> o;
        for (const auto& g : s.gt) o.push_back(g.obj);
        return o;
      })
      .def_readonly("target", &SynthScene::target)
      .def_readonly("classes", &SynthScene::classes)
      .def_readonly("detections", &SynthScene::detections)
      .def_readonly("layout", &SynthScene::layout)
      .def_property_readonly("raw_pyramid", [](const SynthScene& s) {
        return py::array_t<float>(py::ssize_t(s.raw_pyramid.size()), s.raw_pyramid.data());
      })
      .def_property_readonly("prior", [](const SynthScene& s) { return PostProcessPyramid(s.raw_pyramid, s.layout, s.classes); },
                             "PostProcessPyramid of raw_pyramid (a new Prior each access)")
      .def_property_readonly("gt_box", [](const SynthScene& s) { return BoxTuple(s.gt_box); })
      .def_readonly("distance_m", &SynthScene::distance_m)
      .def_readonly("table_angle_rad", &SynthScene::table_angle_rad)
      .def_readonly("occlusion_achieved", &SynthScene::occlusion_achieved)
      .def_readonly("target_detected", &SynthScene::target_detected)
      .def("write", [](const SynthScene& s, const std::string& dir) { WriteSynthScene(s, dir); }, "dir"_a,
           "Writes depth.png, camera.json, gt.json, the mesh, detections.json, prior.pyr, ... to dir.")
      .def("__repr__", [](const SynthScene& s) {
        std::ostringstream os;
        os << "SynthScene(target='" << s.target.name << "', distance_m=" << s.distance_m
           << ", occlusion_achieved=" << s.occlusion_achieved << ", " << s.detections.size() << " detections)";
        return os.str();
      });
  static const std::string scene_doc =
      "Synthetic table-top scene (deterministic per seed). Keywords = SynthOptions fields (ranges and units: "
      "docs/OPTIONS.md, 'Synthetic scenes'): " +
      KeywordList(SynthKeywords()) + ", target_mesh.";
  m.def("make_synth_scene", &MakeScene, "seed"_a = 0, scene_doc.c_str());
  m.def("make_synth_sequence", &MakeSequence, "frames"_a = 10, "seed"_a = 0, py::kw_only(), "speed"_a = 0.01,
        "turn"_a = 0.05, "jump_frame"_a = -1, "jump"_a = 0.0,
        "A synthetic sequence (list of SynthScene, frame 0 = make_synth_scene(seed)): the target slides `speed` m "
        "per frame along the table and turns `turn` rad per frame about its normal; from jump_frame on it is also "
        "displaced by `jump` m. Other keywords as make_synth_scene (occlusion must be 0).");
  m.def("write_synth_sequence", [](const std::vector<SynthScene>& frames, const std::string& dir, const std::string& name) {
    WriteSynthSequence(frames, dir, name);
  }, "frames"_a, "dir"_a, "name"_a = "synth",
        "Writes the frames as a YCB-Video-style dataset folder (dir/models/, dir/scenes/<name>_0000_<frame>/) for "
        "`posefilter track` and `run-dataset`.");
  m.def("synth_option_names", [] {
    std::vector<std::string> n = KeywordNames(SynthKeywords());
    n.push_back("target_mesh");
    return n;
  });
}

}  // namespace posefilter::python
