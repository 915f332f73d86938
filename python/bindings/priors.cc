// python/bindings/priors.cc — detections from Python values, and the bindings of Detection, PyramidLayout, Prior and the prior functions.
#include "bindings.h"

namespace posefilter::python {

Detection DetectionFrom(py::handle h, std::size_t index) {
  if (py::isinstance<Detection>(h)) return h.cast<Detection>();
  const std::string what = "detection " + std::to_string(index);
  if (!py::isinstance<py::dict>(h)) Fail(what + ": expected a Detection or a dict {class, score, bbox}");
  const auto d = py::reinterpret_borrow<py::dict>(h);
  for (const char* key : {"class", "score", "bbox"})
    if (!d.contains(key)) Fail(what + ": missing key '" + key + "'");
  Detection det;
  try {
    det.cls = d["class"].cast<std::string>();
    det.score = d["score"].cast<double>();
  } catch (const py::cast_error&) {
    Fail(what + ": 'class' must be a string and 'score' a number");
  }
  const auto b = AsDoubles(d["bbox"], what + ": 'bbox'");
  CheckShape(b, {4}, what + ": 'bbox'");
  det.x = b.at(0), det.y = b.at(1), det.w = b.at(2), det.h = b.at(3);
  return det;
}

std::vector<Detection> DetectionsFrom(py::handle h) {
  std::vector<Detection> out;
  std::size_t i = 0;
  for (py::handle item : h) out.push_back(DetectionFrom(item, i++));
  return out;
}

// Each message as a Python UserWarning (an exception if the warnings filter makes it one).
void WarnAll(const std::vector<std::string>& messages) {
  for (const auto& m : messages)
    if (PyErr_WarnEx(PyExc_UserWarning, m.c_str(), 1) != 0) throw py::error_already_set();
}

int ClassOf(const Prior& prior, py::handle cls) {
  if (py::isinstance<py::str>(cls)) {
    const std::string name = cls.cast<std::string>();
    const int c = prior.ClassIndex(name);
    if (c < 0) Fail("class '" + name + "' is not a class of the prior");
    return c;
  }
  int c = 0;
  try {
    c = cls.cast<int>();
  } catch (const py::cast_error&) {
    throw py::type_error("class: expected a class name (str) or index (int)");
  }
  if (c < 0 || c >= prior.layout.num_classes)
    Fail("class index " + std::to_string(c) + " out of range [0, " + std::to_string(prior.layout.num_classes) + ")");
  return c;
}

void BindPriors(py::module_& m) {
  // ---- Priors
  py::class_<Detection>(m, "Detection", "A 2D detection: class, score in [0, 1], bbox top-left (x, y) and size (w, h), pixels.")
      .def(py::init([](const std::string& cls, double score, py::handle bbox) {
             Detection d;
             d.cls = cls, d.score = score;
             const auto b = AsDoubles(bbox, "bbox");
             CheckShape(b, {4}, "bbox");
             d.x = b.at(0), d.y = b.at(1), d.w = b.at(2), d.h = b.at(3);
             return d;
           }),
           "cls"_a, "score"_a, "bbox"_a)
      .def_readwrite("cls", &Detection::cls)
      .def_readwrite("score", &Detection::score)
      .def_property_readonly("bbox", [](const Detection& d) { return py::make_tuple(d.x, d.y, d.w, d.h); })
      .def("__repr__", [](const Detection& d) {
        std::ostringstream os;
        os << "Detection('" << d.cls << "', " << d.score << ", (" << d.x << ", " << d.y << ", " << d.w << ", " << d.h << "))";
        return os.str();
      });

  py::class_<PyramidLayout>(m, "PyramidLayout", "Grid levels of the prior (thesis: 15x20, 30x40, 60x80 cells).")
      .def_static("thesis", &PyramidLayout::Thesis, "image_width"_a = 640, "image_height"_a = 480, "num_classes"_a = 21)
      .def_readonly("image_width", &PyramidLayout::image_width)
      .def_readonly("image_height", &PyramidLayout::image_height)
      .def_readonly("num_classes", &PyramidLayout::num_classes)
      .def_property_readonly("levels", [](const PyramidLayout& l) {
        py::list out;
        for (const auto& v : l.levels) out.append(py::make_tuple(v.rows, v.cols, v.anchor_w, v.anchor_h));
        return out;
      }, "[(rows, cols, anchor_w, anchor_h)] coarse to fine")
      .def("cell_count", &PyramidLayout::CellCount)
      .def("level_offset", &PyramidLayout::LevelOffset, "level"_a)
      .def("cell_row_col", [](const PyramidLayout& l, int cell) {
        int level = 0, row = 0, col = 0;
        l.CellRowCol(cell, &level, &row, &col);
        return py::make_tuple(level, row, col);
      }, "cell"_a, "→ (level, row, col)")
      .def("cell_index", &PyramidLayout::CellIndex, "level"_a, "row"_a, "col"_a)
      .def("anchor_box", [](const PyramidLayout& l, int cell) { return BoxTuple(l.AnchorBox(cell)); }, "cell"_a);

  py::class_<Prior>(m, "Prior", "Post-processed stage-1 prior: per cell a box and a probability per class.")
      .def_readonly("layout", &Prior::layout)
      .def_readonly("classes", &Prior::classes)
      .def_property_readonly("prob", [](const Prior& p) {
        py::array_t<float> out({py::ssize_t(p.layout.CellCount()), py::ssize_t(p.layout.num_classes)});
        std::memcpy(out.mutable_data(), p.prob.data(), p.prob.size() * sizeof(float));
        return out;
      }, "cells x classes float32: Prob (eq. 7.1–7.2) (copy)")
      .def_property_readonly("boxes", [](const Prior& p) {
        py::array_t<double> out({py::ssize_t(p.boxes.size()), py::ssize_t(4)});
        auto o = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < p.boxes.size(); ++i)
          o(i, 0) = p.boxes[i].cx, o(i, 1) = p.boxes[i].cy, o(i, 2) = p.boxes[i].w, o(i, 3) = p.boxes[i].h;
        return out;
      }, "cells x 4 float64: decoded box (cx, cy, w, h), pixels")
      .def("class_index", &Prior::ClassIndex, "name"_a, "-1 if absent")
      .def("class_mass", [](const Prior& p, py::handle cls) { return p.ClassMass(ClassOf(p, cls)); }, "cls"_a)
      .def("level_grid", [](const Prior& p, py::handle cls, int level) {
        const int c = ClassOf(p, cls);
        if (level < 0 || level >= int(p.layout.levels.size()))
          Fail("level " + std::to_string(level) + " out of range [0, " + std::to_string(p.layout.levels.size()) + ")");
        const PyramidLevel& L = p.layout.levels[level];
        py::array_t<float> out({py::ssize_t(L.rows), py::ssize_t(L.cols)});
        auto o = out.mutable_unchecked<2>();
        for (int r = 0; r < L.rows; ++r)
          for (int q = 0; q < L.cols; ++q) o(r, q) = p.Prob(p.layout.CellIndex(level, r, q), c);
        return out;
      }, "cls"_a, "level"_a, "Probabilities of one class on one level's grid (rows x cols).")
      .def("__repr__", [](const Prior& p) {
        return "Prior(" + std::to_string(p.layout.CellCount()) + " cells, " + std::to_string(p.classes.size()) + " classes)";
      });

