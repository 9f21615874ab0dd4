#pragma once
// Writing the scale stack (the multi-scale representation of Sec. 1.5) to disk, in the format of
// docs/STACK_FORMAT.md: a directory NAME.stack/ holding manifest.json and one NumPy .npy file per
// quantity, in one of two encodings (StackEncoding.hpp).
//
// Writing is atomic: everything goes to NAME.stack.tmp-<pid>/, each file is fsync'ed, the
// manifest is written last, and only then is the directory renamed to NAME.stack (an older stack
// of that name is replaced only once the new one is complete). A directory without a manifest is
// never accepted by the reader (ScaleStackReader.hpp). computeScaleStackToDisk
// (ScaleStackCompute.hpp) computes and writes a stack scale by scale.
#include <cstddef>
#include <memory>
#include <string>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/scales/ScaleSpace.hpp"
#include "scalespace/scales/StackEncoding.hpp"

namespace scalespace {

/// How a stack is written (kept apart from ScaleSpaceOptions: it does not change the results).
struct StackWriteOptions {
  StackEncoding encoding = StackEncoding::Compact;
  /// Format version of a compact stack: 3, or 2 for the previous layout (for programs that read
  /// only versions 1 and 2, and for the tests of the version-2 reader). OptionError otherwise.
  int compactVersion = kStackFormatVersion;
};

/// FileError unless `path` is absent or a scale stack (isScaleStack): the only thing a stack writer
/// replaces. Callers check it before long work; the writer checks it again.
void checkStackDestination(const std::string& path);

/// Streams a stack to disk scale by scale (peak memory: one ScaleLayer).
class ScaleStackWriter {
 public:
  /// Creates NAME.stack.tmp-<pid>/ beside `path`; throws FileError if it cannot, or if `path`
  /// exists and is not a scale stack (isScaleStack): only a stack is ever replaced.
  ScaleStackWriter(const std::string& path, const PointCloud& cloud,
                   const ScaleSpaceOptions& options, std::size_t scaleCount,
                   const StackWriteOptions& write = {});
  /// Removes the temporary directory unless finish() succeeded.
  ~ScaleStackWriter();
  ScaleStackWriter(const ScaleStackWriter&) = delete;
  ScaleStackWriter& operator=(const ScaleStackWriter&) = delete;

  /// Appends scale j of scale value t (the compact encoding stores lengths in units of t); scales
  /// must come in order 0, 1, ..., scaleCount-1.
  void writeScale(std::size_t j, const ScaleLayer& layer, double t);
  /// Values clamped by the compact encoding so far (out of range or non-finite: float16 beyond
  /// +-65504, offsets beyond 4088 t, log codes above their range or negative;
  /// docs/STACK_FORMAT.md).
  std::size_t clampedValues() const;
  /// Writes the manifest (scales, stats, checksums), syncs and renames into place. Throws Error if
  /// the summary's scale values differ from those given to writeScale.
  void finish(const ScaleSpaceSummary& summary);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes an in-memory stack (computeScaleStackInMemory, ScaleSpace.hpp) to disk.
void writeScaleStack(const std::string& path, const PointCloud& cloud,
                     const ScaleSpaceOptions& options, const ScaleStack& stack,
                     const StackWriteOptions& write = {});

}  // namespace scalespace
