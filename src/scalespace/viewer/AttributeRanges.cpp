#include "scalespace/viewer/AttributeRanges.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace scalespace::viewer {

namespace {

// min, max, 2nd and 98th percentiles of the finite values (all 0 when there are none).
nlohmann::json columnRange(const AttributeColumn& column) {
  std::vector<double> v;
  v.reserve(column.values.size());
  for (double x : column.values)
    if (std::isfinite(x)) v.push_back(x);
  if (v.empty()) return {{"min", 0}, {"max", 0}, {"p02", 0}, {"p98", 0}};
  auto at = [&](double q) {
    const auto k = std::size_t(q * double(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
  };
  const double p02 = at(0.02), p98 = at(0.98);
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return {{"min", *lo}, {"max", *hi}, {"p02", p02}, {"p98", p98}};
}

}  // namespace

nlohmann::json attributeRanges(const PointCloud& cloud) {
  nlohmann::json out = nlohmann::json::array();
  for (const AttributeColumn& column : cloud.attributes()) {
    nlohmann::json a = columnRange(column);
    a["name"] = column.name;
    a["type"] = scalarTypeName(column.type);
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace scalespace::viewer
