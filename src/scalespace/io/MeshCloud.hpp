#pragma once
// Shared by the OFF, OBJ, STL and PLY mesh readers (internal to the io layer): turns a parsed mesh
// into a cloud, applying ReadOptions (vertices or samples; non-finite vertices rejected or
// dropped).
#include <string>

#include "scalespace/io/MeshFormat.hpp"

namespace scalespace::io_detail {

/// `droppedBefore`: vertices the reader already dropped (a PLY reader renumbers the faces
/// itself), added to the report's count.
PointCloud meshToCloud(TriangleMesh mesh, const std::string& file, const ReadOptions& options,
                       ReadReport* report, const std::string& formatDescription,
                       std::size_t droppedBefore = 0);

}  // namespace scalespace::io_detail
