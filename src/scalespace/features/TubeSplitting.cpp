#include "scalespace/features/TubeSplitting.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "scalespace/core/DisjointSets.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

namespace {

using CellKey = std::array<std::int64_t, 3>;

/// The median curvature radius 1 / |kappa1| of the points curved enough to read one (0: none).
double medianCurvatureRadius(const std::vector<float>& kappa1, const std::vector<Index>& points,
                             double t, double minCurvatureFactor) {
  std::vector<double> radii;
  for (const Index i : points)
    if (std::abs(kappa1[i]) * t >= minCurvatureFactor) radii.push_back(1 / std::abs(kappa1[i]));
  return radii.empty() ? 0 : lowerMedian(std::move(radii));
}

/// The parts of `points` split by their axes, part by part while a part's curvature sees tubes
/// thinner than its own (the first density level that parts a cable may leave two strands
/// together), with their tubes (fitted with `partTube`); empty when the points do not split.
/// `whole` is the points' tube as a grown region's (fitted with `tube`), which decides whether
/// they are split.
std::vector<ThinTube> splitTubes(const std::vector<Vec3>& positions,
                                 const std::vector<Vec3>& normals,
                                 const std::vector<Vec3>& scaleNormals,
                                 const std::vector<float>& kappa1, const std::vector<Index>& points,
                                 const TubeFit& whole, double t, const TubeFitOptions& tube,
                                 const TubeFitOptions& partTube, const TubeSplitOptions& options,
                                 int depth) {
  // Only a tube, or one turned down as rough or for a narrow arc: the strands grown into one
  // region are any of these (a cable scanned from one side: its envelope over a narrow arc), while
  // a flat, thin, faceted or too small one holds no tubes side by side. Its curvature must also
  // see thinner tubes (below), and its parts must be tubes to be kept (splitIntoThinnerTubes).
  const bool mayHoldTubes = whole.isTube() || whole.rejection == TubeRejection::Rough ||
                            whole.rejection == TubeRejection::NarrowArc;
  if (!options.enabled || depth > 3 || !(whole.radius > 0) || !mayHoldTubes) return {};
  // The scale's curvature must see tubes thinner than the region's: the strands' own radius at a
  // scale below it; the whole cable, at a scale above the strands, proposes its own axis.
  const double curvatureRadius = medianCurvatureRadius(kappa1, points, t, tube.minCurvatureFactor);
  if (!(curvatureRadius > 0 && curvatureRadius < options.maxRadiusRatio * whole.radius)) return {};
  std::vector<ThinTube> out;
  for (std::vector<Index>& part :
       splitByProposedAxes(positions, scaleNormals, kappa1, points, t, tube.minCurvatureFactor,
                           tube.minPoints, options)) {
    // Whether a part splits again is judged on its tube as a region's, the straight axis free
    // to span two strands' runs: the part's own tube, whose axis must read the curvature's
    // radius, can zigzag between them at about the strands' radius.
    const TubeFit asRegion = fitTube(positions, normals, scaleNormals, kappa1, part, t, tube);
    std::vector<ThinTube> finer = splitTubes(positions, normals, scaleNormals, kappa1, part,
                                             asRegion, t, tube, partTube, options, depth + 1);
    if (finer.empty()) {
      TubeFit fit = fitTube(positions, normals, scaleNormals, kappa1, part, t, partTube);
      out.push_back({std::move(part), std::move(fit)});
    } else {
      for (ThinTube& f : finer) out.push_back(std::move(f));
    }
  }
  return out;
}

}  // namespace

