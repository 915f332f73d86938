// python/bindings/dataset.cc — datasets (posefilter/bop.h, posefilter/run_dataset.h): the targets
// a run estimates, and RunDataset in this process.
#include "bindings.h"
#include "posefilter/bop.h"
#include "posefilter/file_io.h"
#include "posefilter/run_dataset.h"

namespace posefilter::python {
namespace {

// The prior argument of run_dataset: 'uniform', 'auto', ('gt-boxes', SIGMA_PX) or
// ('detections', PATH), into *o.
void DatasetPriorFrom(py::handle prior, RunDatasetOptions* o) {
  if (py::isinstance<py::str>(prior)) {
    const std::string p = prior.cast<std::string>();
    if (p == "uniform") return void(o->prior = DatasetPriorKind::kUniform);
    if (p == "auto") return void(o->prior = DatasetPriorKind::kAuto);
  } else if (py::isinstance<py::tuple>(prior) || py::isinstance<py::list>(prior)) {
    const py::sequence s = prior.cast<py::sequence>();
    if (s.size() == 2 && py::isinstance<py::str>(s[0])) {
      const std::string kind = s[0].cast<std::string>();
      if (kind == "gt-boxes" && (py::isinstance<py::float_>(s[1]) || py::isinstance<py::int_>(s[1])) &&
          !py::isinstance<py::bool_>(s[1])) {
        o->prior = DatasetPriorKind::kGtBoxes;
        o->gt_jitter_px = s[1].cast<double>();
        return;
      }
      if (kind == "detections" && (py::isinstance<py::str>(s[1]) || py::hasattr(s[1], "__fspath__"))) {
        o->prior = DatasetPriorKind::kDetections;
        o->detections_path = py::str(py::module_::import("os").attr("fspath")(s[1]));
        return;
      }
    }
  }
  throw py::type_error("prior: expected 'uniform', 'auto', ('gt-boxes', SIGMA_PX) or ('detections', PATH), got " +
                       std::string(py::repr(prior)));
}

}  // namespace

void BindDataset(py::module_& m) {
  m.def(
      "dataset_targets",
      [](const std::string& dataset, const std::string& split, const std::string& targets) {
        const Dataset ds = OpenDataset(dataset, split, targets);
        py::list out;
        for (const DatasetTarget& t : ds.targets)
          out.append(py::dict("scene_id"_a = t.scene_id, "im_id"_a = t.im_id, "obj_id"_a = t.obj_id,
                              "inst_count"_a = t.inst_count));
        return out;
      },
      "dataset"_a, "split"_a = "test", "targets"_a = "",
      "The targets `run_dataset` (and `posefilter run-dataset`) estimates in a dataset folder (a BOP split or a "
      "YCB-Video folder), as [{scene_id, im_id, obj_id, inst_count}]: `targets` (a test_targets_bop19-style JSON) "
      "when given, else the dataset's test_targets_bop19.json, else every ground-truth object.");
  m.def(
      "run_dataset",
      [](const std::string& dataset, const std::string& out, py::handle prior, const std::string& split,
         const std::string& targets, const std::vector<std::pair<int, int>>& images, int limit, bool scene_pass,
         bool no_time, double gt_box_score, py::handle progress, const py::kwargs& kw) {
        RunDatasetOptions o;
        o.dataset = dataset;
        o.out = out;
        o.out_label = "out";
        o.split = split;
        o.targets_path = targets;
        o.images = images;
        o.limit = limit;
        o.scene_pass = scene_pass;
        o.no_time = no_time;
        o.gt_box_score = gt_box_score;
        DatasetPriorFrom(prior, &o);
        ApplyKeywords(&o.filter, kw, FilterKeywords(), "run_dataset");
        o.filter = CheckedFilterOptions(o.filter);
        CheckOutputPaths({{o.out, "out"}}, {{o.detections_path, "detections"}, {o.targets_path, "targets"}});
        const py::object callback = py::reinterpret_borrow<py::object>(progress);
        if (!callback.is_none() && !PyCallable_Check(callback.ptr())) throw py::type_error("progress: expected a callable");
        RunDatasetCallbacks cb;
        std::vector<std::string> messages;  // warnings and notes, raised as Python warnings at the end
        cb.on_warning = [&messages](const std::string& w) { messages.push_back(w); };
        cb.on_note = [&messages](const std::string& n) { messages.push_back(n); };
        cb.on_image = [&callback](const DatasetImageDone& d) {
          py::gil_scoped_acquire acquire;
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (!callback.is_none())
            callback(d.done, d.total, py::make_tuple(d.image->scene_id, d.image->im_id));
        };
        RunDatasetSummary sum;
        {
          py::gil_scoped_release release;
          sum = RunDataset(o, cb);
        }
        WarnAll(messages);
        return py::dict("images"_a = sum.images, "estimated"_a = sum.estimated, "skipped"_a = sum.skipped,
                        "rows"_a = sum.rows, "failed"_a = sum.failed);
      },
      "dataset"_a, "out"_a, py::kw_only(), "prior"_a, "split"_a = "test", "targets"_a = "",
      "images"_a = std::vector<std::pair<int, int>>{}, "limit"_a = 0, "scene_pass"_a = true, "no_time"_a = false,
      "gt_box_score"_a = 0.9, "progress"_a = py::none(),
      "Estimates every target of a dataset in this process and appends the rows to the BOP results CSV `out`, "
      "resumably: what `posefilter run-dataset` does (posefilter/run_dataset.h). prior: 'uniform', 'auto', "
      "('gt-boxes', SIGMA_PX) or ('detections', PATH). images: only these (scene_id, im_id); limit: only the first N "
      "images with targets (0 = all). Filter options as keywords (as Estimator's). progress(done, total, "
      "(scene_id, im_id)) after each image. Targets without an estimate and resume notes become warnings. Returns "
      "{images, estimated, skipped, rows, failed}. Runs without the GIL.");
}

}  // namespace posefilter::python
