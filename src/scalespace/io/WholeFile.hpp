#pragma once
// Reading a file into memory in one go (internal to the io layer): every parser works on the
// whole data, with the counts its header declares checked against its size.
#include <string>

namespace scalespace::io_detail {

/// The bytes of `path`. FileError naming it when it is a folder, cannot be opened or read.
std::string readWholeFile(const std::string& path);

}  // namespace scalespace::io_detail