bool continuesAxis(const TubeFit& a, const TubeFit& b, double maxGap, double maxOffset,
                   double directionReach) {
  if (a.axis.size() < 2 || b.axis.size() < 2) return false;
  // An axis end and the unit direction in which it leaves its tube, over the last directionReach
  // of the axis: the last segment of a noisy curved axis may point anywhere.
  const auto end = [directionReach](const std::vector<Vec3>& axis, bool back) {
    const std::size_t n = axis.size();
    const Vec3& tip = back ? axis[n - 1] : axis[0];
    Vec3 inner = back ? axis[n - 2] : axis[1];
    double length = 0;
    for (std::size_t k = 1; k < n && length < directionReach; ++k) {
      const Vec3& previous = back ? axis[n - k] : axis[k - 1];
      inner = back ? axis[n - 1 - k] : axis[k];
      length += (inner - previous).norm();
    }
    return std::pair<Vec3, Vec3>(tip, (tip - inner).normalized());
  };
  // Whether p lies on the way the end leaves: within maxOffset of its line, widening by half the
  // distance ahead, as a curved axis (a helical strand's) turns away from its end's tangent.
  const auto ahead = [maxOffset](const std::pair<Vec3, Vec3>& from, const Vec3& p) {
    const Vec3 d = p - from.first;
    const double along = d.dot(from.second);
    return (d - along * from.second).norm() <= maxOffset + 0.5 * std::max(along, 0.0);
  };
  for (const bool ab : {false, true})
    for (const bool bb : {false, true}) {
      const auto ea = end(a.axis, ab), eb = end(b.axis, bb);
      if ((ea.first - eb.first).norm() <= maxGap && ahead(ea, eb.first) && ahead(eb, ea.first))
        return true;
    }
  return false;
}

bool mayBeOneStrand(const TubeFit& a, const TubeFit& b, const TubeSplitOptions& options) {
  const double big = std::max(a.radius, b.radius);
  return radiiAgree(a, b, 0.25) && std::max(shareBeside(a, b), shareBeside(b, a)) <= 0.5 &&
         continuesAxis(a, b, options.maxJoinGap * big, options.maxJoinOffset * big, 2 * big);
}

void validateTubeSplitOptions(const TubeSplitOptions& options) {
  if (!(std::isfinite(options.cellFactor) && options.cellFactor > 0))
    throw OptionError("TubeSplitOptions::cellFactor must be finite and > 0");
  if (!(options.minDensity > 0 && options.minDensity <= 1))
    throw OptionError("TubeSplitOptions::minDensity must be in (0, 1]");
  if (options.densitySteps < 1 || options.densitySteps > 100)
    throw OptionError("TubeSplitOptions::densitySteps must be in [1, 100]");
  if (!(options.minShare > 0 && options.minShare <= 0.5))
    throw OptionError("TubeSplitOptions::minShare must be in (0, 0.5]");
  if (!(options.linkRadius > 0 && options.linkRadius <= 1 &&
        options.linkRadius / options.cellFactor <= 10))
    throw OptionError(
        "TubeSplitOptions::linkRadius must be in (0, 1] and at most 10 x "
        "TubeSplitOptions::cellFactor");
  if (!(options.maxRadiusRatio > 0 && options.maxRadiusRatio <= 1))
    throw OptionError("TubeSplitOptions::maxRadiusRatio must be in (0, 1]");
  if (!(std::isfinite(options.maxJoinGap) && options.maxJoinGap >= 0))
    throw OptionError("TubeSplitOptions::maxJoinGap must be finite and >= 0");
  if (!(options.partMinArcDegrees >= 0 && options.partMinArcDegrees <= 360))
    throw OptionError("TubeSplitOptions::partMinArcDegrees must be in [0, 360]");
  if (!(options.partRadiusDisagreement >= 1))
    throw OptionError("TubeSplitOptions::partRadiusDisagreement must be >= 1 (infinity: off)");
  if (!(std::isfinite(options.maxJoinOffset) && options.maxJoinOffset >= 0))
    throw OptionError("TubeSplitOptions::maxJoinOffset must be finite and >= 0");
}

