#pragma once
// The parts of the `_scalespace` module, one function per group of commands (as cli/ has one file
// per group): Module.cpp calls each on the module.
#include <pybind11/pybind11.h>

namespace scalespace::python {

void bindClouds(pybind11::module_& m);     // read, write, normals, curvature, render
void bindStacks(pybind11::module_& m);     // the multi-scale stack, in memory and on disk
void bindPlanes(pybind11::module_& m);     // planes, their result folders, the segment queries
void bindFeatures(pybind11::module_& m);   // curvature lines, feature curves
void bindCylinders(pybind11::module_& m);  // cylinders across scales
void bindParametrization(pybind11::module_& m);  // parametrize, distortion

}  // namespace scalespace::python
