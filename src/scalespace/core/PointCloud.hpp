#pragma once
// PointCloud: positions, optional normals and named per-point attribute columns.
//
// Positions are stored relative to origin() ("recentred"): georeferenced clouds have coordinates
// around 1e6 where fits lose digits. The origin is an integer (rounded bounding-box centre), so
// p - origin and (p - origin) + origin are exact in double precision: no loss on a round trip.
// Readers call setAbsolutePositions(); writers use absolutePosition(i).
#include <iterator>
#include <memory>
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

/// Read-only view of a cloud's columns, in order (what writers iterate). Each column lives in its
/// own allocation, so a column's address never changes while it exists: see PointCloud.
class AttributeColumns {
 public:
  using Storage = std::vector<std::unique_ptr<AttributeColumn>>;
  class const_iterator {
   public:
    using iterator_category = std::random_access_iterator_tag;
    using value_type = AttributeColumn;
    using difference_type = std::ptrdiff_t;
    using pointer = const AttributeColumn*;
    using reference = const AttributeColumn&;
    explicit const_iterator(Storage::const_iterator it) : it_(it) {}
    reference operator*() const { return **it_; }
    pointer operator->() const { return it_->get(); }
    const_iterator& operator++() {
      ++it_;
      return *this;
    }
    difference_type operator-(const const_iterator& o) const { return it_ - o.it_; }
    bool operator==(const const_iterator& o) const { return it_ == o.it_; }
    bool operator!=(const const_iterator& o) const { return it_ != o.it_; }

   private:
    Storage::const_iterator it_;
  };

  explicit AttributeColumns(const Storage& columns) : columns_(&columns) {}
  std::size_t size() const { return columns_->size(); }
  bool empty() const { return columns_->empty(); }
  const AttributeColumn& operator[](std::size_t i) const { return *(*columns_)[i]; }
  const AttributeColumn& front() const { return *columns_->front(); }
  const AttributeColumn& back() const { return *columns_->back(); }
  const_iterator begin() const { return const_iterator(columns_->begin()); }
  const_iterator end() const { return const_iterator(columns_->end()); }

 private:
  const Storage* columns_;
};

/// A normal a fit can use: finite and of non-negligible length (squared norm above 1e-12).
inline bool isUsableNormal(const Vec3& n) { return n.allFinite() && n.squaredNorm() > 1e-12; }

/// Columns are created and changed through addAttribute / findAttribute, whose references and
/// pointers stay valid until that column is removed (removeAttribute, setAttributes) or the cloud
/// is destroyed or assigned: adding more columns never moves the existing ones. (A vector of
/// columns did move them, and a caller holding references across addAttribute read freed memory.)
class PointCloud {
 public:
  PointCloud() = default;
  PointCloud(const PointCloud& other);
  PointCloud& operator=(const PointCloud& other);
  PointCloud(PointCloud&&) noexcept = default;
  PointCloud& operator=(PointCloud&&) noexcept = default;

  /// The memory of a cloud's positions and normals, without their contents. A caller that builds
  /// clouds of similar sizes over and over (the Python bindings copy every call's arrays in) hands
  /// one cloud's storage to the next, whose setAbsolutePositions / setNormals then fill memory the
  /// process has already touched instead of allocating fresh blocks: glibc maps blocks of tens of
  /// MB in for each allocation and out at each free, and the page faults cost more than the copy.
  struct Storage {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;
    std::size_t bytes() const { return (positions.capacity() + normals.capacity()) * sizeof(Vec3); }
  };
  /// An empty cloud (no points, no normals) whose setters fill `storage` while it is large enough.
  explicit PointCloud(Storage storage);
  /// Empties the cloud (points, normals, columns, origin) and returns its positions' and normals'
  /// memory for the next cloud.
  Storage releaseStorage();

  std::size_t size() const { return positions_.size(); }
  bool empty() const { return positions_.empty(); }

  /// Replaces all positions with absolute coordinates and recentres them (see file comment).
  /// Attribute columns and normals are resized to the new size.
  void setAbsolutePositions(const std::vector<Vec3>& absolute);
  /// Same from `count` packed positions (x y z doubles), e.g. a NumPy array's buffer, which then
  /// needs no intermediate vector.
  void setAbsolutePositions(const Vec3* absolute, std::size_t count);
  /// Same when the caller has already scanned the points (e.g. to check them) and passes the
  /// bounds of the finite ones, `lo` and `hi` (ignored when count is 0): this saves the
  /// overload above its own pass over the input. The cloud is the same, origin included.
  void setAbsolutePositions(const Vec3* absolute, std::size_t count, const Vec3& lo,
                            const Vec3& hi);
  /// Positions relative to origin(); what every algorithm works on.
  const std::vector<Vec3>& positions() const { return positions_; }
  std::vector<Vec3>& positions() { return positions_; }
  const Vec3& origin() const { return origin_; }
  Vec3 absolutePosition(std::size_t i) const { return positions_[i] + origin_; }
  /// Sets positions already relative to `origin` (e.g. a subset of another cloud).
  void setRelativePositions(std::vector<Vec3> relative, const Vec3& origin);

  /// Where the points were seen from (a scanner's position, absolute coordinates), when the
  /// file says so (a PCD's VIEWPOINT): a single scan's surfaces face it, so estimated normals are
  /// oriented to (NormalOrientationOptions::faceViewpoint).
  const std::optional<Vec3>& viewpoint() const { return viewpoint_; }
  void setViewpoint(std::optional<Vec3> viewpoint) { viewpoint_ = viewpoint; }

  bool hasNormals() const { return !normals_.empty(); }
  const std::vector<Vec3>& normals() const { return normals_; }
  std::vector<Vec3>& normals() { return normals_; }
  /// Sets normals (size must equal size()); pass an empty vector to remove them.
  void setNormals(std::vector<Vec3> normals);
  /// Same from `count` (= size()) packed normals, e.g. a NumPy array's buffer.
  void setNormals(const Vec3* normals, std::size_t count);

  AttributeColumns attributes() const { return AttributeColumns(attributes_); }
  /// Replaces every column (each of size() values, names unique; Error otherwise).
  void setAttributes(std::vector<AttributeColumn> columns);
  const AttributeColumn* findAttribute(const std::string& name) const;
  AttributeColumn* findAttribute(const std::string& name);
  /// Adds a column of size() values (initialised to `fill`), or returns the existing column of that
  /// name after converting it to `type` and resizing it. The reference stays valid when more
  /// columns are added (see the class comment).
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
  AttributeColumns::Storage attributes_;
  Vec3 origin_ = Vec3::Zero();
  std::optional<Vec3> viewpoint_;
};

}  // namespace scalespace
