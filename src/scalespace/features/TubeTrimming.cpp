#include "scalespace/features/TubeTrimming.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "scalespace/core/DisjointSets.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

void validateTubeTrimOptions(const TubeTrimOptions& options) {
  if (!(options.keepFraction >= 0 && options.keepFraction <= 1))
    throw OptionError("TubeTrimOptions::keepFraction must be in [0, 1]");
  if (!(std::isfinite(options.minRadiusScales) && options.minRadiusScales >= 0))
    throw OptionError("TubeTrimOptions::minRadiusScales must be finite and >= 0");
  if (!(options.tubeMinAgainstShare >= 0 && options.tubeMinAgainstShare <= 1))
    throw OptionError("TubeTrimOptions::tubeMinAgainstShare must be in [0, 1]");
}

std::vector<Index> trimToOneCurvatureSign(const KnnGraph& graph, const std::vector<float>& kappa1,
                                          const std::vector<Index>& points, double t,
                                          double minCurvatureFactor, std::size_t minPoints,
                                          const TubeTrimOptions& options, double minAgainstShare) {
  if (!options.enabled || points.size() < std::max<std::size_t>(minPoints, 1)) return {};
  if (!std::is_sorted(points.begin(), points.end()) || points.back() >= graph.size() ||
      points.back() >= kappa1.size())
    throw OptionError(
        "trimToOneCurvatureSign: the points must be sorted indices into the graph "
        "and kappa1");
  std::vector<double> convex, concave;  // |kappa1| t of each sign, beyond minCurvatureFactor
  for (const Index i : points) {
    const double k = double(kappa1[i]) * t;
    if (!(std::abs(k) >= minCurvatureFactor)) continue;
    (k > 0 ? convex : concave).push_back(std::abs(k));
  }
  const double sign = convex.size() >= concave.size() ? 1 : -1;
  std::vector<double>& majority = sign > 0 ? convex : concave;
  if (majority.empty()) return {};
  const double least =
      std::max(minCurvatureFactor, options.keepFraction * lowerMedian(std::move(majority)));
  std::vector<Index> kept;
  std::size_t against = 0;
  for (const Index i : points) {
    const double k = sign * double(kappa1[i]) * t;
    if (k >= least) kept.push_back(i);
    against += k <= -least;
  }
  if (double(against) < minAgainstShare * double(points.size())) return {};
  if (kept.size() < std::max<std::size_t>(minPoints, 1)) return {};

  // The largest part of the kept points connected by the graph's edges between them, either way
  // (the k-NN graph is directed); the one holding the lowest index on ties, so the result does
  // not depend on anything but the input. Which kept point a graph vertex is: a table over the
  // whole cloud, one per thread, cleared before anything can throw again (a binary search per
  // edge took a tenth of `cylinders`).
  DisjointSets sets(kept.size());
  std::vector<std::size_t> sizes(kept.size(), 0);
  thread_local std::vector<std::uint32_t> slotOf;  // kept index + 1, 0: not kept
  if (slotOf.size() < graph.size()) slotOf.resize(graph.size(), 0);
  for (std::size_t s = 0; s < kept.size(); ++s) slotOf[kept[s]] = std::uint32_t(s + 1);
  for (std::size_t s = 0; s < kept.size(); ++s)
    for (std::size_t e = graph.offsets[kept[s]]; e < graph.offsets[kept[s] + 1]; ++e)
      if (const std::uint32_t q = slotOf[graph.neighbors[e]]) sets.unite(Index(s), Index(q - 1));
  for (const Index i : kept) slotOf[i] = 0;
  std::vector<Index> rootOf(kept.size());
  for (std::size_t s = 0; s < kept.size(); ++s) ++sizes[rootOf[s] = sets.find(Index(s))];
  const std::size_t bestSize = *std::max_element(sizes.begin(), sizes.end());
  Index best = 0;
  for (std::size_t s = 0; s < kept.size(); ++s)
    if (sizes[rootOf[s]] == bestSize) {
      best = rootOf[s];
      break;
    }
  if (bestSize < std::max<std::size_t>(minPoints, 1) || bestSize == points.size()) return {};
  std::vector<Index> core;
  core.reserve(bestSize);
  for (std::size_t s = 0; s < kept.size(); ++s)
    if (rootOf[s] == best) core.push_back(kept[s]);
  return core;
}

}  // namespace scalespace
