#pragma once
// Shared by the fuzz targets of directory formats (fuzz_stack, fuzz_planes): a valid result is
// written once per process into a temporary directory; each input replaces one of its files
// (first byte: which one; the rest: the new content), the reader runs on the directory, and the
// file is put back. The directory is removed at exit.
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

namespace scalespace::fuzz {

/// A fresh directory under $TMPDIR (or /tmp) for this process, removed at exit.
inline std::filesystem::path processTempDir(const char* prefix) {
  static std::vector<std::filesystem::path> created;
  std::string pattern = (std::filesystem::temp_directory_path() / prefix).string() + ".XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) std::abort();
  if (created.empty())
    std::atexit([] {
      std::error_code ec;
      for (const auto& dir : created) std::filesystem::remove_all(dir, ec);
    });
  created.push_back(pattern);
  return pattern;
}

inline std::string readBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) std::abort();  // the generated result must be there
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeBytes(const std::filesystem::path& file, std::string_view bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) std::abort();
}

/// One file of a valid result: where it lies and its valid content.
struct TemplateFile {
  std::filesystem::path path;
  std::string bytes;
};

/// Every regular file directly in `dir`, sorted by name (a stable order for the selector byte).
inline std::vector<TemplateFile> templateFiles(const std::filesystem::path& dir) {
  std::vector<TemplateFile> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back({entry.path(), readBytes(entry.path())});
  std::sort(files.begin(), files.end(),
            [](const TemplateFile& a, const TemplateFile& b) { return a.path < b.path; });
  return files;
}

/// Writes the input's content over the file its first byte picks; the destructor puts the valid
/// content back, so that the next input starts from the valid result again.
class ReplacedFile {
 public:
  ReplacedFile(const std::vector<TemplateFile>& files, const std::uint8_t* data, std::size_t size)
      : file_(files[data[0] % files.size()]) {
    writeBytes(file_.path, std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1));
  }
  ~ReplacedFile() { writeBytes(file_.path, file_.bytes); }
  ReplacedFile(const ReplacedFile&) = delete;
  ReplacedFile& operator=(const ReplacedFile&) = delete;
  const TemplateFile& file() const { return file_; }

 private:
  const TemplateFile& file_;
};

/// Seeds: one per template file, its index byte followed by its valid content, named
/// DIR-FILE after the file's directory and name.
inline void writeSeeds(const std::vector<TemplateFile>& files, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  for (std::size_t k = 0; k < files.size(); ++k) {
    const auto& path = files[k].path;
    writeBytes(dir / (path.parent_path().filename().string() + "-" + path.filename().string()),
               std::string(1, char(k)) + files[k].bytes);
  }
}

/// Set by `SCALESPACE_FUZZ_SEEDS=DIR fuzz_X`: write the seeds into DIR and exit (make-seeds step).
inline void writeSeedsIfAsked(const std::vector<TemplateFile>& files) {
  if (const char* dir = std::getenv("SCALESPACE_FUZZ_SEEDS")) {
    writeSeeds(files, dir);
    std::exit(0);
  }
}

}  // namespace scalespace::fuzz