std::vector<std::vector<Index>> splitByProposedAxes(
    const std::vector<Vec3>& positions, const std::vector<Vec3>& scaleNormals,
    const std::vector<float>& kappa1, const std::vector<Index>& points, double t,
    double minCurvatureFactor, std::size_t minPoints, const TubeSplitOptions& options) {
  if (!options.enabled || points.size() < 2 * std::max<std::size_t>(minPoints, 1)) return {};
  std::vector<std::pair<Vec3, Index>> proposals;
  std::vector<double> radii;
  for (const Index i : points) {
    const double k = kappa1[i];
    if (!(std::abs(k) * t >= minCurvatureFactor)) continue;
    const Vec3 c = positions[i] - scaleNormals[i] / k;
    if (!c.allFinite()) continue;
    proposals.emplace_back(c, i);
    radii.push_back(1 / std::abs(k));
  }
  if (proposals.size() < 2 * std::max<std::size_t>(minPoints, 1)) return {};
  const double h = options.cellFactor * lowerMedian(std::move(radii));
  // Cells anchored at the proposals' lower corner: a grid fixed in space would cut a translated
  // region differently. Proposals spread over more than 10^9 cells (curvature radii far below the
  // region's size) cannot be counted: no split.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& p : proposals) lo = lo.cwiseMin(p.first), hi = hi.cwiseMax(p.first);
  if (!(h > 0) || !((hi - lo).maxCoeff() / h < 1e9)) return {};
  std::vector<std::pair<CellKey, Index>> keyed;
  keyed.reserve(proposals.size());
  for (const auto& [c, i] : proposals) {
    const Vec3 q = (c - lo) / h;
    keyed.push_back({{std::int64_t(std::floor(q.x())), std::int64_t(std::floor(q.y())),
                      std::int64_t(std::floor(q.z()))},
                     i});
  }
  std::sort(keyed.begin(), keyed.end());
  struct Cell {
    CellKey key;
    std::size_t begin, end;
    double density = 0;
  };
  std::vector<Cell> cells;
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    while (e < keyed.size() && keyed[e].first == keyed[b].first) ++e;
    cells.push_back({keyed[b].first, b, e});
    b = e;
  }
  const auto find = [&](const CellKey& key) {
    const auto it = std::lower_bound(cells.begin(), cells.end(), key,
                                     [](const Cell& c, const CellKey& k) { return c.key < k; });
    return it != cells.end() && it->key == key ? std::size_t(it - cells.begin()) : cells.size();
  };
  const auto around = [&](std::size_t c, auto&& visit) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const CellKey key{cells[c].key[0] + dx, cells[c].key[1] + dy, cells[c].key[2] + dz};
          const std::size_t d = find(key);
          if (d < cells.size()) visit(d);
        }
  };
  for (std::size_t c = 0; c < cells.size(); ++c)
    around(c, [&](std::size_t d) { cells[c].density += double(cells[d].end - cells[d].begin); });
  // The density of the cell holding the median proposal, cells taken by decreasing density.
  std::vector<std::pair<double, std::size_t>> byDensity;
  for (const Cell& c : cells) byDensity.push_back({c.density, c.end - c.begin});
  std::sort(byDensity.begin(), byDensity.end(), std::greater<>());
  std::size_t seen = 0;
  double typical = 0;
  for (const auto& [d, count] : byDensity) {
    seen += count;
    typical = d;
    if (2 * seen >= keyed.size()) break;
  }
  // The lowest density level at which the dense cells fall into two or more components of
  // `big` proposals each.
  std::vector<std::vector<Index>> parts;
  const std::size_t big =
      std::max(minPoints, std::size_t(std::ceil(options.minShare * double(keyed.size()))));
  std::vector<std::vector<Index>> level;
  // Dense cells closer than linkRadius join: one tube's proposals, spread round its axis by the
  // curvature's error, are one part however the levels cut them.
  const double link = std::max(options.linkRadius / options.cellFactor, 1.8) * h;
  std::vector<Vec3> centres;
  std::vector<std::size_t> denseCells;
  std::vector<Neighbor> near;
  for (int step = 1; step <= options.densitySteps; ++step) {
    const double dense = std::max(2.0, step * options.minDensity * typical);
    const auto isDense = [&](std::size_t c) { return cells[c].density >= dense; };
    centres.clear();
    denseCells.clear();
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (isDense(c)) {
        denseCells.push_back(c);
        centres.emplace_back(double(cells[c].key[0]) + 0.5, double(cells[c].key[1]) + 0.5,
                             double(cells[c].key[2]) + 0.5);
        centres.back() *= h;
      }
    if (denseCells.size() < 2) break;
    DisjointSets sets(cells.size());
    const std::unique_ptr<SpatialIndex> index = makeSpatialIndex(centres);
    for (std::size_t k = 0; k < denseCells.size(); ++k) {
      index->radiusSearch(centres[k], link, near);
      for (const Neighbor& nb : near) sets.unite(Index(denseCells[k]), Index(denseCells[nb.index]));
    }
    level.clear();
    std::vector<std::size_t> partOf(cells.size(), std::numeric_limits<std::size_t>::max());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (!isDense(c)) continue;
      const std::size_t root = sets.find(Index(c));
      if (partOf[root] == std::numeric_limits<std::size_t>::max()) {
        partOf[root] = level.size();
        level.emplace_back();
      }
      for (std::size_t k = cells[c].begin; k < cells[c].end; ++k)
        level[partOf[root]].push_back(keyed[k].second);
    }
    level.erase(std::remove_if(level.begin(), level.end(),
                               [&](const std::vector<Index>& p) { return p.size() < big; }),
                level.end());
    if (level.size() >= 2) {
      parts = std::move(level);
      break;
    }
  }
  if (parts.size() < 2) return {};
  for (auto& p : parts) std::sort(p.begin(), p.end());
  return parts;
}

