// The compiled part of the `scalespace` Python package (python/scalespace/__init__.py re-exports
// it with the Cloud type and the docs). Top layer: it includes every library layer, and nothing in
// the library includes it.
#include <pybind11/pybind11.h>

#include "scalespace/core/MemoryReuse.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"
#include "scalespace/python/InputPool.hpp"

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
it by itself; the `scalespace` CLI does it at start-up. The module's own input copies are reused
without it: see release_buffers().)doc");
  m.def("release_buffers", &scalespace::python::releaseBuffers,
        R"doc(Free the memory kept for the next call's input copies; returns how many bytes it held.

Every call copies its points (and normals) into the library's arrays, 48 MB for 1M points. The
module keeps the last call's copies (up to 256 MB; not the arrays it returns) so that the next
call of a similar size copies into memory already mapped in, which saves the page faults of
fresh memory (about 14 ms per 1M points). Call this to give that memory back, e.g. after the last
call on a large cloud; the next call allocates again. Safe at any time, from any thread.)doc");
}
