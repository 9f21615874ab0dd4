#pragma once
// Reading a scale stack written by ScaleStackWriter (docs/STACK_FORMAT.md): random access by scale
// (readScale: scale j of every point) and by point (readPointSeries: point i at every scale)
// without loading the stack, the multi-scale representation of Sec. 1.5 being up to gigabytes.
// The same files are readable without our code: numpy.load(f, mmap_mode='r')[j] is scale j and
// [:, i] is point i (scripts/read_stack.py decodes the compact encoding).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/scales/ScaleSpace.hpp"
#include "scalespace/scales/StackEncoding.hpp"

namespace scalespace {

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
