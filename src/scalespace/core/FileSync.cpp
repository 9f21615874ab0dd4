#include "scalespace/core/FileSync.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "scalespace/core/Error.hpp"

namespace scalespace {

void syncPath(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void writeAll(int fd, const void* data, std::size_t size, const std::string& file) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t w = ::write(fd, p, size);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw FileError(file, "", std::string("cannot write: ") + std::strerror(errno),
                      "check free disk space and permissions");
    }
    p += w;
    size -= std::size_t(w);
  }
}

void preadAll(int fd, void* data, std::size_t size, std::uint64_t offset, const std::string& file,
              const std::string& fix) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t r = ::pread(fd, p, size, off_t(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0)
      throw FileError(file, "byte " + std::to_string(offset),
                      "unexpected end of file or read error", fix);
    p += r;
    size -= std::size_t(r);
    offset += std::uint64_t(r);
  }
}

}  // namespace scalespace
