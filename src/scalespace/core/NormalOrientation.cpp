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

/// NormalOrientationOptions::reflectAcrossBisector: n_a . R(n_b), R the reflection across the
/// plane perpendicular to d = p_b - p_a (unit normals; the offsets along them shrunk towards 0 by
/// `noise`, so that the term fades where they are within the noise). Bilinear in the two normals:
/// turning either over turns its sign, as for n_a . n_b.
double reflectedAgreement(const Vec3& pa, const Vec3& na, const Vec3& pb, const Vec3& nb,
                          double noise) {
  const Vec3 ua = na.normalized(), ub = nb.normalized(), d = pb - pa;
  const double c = ua.dot(ub), lengthSq = d.squaredNorm();
  if (!(lengthSq > 0)) return c;
  const auto shrink = [noise](double x) {
    return std::copysign(std::max(0.0, std::abs(x) - noise), x);
  };
  const double q = c - 2.0 * shrink(ua.dot(d)) * shrink(ub.dot(d)) / lengthSq;
  return std::clamp(q, -1.0, 1.0);
}

/// The offset between two points runs along both normals (within 60 degrees), by more than
/// `minOffset` along each: an edge between the two sides of a thin part rather than along one
/// surface. Under noise, neighbours on one surface are offset along the normals by the noise
/// (minOffset, see noiseOffset()).
bool acrossSheet(const Vec3& pa, const Vec3& na, const Vec3& pb, const Vec3& nb,
                 double minOffset = 0) {
  const OffsetCosines along = offsetCosines(pa, na, pb, nb);
  if (!(along.a > 0.5 && along.b > 0.5)) return false;
  if (!(minOffset > 0)) return true;
  const Vec3 d = pb - pa;
  return std::abs(na.dot(d)) > minOffset * na.norm() && std::abs(nb.dot(d)) > minOffset * nb.norm();
}

/// Mean |n . (q - p)| over the neighbours q of p (`nbrs`, p itself skipped) for the unit normal
/// of p: about 1.1 sigma on a surface with Gaussian noise sigma, about 0 on a clean flat face.
float offPlaneSpread(const std::vector<Vec3>& points, std::size_t i, const Vec3& normal,
                     const std::vector<Neighbor>& nbrs) {
  const Vec3 unit = normal.normalized();
  double sum = 0;
  std::size_t count = 0;
  for (const Neighbor& nb : nbrs) {
    if (nb.index == i) continue;
    sum += std::abs(unit.dot(points[nb.index] - points[i]));
    ++count;
  }
  return count > 0 ? float(sum / double(count)) : -1.0f;
}

/// Offsets along the normals below this many times the cloud's median off-plane spread (the mean
/// |n_i . (p_j - p_i)| over a point's k nearest neighbours) are noise, not the thickness of a thin
/// part. Noisy rotor (libcgal-demo, 100k points, noise 1e-3 of the diagonal; a closed surface),
/// share of the normals against the mesh's for factors 0, 3, 4, 5, 6, 7, 8, 10: 33.6, 13.0, 7.1,
/// 1.4, 1.4, 1.4, 8.3, 8.6% (45% before the closed-surface rules): 6 is the middle of the plateau.
/// With 0 the noise cuts the tree into 14,978 pieces. On clean flat-faced clouds (the CAD parts)
/// the median spread is about 0 and nothing changes; on clean curved ones it is the curvature's,
/// about r^2 / 4R (r the k-th neighbour's distance, R the radius of curvature), well under the
/// thickness of any part the rays can see.
constexpr double kNoiseOffsetFactor = 6.0;

/// Offsets along the normals below this many times the median off-plane spread are left out of
/// reflectedAgreement(): about 3.3 sigma under Gaussian noise sigma; 0 on clean flat faces.
constexpr double kReflectNoiseFactor = 3.0;

/// `factor` times the median of the points' off-plane spreads (negative: none).
double noiseOffset(const std::vector<float>& spread, double factor = kNoiseOffsetFactor) {
  std::vector<float> known;
  known.reserve(spread.size());
  for (float v : spread)
    if (v >= 0) known.push_back(v);
  if (known.empty()) return 0.0;
  std::nth_element(known.begin(), known.begin() + std::ptrdiff_t(known.size() / 2), known.end());
  return factor * double(known[known.size() / 2]);
}

