#pragma once
// LAS (ASPRS LiDAR exchange format), uncompressed, versions 1.0-1.4, point data formats 0-3 and
// 6-8. Coordinates are X * scale + offset computed in double. Attributes kept: intensity
// (uint16), classification (uint8; the 5-bit class for formats 0-3), return_number and
// number_of_returns (uint8), gps_time (float64, formats 1, 3, 6, 7, 8), red green blue (uint16,
// formats 2, 3, 7, 8), nir (uint16, format 8).
// Extra bytes (LAS 1.4 R15 Sec. 4.3), in any version: the "Extra Bytes" VLR (user LASF_Spec,
// record 4; the first one if several) describes the bytes after the standard record. Each scalar
// (data types 1-10) becomes a column named as in its descriptor, of the matching type (64-bit
// integers as float64, rounded beyond 2^53; with the scale or offset option bit, raw * scale +
// offset as float64). Float fields nx ny nz (all three) become the normals, as in PLY. Names are
// made writable: bytes outside printable ASCII, spaces and commas become '_', an empty name is
// extra_bytes_N (N = the descriptor's 1-based index); a name already used by a standard
// attribute or an earlier field gets a suffix _2, _3, ... Undocumented (type 0, size in
// `options`) and deprecated array (11-30) fields are skipped without shifting the fields after
// them; a reserved type (31-255) has no known size, so it and the fields after it are skipped.
// Skipped fields are counted in ReadReport::format. Bytes no descriptor covers (or all extra
// bytes, without the VLR) are ignored. A VLR chain running past the point data, an Extra Bytes
// VLR that is not whole 192-byte descriptors, or descriptors needing more bytes than the record
// holds (the spec's "extra bytes mismatch") throw a FileError. An Extra Bytes EVLR (after the
// points, 1.4) is not looked for.
// Compressed LAZ files (format byte with bit 7 or 6 set) and waveform formats (4, 5, 9, 10) are
// rejected with a FileError saying how to convert them.
// Writing: point format 0, 1 (gps_time), 2 (red green blue) or 3 (both), coordinates quantised to
// 0.1 mm (coarser only when the extent needs it) around the cloud's origin. The normals (float
// nx ny nz) and every column without a standard field (all but intensity, classification,
// return_number, number_of_returns, gps_time and a complete red green blue; nir included) are
// written as extra bytes of their own type, described by an Extra Bytes VLR. Such files are LAS
// 1.4 (375-byte header, 64-bit counts, no EVLR), which PDAL, LAStools and CloudCompare read
// extra bytes from; a cloud with nothing extra is written as LAS 1.2, as before. Names longer
// than 31 characters (a descriptor's name is char[32], NUL-terminated) throw a FileError.
#include <ostream>
#include <string>
#include <string_view>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace {

PointCloud readLas(std::string_view data, const std::string& file, const ReadOptions& options = {},
                   ReadReport* report = nullptr);

/// `file` names the target in error messages.
void writeLas(const PointCloud& cloud, std::ostream& out, const std::string& file);

}  // namespace scalespace