  auto layout_for = [](py::handle layout_or_camera, int num_classes) {
    if (py::isinstance<PyramidLayout>(layout_or_camera)) return layout_or_camera.cast<PyramidLayout>();
    if (py::isinstance<Camera>(layout_or_camera)) {
      const auto& c = layout_or_camera.cast<const Camera&>();
      return PyramidLayout::Thesis(c.width, c.height, num_classes);
    }
    throw py::type_error("layout: expected a PyramidLayout or a Camera (thesis pyramid over its image)");
  };
  m.def("prior_from_detections", [layout_for](py::handle detections, py::handle layout, std::optional<std::vector<std::string>> classes,
                                              double floor_prob, double max_box_px) {
    const auto dets = DetectionsFrom(detections);
    const auto cls = classes ? *classes : ClassesForObjects({}, dets);
    DetectionPriorOptions opt;
    opt.floor_prob = floor_prob, opt.max_box_px = max_box_px;
    return PriorFromDetections(dets, layout_for(layout, int(cls.size())), cls, opt);
  }, "detections"_a, "layout"_a, "classes"_a = py::none(), "floor_prob"_a = DetectionPriorOptions{}.floor_prob,
        "max_box_px"_a = DetectionPriorOptions{}.max_box_px,
        "Detections (Detection or {class, score, bbox}) → Prior; layout = PyramidLayout or Camera; "
        "classes default to the detections' classes.");
  m.def("detections_to_raw_pyramid", [layout_for](py::handle detections, py::handle layout, const std::vector<std::string>& classes,
                                                  double floor_prob, double max_box_px) {
    DetectionPriorOptions opt;
    opt.floor_prob = floor_prob, opt.max_box_px = max_box_px;
    const auto raw = DetectionsToRawPyramid(DetectionsFrom(detections), layout_for(layout, int(classes.size())), classes, opt);
    return py::array_t<float>(py::ssize_t(raw.size()), raw.data());
  }, "detections"_a, "layout"_a, "classes"_a, "floor_prob"_a = DetectionPriorOptions{}.floor_prob,
        "max_box_px"_a = DetectionPriorOptions{}.max_box_px);
  m.def("post_process_pyramid", [layout_for](py::handle raw, py::handle layout, const std::vector<std::string>& classes, double max_box_px) {
    const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(raw);
    if (!a) Fail("raw: expected an array of float32");
    PostProcessOptions opt;
    opt.max_box_px = max_box_px;
    return PostProcessPyramid(std::vector<float>(a.data(), a.data() + a.size()), layout_for(layout, int(classes.size())), classes, opt);
  }, "raw"_a, "layout"_a, "classes"_a, "max_box_px"_a = PostProcessOptions{}.max_box_px,
        "Raw pyramid (cells x (classes + 5) float32, thesis layout) → Prior (eq. 7.1–7.2).");
  m.def("read_raw_pyramid", [layout_for](const std::string& path, py::handle layout, const std::vector<std::string>& classes) {
    const auto raw = ReadRawPyramid(path, layout_for(layout, int(classes.size())));
    return py::array_t<float>(py::ssize_t(raw.size()), raw.data());
  }, "path"_a, "layout"_a, "classes"_a);
  m.def("uniform_prior", [layout_for](py::handle layout, const std::vector<std::string>& classes) {
    return UniformPrior(layout_for(layout, int(classes.size())), classes);
  }, "layout"_a, "classes"_a);
  m.def("read_detections_json", [](const std::string& path, bool allow_empty) { return ReadDetectionsJson(path, allow_empty); },
        "path"_a, "allow_empty"_a = false);
  m.def("write_detections_json", [](py::handle detections, const std::string& path) {
    WriteDetectionsJson(DetectionsFrom(detections), path);
  }, "detections"_a, "path"_a);
  m.def("ycbv_class_names", &YcbVideoClassNames);

