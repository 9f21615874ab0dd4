#include "scalespace/planes/PlaneQueries.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "scalespace/core/Error.hpp"

namespace scalespace {

PlaneModel makePlaneModel(const PlaneDetection& detection) {
  PlaneModel model;
  const RegionGraph& g = detection.graph;
  for (const auto& level : g.levels) model.scales.push_back(level.t);
  model.components = detection.components;
  model.membership = pointMembership(g);
  model.planaritySplit = detection.planaritySplit;
  return model;
}

namespace {
void checkIndices(const PlaneModel& model, const std::vector<Index>& indices, const char* what) {
  for (Index i : indices)
    if (i >= model.membership.pointCount)
      throw OptionError(std::string(what) + ": point index " + std::to_string(i) +
                        " is out of range (the cloud has " +
                        std::to_string(model.membership.pointCount) + " points)");
}

std::set<int> componentsHolding(const PlaneModel& model, const std::vector<Index>& points) {
  std::set<int> out;
  for (Index i : points)
    for (int j = 0; j < model.membership.levelCount; ++j) {
      const int c = model.membership.at(j, i);
      if (c >= 0) out.insert(c);
    }
  return out;
}
}  // namespace

namespace {
std::vector<int> persistenceOf(const PlaneModel& model) {
  std::vector<int> p;
  for (const PlaneComponent& c : model.components) p.push_back(c.persistence);
  return p;
}
}  // namespace

std::vector<int> labelsByPersistence(const PlaneModel& model, int minPersistence) {
  if (!model.planaritySplit)
    return labelsByPersistence(model.membership, persistenceOf(model), minPersistence);
  std::vector<std::uint8_t> planar;
  for (const PlaneComponent& c : model.components) planar.push_back(c.planar);
  return labelsByPersistence(model.membership, persistenceOf(model), minPersistence, &planar);
}

int nearestLevel(const PlaneModel& model, double t) {
  if (model.scales.empty()) throw OptionError("the plane model has no scales");
  if (!(t > 0)) throw OptionError("labelsAtScale: the scale t must be > 0");
  return nearestScaleIndex(model.scales, t);
}

std::vector<int> labelsAtScale(const PlaneModel& model, double t, int minPersistence) {
  return labelsAtLevel(model.membership, persistenceOf(model), nearestLevel(model, t),
                       minPersistence);
}

std::vector<int> labelsOfComponents(const PlaneModel& model, const std::vector<int>& ids) {
  for (int c : ids)
    if (c < 0 || std::size_t(c) >= model.components.size())
      throw OptionError("labelsOfComponents: no component " + std::to_string(c) +
                        " (the model has " + std::to_string(model.components.size()) + ")");
  std::vector<int> labels(model.membership.pointCount, -1);
  for (int c : ids) {
    const int level = model.components[std::size_t(c)].representativeLevel;
    for (std::size_t i = 0; i < labels.size(); ++i)
      if (labels[i] < 0 && model.membership.at(level, i) == c) labels[i] = c;
  }
  return labels;
}

std::vector<BrushMatch> rankByBrush(const PlaneModel& model, const std::vector<Index>& query) {
  checkIndices(model, query, "brush");
  const std::vector<Index> unique = [&] {
    std::vector<Index> q = query;
    std::sort(q.begin(), q.end());
    q.erase(std::unique(q.begin(), q.end()), q.end());
    return q;
  }();
  if (unique.empty()) return {};
  std::map<int, std::size_t> hits;  // |P_Q n P_C|, P_C = points of C over all its levels
  for (Index i : unique) {
    std::set<int> here;
    for (int j = 0; j < model.membership.levelCount; ++j)
      if (model.membership.at(j, i) >= 0) here.insert(model.membership.at(j, i));
    for (int c : here) ++hits[c];
  }
  std::vector<BrushMatch> out;
  const double m = double(model.scaleCount());
  for (const auto& [c, k] : hits) {
    BrushMatch match;
    match.component = c;
    match.overlap = double(k) / double(unique.size());
    match.score = match.overlap * model.components[std::size_t(c)].persistence / m;  // Eq. 2.2
    out.push_back(match);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const BrushMatch& a, const BrushMatch& b) { return a.score > b.score; });
  return out;
}

