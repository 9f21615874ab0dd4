#pragma once
// PCD v0.7 (Point Cloud Library): DATA ascii, binary and binary_compressed (LZF).
//
// Fields x y z -> positions; normal_x normal_y normal_z -> normals; rgb / rgba (a packed 32-bit
// value, stored as float or uint) -> red green blue (uint8; and alpha for rgba); "_" padding is
// skipped; every other field -> an attribute column of its TYPE/SIZE (I1/2/4, U1/2/4, F4/8);
// fields with COUNT > 1 -> columns name_0, name_1, ... 8-byte integer fields are rejected (no
// exact ScalarType). WIDTH * HEIGHT must equal POINTS.
// Writing: ascii or binary; x y z as F4 when exact, else F8; normals F4; attributes with their
// types (COUNT 1 each, so red/green/blue stay separate fields).
#include <ostream>
#include <string>
#include <string_view>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

PointCloud readPcd(std::string_view data, const std::string& file, const ReadOptions& options = {},
                   ReadReport* report = nullptr);

void writePcd(const PointCloud& cloud, std::ostream& out, bool ascii);

}  // namespace scalespace