std::vector<ThinTube> splitIntoThinnerTubes(const std::vector<Vec3>& positions,
                                            const std::vector<Vec3>& normals,
                                            const std::vector<Vec3>& scaleNormals,
                                            const std::vector<float>& kappa1,
                                            const std::vector<Index>& points, const TubeFit& whole,
                                            double t, const TubeFitOptions& tube,
                                            const TubeSplitOptions& options) {
  TubeFitOptions partTube = tube;
  partTube.maxRadiusDisagreement = options.partRadiusDisagreement;
  partTube.minArcDegrees = std::min(tube.minArcDegrees, options.partMinArcDegrees);
  std::vector<ThinTube> kept;
  std::size_t covered = 0;
  for (ThinTube& part : splitTubes(positions, normals, scaleNormals, kappa1, points, whole, t, tube,
                                   partTube, options, 0))
    if (part.tube.isTube() && part.tube.radius < options.maxRadiusRatio * whole.radius) {
      covered += part.points.size();
      kept.push_back(std::move(part));
    }
  // The density levels can cut one strand across where its proposals thin out: parts of the same
  // radius (25%) end to end, not beside one another, whose union is still a tube are one part.
  for (bool joined = true; joined;) {
    joined = false;
    for (std::size_t a = 0; a < kept.size() && !joined; ++a)
      for (std::size_t b = a + 1; b < kept.size() && !joined; ++b) {
        const TubeFit &ta = kept[a].tube, &tb = kept[b].tube;
        if (!mayBeOneStrand(ta, tb, options)) continue;
        std::vector<Index> both;
        std::merge(kept[a].points.begin(), kept[a].points.end(), kept[b].points.begin(),
                   kept[b].points.end(), std::back_inserter(both));
        TubeFit fit = fitTube(positions, normals, scaleNormals, kappa1, both, t, partTube);
        if (!fit.isTube() || !(fit.radius < options.maxRadiusRatio * whole.radius)) continue;
        kept[a] = {std::move(both), std::move(fit)};
        kept.erase(kept.begin() + std::ptrdiff_t(b));
        joined = true;
      }
  }
  if (kept.size() < 2 || 2 * covered < points.size()) return {};
  return kept;
}

}  // namespace scalespace
