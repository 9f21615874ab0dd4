// The compiled part of the `scalespace` Python package (python/scalespace/__init__.py re-exports
// it with the Cloud type and the docs). Top layer: it includes every library layer, and nothing in
// the library includes it.
#include <pybind11/pybind11.h>

#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"

PYBIND11_MODULE(_scalespace, m) {
  m.doc() = "scalespace: multi-scale analysis of 3D point clouds (compiled part)";
  m.attr("__version__") = SCALESPACE_VERSION;
  scalespace::python::recordMainThread();
  scalespace::python::registerErrors(m);
  scalespace::python::bindClouds(m);
  scalespace::python::bindStacks(m);
  scalespace::python::bindPlanes(m);
  scalespace::python::bindFeatures(m);
  scalespace::python::bindCylinders(m);
}
