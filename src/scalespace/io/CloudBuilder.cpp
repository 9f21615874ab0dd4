#include "scalespace/io/CloudBuilder.hpp"

namespace scalespace::io_detail {

std::size_t CloudBuilder::addColumn(const std::string& name, ScalarType type) {
  for (const auto& c : columns_)
    if (c.name == name)
      throw FileError(file_, "", "two columns are named '" + name + "'",
                      "rename one of them: column names must be unique");
  columns_.push_back(AttributeColumn{name, type, {}});
  return columns_.size() - 1;
}

void CloudBuilder::reserve(std::size_t points) {
  positions_.reserve(points);
  if (withNormals_) normals_.reserve(points);
  for (auto& c : columns_) c.values.reserve(points);
}

void CloudBuilder::rejectNonFinite(const std::string& where) const {
  throw FileError(file_, where,
                  "point " + std::to_string(positions_.size() + dropped_ + 1) +
                      " has a NaN, infinite or absurdly large (beyond 1e100) coordinate",
                  "skip such points with ReadOptions::dropNonFinite");
}

PointCloud CloudBuilder::finish(ReadReport* report, const std::string& formatDescription) {
  PointCloud cloud;
  cloud.setAbsolutePositions(positions_);
  positions_ = {};
  // Normals are kept as read, even when some are zero or NaN: the cloud then "has normals" and
  // callers that need valid ones check them (or re-estimate them, e.g. the CLI's --normals).
  if (withNormals_) cloud.setNormals(std::move(normals_));
  cloud.setAttributes(std::move(columns_));
  if (report) {
    report->droppedNonFinite = dropped_;
    report->format = formatDescription;
  }
  return cloud;
}

}  // namespace scalespace::io_detail
