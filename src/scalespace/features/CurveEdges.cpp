#include "scalespace/features/CurveEdges.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "scalespace/core/DisjointSets.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"

namespace scalespace {

namespace {

// The links between labelled points of one curve, both ways, over compact indices.
std::vector<std::vector<Index>> curveLinks(const KnnGraph& graph, const std::vector<int>& curveId,
                                           const std::vector<Index>& labelled,
                                           const std::vector<Index>& compact) {
  std::vector<std::vector<Index>> links(labelled.size());
  for (std::size_t a = 0; a < labelled.size(); ++a) {
    const Index i = labelled[a];
    for (std::size_t k = graph.offsets[i]; k < graph.offsets[i + 1]; ++k) {
      const Index j = graph.neighbors[k];
      if (j == i || curveId[j] != curveId[i]) continue;
      links[a].push_back(compact[j]);
      links[compact[j]].push_back(Index(a));
    }
  }
  for (auto& l : links) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  return links;
}

}  // namespace

CurveEdges splitCurvesAtCorners(const std::vector<Vec3>& positions, const KnnGraph& graph,
                                const std::vector<int>& curveId, const CurveEdgeOptions& options) {
  if (!(options.radius > 0) || !std::isfinite(options.radius))
    throw OptionError("CurveEdgeOptions::radius must be finite and > 0");
  if (!(options.linkDistance > 0) || !std::isfinite(options.linkDistance))
    throw OptionError("CurveEdgeOptions::linkDistance must be finite and > 0");
  if (!(options.maxSpread >= 0 && options.maxSpread <= 1))
    throw OptionError("CurveEdgeOptions::maxSpread must be in [0, 1]");
  if (curveId.size() != positions.size() || graph.size() != positions.size())
    throw OptionError("splitCurvesAtCorners: one curve id and one graph vertex per point needed");
  const std::size_t n = positions.size();
  CurveEdges out;
  out.edgeId.assign(n, -1);
  std::vector<Index> labelled, compact(n, 0);
  std::vector<Vec3> at;
  for (std::size_t i = 0; i < n; ++i)
    if (curveId[i] >= 0) {
      compact[i] = Index(labelled.size());
      labelled.push_back(Index(i));
      at.push_back(positions[i]);
    }
  if (labelled.empty()) return out;
  const std::size_t m = labelled.size();

  // 1. Linear points: their curve's points within the radius spread along one line. Their
  // direction is that of the points within half the radius: near a corner the whole ball's
  // principal axis leans towards the other edge (23 degrees where the test still passes), and
  // leaning directions would chain the two edges round the corner.
  std::vector<std::uint8_t> linear(m, 0);
  std::vector<Vec3> direction(m, Vec3::Zero());
  const auto index = makeSpatialIndex(at);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 256), [&](const auto& r) {
    std::vector<Neighbor> found;
    for (std::size_t a = r.begin(); a != r.end(); ++a) {
      const int curve = curveId[labelled[a]];
      // Principal axes of the curve's points within `reach` (in point order: the same sums for
      // any thread count); false with fewer than 3.
      auto axes = [&](double reach, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eigen) {
        index->radiusSearch(at[a], reach, found);
        std::sort(found.begin(), found.end(),
                  [](const Neighbor& x, const Neighbor& y) { return x.index < y.index; });
        Vec3 mean = Vec3::Zero();
        std::size_t count = 0;
        for (const Neighbor& nb : found)
          if (curveId[labelled[nb.index]] == curve) mean += at[nb.index], ++count;
        if (count < 3) return false;
        mean /= double(count);
        Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
        for (const Neighbor& nb : found)
          if (curveId[labelled[nb.index]] == curve) {
            const Vec3 d = at[nb.index] - mean;
            covariance += d * d.transpose();
          }
        eigen.compute(covariance);
        return true;
      };
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
      if (!axes(options.radius, eigen)) continue;
      linear[a] = eigen.eigenvalues()(2) > 0 &&
                  eigen.eigenvalues()(1) <= options.maxSpread * eigen.eigenvalues()(2);
      if (linear[a] && axes(0.5 * options.radius, eigen))
        direction[a] = eigen.eigenvectors().col(2);
      if (!(direction[a].squaredNorm() > 0)) linear[a] = 0;
    }
  });

  // 2. Edges: linear points of one curve within the link distance of each other, along the same
  // line (a curve's pieces that the votes left apart but FeatureCurveOptions::joinGap joined
  // are one edge when they continue each other); pieces shorter than half the radius are corners.
  const std::vector<std::vector<Index>> links = curveLinks(graph, curveId, labelled, compact);
  const double parallel = std::cos(20 * 3.14159265358979323846 / 180);
  std::vector<std::vector<Index>> near(m);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 256), [&](const auto& r) {
    std::vector<Neighbor> found;
    for (std::size_t a = r.begin(); a != r.end(); ++a) {
      if (!linear[a]) continue;
      index->radiusSearch(at[a], options.linkDistance, found);
      for (const Neighbor& nb : found)
        if (nb.index > a && linear[nb.index] &&
            curveId[labelled[nb.index]] == curveId[labelled[a]] &&
            std::abs(direction[a].dot(direction[nb.index])) >= parallel)
          near[a].push_back(Index(nb.index));
    }
  });
  DisjointSets sets(m);
  for (std::size_t a = 0; a < m; ++a)
    for (const Index b : near[a]) sets.unite(Index(a), b);
  std::map<Index, std::vector<Index>> pieces;  // root -> members (compact, increasing)
  for (std::size_t a = 0; a < m; ++a)
    if (linear[a]) pieces[sets.find(Index(a))].push_back(Index(a));
  std::vector<std::vector<Index>> edges;  // compact members
  for (auto& [root, members] : pieces) {
    Vec3 lo = at[members.front()], hi = lo;
    for (const Index a : members) lo = lo.cwiseMin(at[a]), hi = hi.cwiseMax(at[a]);
    if ((hi - lo).norm() >= 0.5 * options.radius)
      edges.push_back(std::move(members));
    else
      for (const Index a : members) linear[a] = 0;
  }
  std::vector<int> edgeOf(m, -1);
  for (std::size_t e = 0; e < edges.size(); ++e)
    for (const Index a : edges[e]) edgeOf[a] = int(e);

  // 3. Corner points join the nearest edge through the links, layer by layer (ties: lower id).
  std::vector<Index> frontier;
  for (std::size_t a = 0; a < m; ++a)
    if (edgeOf[a] >= 0) frontier.push_back(Index(a));
  while (!frontier.empty()) {
    std::map<Index, int> reached;  // corner point -> lowest edge id reaching it in this layer
    for (const Index a : frontier)
      for (const Index b : links[a])
        if (edgeOf[b] < 0) {
          auto [it, inserted] = reached.try_emplace(b, edgeOf[a]);
          if (!inserted) it->second = std::min(it->second, edgeOf[a]);
        }
    frontier.clear();
    for (const auto& [b, e] : reached) {
      edgeOf[b] = e;
      frontier.push_back(b);
    }
  }
  // Corner points cut off from every edge by a gap join the nearest edge point of their curve.
  {
    std::vector<Vec3> edgePoints;
    std::vector<Index> edgePointOf;
    for (std::size_t a = 0; a < m; ++a)
      if (edgeOf[a] >= 0) edgePoints.push_back(at[a]), edgePointOf.push_back(Index(a));
    if (!edgePoints.empty()) {
      const auto edgeIndex = makeSpatialIndex(edgePoints);
      std::vector<Neighbor> found;
      std::vector<int> assigned(m, -1);
      for (std::size_t a = 0; a < m; ++a) {
        if (edgeOf[a] >= 0) continue;
        edgeIndex->knnSearch(at[a], 32, found);
        for (const Neighbor& nb : found)  // sorted by distance, then index
          if (curveId[labelled[edgePointOf[nb.index]]] == curveId[labelled[a]]) {
            assigned[a] = edgeOf[edgePointOf[nb.index]];
            break;
          }
      }
      for (std::size_t a = 0; a < m; ++a)
        if (assigned[a] >= 0) edgeOf[a] = assigned[a];
    }
  }
  // Curves (or parts) no edge reaches: each connected set is one more edge, in point order.
  for (std::size_t a = 0; a < m; ++a) {
    if (edgeOf[a] >= 0) continue;
    const int e = int(edges.size());
    edges.emplace_back();
    std::vector<Index> stack{Index(a)};
    edgeOf[a] = e;
    while (!stack.empty()) {
      const Index b = stack.back();
      stack.pop_back();
      for (const Index c : links[b])
        if (edgeOf[c] < 0) edgeOf[c] = e, stack.push_back(c);
    }
  }

  // Renumbered by curve, then lowest point.
  std::vector<std::pair<int, Index>> key(edges.size(), {-1, Index(m)});
  for (std::size_t a = 0; a < m; ++a) {
    auto& k = key[std::size_t(edgeOf[a])];
    if (k.first < 0) k = {curveId[labelled[a]], Index(a)};  // a increases: the lowest point
  }
  std::vector<int> order(edges.size());
  for (std::size_t e = 0; e < order.size(); ++e) order[e] = int(e);
  std::sort(order.begin(), order.end(),
            [&](int x, int y) { return key[std::size_t(x)] < key[std::size_t(y)]; });
  std::vector<int> renumber(edges.size());
  for (std::size_t r = 0; r < order.size(); ++r) renumber[std::size_t(order[r])] = int(r);
  out.points.assign(edges.size(), {});
  out.curveOf.assign(edges.size(), -1);
  for (std::size_t a = 0; a < m; ++a) {
    const Index i = labelled[a];
    const int e = renumber[std::size_t(edgeOf[a])];
    out.edgeId[i] = e;
    out.points[std::size_t(e)].push_back(i);
    out.curveOf[std::size_t(e)] = curveId[i];
  }
  return out;
}

}  // namespace scalespace
