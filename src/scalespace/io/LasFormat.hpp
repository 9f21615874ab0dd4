#pragma once
// LAS (ASPRS LiDAR exchange format), uncompressed, versions 1.0-1.4, point data formats 0-3 and
// 6-8. Coordinates are X * scale + offset computed in double. Attributes kept: intensity
// (uint16), classification (uint8; the 5-bit class for formats 0-3), return_number and
// number_of_returns (uint8), gps_time (float64, formats 1, 3, 6, 7, 8), red green blue (uint16,
// formats 2, 3, 7, 8), nir (uint16, format 8). Extra bytes in longer records are skipped.
// Compressed LAZ files (format byte with bit 7 or 6 set) and waveform formats (4, 5, 9, 10) are
// rejected with a FileError saying how to convert them.
// Writing: LAS 1.2, point format 0, 1 (gps_time), 2 (red green blue) or 3 (both), coordinates
// quantised to 0.1 mm (coarser only when the extent needs it) around the cloud's origin.
// Normals and other attributes have no place in LAS 1.2 records and are not written.
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
