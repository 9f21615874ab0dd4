#pragma once
// Options and report shared by every reader (see CloudIO.hpp).
#include <cstddef>
#include <cstdint>
#include <string>

namespace scalespace {

struct ReadOptions {
  /// OFF/OBJ: 0 = the cloud is the mesh vertices; N > 0 = N points sampled uniformly by area with
  /// interpolated vertex normals (Sec. 3.4.1).
  std::size_t meshSamples = 0;
  std::uint64_t seed = 1;  // mesh sampling
  /// NaN/Inf coordinates (or beyond +-1e100, which only corrupt files hold): false -> FileError
  /// naming the first bad point; true -> the point is skipped and counted in
  /// ReadReport::droppedNonFinite. Attributes and normals are never checked (NaN is a legitimate
  /// "no value" there), but normals that are all zero or NaN/Inf are dropped
  /// (ReadReport::unusableNormalsDropped).
  bool dropNonFinite = false;
};

struct ReadReport {
  std::size_t droppedNonFinite = 0;
  /// The file had normals, every one zero or NaN/Inf: the cloud is returned without normals (a
  /// placeholder a writer without normals filled in; estimate them).
  bool unusableNormalsDropped = false;
  std::string format;  // "ply (binary_little_endian)", "las 1.4 format 6", ...
};

}  // namespace scalespace