std::vector<int> findSimilar(const PlaneModel& model, int query, const std::vector<Index>& domain,
                             const SimilarityOptions& options) {
  validate(options);
  if (query < 0 || query >= int(model.components.size()))
    throw OptionError("findSimilar: no component " + std::to_string(query) + " (0.." +
                      std::to_string(int(model.components.size()) - 1) + ")");
  checkIndices(model, domain, "similarity domain");
  const PlaneComponent& q = model.components[std::size_t(query)];
  const double cosAngle = std::cos(options.maxAngleDegrees * M_PI / 180.0);
  std::vector<int> out;
  for (int c : componentsHolding(model, domain)) {
    const PlaneComponent& k = model.components[std::size_t(c)];
    if (std::abs(k.birthLevel - q.birthLevel) > options.birthTolerance) continue;
    if (std::abs(k.deathLevel - q.deathLevel) > options.deathTolerance) continue;
    if (std::abs(k.plane.normal.dot(q.plane.normal)) < cosAngle - 1e-12) continue;
    if (std::abs(k.area - q.area) > options.maxAreaDifference * q.area) continue;
    out.push_back(c);
  }
  return out;
}

void validate(const SimilarityOptions& options) {
  if (options.birthTolerance < 0 || options.deathTolerance < 0)
    throw OptionError(
        "SimilarityOptions::birthTolerance and SimilarityOptions::deathTolerance must be >= 0 "
        "levels");
  if (!(std::isfinite(options.maxAreaDifference) && options.maxAreaDifference >= 0))
    throw OptionError("SimilarityOptions::maxAreaDifference must be a finite fraction >= 0");
  if (!(options.maxAngleDegrees >= 0 && options.maxAngleDegrees <= 90))
    throw OptionError("SimilarityOptions::maxAngleDegrees must be in [0, 90], got " +
                      std::to_string(options.maxAngleDegrees));
}

void validate(const CoverageOptions& options) {
  if (!(std::isfinite(options.maxDistanceFraction) && options.maxDistanceFraction >= 0))
    throw OptionError("CoverageOptions::maxDistanceFraction must be a finite fraction >= 0, got " +
                      std::to_string(options.maxDistanceFraction));
  if (!(options.maxAngleDegrees >= 0 && options.maxAngleDegrees <= 90))
    throw OptionError("CoverageOptions::maxAngleDegrees must be in [0, 90], got " +
                      std::to_string(options.maxAngleDegrees));
}

std::vector<int> extendCoverage(const PlaneModel& model, const std::vector<int>& labels,
                                const std::vector<Vec3>& positions,
                                const std::vector<Vec3>& normals, const KnnGraph& knn,
                                const CoverageOptions& options) {
  validate(options);
  const std::size_t n = positions.size();
  if (labels.size() != n || normals.size() != n || knn.size() != n)
    throw OptionError("coverage: labels, positions, normals and graph differ in size");
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Vec3& p : positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double maxDistance = n ? options.maxDistanceFraction * (hi - lo).norm() : 0.0;
  const double cosAngle = std::cos(options.maxAngleDegrees * M_PI / 180.0);
  std::vector<int> out = labels;
  std::vector<Index> frontier;
  for (std::size_t i = 0; i < n; ++i)
    if (out[i] >= 0) frontier.push_back(Index(i));
  // Breadth-first rounds: every point reached in a round is decided from the labels of the
  // previous round only, so the result does not depend on the visiting order.
  while (!frontier.empty()) {
    std::map<Index, std::pair<double, int>> claims;  // point -> (distance, component)
    for (Index p : frontier)
      for (std::size_t e = knn.offsets[p]; e < knn.offsets[p + 1]; ++e) {
        const Index q = knn.neighbors[e];
        if (out[q] >= 0) continue;
        const int c = out[p];
        const PlaneFit& plane = model.components[std::size_t(c)].plane;
        if (!plane.valid) continue;
        const double d = std::abs(plane.normal.dot(positions[q]) - plane.offset);
        if (d > maxDistance || std::abs(plane.normal.dot(normals[q].normalized())) < cosAngle)
          continue;
        const auto claim = std::make_pair(d, c);
        auto it = claims.find(q);
        if (it == claims.end() || claim < it->second) claims[q] = claim;
      }
    frontier.clear();
    for (const auto& [q, claim] : claims) {
      out[q] = claim.second;
      frontier.push_back(q);
    }
  }
  return out;
}

}  // namespace scalespace
