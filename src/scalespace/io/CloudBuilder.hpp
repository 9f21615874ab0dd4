#pragma once
// Accumulates the points a reader decodes (internal to the io layer) and applies the policy every
// reader shares: non-finite (or absurdly large, see kMaxCoordinate) coordinates throw a FileError
// naming the point's place in the file or, with ReadOptions::dropNonFinite, skip the point and
// count it.
#include <string>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/ReadOptions.hpp"

namespace scalespace::io_detail {

/// Coordinates beyond this magnitude are treated like NaN/Inf: no real cloud has them (1e100 m
/// dwarfs the observable universe in any unit), and accepting them would let recentring and the
/// squared distances of later layers overflow to infinity.
constexpr double kMaxCoordinate = 1e100;

inline bool isUsablePosition(const Vec3& p) {
  return p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxCoordinate;
}

class CloudBuilder {
 public:
  CloudBuilder(const std::string& file, const ReadOptions& options)
      : file_(file), dropNonFinite_(options.dropNonFinite) {}

  /// Declares an attribute column; returns its index for addPoint's `values`. Throws FileError on
  /// a duplicate name (a column would silently shadow another).
  std::size_t addColumn(const std::string& name, ScalarType type);
  void enableNormals() { withNormals_ = true; }
  bool hasNormals() const { return withNormals_; }
  std::size_t columnCount() const { return columns_.size(); }
  /// Capacity hint; callers pass a count already checked against the file size.
  void reserve(std::size_t points);

  /// Adds one point (`values` holds columnCount() values, `normal` is ignored without normals).
  /// `where` is called only for an error message, e.g. [&] { return lineWhere(n); }.
  template <class Where>
  bool addPoint(const Vec3& position, const Vec3& normal, const double* values, Where&& where) {
    if (!isUsablePosition(position)) {
      if (dropNonFinite_) {
        if (recordDrops_) droppedOrdinals_.push_back(positions_.size() + dropped_);
        ++dropped_;
        return false;
      }
      rejectNonFinite(where());
    }
    positions_.push_back(position);
    if (withNormals_) normals_.push_back(normal);
    for (std::size_t c = 0; c < columns_.size(); ++c) columns_[c].values.push_back(values[c]);
    return true;
  }

  /// From now on, keeps the 0-based file order of each point skipped: readers that also hand back
  /// indices into the points (PLY faces and edges) renumber with it. Off by default: a scan that
  /// is mostly NaN (an organised PCD) would otherwise pay 8 bytes per dropped point for nothing.
  void recordDroppedOrdinals() { recordDrops_ = true; }
  /// The points skipped since recordDroppedOrdinals().
  const std::vector<std::size_t>& droppedOrdinals() const { return droppedOrdinals_; }

  /// Moves everything into a PointCloud (recentred positions) and fills `report` if given.
  PointCloud finish(ReadReport* report, const std::string& formatDescription);

 private:
  [[noreturn]] void rejectNonFinite(const std::string& where) const;
  const std::string& file_;
  bool dropNonFinite_;
  bool withNormals_ = false;
  bool recordDrops_ = false;
  std::size_t dropped_ = 0;
  std::vector<std::size_t> droppedOrdinals_;
  std::vector<Vec3> positions_;
  std::vector<Vec3> normals_;
  std::vector<AttributeColumn> columns_;
};

}  // namespace scalespace::io_detail