/// The signed agreement of two oriented normals along a graph edge (in [-1, 1]): n_a . n_b
/// (Hoppe) or reflectedAgreement() (NormalOrientationOptions::reflectAcrossBisector).
struct EdgeAgreement {
  const std::vector<Vec3>& points;
  bool reflect = false;
  double noise = 0;  // reflectedAgreement's
  double operator()(const Vec3& na, Index a, const Vec3& nb, Index b) const {
    if (reflect) return reflectedAgreement(points[a], na, points[b], nb, noise);
    return std::clamp(na.dot(nb) / (na.norm() * nb.norm()), -1.0, 1.0);
  }
};

/// The tree cut where its sign decision is a guess: a crease (|agreement| < creaseThreshold) or
/// an edge across a thin part (acrossSheet with `minOffset` of the edge's child). `parent` and
/// `treeOrder` are the tree (parents first); returns the number of pieces.
template <class MinOffset>
Index cutTree(const std::vector<Vec3>& points, const std::vector<Vec3>& oriented,
              const std::vector<Index>& parent, const std::vector<Index>& treeOrder,
              const EdgeAgreement& agreement, double creaseThreshold, const MinOffset& minOffset,
              std::vector<Index>& piece) {
  Index pieces = 0;
  for (const Index c : treeOrder) {
    const Index p = parent[c];
    if (p == kNone) {
      piece[c] = pieces++;
      continue;
    }
    const double cosine = std::abs(agreement(oriented[c], c, oriented[p], p));
    const bool guess = cosine < creaseThreshold ||
                       acrossSheet(points[p], oriented[p], points[c], oriented[c], minOffset(c));
    piece[c] = guess ? pieces++ : piece[p];
  }
  return pieces;
}

/// Points of each of the `pieces` pieces of the tree.
std::vector<std::size_t> countMembers(const std::vector<Index>& piece, Index pieces,
                                      const std::vector<Index>& treeOrder) {
  std::vector<std::size_t> members(pieces, 0);
  for (const Index v : treeOrder) ++members[piece[v]];
  return members;
}

/// A piece whose rays disagree, one part saying it faces in and another that it faces out, joins
/// two sides the cuts missed (a thin part's rim under noise). It is split at the tree edge that
/// best separates them: the subtree whose net vote (against minus for) has the sign opposite to
/// the rest's, with the larger of the two smaller net votes, when that is at least `minPiece`
/// and both parts have at least `minPiece` points. Up to 8 rounds, each splitting every piece once
/// at most. Deterministic: ties go to the first subtree in tree order. Noisy creases
/// (bench_features): 6.0% -> 3.2% of the normals against the mesh's, MCC 0.710 -> 0.783.
void splitMixedPieces(const std::vector<Index>& parent, const std::vector<Index>& treeOrder,
                      const std::vector<std::int8_t>& vote, const std::vector<std::uint8_t>& voted,
                      std::size_t minPiece, std::vector<Index>& piece, Index& pieces) {
  const std::size_t n = piece.size();
  std::vector<long> net(n), size(n);
  for (int round = 0; round < 8; ++round) {
    std::vector<long> total(pieces, 0), count(pieces, 0);
    for (const Index v : treeOrder) {
      net[v] = voted[v] ? long(vote[v] < 0) - long(vote[v] > 0) : 0;
      size[v] = 1;
      total[piece[v]] += net[v];
      ++count[piece[v]];
    }
    for (std::size_t r = treeOrder.size(); r-- > 0;) {  // children before parents
      const Index v = treeOrder[r], p = parent[v];
      if (p == kNone || piece[p] != piece[v]) continue;
      net[p] += net[v];
      size[p] += size[v];
    }
    std::vector<long> bestScore(pieces, 0);
    std::vector<Index> best(pieces, kNone);
    for (const Index v : treeOrder) {
      const Index p = parent[v];
      if (p == kNone || piece[p] != piece[v]) continue;
      const Index q = piece[v];
      const long a = net[v], b = total[q] - net[v];
      const long smaller = std::min(size[v], count[q] - size[v]);
      if (a == 0 || b == 0 || (a > 0) == (b > 0) || smaller < long(minPiece)) continue;
      const long score = std::min(std::abs(a), std::abs(b));
      if (score >= long(minPiece) && score > bestScore[q]) bestScore[q] = score, best[q] = v;
    }
    const std::vector<Index> before = piece;
    bool any = false;
    for (const Index v : treeOrder) {  // parents first: a subtree follows its moved root
      const Index p = parent[v];
      if (best[before[v]] == v) {
        piece[v] = pieces++;
        any = true;
      } else if (p != kNone && before[p] == before[v]) {
        piece[v] = piece[p];
      }
    }
    if (!any) return;
  }
}