  // The initialisation's importance sampling (thesis §7.4, eq. 7.3 [ALGORITHM.md]): CDF of the class's cell
  // probabilities and `n` cells drawn from it with the filter's CDF sampler and threshold tracker.
  m.def("sample_cells", [](const Prior& prior, py::handle cls, int n, std::uint64_t seed, int tracker_bins,
                           py::handle depth, std::optional<Camera> camera, std::optional<double> depth_scale) {
    const int c = ClassOf(prior, cls);
    if (n < 1) Fail("sample_cells: n must be >= 1");
    if (tracker_bins < 1) Fail("sample_cells: tracker_bins must be >= 1");
    std::vector<double> w(prior.layout.CellCount());
    for (int i = 0; i < prior.layout.CellCount(); ++i) w[i] = prior.Prob(i, c);
    if (!depth.is_none()) {
      // As EstimatePose: a cell without a heuristic volume (too little depth in its box) has no mass.
      if (!camera) Fail("sample_cells: depth needs camera=");
      const auto volumes = ComputeHeuristics(DepthFrom(depth, depth_scale, &*camera, "depth"), *camera, prior.boxes);
      for (std::size_t i = 0; i < w.size(); ++i)
        if (!volumes[i].valid) w[i] = 0;
    }
    filter::CdfSampler sampler(w, tracker_bins);
    Rng rng(seed);
    py::array_t<std::int32_t> cells(n);
    auto* out = cells.mutable_data();
    for (int i = 0; i < n; ++i) out[i] = sampler.Sample(1.0 - rng.Uniform());
    return py::dict("cells"_a = cells, "cdf"_a = ToNumpy(sampler.cdf()), "weights"_a = ToNumpy(w),
                    "reads"_a = sampler.reads(), "reads_linear"_a = sampler.reads_linear());
  }, "prior"_a, "cls"_a, "n"_a, "seed"_a = 1, "tracker_bins"_a = FilterOptions{}.tracker_bins, "depth"_a = py::none(),
        "camera"_a = py::none(), "depth_scale"_a = py::none(),
        "Importance sampling of cells as the filter's initialisation does it (§7.4): → dict(cells, cdf, weights, "
        "reads, reads_linear). With depth and camera, cells without a heuristic volume get no mass.");
}

}  // namespace posefilter::python
