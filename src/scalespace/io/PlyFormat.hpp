#pragma once
// PLY (Stanford polygon format): ascii, binary_little_endian and binary_big_endian.
//
// Reading: the `vertex` element gives the points: x y z -> positions, nx ny nz -> normals, every
// other scalar property -> an attribute column of that PLY type (char/uchar/.../double and the
// int8/.../float64 aliases). List properties and other elements (faces, edges, ...) are parsed
// and skipped; comments and obj_info are ignored.
// Writing: x y z as float32 when that is exact, else float64; nx ny nz float32; then every
// attribute column with its ScalarType, in column order.
#include <ostream>
#include <string>
#include <string_view>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

/// Parses a whole PLY file held in `data`; `file` names it in error messages.
PointCloud readPly(std::string_view data, const std::string& file, const ReadOptions& options = {},
                   ReadReport* report = nullptr);

void writePly(const PointCloud& cloud, std::ostream& out, PlyEncoding encoding);

}  // namespace scalespace
