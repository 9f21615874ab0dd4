#include "scalespace/features/LineRegularity.hpp"

#include <algorithm>
#include <cmath>

#include "scalespace/core/Error.hpp"

namespace scalespace {

LineRegularity lineRegularity(const CurvatureLine& line) {
  LineRegularity r;
  const auto& v = line.vertices;
  const std::size_t n = v.size();
  for (const CurvatureLineVertex& vertex : v)
    r.totalVariation += std::tanh(vertex.geometricVariation);
  if (n < 2) return r;
  for (std::size_t i = 0; i + 1 < n; ++i) r.length += (v[i + 1].position - v[i].position).norm();
  if (line.closed) r.length += (v[0].position - v[n - 1].position).norm();
  // The angle between consecutive steps at vertex i (Eq. 3.6); a closed line turns at every vertex.
  auto turnAt = [&](std::size_t prev, std::size_t at, std::size_t next) {
    const Vec3 a = v[at].position - v[prev].position, b = v[next].position - v[at].position;
    const double na = a.norm(), nb = b.norm();
    if (na == 0 || nb == 0) return 0.0;
    return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0));
  };
  for (std::size_t i = 1; i + 1 < n; ++i) r.totalCurvature += turnAt(i - 1, i, i + 1);
  if (line.closed && n >= 3) r.totalCurvature += turnAt(n - 2, n - 1, 0) + turnAt(n - 1, 0, 1);
  return r;
}

void validateLineFilterOptions(const LineFilterOptions& options) {
  auto check = [](double value, const char* name) {
    if (!(std::isfinite(value) && value >= 0))
      throw OptionError("LineFilterOptions::" + std::string(name) + " must be finite and >= 0");
  };
  check(options.minLengthFactor, "minLengthFactor");
  check(options.maxCurvatureFactor, "maxCurvatureFactor");
  check(options.maxMeanVariation, "maxMeanVariation");
}

bool isRegularLine(const CurvatureLine& line, double t, const LineFilterOptions& options) {
  const LineRegularity r = lineRegularity(line);
  return r.length >= options.minLengthFactor * t &&
         r.totalCurvature <= options.maxCurvatureFactor * r.length / t &&
         r.totalVariation <= options.maxMeanVariation * double(line.vertices.size());
}

}  // namespace scalespace
