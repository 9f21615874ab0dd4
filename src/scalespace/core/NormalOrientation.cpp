#include "scalespace/core/NormalOrientation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "scalespace/core/DisjointSets.hpp"
#include "scalespace/core/OccupancyGrid.hpp"
#include "scalespace/core/SpatialOrder.hpp"

namespace scalespace {
namespace {

constexpr Index kNone = std::numeric_limits<Index>::max();

bool usable(const Vec3& n) { return n.allFinite() && n.squaredNorm() > 0.0; }

struct Edge {
  float cost;  // 1 - |n_a . n_b| [Hoppe 1992] + the across-sheet term (edgeCost)
  Index a, b;  // a < b; a == kNone marks an empty slot
  bool operator<(const Edge& o) const {
    if (cost != o.cost) return cost < o.cost;
    if (a != o.a) return a < o.a;
    return b < o.b;
  }
  bool operator==(const Edge& o) const { return a == o.a && b == o.b; }
};

/// Hoppe's 1 - |cos(n_a, n_b)|, plus acrossWeight |cos(n_a, d)| |cos(n_b, d)|, d = p_b - p_a: two
/// parallel sheets facing each other (the two sides of a thin part) have parallel normals, so
/// Hoppe's cost is 0 across them, and the propagation, which keeps n_b . n_a > 0, orients both
/// sides alike where one must face the other way. Their offset runs along both normals; between
/// neighbours of one sheet it lies in the tangent planes (the term is about 0), and across a crease
/// along at most one of the two normals.
/// |cos| of the angles between the offset d = pb - pa and each normal (0 for coincident points).
struct OffsetCosines {
  double a = 0, b = 0;
};
OffsetCosines offsetCosines(const Vec3& pa, const Vec3& na, const Vec3& pb, const Vec3& nb) {
  const Vec3 d = pb - pa;
  const double length = d.norm();
  if (!(length > 0)) return {};
  return {std::abs(na.dot(d)) / (length * na.norm()), std::abs(nb.dot(d)) / (length * nb.norm())};
}

double edgeCost(const Vec3& pa, const Vec3& na, const Vec3& pb, const Vec3& nb,
                double acrossWeight) {
  const double c = std::min(1.0, std::abs(na.dot(nb)) / (na.norm() * nb.norm()));
  if (!(acrossWeight > 0)) return 1.0 - c;
  const OffsetCosines along = offsetCosines(pa, na, pb, nb);
  return 1.0 - c + acrossWeight * along.a * along.b;
}

/// The offset between two points runs along both normals (within 60 degrees): an edge between the
/// two sides of a thin part rather than along one surface.
bool acrossSheet(const Vec3& pa, const Vec3& na, const Vec3& pb, const Vec3& nb) {
  const OffsetCosines along = offsetCosines(pa, na, pb, nb);
  return along.a > 0.5 && along.b > 0.5;
}

/// The rays of one side of a point: along the normal and four tilted 25 degrees around it.
int escapingRays(const OccupancyGrid& grid, const Vec3& p, const Vec3& unitNormal) {
  const Vec3 u = unitNormal.unitOrthogonal();
  const Vec3 v = unitNormal.cross(u);
  const double c = std::cos(25.0 * M_PI / 180.0), s = std::sin(25.0 * M_PI / 180.0);
  const Vec3 rays[5] = {unitNormal, c * unitNormal + s * u, c * unitNormal - s * u,
                        c * unitNormal + s * v, c * unitNormal - s * v};
  int count = 0;
  for (const Vec3& r : rays) count += grid.escapes(p, r, 3) ? 1 : 0;
  return count;
}

/// Each graph edge that agrees with a piece's sign outweighs two of the rays' votes against it.
/// Measured on libcgal-demo's points_3 (bench/README.md, "visibility"): with 1, the floor of
/// building.ply, under its roof and open below, is turned down (its points against the file's
/// normals: 2.1% -> 30.7%); with 2 it stays up, and the thin parts of rotor and blade and the
/// pieces of spheres.ply are still turned.
constexpr double kEdgeWeight = 2.0;

/// Visibility pass (file comment of the header). A point votes for its side when at least three
/// more of its five rays escape on that side than on the other; a piece is a candidate when its
/// votes against its side are at least a quarter of its points and more than twice those for.
void correctByVisibility(const std::vector<Vec3>& points, std::vector<Vec3>& oriented,
                         const SpatialIndex& index, const std::vector<std::uint8_t>& inGraph,
                         const std::vector<float>& kthDistance, const std::vector<Index>& piece,
                         Index pieces, const NormalOrientationOptions& options,
                         const ProgressCallback& progress, std::vector<std::uint8_t>& flipped,
                         NormalOrientationResult& result) {
  const std::size_t n = points.size();
  result.pieceCount = pieces;
  std::vector<float> spacing;
  for (std::size_t i = 0; i < n; ++i)
    if (inGraph[i] && kthDistance[i] > 0) spacing.push_back(kthDistance[i]);
  if (spacing.empty() || pieces == 0) return;
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  const double cell = options.visibilityCell * spacing[spacing.size() / 2];
  if (!(cell > 0) || !std::isfinite(cell)) return;
  const OccupancyGrid grid(points, cell, std::size_t(1) << 27);  // 16 MB of bits at most

  // Every point of a piece of fewer than 16 points casts rays; in larger ones one point in
  // `stride`, so that about kVoters points cast rays in all (the rays cost more than the rest of
  // the orientation: 460k points of the table scan, 3.1 s of rays from every point).
  std::vector<std::size_t> members(pieces, 0), voters(pieces, 0);
  std::size_t graphSize = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (inGraph[i] && piece[i] != kNone) ++members[piece[i]], ++graphSize;
  constexpr std::size_t kVoters = 100000;
  // Pieces of fewer than k points (noise and creases in a scan cut the tree into many) are left
  // as the tree oriented them: turned on a handful of votes they disagreed with their neighbours
  // more often than before (the table scan: 94.2% -> 93.1% of their 10-NN edges agreeing).
  const std::size_t minPiece = options.k;
  const std::size_t stride = std::max<std::size_t>(1, (graphSize + kVoters - 1) / kVoters);
  auto votes = [&](std::size_t i) {
    const std::size_t size = inGraph[i] && piece[i] != kNone ? members[piece[i]] : 0;
    return size >= minPiece && (i % stride == 0 || size < 16);
  };
  std::vector<std::int8_t> vote(n, 0);
  ProgressTracker tracker(progress, "orientation visibility", n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (tracker.cancelled()) return;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        if (!votes(i)) continue;
                        const Vec3 nrm = oriented[i].normalized();
                        const int out = escapingRays(grid, points[i], nrm);
                        const int in = escapingRays(grid, points[i], -nrm);
                        vote[i] = out - in >= 3 ? 1 : (in - out >= 3 ? -1 : 0);
                      }
                      tracker.advance(range.size());
                    });
  tracker.finish();
  // Votes scaled to the whole piece, so that they weigh against its edges as if all had voted.
  std::vector<double> against(pieces, 0), along(pieces, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!votes(i)) continue;
    ++voters[piece[i]];
    against[piece[i]] += vote[i] < 0 ? 1 : 0;
    along[piece[i]] += vote[i] > 0 ? 1 : 0;
  }
  for (Index q = 0; q < pieces; ++q) {
    if (voters[q] == 0) continue;
    const double scale = double(members[q]) / double(voters[q]);
    against[q] *= scale;
    along[q] *= scale;
  }
  std::vector<std::uint8_t> turn(pieces, 0);
  for (Index q = 0; q < pieces; ++q)
    turn[q] = 4 * against[q] >= double(members[q]) && against[q] > 2 * along[q] ? 1 : 0;
  // The rays can be wrong where an object is open (a scan's missing base lets the inward rays
  // out) and its own parts hide the outside. The graph edges that join a piece to the rest along
  // one surface (not across a thin part, normals within 60 degrees) also speak for its sign: a
  // group of candidates (joined by such edges that agree) is turned only when its votes against
  // outnumber those for by more than kEdgeWeight times the edges to other pieces that agree
  // with its sign outnumber those that disagree.
  std::vector<std::uint16_t> agreeAt(n, 0), disagreeAt(n, 0);
  using Link = std::pair<Index, Index>;
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  tbb::enumerable_thread_specific<std::vector<Link>> linkScratch;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<Neighbor>& nbrs = scratch.local();
                      std::vector<Link>& links = linkScratch.local();
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        if (!inGraph[i] || piece[i] == kNone || !turn[piece[i]]) continue;
                        index.knnSearch(points[i], options.k + 1, nbrs);
                        for (const Neighbor& nb : nbrs) {
                          const Index j = nb.index;
                          if (j == i || !inGraph[j] || piece[j] == piece[i] || piece[j] == kNone)
                            continue;
                          if (acrossSheet(points[i], oriented[i], points[j], oriented[j])) continue;
                          const double c = oriented[i].dot(oriented[j]) /
                                           (oriented[i].norm() * oriented[j].norm());
                          if (c >= 0.5 && turn[piece[j]]) {
                            links.emplace_back(piece[i], piece[j]);
                            continue;
                          }
                          agreeAt[i] += c >= 0.5 ? 1 : 0;
                          disagreeAt[i] += c <= -0.5 ? 1 : 0;
                        }
                      }
                    });
  // Candidates that agree with each other along one surface are decided together: noise cuts a
  // misoriented side into many pieces, each agreeing with the next.
  DisjointSets groups(pieces);
  for (const std::vector<Link>& links : linkScratch)
    for (const Link& l : links) groups.unite(l.first, l.second);
  std::vector<double> groupAgainst(pieces, 0), groupAlong(pieces, 0), groupAgree(pieces, 0),
      groupDisagree(pieces, 0), groupMembers(pieces, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i] || piece[i] == kNone || !turn[piece[i]]) continue;
    const Index g = groups.find(piece[i]);
    groupAgree[g] += agreeAt[i];
    groupDisagree[g] += disagreeAt[i];
  }
  for (Index q = 0; q < pieces; ++q) {
    if (!turn[q]) continue;
    const Index g = groups.find(q);
    groupAgainst[g] += against[q];
    groupAlong[g] += along[q];
    groupMembers[g] += double(members[q]);
  }
  for (Index q = 0; q < pieces; ++q) {
    if (!turn[q]) continue;
    const Index g = groups.find(q);
    turn[q] =
        groupAgainst[g] - groupAlong[g] > kEdgeWeight * (groupAgree[g] - groupDisagree[g]) ? 1 : 0;
    result.piecesFlipped += turn[q];
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i] || piece[i] == kNone || !turn[piece[i]]) continue;
    oriented[i] = -oriented[i];
    flipped[i] ^= 1;
  }
}

