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

/// Throws Error when an attribute name cannot be written: empty, containing whitespace or a
/// comma, equal to one of the `reserved` names (positions, format keywords), or to one of the
/// `normalNames` when the cloud has normals. A cloud without normals may carry some of the normal
/// names as attributes (a reader keeps a partial nx/ny/nz as attributes), but not three of them:
/// they would read back as normals. `caseInsensitive` for formats whose reader ignores case (XYZ).
void checkAttributeNames(const PointCloud& cloud, const char* format,
                         std::initializer_list<const char*> reserved,
                         std::initializer_list<const char*> normalNames,
                         bool caseInsensitive = false);

}  // namespace scalespace::io_detail
