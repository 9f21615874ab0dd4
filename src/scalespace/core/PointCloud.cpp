#include "scalespace/core/PointCloud.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "scalespace/core/Error.hpp"

namespace scalespace {

const char* scalarTypeName(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
      return "int8";
    case ScalarType::UInt8:
      return "uint8";
    case ScalarType::Int16:
      return "int16";
    case ScalarType::UInt16:
      return "uint16";
    case ScalarType::Int32:
      return "int32";
    case ScalarType::UInt32:
      return "uint32";
    case ScalarType::Float32:
      return "float32";
    case ScalarType::Float64:
      return "float64";
  }
  return "unknown";
}

std::size_t scalarTypeSize(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
    case ScalarType::UInt8:
      return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16:
      return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32:
      return 4;
    case ScalarType::Float64:
      return 8;
  }
  return 0;
}

bool isIntegerType(ScalarType type) {
  return type != ScalarType::Float32 && type != ScalarType::Float64;
}

void PointCloud::setAbsolutePositions(const std::vector<Vec3>& absolute) {
  setAbsolutePositions(absolute.data(), absolute.size());
}

namespace {

// Large inputs (a NumPy array of 1M points, a reader's buffer) are bounded and copied in parallel
// blocks: the copy is memory-bound and its page faults are paid per thread. Min and max are exact
// in any order, so the origin does not depend on the thread count.
constexpr std::size_t kCopyGrain = std::size_t(1) << 15;

struct Bounds {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void add(const Bounds& o) {
    lo = lo.cwiseMin(o.lo);
    hi = hi.cwiseMax(o.hi);
  }
  bool empty() const { return !(lo.array() <= hi.array()).all(); }
};

Bounds finiteBounds(const Vec3* points, std::size_t count) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, count, kCopyGrain), Bounds(),
      [&](const tbb::blocked_range<std::size_t>& r, Bounds b) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
          if (points[i].allFinite()) b.add(points[i]);  // readers reject the others; be defensive
        return b;
      },
      [](Bounds a, const Bounds& b) {
        a.add(b);
        return a;
      });
}

void copyShifted(const Vec3* from, std::size_t count, const Vec3& shift, std::vector<Vec3>& to) {
  to.resize(count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kCopyGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) to[i] = from[i] - shift;
                    });
}

}  // namespace

void PointCloud::setAbsolutePositions(const Vec3* absolute, std::size_t count) {
  const Bounds b = finiteBounds(absolute, count);
  if (b.empty())
    setAbsolutePositions(absolute, count, Vec3::Zero(), Vec3::Zero());
  else
    setAbsolutePositions(absolute, count, b.lo, b.hi);
}

void PointCloud::setAbsolutePositions(const Vec3* absolute, std::size_t count, const Vec3& lo,
                                      const Vec3& hi) {
  // An integer origin keeps p - origin exact (both are multiples of ulp(p) and |p - o| <= |p|
  // whenever the cloud does not straddle far from its centre); small clouds keep origin 0.
  const Vec3 centre = count == 0 ? Vec3::Zero() : Vec3(0.5 * lo + 0.5 * hi);  // lo + hi: overflow
  origin_ = centre.cwiseAbs().maxCoeff() < 1e3 ? Vec3::Zero() : Vec3(centre.array().round());
  copyShifted(absolute, count, origin_, positions_);
  resizeColumns();
}

void PointCloud::setRelativePositions(std::vector<Vec3> relative, const Vec3& origin) {
  positions_ = std::move(relative);
  origin_ = origin;
  resizeColumns();
}

void PointCloud::setNormals(std::vector<Vec3> normals) {
  if (!normals.empty() && normals.size() != positions_.size())
    throw Error("PointCloud::setNormals: " + std::to_string(normals.size()) + " normals for " +
                std::to_string(positions_.size()) + " points");
  normals_ = std::move(normals);
}

void PointCloud::setNormals(const Vec3* normals, std::size_t count) {
  if (count != positions_.size())
    throw Error("PointCloud::setNormals: " + std::to_string(count) + " normals for " +
                std::to_string(positions_.size()) + " points");
  copyShifted(normals, count, Vec3::Zero(), normals_);
}

