// python/bindings/geometry.cc — bindings of Camera, Mesh, the built-in shapes and pose conversions.
#include "bindings.h"

namespace posefilter::python {

void BindGeometry(py::module_& m) {
  // ---- Camera
  py::class_<Camera>(m, "Camera", "Pinhole camera (OpenCV frame): intrinsics in pixels, base_to_camera 4x4.")
      .def(py::init([](double fx, double fy, double cx, double cy, int width, int height, py::object base_to_camera) {
             Camera c;
             c.fx = fx, c.fy = fy, c.cx = cx, c.cy = cy, c.width = width, c.height = height;
             if (!base_to_camera.is_none()) c.base_to_camera = TransformFrom(base_to_camera, "base_to_camera");
             return CheckedCamera(c, "Camera");
           }),
           py::kw_only(), "fx"_a = Camera{}.fx, "fy"_a = Camera{}.fy, "cx"_a = Camera{}.cx, "cy"_a = Camera{}.cy,
           "width"_a = Camera{}.width, "height"_a = Camera{}.height, "base_to_camera"_a = py::none())
      .def_readonly("fx", &Camera::fx)
      .def_readonly("fy", &Camera::fy)
      .def_readonly("cx", &Camera::cx)
      .def_readonly("cy", &Camera::cy)
      .def_readonly("width", &Camera::width)
      .def_readonly("height", &Camera::height)
      .def_property_readonly("base_to_camera", [](const Camera& c) { return ToNumpy(c.base_to_camera); })
      .def_property_readonly("K", [](const Camera& c) {
        py::array_t<double> K({3, 3});
        auto k = K.mutable_unchecked<2>();
        const double v[3][3] = {{c.fx, 0, c.cx}, {0, c.fy, c.cy}, {0, 0, 1}};
        for (int r = 0; r < 3; ++r)
          for (int q = 0; q < 3; ++q) k(r, q) = v[r][q];
        return K;
      })
      .def("project", [](const Camera& c, py::handle p) {
             const auto pts = PointsFrom(p, "points");
             py::array_t<double> out({py::ssize_t(pts.size()), py::ssize_t(2)});
             auto o = out.mutable_unchecked<2>();
             for (std::size_t i = 0; i < pts.size(); ++i) {
               if (!(pts[i].z() > 0)) Fail("points: point " + std::to_string(i) + " has z <= 0");
               const Eigen::Vector2d uv = c.Project(pts[i].cast<double>());
               o(i, 0) = uv.x(), o(i, 1) = uv.y();
             }
             return out;
           }, "points"_a, "Camera-frame points (N x 3, metres, z > 0) → pixels (N x 2, u = column, v = row).")
      .def("__repr__", [](const Camera& c) { return Repr(c); })
      .def(py::pickle([](const Camera& c) { return py::make_tuple(c.fx, c.fy, c.cx, c.cy, c.width, c.height, ToNumpy(c.base_to_camera)); },
                      [](py::tuple t) {
                        Camera c;
                        c.fx = t[0].cast<double>(), c.fy = t[1].cast<double>(), c.cx = t[2].cast<double>(), c.cy = t[3].cast<double>();
                        c.width = t[4].cast<int>(), c.height = t[5].cast<int>();
                        c.base_to_camera = TransformFrom(t[6], "base_to_camera");
                        return c;
                      }));

  // ---- Mesh
  py::class_<Mesh>(m, "Mesh", "Triangle mesh, object frame, metres; faces CCW seen from outside.")
      .def(py::init([](py::handle vertices, py::handle faces, const std::string& name) {
             Mesh mesh;
             mesh.name = name;
             mesh.vertices = PointsFrom(vertices, "vertices");
             if (!py::isinstance<py::array>(faces) && !py::isinstance<py::sequence>(faces)) Fail("faces: expected an M x 3 integer array");
             const auto fa = py::array::ensure(faces);
             if (!fa || (fa.dtype().kind() != 'i' && fa.dtype().kind() != 'u'))
               Fail("faces: expected an M x 3 integer array");
             const auto f = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(fa);
             if (f.ndim() != 2 || f.shape(1) != 3) Fail("faces: expected an M x 3 array, got shape " + ShapeString(f));
             for (py::ssize_t i = 0; i < f.shape(0); ++i) {
               std::array<std::uint32_t, 3> tri{};
               for (int k = 0; k < 3; ++k) {
                 const std::int64_t v = f.at(i, k);
                 if (v < 0 || v >= std::int64_t(mesh.vertices.size()))
                   Fail("faces: face " + std::to_string(i) + " indexes vertex " + std::to_string(v) + " of " +
                        std::to_string(mesh.vertices.size()));
                 tri[k] = std::uint32_t(v);
               }
               mesh.faces.push_back(tri);
             }
             std::string why;
             if (!mesh.IsValid(&why)) Fail("Mesh '" + name + "': " + why);
             return mesh;
           }),
           "vertices"_a, "faces"_a, "name"_a = "mesh")
      .def_readwrite("name", &Mesh::name, "object/class name (the prior class it is looked up as)")
      .def_property_readonly("vertices", [](const Mesh& s) { return ToNumpy(s.vertices); }, "V x 3 float32, metres (copy)")
      .def_property_readonly("faces", [](const Mesh& s) {
        py::array_t<std::uint32_t> out({py::ssize_t(s.faces.size()), py::ssize_t(3)});
        if (!s.faces.empty()) std::memcpy(out.mutable_data(), s.faces.data(), s.faces.size() * 3 * sizeof(std::uint32_t));
        return out;
      }, "F x 3 uint32 (copy)")
      .def("diameter", &Mesh::Diameter, "largest vertex distance, metres")
      .def("bounds", [](const Mesh& s) {
        const Eigen::Vector3f lo = s.Min(), hi = s.Max();
        return py::make_tuple(py::array_t<float>(3, lo.data()), py::array_t<float>(3, hi.data()));
      }, "(min, max) corners of the axis-aligned bounds, object frame, metres")
      .def("save_ply", [](const Mesh& s, const std::string& path) { SaveMeshPly(s, path); }, "path"_a)
      .def("__repr__", [](const Mesh& s) {
        return "Mesh('" + s.name + "', " + std::to_string(s.vertices.size()) + " vertices, " +
               std::to_string(s.faces.size()) + " faces)";
      });

  m.def("load_mesh", [](py::handle path, py::handle units, std::optional<std::string> name) {
    double scale = 1.0;
    if (py::isinstance<py::str>(units)) {
      const std::string u = units.cast<std::string>();
      if (u == "m") scale = 1.0;
      else if (u == "cm") scale = 0.01;
      else if (u == "mm") scale = 0.001;
      else Fail("load_mesh: units must be 'm', 'cm', 'mm' or a positive number (got '" + u + "')");
    } else {
      try {
        scale = units.cast<double>();
      } catch (const py::cast_error&) {
        throw py::type_error("load_mesh: units must be 'm', 'cm', 'mm' or a number");
      }
      if (!(std::isfinite(scale) && scale > 0)) Fail("load_mesh: units must be a finite number > 0");
    }
    Mesh mesh = LoadMesh(py::str(py::module_::import("os").attr("fspath")(path)), scale);
    if (name) mesh.name = *name;
    return mesh;
  }, "path"_a, "units"_a = 1.0, "name"_a = py::none(),
        "Loads a PLY/OBJ/STL mesh; units: 'm', 'cm', 'mm' or metres per file unit. Name defaults to the file stem.");
  m.def("make_box", &MakeBox, "sx"_a, "sy"_a, "sz"_a, "name"_a = "box", "Box of side lengths sx, sy, sz (metres).");
  m.def("make_cylinder", &MakeCylinder, "radius"_a, "height"_a, "segments"_a = 32, "name"_a = "cylinder");
  m.def("make_lshape", &MakeLShape, "size"_a, "thickness"_a, "depth"_a, "name"_a = "lshape");
  m.def("make_torus", &MakeTorus, "major_r"_a, "minor_r"_a, "nu"_a = 32, "nv"_a = 32, "name"_a = "torus");
  m.def("make_shape", &MakeShape, "kind"_a, "One of synth_class_names() with its default size.");
  m.def("synth_class_names", &SynthClassNames);

  // ---- Poses
  m.def("pose_to_transform", [](py::handle p) { return ToNumpy(PoseToTransform(Pose6From(p, "pose"))); }, "pose"_a,
        "(x, y, z, roll, pitch, yaw) → 4x4, T = Tr·Rz(yaw)·Ry(pitch)·Rx(roll) (eq. 6.2).");
  m.def("transform_to_pose", [](py::handle T) { return ToNumpy(TransformToPose(TransformFrom(T, "T"))); }, "T"_a,
        "4x4 → (x, y, z, roll, pitch, yaw), pitch in [-pi/2, pi/2].");
  m.def("wrap_angle", &WrapAngle, "a"_a, "Angle wrapped to (-pi, pi].");
}

}  // namespace posefilter::python
