#pragma once
// The scale stack on disk (docs/STACK_FORMAT.md): a directory NAME.stack/ holding manifest.json
// and one NumPy .npy file per quantity, shaped (M, N), (M, N, 3) or (M, ceil(N / 8)) for
// bit-packed flags, so that numpy.load(f, mmap_mode='r')[j] is scale j and [:, i] is point i
// without our code. Two encodings: float32 (format version 1) and compact (version 3: float16 in
// units of t, octahedral frames, bit-packed flags, shared-exponent offsets and 8-bit log codes;
// version 2, with float16 offsets, anisotropy and nu, is still read; the pure codecs are in
// StackQuantization.hpp).
//
// Writing is atomic: everything goes to NAME.stack.tmp-<pid>/, each file is fsync'ed, the
// manifest is written last, and only then is the directory renamed to NAME.stack (an older stack
// of that name is replaced only once the new one is complete). A directory without a manifest is
// never accepted by the reader.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/scales/ScaleSpace.hpp"

namespace scalespace {

/// The newest format version this program writes and reads. Version 1: float32 only; version 2
/// adds the "encoding" key and the compact encoding; version 3 changes three compact files
/// (projection_offset, anisotropy, geometric_variation: 4 bytes less per point per scale, so that
/// 1M points x 50 scales fit in 1 GB). Float32 stacks are still written as version 1 (identical to
/// what older programs wrote and read); compact stacks are version 3. All three are read.
constexpr int kStackFormatVersion = 3;

/// How the per-scale quantities are stored (docs/STACK_FORMAT.md).
enum class StackEncoding {
  Compact,  // quantised, 19.125 bytes per point per scale (version 3; version 2: 23.125)
  Float32,  // every ScaleLayer field as float32 / uint16 / uint8, 83 bytes per point per scale
};
const char* stackEncodingName(StackEncoding encoding);
/// "compact" | "float32"; OptionError otherwise.
StackEncoding parseStackEncoding(const std::string& name);

/// How a stack is written (kept apart from ScaleSpaceOptions: it does not change the results).
struct StackWriteOptions {
  StackEncoding encoding = StackEncoding::Compact;
  /// Format version of a compact stack: 3, or 2 for the previous layout (for programs that read
  /// only versions 1 and 2, and for the tests of the version-2 reader). OptionError otherwise.
  int compactVersion = kStackFormatVersion;
};

/// Streams a stack to disk scale by scale (peak memory: one ScaleLayer).
class ScaleStackWriter {
 public:
  /// Creates NAME.stack.tmp-<pid>/ beside `path`; throws FileError if it cannot.
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

/// Computes the scale space of `cloud` and streams it into the stack `path`.
ScaleSpaceSummary computeScaleStack(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                    const std::string& path, const ProgressCallback& progress = {},
                                    const StackWriteOptions& write = {});

/// Writes an in-memory stack.
void writeScaleStack(const std::string& path, const PointCloud& cloud,
                     const ScaleSpaceOptions& options, const ScaleStack& stack,
                     const StackWriteOptions& write = {});

/// What the manifest says, besides the arrays.
struct StackInfo {
  int formatVersion = 0;
  StackEncoding encoding = StackEncoding::Float32;
  double bytesPerPointPerScale = 0;  // the per-scale files' data, divided by N
  std::size_t clampedValues = 0;     // compact: values clamped when written
  std::string programVersion;
  std::size_t pointCount = 0;
  std::vector<double> scales;
  std::vector<ScaleStats> stats;
  std::uint64_t inputChecksum = 0;
  Vec3 origin = Vec3::Zero();  // projections are stored relative to it
  std::string parametersJson;  // the options, as JSON text
  std::string manifestJson;    // the whole manifest, as JSON text
};

/// Random access to a stack without loading it: reads with pread at computed offsets.
class ScaleStackReader {
 public:
  /// Validates the manifest, every file's header, dtype, shape and size (FileError naming the
  /// file and the fix on any mismatch; a directory without manifest.json is an incomplete stack).
  explicit ScaleStackReader(const std::string& path);
  ~ScaleStackReader();
  ScaleStackReader(const ScaleStackReader&) = delete;
  ScaleStackReader& operator=(const ScaleStackReader&) = delete;

  const StackInfo& info() const;
  std::size_t pointCount() const { return info().pointCount; }
  std::size_t scaleCount() const { return info().scales.size(); }

  /// Scale j for every point (input order). A compact stack is decoded (docs/STACK_FORMAT.md):
  /// invalid fits read as zeros, never NaN.
  ScaleLayer readScale(std::size_t j) const;
  /// Point i at every scale: entry j of each array is scale j.
  ScaleLayer readPointSeries(std::size_t i) const;
  /// The input positions (absolute coordinates), in input order.
  std::vector<Vec3> inputPositions() const;

  /// Re-reads every file and compares its checksum with the manifest (FileError on mismatch).
  void verifyChecksums() const;
  /// FileError when `cloud` is not the input the stack was computed from.
  void checkInput(const PointCloud& cloud, const std::string& cloudName) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// True if `path` is a directory whose manifest.json says it is a scale stack (format
/// "scalespace-stack"): the only kind of existing path a stack writer replaces.
bool isScaleStack(const std::string& path);

}  // namespace scalespace