/// The visibility correction trusts the rays more on a closed surface: there, a point's rays
/// escape on one side at most. When no more than this share of the points of a component of the
/// graph that cast rays see out on both sides (3 of 5 rays each), the component is taken as
/// closed. Measured: libcgal-demo's CAD parts sampled (bench_features) 0.3-0.5%, noisy blade 2.5%,
/// clean blade 6.9% (rays pass through its thin rim), kitten, ball, blobby, sphere_20k_normal
/// 0-0.4%; open scans: the real table scan 38%, hippo1 99%, building 18%, spheres 17%, oni 11%.
constexpr double kClosedOpenShare = 0.05;

/// A point's vote on its normal from the rays escaping in front (`out`) and behind (`in`): +1
/// when at least three more escape in front, -1 the other way round, else 0.
std::int8_t voteOf(int out, int in) { return out - in >= 3 ? 1 : (in - out >= 3 ? -1 : 0); }

/// Each graph edge that agrees with a piece's sign outweighs two of the rays' votes against it.
/// Measured on libcgal-demo's points_3 (bench/README.md, "visibility"): with 1, the floor of
/// building.ply, under its roof and open below, is turned down (its points against the file's
/// normals: 2.1% -> 30.7%); with 2 it stays up, and the thin parts of rotor and blade and the
/// pieces of spheres.ply are still turned.
constexpr double kEdgeWeight = 2.0;

