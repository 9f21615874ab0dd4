#pragma once
// PointCloud: positions, optional normals and named per-point attribute columns.
//
// Positions are stored relative to origin() ("recentred"): georeferenced clouds have coordinates
// around 1e6 where fits lose digits. The origin is an integer (rounded bounding-box centre), so
// p - origin and (p - origin) + origin are exact in double precision: no loss on a round trip.
// Readers call setAbsolutePositions(); writers use absolutePosition(i).
#include <optional>
#include <string>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

/// The type a column has (or had) on file. Values are held as double, which is exact for every
/// type listed, so a read/write round trip restores the values bit for bit.
enum class ScalarType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

const char* scalarTypeName(ScalarType type);  // "int8", "uint8", ..., "float32", "float64"
std::size_t scalarTypeSize(ScalarType type);  // bytes on file
bool isIntegerType(ScalarType type);

struct AttributeColumn {
  std::string name;
  ScalarType type = ScalarType::Float32;
  std::vector<double> values;  // one per point
};

class PointCloud {
 public:
  std::size_t size() const { return positions_.size(); }
  bool empty() const { return positions_.empty(); }

  /// Replaces all positions with absolute coordinates and recentres them (see file comment).
  /// Attribute columns and normals are resized to the new size.
  void setAbsolutePositions(const std::vector<Vec3>& absolute);
  /// Positions relative to origin(); what every algorithm works on.
  const std::vector<Vec3>& positions() const { return positions_; }
  std::vector<Vec3>& positions() { return positions_; }
  const Vec3& origin() const { return origin_; }
  Vec3 absolutePosition(std::size_t i) const { return positions_[i] + origin_; }
  /// Sets positions already relative to `origin` (e.g. a subset of another cloud).
  void setRelativePositions(std::vector<Vec3> relative, const Vec3& origin);

  bool hasNormals() const { return !normals_.empty(); }
  const std::vector<Vec3>& normals() const { return normals_; }
  std::vector<Vec3>& normals() { return normals_; }
  /// Sets normals (size must equal size()); pass an empty vector to remove them.
  void setNormals(std::vector<Vec3> normals);

  const std::vector<AttributeColumn>& attributes() const { return attributes_; }
  std::vector<AttributeColumn>& attributes() { return attributes_; }
  const AttributeColumn* findAttribute(const std::string& name) const;
  AttributeColumn* findAttribute(const std::string& name);
  /// Adds a column of size() values (initialised to `fill`), or returns the existing column of that
  /// name after converting it to `type` and resizing it.
  AttributeColumn& addAttribute(const std::string& name, ScalarType type, double fill = 0.0);
  bool removeAttribute(const std::string& name);

  /// Keeps the points listed in `indices` (in that order), with their normals and attributes.
  PointCloud subset(const std::vector<Index>& indices) const;

  /// Axis-aligned bounds of the relative positions; {0,0} for an empty cloud.
  void bounds(Vec3& lo, Vec3& hi) const;
  double boundingBoxDiagonal() const;

 private:
  void resizeColumns();
  std::vector<Vec3> positions_;
  std::vector<Vec3> normals_;
  std::vector<AttributeColumn> attributes_;
  Vec3 origin_ = Vec3::Zero();
};

}  // namespace scalespace