// NormalOrientationOptions::faceViewpoint: each piece of the tree (cut at its guesses: creases,
// thin parts) whose normals face away from the viewpoint (mean cosine to it below -0.1: a piece
// seen edge-on says nothing) is turned over. A component is left as the tree oriented it when
// the viewpoint lies within its bounding box (a frame's origin inside an object or a scene is no
// scanner looking at it from one side) or farther from the box than its diagonal (a default
// VIEWPOINT at the origin of georeferenced points).
void turnPiecesToFace(const std::vector<Vec3>& points, const Vec3& viewpoint,
                      const std::vector<std::uint8_t>& inGraph, DisjointSets& sets,
                      const std::vector<Index>& piece, Index pieces, std::vector<Vec3>& oriented,
                      std::vector<std::uint8_t>& flipped) {
  const std::size_t n = points.size();
  std::vector<double> facing(pieces, 0.0);
  std::vector<std::size_t> count(pieces, 0);
  std::vector<Vec3> lo(n, Vec3::Constant(std::numeric_limits<double>::infinity()));
  std::vector<Vec3> hi(n, Vec3::Constant(-std::numeric_limits<double>::infinity()));
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i]) continue;
    const Index root = sets.find(Index(i));
    const Vec3 towards = viewpoint - points[i];
    const double norm = towards.norm() * oriented[i].norm();
    if (norm > 0) facing[piece[i]] += oriented[i].dot(towards) / norm;
    ++count[piece[i]];
    lo[root] = lo[root].cwiseMin(points[i]);
    hi[root] = hi[root].cwiseMax(points[i]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i] || !(facing[piece[i]] < -0.1 * double(count[piece[i]]))) continue;
    const Index root = sets.find(Index(i));
    const Vec3 outside = (lo[root] - viewpoint).cwiseMax(viewpoint - hi[root]).cwiseMax(0.0);
    if (outside.isZero() || outside.norm() > (hi[root] - lo[root]).norm()) continue;
    oriented[i] = -oriented[i];
    flipped[i] ^= 1;
  }
}

