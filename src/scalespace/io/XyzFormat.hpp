#pragma once
// Text columns (.xyz .txt .csv .pts, and CGAL's .pwn): one point per line, "x y z [nx ny nz] [more
// columns]".
//
// Fields are separated by whitespace, or by commas when the line holds a comma. Blank lines and
// lines starting with '#' are skipped, and so is a first line holding a single integer (the
// point count of Leica .pts files). If the first data line holds a token that is not a
// number, it is a header naming the columns (case-insensitive x/y/z, nx/ny/nz or
// normal_x/normal_y/normal_z; a leading "//" as CloudCompare writes it is ignored); x, y and z
// must all be named. Without a header the column count decides, and only these counts:
//   3 -> x y z;  6 -> x y z nx ny nz;  4, 5, 7+ -> x y z then attributes scalar_1, scalar_2, ...
// (a 7+ column file is ambiguous - x y z r g b i, x y z nx ny nz s... - so nothing is guessed;
// write a header to get normals). Every attribute column is Float64 (text keeps no type). Every
// line must have the same number of fields.
// Writing: a header line "x y z [nx ny nz] names...", then shortest round-trip numbers (the text
// reads back to the same doubles).
#include <ostream>
#include <string>
#include <string_view>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

PointCloud readXyz(std::string_view data, const std::string& file, const ReadOptions& options = {},
                   ReadReport* report = nullptr);

/// `separator` is ' ' or ','.
void writeXyz(const PointCloud& cloud, std::ostream& out, char separator = ' ');

/// CGAL's .pwn (points with normals, as its demos and read_points() take them): "x y z nx ny nz"
/// per line, no header. A .pwn has no place for attributes: they are not written. Throws
/// OptionError (checkPwnWritable) when the cloud has no normals or a non-finite one.
void writePwn(const PointCloud& cloud, std::ostream& out);
void checkPwnWritable(const PointCloud& cloud);

}  // namespace scalespace
