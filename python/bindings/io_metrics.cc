// python/bindings/io_metrics.cc — bindings of the depth/image files, overlays and renderings, the JSON files and the pose metrics.
#include "bindings.h"

namespace posefilter::python {

void BindIoAndMetrics(py::module_& m) {
  // ---- Depth and images
  m.def("load_depth_png", [](const std::string& path, double depth_scale) { return ToNumpy(LoadDepthPng(path, depth_scale)); },
        "path"_a, "depth_scale"_a, "16-bit PNG → H x W float32 metres (value × depth_scale; 0 = missing).");
  m.def("save_depth_png", [](py::handle depth, const std::string& path, double depth_scale) {
    SaveDepthPng(DepthFrom(depth, std::nullopt, nullptr, "depth"), path, depth_scale);
  }, "depth"_a, "path"_a, "depth_scale"_a, "H x W metres → 16-bit PNG, value = round(metres / depth_scale).");
  m.def("load_rgb_png", [](const std::string& path) { return ToNumpy(LoadRgbPng(path)); }, "path"_a);
  m.def("save_rgb_png", [](py::handle img, const std::string& path) { SaveRgbPng(RgbFrom(img, "image"), path); },
        "image"_a, "path"_a);
  m.def("shade_depth", [](py::handle depth) { return ToNumpy(ShadeDepth(DepthFrom(depth, std::nullopt, nullptr, "depth"))); },
        "depth"_a, "Grey shading (H x W x 3 uint8): near bright, far dark, missing black.");
  m.def("draw_pose_overlay", [](py::handle image, const Mesh& mesh, py::handle T, const Camera& camera,
                                std::array<std::uint8_t, 3> color) {
    RgbImage img = RgbFrom(image, "image");
    CheckedCamera(camera, "camera");
    if (img.width != camera.width || img.height != camera.height) Fail("image: size differs from the camera's");
    DrawPoseOverlay(&img, mesh, TransformFrom(T, "T_cam_obj"), camera, color);
    return ToNumpy(img);
  }, "image"_a, "mesh"_a, "T_cam_obj"_a, "camera"_a, "color"_a = kEstimateColor,
        "A copy of image with mesh drawn at T_cam_obj: tinted silhouette and outline in color.");
  m.def("draw_legend", [](py::handle image, const std::vector<std::pair<std::string, std::array<std::uint8_t, 3>>>& entries) {
    RgbImage img = RgbFrom(image, "image");
    std::vector<LegendEntry> legend;
    for (const auto& [text, color] : entries) legend.push_back({text, color});
    DrawLegend(&img, legend);
    return ToNumpy(img);
  }, "image"_a, "entries"_a,
        "A copy of image with a legend in its top-left corner: one (text, (r, g, b)) entry per line, a swatch of "
        "the colour and the text.");
  m.def("render_depth", [](const Mesh& mesh, py::handle T, const Camera& camera, py::handle depth) {
    CheckedCamera(camera, "camera");
    DepthImage d = depth.is_none() ? DepthImage(camera.width, camera.height) : DepthFrom(depth, std::nullopt, &camera, "depth");
    const Eigen::Isometry3d T_cam_obj = TransformFrom(T, "T_cam_obj");
    std::vector<int> labels(std::size_t(camera.width) * camera.height, 0);
    RenderDepth(mesh, T_cam_obj, camera, &d, &labels, 1);
    py::array_t<bool> mask({py::ssize_t(camera.height), py::ssize_t(camera.width)});
    bool* mk = mask.mutable_data();
    for (std::size_t i = 0; i < labels.size(); ++i) mk[i] = labels[i] == 1;
    return py::make_tuple(ToNumpy(d), mask);
  }, "mesh"_a, "T_cam_obj"_a, "camera"_a, "depth"_a = py::none(),
        "Renders mesh over depth (default empty) with a z-test: (depth H x W float32, mask of the pixels it won).");
  m.def("projected_box", [](const Mesh& mesh, py::handle T, const Camera& camera) {
    return BoxTuple(ProjectedBox(mesh, TransformFrom(T, "T_cam_obj"), camera));
  }, "mesh"_a, "T_cam_obj"_a, "camera"_a, "Bounding box (cx, cy, w, h) of the rendered silhouette, pixels (w = h = 0: not visible).");

  // ---- JSON files
  m.def("read_camera_json", [](const std::string& path) {
    const CameraFile f = ReadCameraJson(path);
    return py::make_tuple(f.camera, f.depth_scale);
  }, "path"_a, "→ (Camera, depth_scale).");
  m.def("write_camera_json", [](const Camera& c, const std::string& path, double depth_scale) {
    WriteCameraJson(CameraFile{c, depth_scale}, path);
  }, "camera"_a, "path"_a, "depth_scale"_a);
  m.def("read_gt_json", [](const std::string& path) {
    py::list out;
    for (const auto& g : ReadGtJson(path)) out.append(py::make_tuple(g.obj, ToNumpy(g.T_cam_obj)));
    return out;
  }, "path"_a, "→ [(obj, T_cam_obj 4x4)].");
  m.def("write_gt_json", [](py::handle objects, const std::string& path) {
    std::vector<GtObject> gt;
    for (py::handle o : objects) {
      if (!py::isinstance<py::sequence>(o) || py::isinstance<py::str>(o) || py::len(o) != 2 ||
          !py::isinstance<py::str>(o[py::int_(0)]))
        Fail("write_gt_json: expected (obj, T_cam_obj) pairs");
      gt.push_back({o[py::int_(0)].cast<std::string>(), TransformFrom(o[py::int_(1)], "T_cam_obj")});
    }
    WriteGtJson(gt, path);
  }, "objects"_a, "path"_a);
  m.def("read_results_json", [](const std::string& path) {
    py::list out;
    for (const auto& r : ReadResultsJson(path))
      out.append(py::dict("obj"_a = r.obj, "pose6"_a = ToNumpy(r.pose_base), "T_cam_obj"_a = ToNumpy(r.T_cam_obj),
                          "weight"_a = r.weight, "iterations"_a = r.iterations, "time_ms"_a = r.time_ms));
    return out;
  }, "path"_a, "results.json of `posefilter estimate` → list of dicts (obj, pose6, T_cam_obj, weight, iterations, time_ms).");

  // ---- Metrics
  py::class_<PoseErrors>(m, "PoseErrors", "Errors of one estimate (metres, degrees).")
      .def_readonly("add", &PoseErrors::add)
      .def_readonly("adds", &PoseErrors::adds)
      .def_readonly("rot_deg", &PoseErrors::rot_deg)
      .def_readonly("trans_m", &PoseErrors::trans_m)
      .def_readonly("diameter", &PoseErrors::diameter)
      .def_readonly("add_ok", &PoseErrors::add_ok)
      .def_readonly("adds_ok", &PoseErrors::adds_ok)
      .def("__repr__", [](const PoseErrors& e) {
        std::ostringstream os;
        os << std::boolalpha << "PoseErrors(add=" << e.add << ", adds=" << e.adds << ", rot_deg=" << e.rot_deg << ", trans_m=" << e.trans_m
           << ", diameter=" << e.diameter << ", add_ok=" << e.add_ok << ", adds_ok=" << e.adds_ok << ")";
        return os.str();
      });
  auto model_points = [](py::handle model) {
    return py::isinstance<Mesh>(model) ? SamplePoints(model.cast<const Mesh&>()) : PointsFrom(model, "points");
  };
  m.def("add_error", [model_points](py::handle model, py::handle Te, py::handle Tg) {
    return AddError(model_points(model), TransformFrom(Te, "T_est"), TransformFrom(Tg, "T_gt"));
  }, "model"_a, "T_est"_a, "T_gt"_a, "ADD, metres; model = Mesh (its sampled vertices) or N x 3 points.");
  m.def("adds_error", [model_points](py::handle model, py::handle Te, py::handle Tg) {
    return AddSError(model_points(model), TransformFrom(Te, "T_est"), TransformFrom(Tg, "T_gt"));
  }, "model"_a, "T_est"_a, "T_gt"_a, "ADD-S, metres.");
  m.def("rotation_error_deg", [](py::handle Re, py::handle Rg) {
    return RotationErrorDeg(Matrix3From(Re, "R_est"), Matrix3From(Rg, "R_gt"));
  }, "R_est"_a, "R_gt"_a);
  m.def("translation_error", [](py::handle te, py::handle tg) {
    return TranslationError(Vector3From(te, "t_est"), Vector3From(tg, "t_gt"));
  }, "t_est"_a, "t_gt"_a, "metres");
  m.def("pose_errors", [model_points](py::handle model, py::handle Te, py::handle Tg, double threshold, std::optional<double> diameter) {
    if (!diameter) {
      if (!py::isinstance<Mesh>(model)) Fail("pose_errors: give diameter= (metres) with a point array");
      diameter = model.cast<const Mesh&>().Diameter();
    }
    return ComputePoseErrors(model_points(model), *diameter, TransformFrom(Te, "T_est"), TransformFrom(Tg, "T_gt"), threshold);
  }, "model"_a, "T_est"_a, "T_gt"_a, "threshold"_a = 0.1, "diameter"_a = py::none(),
        "ADD, ADD-S, rotation/translation errors; ok = error < threshold·diameter (default the mesh's).");
  m.def("sample_points", [](const Mesh& mesh, int max_points) { return ToNumpy(SamplePoints(mesh, max_points)); },
        "mesh"_a, "max_points"_a = 2000);
  m.def("read_xyz_points", [](const std::string& path) { return ToNumpy(ReadXyzPoints(path)); }, "path"_a);
}

}  // namespace posefilter::python