void checkCancel(const ProgressCallback& progress, double fraction, const char* stage) {
  if (progress && !progress(fraction, stage)) throw Cancelled();
}

NormalOrientationResult orientByViewpoint(const std::vector<Vec3>& points,
                                          std::vector<Vec3>& normals,
                                          const std::vector<std::uint8_t>& valid,
                                          const NormalOrientationOptions& options,
                                          const ProgressCallback& progress) {
  const std::size_t n = points.size();
  NormalOrientationResult result;
  result.reliable.assign(n, 0);
  std::vector<std::uint8_t> flipped(n, 0);
  std::vector<Vec3> oriented = normals;
  ProgressTracker tracker(progress, "normal orientation (viewpoint)", n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (tracker.cancelled()) return;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        Vec3& nrm = oriented[i];
                        if (!usable(nrm)) continue;
                        const Vec3 view = options.viewpoint - points[i];
                        const double d = nrm.dot(view);
                        if (d < 0.0) {
                          nrm = -nrm;
                          flipped[i] = 1;
                        }
                        const double scale = view.norm() * nrm.norm();
                        const bool ok = (valid.empty() || valid[i]) && scale > 0.0 &&
                                        std::abs(d) >= options.grazingThreshold * scale;
                        result.reliable[i] = ok ? 1 : 0;
                      }
                      tracker.advance(range.size());
                    });
  tracker.finish();
  normals.swap(oriented);
  for (std::size_t i = 0; i < n; ++i) {
    result.flippedCount += flipped[i];
    result.unreliableCount += result.reliable[i] ? 0 : 1;
  }
  return result;
}

