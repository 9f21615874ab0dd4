#pragma once
// Shared by the OFF and OBJ readers (internal to the io layer): turns a parsed mesh into a cloud,
// applying ReadOptions (vertices or samples; non-finite vertices rejected or dropped).
#include <string>

#include "scalespace/io/MeshFormat.hpp"

namespace scalespace::io_detail {

PointCloud meshToCloud(TriangleMesh mesh, const std::string& file, const ReadOptions& options,
                       ReadReport* report, const std::string& formatDescription);

}  // namespace scalespace::io_detail
