// Every file under tests/data/malformed/ (made by make_corpus.py, plus fuzzing crashers) must be
// rejected with a FileError naming the file: no crash, no hang, no huge allocation, no silent
// success. Runs under ASan+UBSan in CI.
#include <gtest/gtest.h>

#include <filesystem>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"

namespace scalespace {
namespace {

TEST(MalformedCorpus, EveryFileIsRejectedWithAFileErrorNamingIt) {
  const std::filesystem::path root = std::filesystem::path(SCALESPACE_TEST_DATA) / "malformed";
  std::size_t checked = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file() || entry.path().extension() == ".py") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    ++checked;
    for (const bool drop : {false, true}) {
      ReadOptions options;
      options.dropNonFinite = drop;
      try {
        const PointCloud cloud = readCloud(path, options);
        // With --drop-invalid a file whose only fault is NaN coordinates is legitimately read.
        const std::string name = entry.path().filename().string();
        const bool nonFiniteOnly =
            name.find("nan") != std::string::npos || name.find("inf") != std::string::npos;
        if (!(drop && nonFiniteOnly))
          ADD_FAILURE() << "read " << cloud.size() << " points without an error";
      } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      } catch (const std::exception& e) {
        ADD_FAILURE() << "not a FileError: " << e.what();
      }
    }
  }
  EXPECT_GE(checked, 90u);  // the corpus is there
}

TEST(MalformedCorpus, MeshSamplingRejectsTheMeshFilesToo) {
  const std::filesystem::path root = std::filesystem::path(SCALESPACE_TEST_DATA) / "malformed";
  for (const char* folder : {"off", "obj", "stl"}) {
    for (const auto& entry : std::filesystem::directory_iterator(root / folder)) {
      const std::string path = entry.path().string();
      SCOPED_TRACE(path);
      ReadOptions options;
      options.meshSamples = 10;
      EXPECT_THROW(readCloud(path, options), FileError);
    }
  }
}

}  // namespace
}  // namespace scalespace
