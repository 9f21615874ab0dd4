#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/FileSync.hpp"

namespace scalespace {
namespace {

// A file of the temporary folder, named after the process and the test, removed on destruction.
struct ScratchFile {
  explicit ScratchFile(const std::string& name)
      : path((std::filesystem::temp_directory_path() /
              ("scalespace-filesync-" + std::to_string(::getpid()) + "-" + name))
                 .string()) {}
  ~ScratchFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
  std::string path;
};

TEST(FileSync, WriteAllThenPreadAllRoundTripAtAnyOffset) {
  const ScratchFile scratch("roundtrip");
  std::vector<unsigned char> data(1 << 20);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>(i * 7 + 3);
  const int out = ::open(scratch.path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(out, 0);
  writeAll(out, data.data(), data.size(), scratch.path);
  ::close(out);
  syncPath(scratch.path);
  syncPath(std::filesystem::temp_directory_path().string());  // a directory is synced too

  const int in = ::open(scratch.path.c_str(), O_RDONLY);
  ASSERT_GE(in, 0);
  std::vector<unsigned char> back(data.size() - 1001);
  preadAll(in, back.data(), back.size(), 1001, scratch.path, "");
  EXPECT_TRUE(std::equal(back.begin(), back.end(), data.begin() + 1001));
  ::close(in);
}

TEST(FileSync, ReadingPastTheEndIsAFileErrorNamingTheFileOffsetAndFix) {
  const ScratchFile scratch("short");
  const int out = ::open(scratch.path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(out, 0);
  writeAll(out, "0123456789", 10, scratch.path);
  ::close(out);
  const int in = ::open(scratch.path.c_str(), O_RDONLY);
  ASSERT_GE(in, 0);
  char buf[8];
  try {
    preadAll(in, buf, sizeof buf, 6, scratch.path, "recompute it");
    FAIL() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), scratch.path);
    const std::string what = e.what();
    EXPECT_NE(what.find("byte 10"), std::string::npos) << what;  // where the data ran out
    EXPECT_NE(what.find("recompute it"), std::string::npos) << what;
  }
  ::close(in);
}

TEST(FileSync, WritingToABadDescriptorIsAFileErrorNamingTheFile) {
  EXPECT_THROW(writeAll(-1, "x", 1, "some/file"), FileError);
  try {
    writeAll(-1, "x", 1, "some/file");
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), "some/file");
  }
}

TEST(FileSync, SyncingAMissingPathIsANoOp) {
  EXPECT_NO_THROW(syncPath("/no/such/path/for/scalespace"));
}

}  // namespace
}  // namespace scalespace
