#include "scalespace/features/CurveEdges.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "scalespace/core/DisjointSets.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/PointMoments.hpp"
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

/// A point set's least-squares line.
struct Line {
  Vec3 direction;
  double rms;      // of the points' distances to the line
  bool elongated;  // the second eigenvalue at most half the first: the direction means something
  bool blob;       // not elongated, and its RMS extent along the direction within `radius`
  double extent;   // RMS extent along the direction
};

/// The line through the points of `moments` (none below 3 points).
std::optional<Line> fitLine(const PointMoments& moments, double radius) {
  if (moments.count < 3) return std::nullopt;
  Line line;
  Eigen::SelfAdjointEigenSolver<Mat3> eigen(moments.covariance());
  const Vec3 lambda = eigen.eigenvalues().cwiseMax(0.0);
  line.direction = eigen.eigenvectors().col(2);
  line.rms = std::sqrt(lambda(0) + lambda(1));
  line.elongated = lambda(2) > 0 && lambda(1) <= 0.5 * lambda(2);  // coincident points: no line
  line.blob = !line.elongated && lambda(2) <= radius * radius;
  line.extent = std::sqrt(lambda(2));
  return line;
}

/// Joins adjacent edges (edgeOf, ids below edgeCount) of one curve along one line, most parallel
/// pairs first, each edge joined at most once per round, until no pair qualifies; edgeOf then
/// holds one id per joined set. Sequential: the same for any thread count.
void mergeCollinearEdges(const std::vector<Vec3>& at, const std::vector<int>& curveId,
                         const std::vector<Index>& labelled, const SpatialIndex& index,
                         const CurveEdgeOptions& options, std::vector<int>& edgeOf,
                         std::size_t edgeCount) {
  if (!(options.mergeAngleDegrees > 0) || edgeCount < 2) return;
  const std::size_t m = at.size();
  // Adjacent edges: points within the link distance of each other (found in parallel, then
  // sorted: the same set for any thread count). Edges of one curve may join; those of another
  // curve (a crease of the other sign) only mark junctions.
  std::vector<int> curveOfEdge(edgeCount, -1);
  for (std::size_t a = 0; a < m; ++a) curveOfEdge[std::size_t(edgeOf[a])] = curveId[labelled[a]];
  std::vector<std::vector<std::pair<int, int>>> near(m);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 256), [&](const auto& range) {
    std::vector<Neighbor> found;
    for (std::size_t a = range.begin(); a != range.end(); ++a) {
      index.radiusSearch(at[a], options.linkDistance, found);
      for (const Neighbor& nb : found)
        if (edgeOf[a] < edgeOf[nb.index]) near[a].push_back({edgeOf[a], edgeOf[nb.index]});
    }
  });
  std::vector<std::pair<int, int>> adjacent;
  for (const auto& pairs : near) adjacent.insert(adjacent.end(), pairs.begin(), pairs.end());
  std::sort(adjacent.begin(), adjacent.end());
  adjacent.erase(std::unique(adjacent.begin(), adjacent.end()), adjacent.end());
  if (adjacent.empty()) return;
  std::vector<PointMoments> moments(edgeCount);
  for (std::size_t a = 0; a < m; ++a) moments[std::size_t(edgeOf[a])].add(at[a]);
  DisjointSets sets(edgeCount);
  const double parallel = std::cos(options.mergeAngleDegrees * kPi / 180);
  const double r = options.radius;
  for (;;) {
    // The joined sets that touch, and each set's line (none below 3 points).
    std::vector<std::pair<int, int>> pairs;
    for (const auto& [ex, ey] : adjacent) {
      const int x = int(sets.find(Index(ex))), y = int(sets.find(Index(ey)));
      if (x != y) pairs.push_back({std::min(x, y), std::max(x, y)});
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    std::vector<std::vector<int>> around(edgeCount);  // per joined set, the sets it touches
    for (const auto& [x, y] : pairs)
      around[std::size_t(x)].push_back(y), around[std::size_t(y)].push_back(x);
    for (auto& a : around) std::sort(a.begin(), a.end());  // pairs are unique: so are these
    std::vector<std::optional<Line>> line(edgeCount);
    for (std::size_t e = 0; e < edgeCount; ++e)
      if (sets.find(Index(e)) == e) line[e] = fitLine(moments[e], r);
    // A third edge of any curve (elongated, its RMS extent along its line at least half the
    // radius: about 1.7 radius long) touching both: a junction where it meets the line; the two
    // pieces are edges of their own there, as on the mesh.
    const auto junction = [&](int x, int y) {
      const std::vector<int>& ay = around[std::size_t(y)];
      for (const int z : around[std::size_t(x)]) {
        const std::optional<Line>& lz = line[std::size_t(z)];
        if (lz && lz->elongated && lz->extent >= 0.5 * r &&
            std::binary_search(ay.begin(), ay.end(), z))
          return true;
      }
      return false;
    };
    struct Candidate {
      double cosine;
      int x, y;
    };
    std::vector<Candidate> candidates;
    for (const auto& [x, y] : pairs) {
      if (curveOfEdge[std::size_t(x)] != curveOfEdge[std::size_t(y)] || !line[std::size_t(x)] ||
          !line[std::size_t(y)])
        continue;
      const Line &lx = *line[std::size_t(x)], &ly = *line[std::size_t(y)];
      // A small blob (a patch of the band chained by its local directions) has no direction of
      // its own to compare: the union's thickness decides alone.
      if (!(lx.elongated || lx.blob) || !(ly.elongated || ly.blob) || (lx.blob && ly.blob))
        continue;
      if (std::max(lx.rms, ly.rms) > 0.5 * r) continue;
      const double cosine =
          lx.elongated && ly.elongated ? std::abs(lx.direction.dot(ly.direction)) : parallel;
      if (cosine < parallel) continue;
      PointMoments both = moments[std::size_t(x)];
      both.add(moments[std::size_t(y)]);
      const std::optional<Line> lu = fitLine(both, r);
      // Each piece and their union lie along a line, within half the radius of it (a curved
      // edge's pieces are left as they are), and the union is about as thin as the thicker
      // piece (a corner's arms are not: their union is as wide as they are long). The slack,
      // 1e-6 of the extent, covers the eigensolver's error on exactly straight pieces.
      if (lu && lu->elongated && lu->rms <= 0.5 * r &&
          lu->rms <= options.mergeThickening * std::max(lx.rms, ly.rms) + 1e-6 * lu->extent &&
          !junction(x, y))
        candidates.push_back({cosine, x, y});
    }
    if (candidates.empty()) break;
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& p, const Candidate& q) {
      return p.cosine != q.cosine ? p.cosine > q.cosine
                                  : std::make_pair(p.x, p.y) < std::make_pair(q.x, q.y);
    });
    std::vector<std::uint8_t> joined(edgeCount, 0);
    for (const Candidate& c : candidates) {
      if (joined[std::size_t(c.x)] || joined[std::size_t(c.y)]) continue;
      joined[std::size_t(c.x)] = joined[std::size_t(c.y)] = 1;
      PointMoments merged = moments[std::size_t(c.x)];
      merged.add(moments[std::size_t(c.y)]);
      sets.unite(Index(c.x), Index(c.y));
      moments[std::size_t(sets.find(Index(c.x)))] = merged;
    }
  }
  for (std::size_t a = 0; a < m; ++a) edgeOf[a] = int(sets.find(Index(edgeOf[a])));
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
  if (!(options.mergeAngleDegrees >= 0 && options.mergeAngleDegrees <= 90))
    throw OptionError("CurveEdgeOptions::mergeAngleDegrees must be in [0, 90] degrees (0 = off)");
  if (!(options.mergeThickening >= 1) || !std::isfinite(options.mergeThickening))
    throw OptionError("CurveEdgeOptions::mergeThickening must be finite and >= 1");
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
  const double parallel = std::cos(20 * kPi / 180);
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

  // 4. Pieces of one straight edge rejoined (not in the thesis): on a scan the band is wider and
  // its directions noisier than on a CAD model, so the linearity test cuts a long edge into runs
  // between non-linear patches. Adjacent edges of a curve whose lines agree and whose union is
  // about as thin as each are one edge; a corner's arms are not (their union is as wide as they
  // are long).
  mergeCollinearEdges(at, curveId, labelled, *index, options, edgeOf, edges.size());
  std::size_t edgeCount = 0;
  {
    std::vector<int> dense(std::max<std::size_t>(edges.size(), 1), -1);
    for (std::size_t a = 0; a < m; ++a) {
      int& d = dense[std::size_t(edgeOf[a])];
      if (d < 0) d = int(edgeCount++);
      edgeOf[a] = d;
    }
    edges.assign(edgeCount, {});
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
