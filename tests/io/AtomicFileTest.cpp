#include <gtest/gtest.h>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/AtomicFile.hpp"

namespace scalespace {
namespace {

using test::ScratchDir;

TEST(AtomicFile, WritesAndReplacesWithoutLeavingTemporaries) {
  ScratchDir dir;
  const std::string path = dir.file("out.txt");
  writeFileAtomically(path, [](std::ostream& out) { out << "first"; });
  EXPECT_EQ(test::readText(path), "first");
  writeFileAtomically(path, [](std::ostream& out) { out << "second"; });
  EXPECT_EQ(test::readText(path), "second");
  EXPECT_EQ(dir.entryCount(), 1u);
}

TEST(AtomicFile, ThrowingWriterLeavesTargetUntouchedAndNoTemporary) {
  ScratchDir dir;
  const std::string path = dir.file("out.txt");
  test::writeText(path, "original");
  EXPECT_THROW(writeFileAtomically(path,
                                   [](std::ostream& out) {
                                     out << "partial content";
                                     throw Cancelled();
                                   }),
               Cancelled);
  EXPECT_EQ(test::readText(path), "original");
  EXPECT_EQ(dir.entryCount(), 1u);
}

TEST(AtomicFile, MissingFoldersAreCreated) {
  ScratchDir dir;
  const std::string path = dir.file("no/such/folder/out.txt");
  writeFileAtomically(path, [](std::ostream& out) { out << "x"; });
  EXPECT_EQ(test::readText(path), "x");
}

TEST(AtomicFile, AFileInPlaceOfAFolderIsAFileErrorNamingThePath) {
  ScratchDir dir;
  writeFileAtomically(dir.file("plain"), [](std::ostream& out) { out << "keep"; });
  const std::string path = dir.file("plain/out.txt");
  try {
    writeFileAtomically(path, [](std::ostream& out) { out << "x"; });
    FAIL() << "expected FileError";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
  EXPECT_EQ(test::readText(dir.file("plain")), "keep");
  EXPECT_EQ(dir.entryCount(), 1u);
}

TEST(AtomicFile, RenameOntoAFolderFailsCleanly) {
  ScratchDir dir;
  const std::string path = dir.file("target");
  std::filesystem::create_directories(path + "/inside");
  EXPECT_THROW(writeFileAtomically(path, [](std::ostream& out) { out << "x"; }), FileError);
  EXPECT_TRUE(std::filesystem::is_directory(path));
  EXPECT_EQ(dir.entryCount(), 1u);
}

}  // namespace
}  // namespace scalespace
