// The compiled part of the `scalespace` Python package (python/scalespace/__init__.py re-exports
// it with the Cloud type and the docs). Top layer: it includes every library layer, and nothing in
// the library includes it.
#include <pybind11/pybind11.h>

#include "scalespace/core/MemoryReuse.hpp"
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
  scalespace::python::bindParametrization(m);
  m.def("retain_freed_memory", &scalespace::retainFreedMemory,
        R"doc(Keep freed memory in the process for reuse (glibc only; returns whether it applied).

Every call copies its input into the library's arrays and each scale allocates arrays of tens of
MB; by default glibc returns such blocks to the system when they are freed, so the next call
touches fresh pages, which costs milliseconds per million points (page faults). After this, freed
blocks stay in the process and are reused: repeated calls are faster, at the price of a higher
resident memory. It changes the allocator of the whole Python process, so the module never does
it by itself; the `scalespace` CLI does it at start-up.)doc");
}