/// Visibility pass (file comment of the header). A point votes for its side when at least three
/// more of its five rays escape on that side than on the other; a piece is a candidate when its
/// votes against its side are at least a quarter of its points (a tenth on a closed surface) and
/// more than twice those for. On the closed components (kClosedOpenShare) the tree is cut again
/// with the noise taken into account (noiseOffset() of the points' off-plane `spread`,
/// acrossSheet) and the mixed pieces are split (splitMixedPieces()). Points whose component faced
/// a viewpoint (`settled`) cast no votes: a scan's line of sight is better evidence than the rays.
void correctByVisibility(const std::vector<Vec3>& points, std::vector<Vec3>& oriented,
                         const SpatialIndex& index, const std::vector<std::uint8_t>& inGraph,
                         const std::vector<std::uint8_t>& settled,
                         const std::vector<float>& kthDistance, const std::vector<Index>& parent,
                         const std::vector<Index>& treeOrder, const std::vector<float>& spread,
                         const EdgeAgreement& agreement, std::vector<Index>& piece, Index pieces,
                         const NormalOrientationOptions& options, const ProgressCallback& progress,
                         std::vector<std::uint8_t>& flipped, NormalOrientationResult& result) {
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
  std::vector<std::size_t> members = countMembers(piece, pieces, treeOrder);
  const std::size_t graphSize = treeOrder.size();
  constexpr std::size_t kVoters = 100000;
  // Pieces of fewer than k points (noise and creases in a scan cut the tree into many) are left
  // as the tree oriented them: turned on a handful of votes they disagreed with their neighbours
  // more often than before (the table scan: 94.2% -> 93.1% of their 10-NN edges agreeing).
  const std::size_t minPiece = options.k;
  const std::size_t stride = std::max<std::size_t>(1, (graphSize + kVoters - 1) / kVoters);
  // Points of the smaller pieces cast rays too (`probes`), one in `stride`, only to tell closed
  // from open: under heavy noise the tree falls apart into pieces of a few points (bench_features'
  // noisy blade, k = 80: 34,833 pieces), none cast, and the surface was neither.
  std::vector<std::uint8_t> casts(n, 0), probes(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t size = inGraph[i] && piece[i] != kNone ? members[piece[i]] : 0;
    casts[i] = !settled[i] && size >= minPiece && (i % stride == 0 || size < 16) ? 1 : 0;
    probes[i] = !casts[i] && !settled[i] && size > 0 && i % stride == 0 ? 1 : 0;
  }
  std::vector<std::int8_t> vote(n, 0);
  std::vector<std::uint8_t> openBoth(n, 0);
  ProgressTracker tracker(progress, "orientation visibility", n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (tracker.cancelled()) return;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        if (!casts[i] && !probes[i]) continue;
                        const Vec3 nrm = oriented[i].normalized();
                        const int out = grid.escapingRays(points[i], nrm);
                        const int in = grid.escapingRays(points[i], -nrm);
                        if (casts[i]) vote[i] = voteOf(out, in);
                        openBoth[i] = out >= 3 && in >= 3 ? 1 : 0;
                      }
                      tracker.advance(range.size());
                    });
  tracker.finish();
  // Closed or open is decided per component of the graph: a scene holds closed objects (pipes
  // floating above a floor, scanned all round) next to open sheets (the floor), and the floor's
  // rays, out on both sides, must not deny the pipes the closed rules (pipe rack of
  // bench_cylinders, noisy: the thin and the bent pipes 78% and 99% inward without).
  std::vector<Index> component(n, kNone);
  Index components = 0;
  for (const Index c : treeOrder)
    component[c] = parent[c] == kNone ? components++ : component[parent[c]];
  std::vector<std::size_t> casters(components, 0), open(components, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (casts[i] || probes[i]) ++casters[component[i]], open[component[i]] += openBoth[i];
  std::vector<std::uint8_t> closedComponent(components, 0);
  bool anyClosed = false, anyOpen = false;
  for (Index c = 0; c < components; ++c) {
    if (casters[c] == 0) continue;
    closedComponent[c] = double(open[c]) <= kClosedOpenShare * double(casters[c]) ? 1 : 0;
    result.openShare = std::max(result.openShare, double(open[c]) / double(casters[c]));
    anyClosed = anyClosed || closedComponent[c];
    anyOpen = anyOpen || !closedComponent[c];
    result.closedComponents += closedComponent[c];
  }
  result.closedSurface = anyClosed && !anyOpen;
  const auto isClosed = [&](std::size_t i) { return closedComponent[component[i]] != 0; };
  const double noise = anyClosed ? noiseOffset(spread) : 0.0;
  const auto noiseAt = [&](std::size_t i) { return isClosed(i) ? noise : 0.0; };
  if (anyClosed) {
    pieces = cutTree(points, oriented, parent, treeOrder, agreement, options.creaseThreshold,
                     noiseAt, piece);
    members = countMembers(piece, pieces, treeOrder);
    // Not on flat-faced clean clouds (median off-plane spread under a thousandth of the spacing;
    // curvature or noise lift it above): there the cuts are where the sides meet, and a piece
    // whose rays disagree has rays that leak (clean rotor with sheet normals: 12.6% -> 13.8% of
    // the normals against the mesh's when split, per-curve recall 0.89 -> 0.78). On the clean
    // curved sphere_20k_normal it runs: 19.3% -> 16.5% against the file's normals. The points
    // that cast rays were chosen on the first cut's pieces: fragments of fewer than k points
    // there cast none, and their votes are left out of the pieces they join.
    if (noise > 1e-3 * spacing[spacing.size() / 2]) {
      std::vector<std::uint8_t> voted(n, 0);
      for (std::size_t i = 0; i < n; ++i)
        voted[i] = casts[i] && isClosed(i) && members[piece[i]] >= minPiece ? 1 : 0;
      splitMixedPieces(parent, treeOrder, vote, voted, minPiece, piece, pieces);
      members = countMembers(piece, pieces, treeOrder);
    }
    result.pieceCount = pieces;
  }
  auto votes = [&](std::size_t i) { return casts[i] && members[piece[i]] >= minPiece; };
  // Votes scaled to the whole piece, so that they weigh against its edges as if all had voted.
  std::vector<std::size_t> voters(pieces, 0);
  std::vector<double> against(pieces, 0), along(pieces, 0), seesThrough(pieces, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!votes(i)) continue;
    ++voters[piece[i]];
    against[piece[i]] += vote[i] < 0 ? 1 : 0;
    along[piece[i]] += vote[i] > 0 ? 1 : 0;
    seesThrough[piece[i]] += openBoth[i];
  }
  for (Index q = 0; q < pieces; ++q) {
    if (voters[q] == 0) continue;
    const double scale = double(members[q]) / double(voters[q]);
    against[q] *= scale;
    along[q] *= scale;
    seesThrough[q] *= scale;
  }
  // On a closed surface, a tenth: a thin part's rays pass through it and abstain (rotor with
  // sheet normals: a misoriented piece of 18,929 points, 1,483 votes against, 26 for).
  std::vector<std::uint8_t> closedPiece(pieces, 0);
  for (const Index v : treeOrder) closedPiece[piece[v]] = isClosed(v) ? 1 : 0;
  std::vector<std::uint8_t> turn(pieces, 0);
  for (Index q = 0; q < pieces; ++q) {
    const double share = closedPiece[q] ? 0.1 : 0.25;
    turn[q] = against[q] >= share * double(members[q]) && against[q] > 2 * along[q] ? 1 : 0;
    // An open piece whose points see out on both sides at least as often as they say it faces in
    // is a sheet partly hidden by what stands over it, not the inside of a closed surface: there
    // the rays escape behind nearly every point and almost none see out on both sides. The pipe
    // rack of `generate pipes` without normals: its floor, a third of it under the pipes, had 32%
    // of its points voting against it, 0.2% for it and 66% seeing out on both sides, and was
    // turned down (61% of the scene's normals against the exact ones; 0.3% with this).
    if (!closedPiece[q] && seesThrough[q] >= against[q]) turn[q] = 0;
  }
  // The rays can be wrong where an object is open (a scan's missing base lets the inward rays
  // out) and its own parts hide the outside. The graph edges that join a piece to the rest along
  // one surface (not across a thin part, normals within 60 degrees) also speak for its sign: a
  // group of candidates (joined by such edges that agree) is turned only when its votes against
  // outnumber those for by more than kEdgeWeight times the edges to other pieces that agree
  // with its sign outnumber those that disagree. On a closed surface the pieces of fewer than k
  // points do not speak: noise cuts a misoriented side into fragments that the tree oriented
  // alike, and their edges outvoted the rays (noisy rotor: no piece turned, 45% of the normals
  // against the mesh's).
  std::vector<std::uint16_t> agreeAt(n, 0), disagreeAt(n, 0);
  using Link = std::pair<Index, Index>;
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  tbb::enumerable_thread_specific<std::vector<Link>> linkScratch;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 1024),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<Neighbor>& nbrs = scratch.local();
        std::vector<Link>& links = linkScratch.local();
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (!inGraph[i] || piece[i] == kNone || !turn[piece[i]]) continue;
          index.knnSearch(points[i], options.k + 1, nbrs);
          for (const Neighbor& nb : nbrs) {
            const Index j = nb.index;
            if (j == i || !inGraph[j] || piece[j] == piece[i] || piece[j] == kNone) continue;
            if (isClosed(i) && members[piece[j]] < minPiece) continue;
            if (acrossSheet(points[i], oriented[i], points[j], oriented[j], noiseAt(i))) continue;
            const double c =
                oriented[i].dot(oriented[j]) / (oriented[i].norm() * oriented[j].norm());
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
// seen edge-on says nothing) is turned over; then each point that still faces away beyond
// grazing (cosine below -kFacingCut) is turned alone: no scan sees a surface from behind. With
// the pieces alone 37% of the normals of the pipe rack's cable seen from one side faced away (the
// tree crossed from one strand to the next through their grazing sides with the wrong sign, and
// a piece held both), 6.5% with this; the real table scan 6.0% -> 4.1%. A component is left as
// the tree oriented it when the viewpoint lies within its bounding box (a frame's origin inside
// an object or a scene is no scanner looking at it from one side). No component is turned when
// the viewpoint lies farther from the cloud's bounding box than its diagonal (a default VIEWPOINT
// at the origin of georeferenced points); the cloud's box, not each component's: a scanner 5 m
// from a cable 4 m long in a 7 m scene sees it. The points of the components it decides are
// marked `settled`.
constexpr double kFacingCut = 0.1;

void turnPiecesToFace(const std::vector<Vec3>& points, const Vec3& viewpoint,
                      const std::vector<std::uint8_t>& inGraph, DisjointSets& sets,
                      const std::vector<Index>& piece, Index pieces, std::vector<Vec3>& oriented,
                      std::vector<std::uint8_t>& flipped, std::vector<std::uint8_t>& settled) {
  const std::size_t n = points.size();
  std::vector<double> cosine(n, 0.0);  // of each normal to the viewpoint
  std::vector<double> facing(pieces, 0.0);
  std::vector<std::size_t> count(pieces, 0);
  std::vector<Vec3> lo(n, Vec3::Constant(std::numeric_limits<double>::infinity()));
  std::vector<Vec3> hi(n, Vec3::Constant(-std::numeric_limits<double>::infinity()));
  Vec3 cloudLo = Vec3::Constant(std::numeric_limits<double>::infinity()), cloudHi = -cloudLo;
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i]) continue;
    cloudLo = cloudLo.cwiseMin(points[i]);
    cloudHi = cloudHi.cwiseMax(points[i]);
    const Index root = sets.find(Index(i));
    const Vec3 towards = viewpoint - points[i];
    const double norm = towards.norm() * oriented[i].norm();
    if (norm > 0) cosine[i] = oriented[i].dot(towards) / norm;
    facing[piece[i]] += cosine[i];
    ++count[piece[i]];
    lo[root] = lo[root].cwiseMin(points[i]);
    hi[root] = hi[root].cwiseMax(points[i]);
  }
  const Vec3 outsideCloud = (cloudLo - viewpoint).cwiseMax(viewpoint - cloudHi).cwiseMax(0.0);
  if (outsideCloud.norm() > (cloudHi - cloudLo).norm()) return;
  for (std::size_t i = 0; i < n; ++i) {
    if (!inGraph[i]) continue;
    const Index root = sets.find(Index(i));
    const Vec3 outside = (lo[root] - viewpoint).cwiseMax(viewpoint - hi[root]).cwiseMax(0.0);
    if (outside.isZero()) continue;
    settled[i] = 1;
    const bool pieceAway = facing[piece[i]] < -0.1 * double(count[piece[i]]);
    const double c = pieceAway ? -cosine[i] : cosine[i];  // after the piece's turn
    if (pieceAway == (c < -kFacingCut)) continue;         // turned twice, or not at all
    oriented[i] = -oriented[i];
    flipped[i] ^= 1;
  }
}

