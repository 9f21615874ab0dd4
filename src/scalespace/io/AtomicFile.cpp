#include "scalespace/io/AtomicFile.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/FileSync.hpp"

namespace scalespace {

namespace {

std::string temporaryPathFor(const std::string& path) {
  // pid + random suffix: two processes (or two threads) writing the same target never share a
  // temporary file.
  std::random_device device;
  std::ostringstream name;
  name << path << ".tmp-" << ::getpid() << '-' << std::hex << device() << device();
  return name.str();
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  // Missing folders are created, as the stack and planes writers create theirs: one rule for
  // every output.
  const fs::path parent = fs::path(path).parent_path();
  std::error_code created;
  if (!parent.empty()) fs::create_directories(parent, created);
  if (created)
    throw FileError(path, "",
                    "cannot create the folder " + parent.string() + ": " + created.message());
  const std::string temporary = temporaryPathFor(path);
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out)
    throw FileError(path, "", "cannot create the temporary file " + temporary,
                    "check that the output folder exists and is writable");
  const auto removeTemporary = [&] {
    std::error_code ignored;
    fs::remove(temporary, ignored);
  };
  try {
    write(out);
    out.flush();
    if (!out) throw FileError(path, "", "writing failed", "check free disk space and permissions");
    out.close();
    if (out.fail())
      throw FileError(path, "", "closing the file failed", "check free disk space and permissions");
  } catch (...) {
    if (out.is_open()) out.close();
    removeTemporary();
    throw;
  }
  // fsync before the rename, so that it never exposes a file whose content is only in the page
  // cache (core/FileSync.hpp).
  syncPath(temporary);
  std::error_code ec;
  fs::rename(temporary, path, ec);
  if (ec) {
    removeTemporary();
    throw FileError(path, "", "cannot replace the file: " + ec.message(),
                    "check that the path is not a folder and that it is writable");
  }
}

}  // namespace scalespace