NormalOrientationResult orientByMst(const std::vector<Vec3>& points, std::vector<Vec3>& normals,
                                    const SpatialIndex& index,
                                    const std::vector<std::uint8_t>& valid,
                                    const NormalOrientationOptions& options,
                                    const ProgressCallback& progress) {
  const std::size_t n = points.size();
  const std::size_t k = options.k;
  NormalOrientationResult result;
  result.reliable.assign(n, 0);
  std::vector<Vec3> oriented = normals;
  std::vector<std::uint8_t> inGraph(n);
  for (std::size_t i = 0; i < n; ++i)
    inGraph[i] = usable(oriented[i]) && (valid.empty() || valid[i]) ? 1 : 0;

  // 1. Riemannian graph: k slots per point, edge stored as (min, max) so that sorting brings the
  //    two copies of a mutual-neighbour edge together for unique(). Points outside the graph
  //    record their nearest graph neighbour to copy its orientation at the end.
  std::vector<Edge> edges(n * k, Edge{0.0f, kNone, kNone});
  std::vector<Index> adopter(n, kNone);
  std::vector<float> kthDistance(n, 0.0f);  // the visibility grid's cell size
  {
    // Queries along the Morton curve (as in NormalEstimation); each point fills its own slots.
    const std::vector<Index> order = spatialOrder(points);
    ProgressTracker tracker(progress, "orientation graph", n);
    tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        if (tracker.cancelled()) return;
                        std::vector<Neighbor>& nbrs = scratch.local();
                        for (std::size_t v = range.begin(); v != range.end(); ++v) {
                          const std::size_t i = order[v];
                          if (!usable(oriented[i])) continue;
                          index.knnSearch(points[i], k + 1, nbrs);
                          if (!nbrs.empty()) kthDistance[i] = float(std::sqrt(nbrs.back().distSq));
                          std::size_t slot = 0;
                          for (const Neighbor& nb : nbrs) {
                            const Index j = nb.index;
                            if (j == i || !inGraph[j]) continue;
                            if (!inGraph[i]) {  // first (nearest) graph neighbour adopts this point
                              adopter[i] = j;
                              break;
                            }
                            if (slot == k) break;
                            const double cost = edgeCost(points[i], oriented[i], points[j],
                                                         oriented[j], options.acrossWeight);
                            edges[i * k + slot++] =
                                Edge{float(cost), Index(std::min<std::size_t>(i, j)),
                                     Index(std::max<std::size_t>(i, j))};
                          }
                        }
                        tracker.advance(range.size());
                      });
    tracker.finish();
  }
  // Empty slots sort last with a cost above any real one.
  tbb::parallel_for(std::size_t(0), edges.size(), [&](std::size_t e) {
    if (edges[e].a == kNone) edges[e].cost = std::numeric_limits<float>::infinity();
  });
  checkCancel(progress, 0.0, "orientation sort");
  tbb::parallel_sort(edges.begin(), edges.end());
  checkCancel(progress, 1.0, "orientation sort");

  // 2. Kruskal: minimum spanning forest. Duplicate edges are adjacent after the sort (same cost,
  //    same ends) and the second copy is rejected by the union-find anyway.
  DisjointSets sets(n);
  std::vector<Index> treeA, treeB;
  treeA.reserve(n);
  treeB.reserve(n);
  for (const Edge& e : edges) {
    if (e.a == kNone) break;
    if (sets.unite(e.a, e.b)) {
      treeA.push_back(e.a);
      treeB.push_back(e.b);
    }
  }
  std::vector<Edge>().swap(edges);
  checkCancel(progress, 0.5, "orientation tree");

  // 3. Tree adjacency (CSR) and one seed per component: the highest point (largest z).
  std::vector<std::size_t> start(n + 1, 0);
  for (std::size_t e = 0; e < treeA.size(); ++e) {
    ++start[treeA[e] + 1];
    ++start[treeB[e] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<Index> adjacent(start[n]);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t e = 0; e < treeA.size(); ++e) {
      adjacent[fill[treeA[e]]++] = treeB[e];
      adjacent[fill[treeB[e]]++] = treeA[e];
    }
  }
  std::vector<Index> seedOf(n, kNone);  // indexed by the component's root
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i]) continue;
    const Index root = sets.find(Index(i));
    const Index s = seedOf[root];
    if (s == kNone || points[i].z() > points[s].z()) seedOf[root] = Index(i);
  }

  // 4. Propagation from each seed (breadth first), seeds in increasing index order.
  std::vector<std::uint8_t> flipped(n, 0), visited(n, 0);
  std::vector<Index> piece(n, kNone);  // the tree cut at its guesses (visibility)
  Index pieces = 0;
  std::vector<Index> queue;
  queue.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i] || sets.find(Index(i)) != Index(i)) continue;
    const Index seed = seedOf[i];
    ++result.componentCount;
    if (oriented[seed].z() < 0.0) {  // seed oriented towards +z (file comment)
      oriented[seed] = -oriented[seed];
      flipped[seed] = 1;
    }
    visited[seed] = 1;
    piece[seed] = pieces++;
    // A lone point has nothing to agree with: its +z orientation is a guess.
    result.reliable[seed] = start[seed + 1] > start[seed] ? 1 : 0;
    queue.clear();
    queue.push_back(seed);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const Index p = queue[head];
      for (std::size_t a = start[p]; a < start[p + 1]; ++a) {
        const Index c = adjacent[a];
        if (visited[c]) continue;
        visited[c] = 1;
        const double d = oriented[c].dot(oriented[p]);
        if (d < 0.0) {
          oriented[c] = -oriented[c];
          flipped[c] = 1;
        }
        const double cosine = std::abs(d) / (oriented[c].norm() * oriented[p].norm());
        result.reliable[c] = cosine >= options.creaseThreshold ? 1 : 0;
        const bool guess = cosine < options.creaseThreshold ||
                           acrossSheet(points[p], oriented[p], points[c], oriented[c]);
        piece[c] = guess ? pieces++ : piece[p];
        queue.push_back(c);
      }
    }
  }
  checkCancel(progress, 1.0, "orientation tree");

  if (options.faceViewpoint)
    turnPiecesToFace(points, options.viewpoint, inGraph, sets, piece, pieces, oriented, flipped);

  if (options.visibility)
    correctByVisibility(points, oriented, index, inGraph, kthDistance, piece, pieces, options,
                        progress, flipped, result);

  // 5. Points outside the graph follow their nearest graph neighbour; never reliable.
  for (std::size_t i = 0; i < n; ++i) {
    if (inGraph[i] || adopter[i] == kNone) continue;
    if (oriented[i].dot(oriented[adopter[i]]) < 0.0) {
      oriented[i] = -oriented[i];
      flipped[i] = 1;
    }
  }
  normals.swap(oriented);
  for (std::size_t i = 0; i < n; ++i) {
    result.flippedCount += flipped[i];
    result.unreliableCount += result.reliable[i] ? 0 : 1;
  }
  return result;
}

}  // namespace