// Hoppe's seed, the highest point, faces +z: right where the top of a scene is a surface facing
// up, a guess where it is the rim of a wall or of a vertical pole, whose normal lies flat (the
// rack and the poles of `generate pipes|poles` turned over as a whole: 66-100% of the normals
// facing down and in), or a noisy point. The component's sign is instead what is seen from above:
// over a 64 x 64 grid of its footprint, the highest point of each column votes with the sign of its
// normal's z where that normal is within 45 degrees of vertical (a floor, a table top, a roof, the
// top of a closed object); the majority turns the whole component (the tree's relative signs are
// kept). Without votes, or on a tie, the seed's sign stays. Not on a component a viewpoint
// decided (faceViewpoint): a scan's line of sight is better evidence, and a scan in its sensor's
// frame need not have z up (the table scan of python3-pcl: the vote changed only its grazing
// pieces, 6.45% of its normals, 44.8% of them facing the scanner before and 55.2% after).
// `component`: the points order[begin, end).
void turnToFaceUp(const std::vector<Index>& order, std::size_t begin, std::size_t end,
                  const std::vector<Vec3>& points, std::vector<Vec3>& oriented,
                  std::vector<std::uint8_t>& flipped) {
  const auto first = order.begin() + std::ptrdiff_t(begin),
             last = order.begin() + std::ptrdiff_t(end);
  constexpr int kColumns = 64;
  constexpr double kNearVertical = 0.70710678118654752;  // cos 45 degrees
  double loX = std::numeric_limits<double>::max(), loY = loX, hiX = -loX, hiY = -loX;
  for (auto it = first; it != last; ++it) {
    const Index i = *it;
    loX = std::min(loX, points[i].x()), hiX = std::max(hiX, points[i].x());
    loY = std::min(loY, points[i].y()), hiY = std::max(hiY, points[i].y());
  }
  const double size = std::max(hiX - loX, hiY - loY) / kColumns;
  if (!(size > 0)) return;
  auto column = [&](double v, double lo) {
    return std::min(kColumns - 1, std::max(0, int((v - lo) / size)));
  };
  std::vector<Index> top(std::size_t(kColumns) * kColumns, kNone);
  for (auto it = first; it != last; ++it) {
    const Index i = *it;
    Index& t = top[std::size_t(column(points[i].x(), loX)) * kColumns +
                   std::size_t(column(points[i].y(), loY))];
    if (t == kNone || points[i].z() > points[t].z() || (points[i].z() == points[t].z() && i < t))
      t = i;
  }
  long vote = 0;
  for (const Index t : top) {
    if (t == kNone) continue;
    const double norm = oriented[t].norm();
    if (norm > 0 && std::abs(oriented[t].z()) >= kNearVertical * norm)
      vote += oriented[t].z() > 0 ? 1 : -1;
  }
  if (vote >= 0) return;
  for (auto it = first; it != last; ++it) {
    const Index i = *it;
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
  std::vector<float> spread(n, -1.0f);      // mean |n . offset| to the neighbours (noiseOffset)
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
                          if (inGraph[i] && (options.visibility || options.reflectAcrossBisector))
                            spread[i] = offPlaneSpread(points, i, oriented[i], nbrs);
                          std::size_t slot = 0;
                          for (const Neighbor& nb : nbrs) {
                            const Index j = nb.index;
                            if (j == i || !inGraph[j]) continue;
                            if (!inGraph[i]) {  // first (nearest) graph neighbour adopts this point
                              adopter[i] = j;
                              break;
                            }
                            if (slot == k) break;
                            // The reflected cost needs the cloud's noise: set once it is known.
                            const double cost = options.reflectAcrossBisector
                                                    ? 0.0
                                                    : edgeCost(points[i], oriented[i], points[j],
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
  // The reflected agreement needs the cloud's noise (its median off-plane spread) first.
  const EdgeAgreement agreement{
      points, options.reflectAcrossBisector,
      options.reflectAcrossBisector ? noiseOffset(spread, kReflectNoiseFactor) : 0.0};
  // Empty slots sort last with a cost above any real one.
  tbb::parallel_for(std::size_t(0), edges.size(), [&](std::size_t e) {
    Edge& edge = edges[e];
    if (edge.a == kNone)
      edge.cost = std::numeric_limits<float>::infinity();
    else if (agreement.reflect)
      edge.cost =
          float(1.0 - std::abs(agreement(oriented[edge.a], edge.a, oriented[edge.b], edge.b)));
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

  // 3. Tree adjacency (CSR) and one seed per component: the highest point (largest z), where the
  //    propagation starts; the component's sign is then the viewpoint's or turnToFaceUp's.
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
  std::vector<Index> piece(n, kNone);              // the tree cut at its guesses (visibility)
  std::vector<Index> parent(n, kNone), treeOrder;  // the tree, breadth first from each seed
  treeOrder.reserve(n);
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
        const double d = agreement(oriented[c], c, oriented[p], p);
        if (d < 0.0) {
          oriented[c] = -oriented[c];
          flipped[c] = 1;
        }
        result.reliable[c] = std::abs(d) >= options.creaseThreshold ? 1 : 0;
        parent[c] = p;
        queue.push_back(c);
      }
    }
    treeOrder.insert(treeOrder.end(), queue.begin(), queue.end());
  }
  checkCancel(progress, 1.0, "orientation tree");
  const Index pieces = cutTree(
      points, oriented, parent, treeOrder, agreement, options.creaseThreshold,
      [](Index) { return 0.0; }, piece);

  std::vector<std::uint8_t> settled(n, 0);  // the viewpoint decided (turnPiecesToFace)
  if (options.faceViewpoint)
    turnPiecesToFace(points, options.viewpoint, inGraph, sets, piece, pieces, oriented, flipped,
                     settled);
  // Where no viewpoint decided, what is seen from above does (each component is a run of
  // treeOrder starting at its seed, the one point without a parent).
  for (std::size_t begin = 0, end = 0; begin < treeOrder.size(); begin = end) {
    end = begin + 1;
    while (end < treeOrder.size() && parent[treeOrder[end]] != kNone) ++end;
    if (!settled[treeOrder[begin]]) turnToFaceUp(treeOrder, begin, end, points, oriented, flipped);
  }

  if (options.visibility)
    correctByVisibility(points, oriented, index, inGraph, settled, kthDistance, parent, treeOrder,
                        spread, agreement, piece, pieces, options, progress, flipped, result);

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
  if (options.acrossWeight > 0 && options.reflectAcrossBisector)
    throw OptionError(
        "NormalOrientationOptions::acrossWeight adds to Hoppe's cost; it cannot be combined with "
        "reflectAcrossBisector, which orients the two sides of a thin part by itself");
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

RayComparison compareByRays(const std::vector<Vec3>& points, const std::vector<Vec3>& first,
                            const std::vector<Vec3>& second, const SpatialIndex& index,
                            const NormalOrientationOptions& options, std::size_t maxPoints) {
  if (first.size() != points.size() || second.size() != points.size())
    throw OptionError("compareByRays: " + std::to_string(first.size()) + " and " +
                      std::to_string(second.size()) + " normals for " +
                      std::to_string(points.size()) + " points");
  if (options.k < 1) throw OptionError("NormalOrientationOptions::k must be >= 1");
  RayComparison result;
  const std::size_t n = points.size();
  const auto usable = [&](std::size_t i) {
    return points[i].allFinite() && first[i].allFinite() && second[i].allFinite() &&
           first[i].squaredNorm() > 0 && second[i].squaredNorm() > 0;
  };
  std::vector<Index> differing;
  for (std::size_t i = 0; i < n; ++i)
    if (usable(i) && first[i].dot(second[i]) < 0) differing.push_back(Index(i));
  result.differing = differing.size();
  if (differing.empty()) return result;
  // The cell: the median distance to the k-th neighbour over about kSpacingSample points.
  constexpr std::size_t kSpacingSample = 10000;
  std::vector<Index> probes;
  for (std::size_t i = 0; i < n; i += std::max<std::size_t>(1, n / kSpacingSample))
    if (points[i].allFinite()) probes.push_back(Index(i));
  std::vector<double> kth(probes.size(), 0.0);
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, probes.size(), 256), [&](const auto& r) {
    std::vector<Neighbor>& nbrs = scratch.local();
    for (std::size_t s = r.begin(); s != r.end(); ++s) {
      index.knnSearch(points[probes[s]], options.k + 1, nbrs);
      if (!nbrs.empty()) kth[s] = std::sqrt(nbrs.back().distSq);
    }
  });
  std::vector<double> positive;
  for (const double d : kth)
    if (d > 0) positive.push_back(d);
  if (positive.empty()) return result;
  std::nth_element(positive.begin(), positive.begin() + positive.size() / 2, positive.end());
  const double cell = options.visibilityCell * positive[positive.size() / 2];
  if (!(cell > 0) || !std::isfinite(cell)) return result;
  const OccupancyGrid grid(points, cell, std::size_t(1) << 27);
  const std::size_t cap = std::max<std::size_t>(maxPoints, 1);
  const std::size_t stride = (differing.size() + cap - 1) / cap;
  std::vector<Index> sample;
  for (std::size_t s = 0; s < differing.size(); s += stride) sample.push_back(differing[s]);
  // One pair of ray fans per point serves both: its two normals point to opposite sides.
  std::vector<std::int8_t> vote(sample.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sample.size(), 256), [&](const auto& r) {
    for (std::size_t s = r.begin(); s != r.end(); ++s) {
      const Vec3& p = points[sample[s]];
      const Vec3 nrm = first[sample[s]].normalized();
      vote[s] = voteOf(grid.escapingRays(p, nrm), grid.escapingRays(p, -nrm));
    }
  });
  result.sampled = sample.size();
  for (const std::int8_t v : vote) {
    result.firstInward += v < 0 ? 1 : 0;
    result.secondInward += v > 0 ? 1 : 0;
  }
  return result;
}

}  // namespace scalespace
