#pragma once
// Decisions shared by the writers (internal to the io layer).
#include <initializer_list>
#include <string>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace::io_detail {

/// Absolute positions are written as float32 only when every coordinate is exactly a float (a
/// cloud read from a float file, far from georeferenced coordinates); otherwise float64, so a
/// write -> read round trip never loses a digit.
ScalarType positionTypeFor(const PointCloud& cloud);

/// Throws Error when an attribute name cannot be written (empty, containing whitespace or a
/// separator, or equal to one of the `reserved` names the format uses for positions/normals).
void checkAttributeNames(const PointCloud& cloud, const char* format,
                         std::initializer_list<const char*> reserved);

}  // namespace scalespace::io_detail