PointCloud::PointCloud(Storage storage)
    : positions_(std::move(storage.positions)), normals_(std::move(storage.normals)) {
  positions_.clear();  // keeps the capacity: the point of taking the storage
  normals_.clear();
}

PointCloud::Storage PointCloud::releaseStorage() {
  Storage storage{std::move(positions_), std::move(normals_)};
  *this = PointCloud();
  storage.positions.clear();
  storage.normals.clear();
  return storage;
}

PointCloud::PointCloud(const PointCloud& other)
    : positions_(other.positions_),
      normals_(other.normals_),
      origin_(other.origin_),
      viewpoint_(other.viewpoint_) {
  attributes_.reserve(other.attributes_.size());
  for (const auto& a : other.attributes_)
    attributes_.push_back(std::make_unique<AttributeColumn>(*a));
}

PointCloud& PointCloud::operator=(const PointCloud& other) {
  if (this != &other) *this = PointCloud(other);
  return *this;
}

void PointCloud::setAttributes(std::vector<AttributeColumn> columns) {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].values.size() != size())
      throw Error("PointCloud::setAttributes: column '" + columns[c].name + "' has " +
                  std::to_string(columns[c].values.size()) + " values for " +
                  std::to_string(size()) + " points");
    for (std::size_t d = 0; d < c; ++d)
      if (columns[d].name == columns[c].name)
        throw Error("PointCloud::setAttributes: two columns are named '" + columns[c].name + "'");
  }
  attributes_.clear();
  for (auto& c : columns) attributes_.push_back(std::make_unique<AttributeColumn>(std::move(c)));
}

const AttributeColumn* PointCloud::findAttribute(const std::string& name) const {
  for (const auto& a : attributes_)
    if (a->name == name) return a.get();
  return nullptr;
}

AttributeColumn* PointCloud::findAttribute(const std::string& name) {
  for (auto& a : attributes_)
    if (a->name == name) return a.get();
  return nullptr;
}

AttributeColumn& PointCloud::addAttribute(const std::string& name, ScalarType type, double fill) {
  if (AttributeColumn* existing = findAttribute(name)) {
    existing->type = type;
    existing->values.resize(size(), fill);
    return *existing;
  }
  attributes_.push_back(std::make_unique<AttributeColumn>(
      AttributeColumn{name, type, std::vector<double>(size(), fill)}));
  return *attributes_.back();
}

bool PointCloud::removeAttribute(const std::string& name) {
  auto it = std::find_if(attributes_.begin(), attributes_.end(),
                         [&](const auto& a) { return a->name == name; });
  if (it == attributes_.end()) return false;
  attributes_.erase(it);
  return true;
}

PointCloud PointCloud::subset(const std::vector<Index>& indices) const {
  PointCloud out;
  std::vector<Vec3> pos(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) pos[k] = positions_.at(indices[k]);
  out.setRelativePositions(std::move(pos), origin_);
  out.viewpoint_ = viewpoint_;
  if (hasNormals()) {
    std::vector<Vec3> nrm(indices.size());
    for (std::size_t k = 0; k < indices.size(); ++k) nrm[k] = normals_[indices[k]];
    out.setNormals(std::move(nrm));
  }
  for (const auto& a : attributes_) {
    AttributeColumn& c = out.addAttribute(a->name, a->type);
    for (std::size_t k = 0; k < indices.size(); ++k) c.values[k] = a->values[indices[k]];
  }
  return out;
}

void PointCloud::bounds(Vec3& lo, Vec3& hi) const {
  lo = hi = Vec3::Zero();
  if (positions_.empty()) return;
  lo = hi = positions_[0];
  for (const Vec3& p : positions_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

double PointCloud::boundingBoxDiagonal() const {
  Vec3 lo, hi;
  bounds(lo, hi);
  return (hi - lo).norm();
}

void PointCloud::resizeColumns() {
  if (!normals_.empty()) normals_.resize(positions_.size(), Vec3::UnitZ());
  for (auto& a : attributes_) a->values.resize(positions_.size(), 0.0);
}

}  // namespace scalespace
