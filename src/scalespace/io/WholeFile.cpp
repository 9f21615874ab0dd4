#include "scalespace/io/WholeFile.hpp"

#include <filesystem>
#include <fstream>

#include "scalespace/core/Error.hpp"

namespace scalespace::io_detail {

std::string readWholeFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw FileError(path, "", "is a folder, not a file", "give the path of a file");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw FileError(path, "", "cannot open the file", "check that it exists and is readable");
  // One read of the whole file: the parsers work on memory, with every count checked against
  // this size. (Streams that cannot seek, e.g. pipes, fall back to reading chunk by chunk.)
  std::string data;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size > 0) {
    data.resize(std::size_t(size));
    in.read(data.data(), size);
    if (in.gcount() != size) throw FileError(path, "", "reading the file failed", "check the disk");
  } else {
    in.clear();
    char buffer[65536];
    while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0)
      data.append(buffer, std::size_t(in.gcount()));
  }
  if (in.bad()) throw FileError(path, "", "reading the file failed", "check the disk");
  return data;
}

}  // namespace scalespace::io_detail
