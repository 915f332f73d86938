// python/bindings/module.cc — the `posefilter._posefilter` extension (pybind11): registers the
// error type and binds each part of the API (bindings.h lists the files).
#include "bindings.h"

PYBIND11_MODULE(_posefilter, m) {
  using namespace posefilter;
  using namespace posefilter::python;
  m.doc() = "posefilter: 6-DoF object pose estimation with a rendering particle filter (C++ core).";

  // posefilter::Error → posefilter.Error, a ValueError (bad input: files, arrays, options).
  py::register_exception<Error>(m, "Error", PyExc_ValueError);
  m.attr("__version__") = Version();
  m.attr("__git_revision__") = GitRevision();

  BindGeometry(m);
  BindIoAndMetrics(m);
  BindPriors(m);
  BindEstimation(m);
  BindSynth(m);
  BindTracking(m);
  BindDataset(m);
}