NormalOrientationResult orientNormals(const std::vector<Vec3>& points, std::vector<Vec3>& normals,
                                      const SpatialIndex& index,
                                      const NormalOrientationOptions& options,
                                      const std::vector<std::uint8_t>& valid,
                                      const ProgressCallback& progress) {
  if (normals.size() != points.size())
    throw OptionError("orientNormals: " + std::to_string(normals.size()) + " normals for " +
                      std::to_string(points.size()) + " points");
  if (!valid.empty() && valid.size() != points.size())
    throw OptionError("orientNormals: " + std::to_string(valid.size()) + " validity flags for " +
                      std::to_string(points.size()) + " points");
  if (options.method == OrientationMethod::Viewpoint) {
    if (!options.viewpoint.allFinite())
      throw OptionError("orientNormals: the viewpoint must have finite coordinates");
    return orientByViewpoint(points, normals, valid, options, progress);
  }
  if (options.k < 1 || options.k > kMaxNeighborCount)
    throw OptionError("NormalOrientationOptions::k must be in [1, " +
                      std::to_string(kMaxNeighborCount) + "] (default 10), got " +
                      std::to_string(options.k));
  if (!(options.visibilityCell > 0) || !std::isfinite(options.visibilityCell))
    throw OptionError(
        "NormalOrientationOptions::visibilityCell must be finite and > 0 (default 0.7, in units of "
        "the median distance to the k-th neighbour)");
  if (!std::isfinite(options.acrossWeight) || options.acrossWeight < 0)
    throw OptionError(
        "NormalOrientationOptions::acrossWeight must be finite and >= 0 (0: Hoppe's "
        "cost alone)");
  if (index.size() != points.size())
    throw OptionError("orientNormals: the index holds " + std::to_string(index.size()) +
                      " points but " + std::to_string(points.size()) + " were given");
  return orientByMst(points, normals, index, valid, options, progress);
}

NormalOrientationResult orientNormals(const std::vector<Vec3>& points, std::vector<Vec3>& normals,
                                      const NormalOrientationOptions& options,
                                      const std::vector<std::uint8_t>& valid,
                                      const ProgressCallback& progress) {
  if (options.method == OrientationMethod::Viewpoint) {
    const BruteForceIndex unused(points);  // the viewpoint method makes no queries
    return orientNormals(points, normals, unused, options, valid, progress);
  }
  const auto index = makeSpatialIndex(points);
  return orientNormals(points, normals, *index, options, valid, progress);
}

}  // namespace scalespace
