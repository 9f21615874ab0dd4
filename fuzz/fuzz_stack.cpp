// libFuzzer target for the scale-stack reader (ScaleStackReader, docs/STACK_FORMAT.md). At start-up
// three tiny valid stacks are computed (compact version 3, compact version 2, float32: 48 points,
// 3 scales); each input replaces one of their files (first byte: which one, over the three
// stacks; the rest: its new content), then the stack is opened and read every way the reader
// offers. Any input must either be read or throw scalespace::Error: no crash, hang or huge
// allocation. `SCALESPACE_FUZZ_SEEDS=fuzz/corpus/stack fuzz_stack` writes the seeds and exits.
#include <filesystem>
#include <vector>

#include "FuzzFiles.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/scales/ScaleStackIO.hpp"

namespace {

using scalespace::fuzz::TemplateFile;

// The files of every stack, stack after stack.
std::vector<TemplateFile> makeStacks() {
  scalespace::SceneOptions scene;
  scene.pointCount = 48;
  const scalespace::PointCloud cloud = scalespace::generateScene(scalespace::SceneKind::Box, scene);
  scalespace::ScaleSpaceOptions options;
  options.series.count = 3;
  options.threads = 1;
  const std::filesystem::path root = scalespace::fuzz::processTempDir("fuzz_stack");
  struct Variant {
    const char* name;
    scalespace::StackWriteOptions write;
  };
  const Variant variants[] = {
      {"compact3.stack", {scalespace::StackEncoding::Compact, 3}},
      {"compact2.stack", {scalespace::StackEncoding::Compact, 2}},
      {"float32.stack", {scalespace::StackEncoding::Float32, 3}},
  };
  std::vector<TemplateFile> files;
  for (const Variant& v : variants) {
    const std::filesystem::path dir = root / v.name;
    scalespace::computeScaleStack(cloud, options, dir.string(), {}, v.write);
    for (auto& file : scalespace::fuzz::templateFiles(dir)) files.push_back(std::move(file));
  }
  return files;
}

const std::vector<TemplateFile>& stackFiles() {
  static const std::vector<TemplateFile> files = makeStacks();
  return files;
}

// Everything a reader of a stack can ask; returns normally or throws scalespace::Error.
void readEverything(const std::string& dir) {
  if (!scalespace::isScaleStack(dir)) std::abort();  // the manifest is always there
  const scalespace::ScaleStackReader reader(dir);
  const scalespace::StackInfo& info = reader.info();
  const std::size_t n = reader.pointCount(), m = reader.scaleCount();
  if (info.scales.size() != m || info.stats.size() != m) std::abort();
  for (std::size_t j = 0; j < m; ++j)
    if (reader.readScale(j).size() != n) std::abort();
  if (n > 0)
    for (const std::size_t i : {std::size_t(0), n / 2, n - 1})
      if (reader.readPointSeries(i).size() != m) std::abort();
  if (reader.inputPositions().size() != n) std::abort();
  reader.verifyChecksums();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  scalespace::fuzz::writeSeedsIfAsked(stackFiles());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const scalespace::fuzz::ReplacedFile replaced(stackFiles(), data, size);
  try {
    readEverything(replaced.file().path.parent_path().string());
  } catch (const scalespace::Error&) {
  }
  return 0;
}
