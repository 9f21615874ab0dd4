#include "scalespace/features/FeatureCurves.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>
#include <string>

#include "scalespace/core/DisjointSets.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/OccupancyGrid.hpp"
#include "scalespace/core/RegionGrower.hpp"
#include "scalespace/core/SheetBorder.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/features/CreaseLine.hpp"
#include "scalespace/features/CurveEdges.hpp"
#include "scalespace/scales/PointNoise.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw OptionError(message);
}

/// The region grower's criterion (core/RegionGrower.hpp): a curve joins points of its seed's sign.
struct SameSign {
  const std::vector<std::int8_t>& sign;
  std::int8_t payload(Index point) const { return sign[point]; }
  bool accept(std::int8_t seed, std::int8_t, std::int8_t candidate) const {
    return candidate == seed;
  }
};

/// The p-quantile (nearest rank) of `values`; 0 when empty.
double quantile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  const std::size_t k =
      std::min(values.size() - 1, std::size_t(std::floor(p * double(values.size() - 1) + 0.5)));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

/// Length of a curve given as a band of points: the minimum spanning tree of a Poisson-disk
/// thinning of the band at `separation` (Prim on the complete graph). With the separation larger
/// than the band's width the samples form a chain along the curve, so the tree follows it.
double bandLength(const std::vector<Vec3>& positions, const std::vector<Index>& points,
                  double separation) {
  const std::vector<Index> kept = poissonDiskSample(positions, points, separation, 7);
  const std::size_t m = kept.size();
  if (m < 2) return 0;
  std::vector<double> best(m, std::numeric_limits<double>::infinity());
  std::vector<std::uint8_t> inTree(m, 0);
  double total = 0;
  std::size_t current = 0;
  inTree[0] = 1;
  for (std::size_t added = 1; added < m; ++added) {
    std::size_t next = m;
    for (std::size_t j = 0; j < m; ++j) {
      if (inTree[j]) continue;
      best[j] = std::min(best[j], (positions[kept[j]] - positions[kept[current]]).norm());
      if (next == m || best[j] < best[next]) next = j;
    }
    total += best[next];
    inTree[next] = 1;
    current = next;
  }
  return total;
}

/// Of the salient vertices of one scale, those with the largest |kappa1| across the lines near
/// them: no vertex of the same sign within t, displaced across the first one's line (its offset
/// along that line's tangent under half its length), is more curved. Parallel lines flank a
/// crease over a band as wide as t; only the one on the crease is kept (non-maximum suppression,
/// as an edge detector thins its gradient). A vertex under `crossSignBelow` (|kappa1|) is also
/// suppressed by a more curved one of the other sign: the fits across a crease read a weaker
/// curvature of the opposite sign on its flanks (FeatureCurveOptions::salientBoundCap).
std::vector<std::uint8_t> acrossLineMaxima(const std::vector<const CurvatureLineVertex*>& vertices,
                                           double t, double crossSignBelow) {
  std::vector<Vec3> positions(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) positions[i] = vertices[i]->position;
  std::vector<std::uint8_t> keep(vertices.size(), 1);
  if (vertices.empty()) return keep;
  const auto index = makeSpatialIndex(positions);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices.size(), 256), [&](const auto& r) {
    std::vector<Neighbor> found;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const CurvatureLineVertex& v = *vertices[i];
      const bool anySign = std::abs(v.kappa1) < crossSignBelow;
      index->radiusSearch(v.position, t, found);
      for (const Neighbor& nb : found) {
        const CurvatureLineVertex& u = *vertices[nb.index];
        if ((!anySign && (u.kappa1 > 0) != (v.kappa1 > 0)) ||
            !(std::abs(u.kappa1) > std::abs(v.kappa1)))
          continue;
        const Vec3 d = u.position - v.position;
        if (std::abs(d.dot(v.tangent)) < 0.5 * d.norm()) {
          keep[i] = 0;
          break;
        }
      }
    }
  });
  return keep;
}

/// Per eligible target: stays eligible unless it lies farther than `halfWidth` from the centreline
/// of its curve, a line fitted (weighted PCA) to the salient vertices of its sign within `reach`.
/// Each vertex lies a little off the crease (across it, and inside the solid: the APSS rounds the
/// edge), so the union of the vote balls is a band wider than the vote radius; the many vertices of
/// several scales within `reach` average to the crease. Where they do not lie along a line (largest
/// eigenvalue under `linearity` of the trace: corners, blobs) the point keeps its label.
/// Where the cloud points near it form two flat sides (`crease`, features/CreaseLine; its reach 0:
/// never) the line where their planes meet replaces the centreline, with `creaseHalfWidth`.
struct CreaseBand {
  const std::vector<Vec3>& positions;
  const std::vector<Vec3>& normals;
  const SpatialIndex& index;
  CreaseLineOptions line;
  double halfWidth = 0;
  RimLineOptions rim;  // its reach 0: never
};

void trimToCentreline(const std::vector<Vec3>& targets, const std::vector<Vec3>& salient,
                      const std::vector<std::int8_t>& salientSign, const SpatialIndex& index,
                      double reach, double halfWidth, double linearity, const CreaseBand& crease,
                      std::vector<std::uint8_t>& eligible, std::vector<std::int8_t>& sign) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, targets.size(), 1024), [&](const auto& r) {
    std::vector<Neighbor> found;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      if (!eligible[i]) continue;
      index.radiusSearch(targets[i], reach, found);
      // In vertex order: the same sums for any thread count.
      std::sort(found.begin(), found.end(),
                [](const Neighbor& a, const Neighbor& b) { return a.index < b.index; });
      double total = 0;
      Vec3 mean = Vec3::Zero();
      for (const Neighbor& nb : found) {
        if (salientSign[nb.index] != sign[i]) continue;
        const double w = 1 - nb.distSq / (reach * reach);
        total += w * w;
        mean += w * w * salient[nb.index];
      }
      if (!(total > 0)) continue;
      mean /= total;
      Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
      for (const Neighbor& nb : found) {
        if (salientSign[nb.index] != sign[i]) continue;
        const double w = 1 - nb.distSq / (reach * reach);
        const Vec3 d = salient[nb.index] - mean;
        covariance += w * w * d * d.transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
      const double trace = eigen.eigenvalues().sum();
      if (!(trace > 0) || eigen.eigenvalues()(2) < linearity * trace) continue;
      const Vec3 direction = eigen.eigenvectors().col(2);
      Vec3 through = mean, along = direction;
      double width = halfWidth;
      bool onCrease = false;
      if (crease.line.reach > 0)
        if (const auto line = fitCreaseLine(crease.positions, crease.normals, crease.index,
                                            targets[i], direction, crease.line, &mean);
            line && distanceToLine(mean, line->point, line->direction) <= crease.halfWidth) {
          // The salient vertices lie along the edge found: not two faces of a thin part, whose
          // planes meet far from it or not at all.
          through = line->point;
          along = line->direction;
          width = crease.halfWidth;
          onCrease = true;
        }
      if (!onCrease && crease.rim.reach > 0)
        if (const auto rim =
                fitRimLine(crease.positions, crease.index, mean, direction, crease.rim)) {
          // A thin part's rim: the band is the sheet within creaseHalfWidth of its border, both
          // faces alike (a distance across the sheet, not to the line).
          if (!withinRim(*rim, targets[i], crease.halfWidth)) {
            eligible[i] = 0;
            sign[i] = 0;
          }
          continue;
        }
      if (distanceToLine(targets[i], through, along) > width) {
        eligible[i] = 0;
        sign[i] = 0;
      }
    }
  });
}

std::vector<Vec3> positionsOf(const std::vector<Vec3>& from, const std::vector<Index>& kept) {
  std::vector<Vec3> out(kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) out[k] = from[kept[k]];
  return out;
}

// (not in the thesis) FeatureCurveOptions::foldBorders: the targets not yet `eligible` at a
// border of the sheet the cloud samples (core/SheetBorder). The share is read first at a
// Poisson-disk sample of the targets (e / 2 apart) with the cloud's sample (the same) as
// neighbours, then at every target within e / 2 of a sample that came within kFoldMargin of the
// bound, with all the cloud's points: over e / 2 it changes by less (0.17 per e across a straight
// border at a reach of 3 e). The samples, evenly spread, give a centroid as steady as all the
// points. Reading it at every point with all of them cost 5-9 s on 1M points, this 1.6 s; the
// labels of bench_features' models are the same but for 0-3 points.
//
// With FeatureCurveOptions::foldSeeThroughShare, they are kept only when enough of them see out on
// both sides (`seeThrough`, the share over those with a usable normal; -1, and none kept, when no
// such point was found). A mesh's vertices take the normal of their nearest sample.
std::vector<std::uint8_t> foldPoints(const PointCloud& cloud, const SpatialIndex& cloudIndex,
                                     const std::vector<Vec3>& targets,
                                     const std::vector<std::uint8_t>& eligible, double e,
                                     const FeatureCurveOptions& options, double& seeThrough) {
  constexpr double kFoldMargin = 0.1;
  constexpr std::uint64_t kSampleSeed = 11;
  const bool cloudTargets = &targets == &cloud.positions();
  const std::vector<Index> samples = poissonDiskSample(targets, 0.5 * e, kSampleSeed);
  const std::vector<Vec3> sampled = positionsOf(targets, samples);
  const std::vector<Vec3> sampledCloud =
      cloudTargets ? std::vector<Vec3>()
                   : positionsOf(cloud.positions(),
                                 poissonDiskSample(cloud.positions(), 0.5 * e, kSampleSeed));
  const std::vector<Vec3>& sparseCloud = cloudTargets ? sampled : sampledCloud;
  SheetBorderOptions border;
  border.radius = options.foldReach * e;
  SheetBorderOptions sparse = border;
  sparse.minCount = 4;
  const std::vector<float> coarse =
      sheetBorderShare(sparseCloud, *makeSpatialIndex(sparseCloud), sampled, sparse);

  const auto ownIndex = cloudTargets ? nullptr : makeSpatialIndex(targets);
  const SpatialIndex& targetIndex = ownIndex ? *ownIndex : cloudIndex;
  std::vector<std::uint8_t> skip(targets.size(), 1);
  std::vector<Neighbor> near;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (!(coarse[k] >= options.foldBorderShare - kFoldMargin)) continue;
    targetIndex.radiusSearch(sampled[k], 0.5 * e, near);
    for (const Neighbor& nb : near) skip[nb.index] = eligible[nb.index];
    skip[samples[k]] = eligible[samples[k]];
  }
  const std::vector<float> share =
      sheetBorderShare(cloud.positions(), cloudIndex, targets, border, skip);
  std::vector<std::uint8_t> fold(targets.size(), 0);
  for (std::size_t i = 0; i < targets.size(); ++i)
    fold[i] = !skip[i] && share[i] >= options.foldBorderShare ? 1 : 0;
  seeThrough = -1;
  if (!(options.foldSeeThroughShare > 0)) return fold;
  if (std::find(fold.begin(), fold.end(), 1) == fold.end()) return fold;  // nothing to test
  const OccupancyGrid grid(cloud.positions(), options.foldRayCell * e, std::size_t(1) << 27);
  std::size_t found = 0, through = 0;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (!fold[i]) continue;
    Vec3 normal = Vec3::Zero();
    if (cloudTargets) {
      normal = cloud.normals()[i];
    } else {
      cloudIndex.knnSearch(targets[i], 1, near);
      if (!near.empty()) normal = cloud.normals()[near.front().index];
    }
    if (!normal.allFinite() || !(normal.squaredNorm() > 0)) continue;  // no side to cast from
    ++found;
    through += grid.seesOutBothSides(targets[i], normal.normalized()) ? 1 : 0;
  }
  if (found > 0) seeThrough = double(through) / double(found);
  if (!(seeThrough >= options.foldSeeThroughShare)) std::fill(fold.begin(), fold.end(), 0);
  return fold;
}

// Curves of the same sign whose points come within `gap` of each other, as groups of curve indices
// (each group increasing, groups ordered by their first curve).
std::vector<std::vector<std::size_t>> curvesWithinGap(const std::vector<Vec3>& positions,
                                                      const std::vector<std::vector<Index>>& curves,
                                                      const std::vector<std::int8_t>& sign,
                                                      double gap) {
  std::vector<Vec3> points;
  std::vector<Index> owner;
  for (std::size_t c = 0; c < curves.size(); ++c)
    for (const Index p : curves[c]) {
      points.push_back(positions[p]);
      owner.push_back(Index(c));
    }
  DisjointSets sets(curves.size());
  if (!points.empty()) {
    const auto index = makeSpatialIndex(points);
    tbb::enumerable_thread_specific<std::vector<std::pair<Index, Index>>> found;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024), [&](const auto& r) {
      std::vector<Neighbor> near;
      auto& pairs = found.local();
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        index->radiusSearch(points[i], gap, near);
        for (const Neighbor& nb : near) {
          const Index a = owner[i], b = owner[nb.index];
          // Points come curve by curve, so a pair repeats along a shared stretch: kept once.
          if (a < b && sign[a] == sign[b] && (pairs.empty() || pairs.back() != std::pair(a, b)))
            pairs.emplace_back(a, b);
        }
      }
    });
    // Connected components do not depend on the order of the unions (nor on the thread count).
    for (const auto& pairs : found)
      for (const auto& [a, b] : pairs) sets.unite(a, b);
  }
  std::vector<std::vector<std::size_t>> groups;
  std::vector<int> groupOfRoot(curves.size(), -1);
  for (std::size_t c = 0; c < curves.size(); ++c) {
    int& g = groupOfRoot[sets.find(Index(c))];
    if (g < 0) {
      g = int(groups.size());
      groups.emplace_back();
    }
    groups[std::size_t(g)].push_back(c);
  }
  return groups;
}

}  // namespace

bool nearlyClosed(const NormalOrientationResult& orientation) {
  constexpr double kNearlyClosedShare = 0.15;
  return !orientation.closedSurface && orientation.openShare > 0 &&
         orientation.openShare < kNearlyClosedShare;
}

void chooseFoldBorders(FeatureCurveOptions& options, const NormalOrientationResult& orientation) {
  options.foldBorders = orientation.closedSurface || nearlyClosed(orientation);
  options.foldSeeThroughShare = nearlyClosed(orientation) ? kFoldSeeThroughShare : 0.0;
}

std::string foldBordersHint(const NormalOrientationResult& orientation,
                            const FeatureCurveResult& result, std::string_view turnOn) {
  if (!nearlyClosed(orientation) || result.foldsApplied || !(result.foldSeeThrough >= 0)) return {};
  char figures[160];
  std::snprintf(figures, sizeof figures,
                "%.1f%% of the points (a closed surface: at most 5%%), and %.0f%% of the borders "
                "found there see out on both sides",
                100 * orientation.openShare, 100 * result.foldSeeThrough);
  return std::string("the rays found the surface open at ") + figures +
         ": the edges of an opening, not the rim of a part thinner than the noise, so they are "
         "not taken as folds; " +
         std::string(turnOn) + " makes them convex curves all the same";
}

OrientedNormalsOptions featureNormalOptions(double sheetTolerance) {
  OrientedNormalsOptions options;
  options.estimation.sheetTolerance = sheetTolerance;
  options.sheetSign = SheetSign::ByRays;
  options.orientation.reflectAcrossBisector = true;
  return options;
}

void validateFeatureCurveOptions(const FeatureCurveOptions& o) {
  require(std::isfinite(o.spacing) && o.spacing >= 0,
          "FeatureCurveOptions::spacing must be finite and >= 0 (0 = from the cloud)");
  require(o.spacingNeighbors >= 1 && std::size_t(o.spacingNeighbors) <= kMaxNeighborCount,
          "FeatureCurveOptions::spacingNeighbors must be in [1, " +
              std::to_string(kMaxNeighborCount) + "]");
  require(o.scaleCount >= 1 && o.scaleCount <= 32,
          "FeatureCurveOptions::scaleCount must be in [1, 32]");
  require(std::isfinite(o.minScaleFactor) && std::isfinite(o.maxScaleFactor) &&
              o.minScaleFactor > 0 && o.maxScaleFactor >= o.minScaleFactor,
          "FeatureCurveOptions::minScaleFactor and maxScaleFactor must be finite with 0 < min <= "
          "max");
  require(
      std::isfinite(o.salientPercentile) && o.salientPercentile >= 0 && o.salientPercentile <= 1,
      "FeatureCurveOptions::salientPercentile must be in [0, 1]");
  require(std::isfinite(o.salientThreshold) && o.salientThreshold >= 0 && o.salientThreshold <= 1,
          "FeatureCurveOptions::salientThreshold must be in [0, 1]");
  require(std::isfinite(o.minSalientCurvature) && o.minSalientCurvature >= 0,
          "FeatureCurveOptions::minSalientCurvature must be finite and >= 0");
  require(std::isfinite(o.salientBoundCap) && o.salientBoundCap >= 0,
          "FeatureCurveOptions::salientBoundCap must be finite and >= 0 (0 = off)");
  require(std::isfinite(o.edgeReach) && o.edgeReach >= 0,
          "FeatureCurveOptions::edgeReach must be finite and >= 0 (0 = off)");
  require(o.edgeSpread >= 0 && o.edgeSpread <= 1,
          "FeatureCurveOptions::edgeSpread must be in [0, 1]");
  require(o.edgeRejoinAngle >= 0 && o.edgeRejoinAngle <= 90,
          "FeatureCurveOptions::edgeRejoinAngle must be in [0, 90] degrees (0 = off)");
  require(std::isfinite(o.joinGap) && o.joinGap >= 0,
          "FeatureCurveOptions::joinGap must be finite and >= 0");
  require(std::isfinite(o.noiseSalientFactor) && o.noiseSalientFactor >= 0,
          "FeatureCurveOptions::noiseSalientFactor must be finite and >= 0");
  require(std::isfinite(o.voteRadiusFactor) && o.voteRadiusFactor > 0,
          "FeatureCurveOptions::voteRadiusFactor must be finite and > 0");
  require(std::isfinite(o.voteThreshold) && o.voteThreshold >= 0 && o.voteThreshold < 1,
          "FeatureCurveOptions::voteThreshold must be in [0, 1)");
  require(o.minVotingScales >= 1 && o.minVotingScales <= o.scaleCount,
          "FeatureCurveOptions::minVotingScales must be in [1, FeatureCurveOptions::scaleCount = " +
              std::to_string(o.scaleCount) + "], got " + std::to_string(o.minVotingScales));
  require(std::isfinite(o.centrelineReach) && o.centrelineReach >= 0,
          "FeatureCurveOptions::centrelineReach must be finite and >= 0 (0 = off)");
  require(std::isfinite(o.bandHalfWidth) && o.bandHalfWidth > 0,
          "FeatureCurveOptions::bandHalfWidth must be finite and > 0");
  require(std::isfinite(o.creaseReach) && o.creaseReach >= 0,
          "FeatureCurveOptions::creaseReach must be finite and >= 0 (0 = off)");
  require(std::isfinite(o.creaseHalfWidth) && o.creaseHalfWidth > 0,
          "FeatureCurveOptions::creaseHalfWidth must be finite and > 0");
  require(std::isfinite(o.creaseFlatness) && o.creaseFlatness >= 0,
          "FeatureCurveOptions::creaseFlatness must be finite and >= 0");
  require(std::isfinite(o.creaseSideMargin) && o.creaseSideMargin >= 0,
          "FeatureCurveOptions::creaseSideMargin must be finite and >= 0");
  require(std::isfinite(o.creaseSideNoise) && o.creaseSideNoise >= 0,
          "FeatureCurveOptions::creaseSideNoise must be finite and >= 0");
  require(std::isfinite(o.centrelineLinearity) && o.centrelineLinearity >= 0 &&
              o.centrelineLinearity <= 1,
          "FeatureCurveOptions::centrelineLinearity must be in [0, 1]");
  require(std::isfinite(o.foldReach) && o.foldReach > 0,
          "FeatureCurveOptions::foldReach must be finite and > 0");
  require(std::isfinite(o.foldBorderShare) && o.foldBorderShare > 0 && o.foldBorderShare <= 1,
          "FeatureCurveOptions::foldBorderShare must be in (0, 1]");
  require(std::isfinite(o.foldSeeThroughShare) && o.foldSeeThroughShare >= 0 &&
              o.foldSeeThroughShare <= 1,
          "FeatureCurveOptions::foldSeeThroughShare must be in [0, 1]");
  require(std::isfinite(o.foldRayCell) && o.foldRayCell > 0,
          "FeatureCurveOptions::foldRayCell must be finite and > 0");
  require(std::isfinite(o.minCurveExtent) && o.minCurveExtent >= 0,
          "FeatureCurveOptions::minCurveExtent must be finite and >= 0");
  require(std::isfinite(o.minPieceExtent) && o.minPieceExtent >= 0,
          "FeatureCurveOptions::minPieceExtent must be finite and >= 0");
  require(o.graphNeighbors >= 1 && std::size_t(o.graphNeighbors) <= kMaxNeighborCount,
          "FeatureCurveOptions::graphNeighbors must be in [1, " +
              std::to_string(kMaxNeighborCount) + "]");
  CurvatureLineOptions lines = o.lines;
  lines.scale = 1;  // set per scale
  validateCurvatureLineOptions(lines);
}

double meanKthNeighborDistance(const std::vector<Vec3>& positions, int k) {
  require(k >= 1, "meanKthNeighborDistance: k must be >= 1");
  if (positions.size() < 2) return 0;
  const auto index = makeSpatialIndex(positions);
  const int kk = int(std::min<std::size_t>(std::size_t(k), positions.size() - 1));
  double sum = 0;  // in index order: the same for any thread count
  for (const double d : knnRadii(positions, *index, kk)) sum += d;
  return sum / double(positions.size());
}

KnnGraph buildMeshEdgeGraph(std::size_t vertexCount,
                            const std::vector<std::array<Index, 3>>& triangles) {
  std::vector<std::vector<Index>> adjacent(vertexCount);
  for (const auto& tri : triangles)
    for (int c = 0; c < 3; ++c) {
      const Index a = tri[c], b = tri[(c + 1) % 3];
      require(a < vertexCount && b < vertexCount,
              "buildMeshEdgeGraph: a triangle references vertex " + std::to_string(std::max(a, b)) +
                  " of " + std::to_string(vertexCount));
      if (a == b) continue;
      adjacent[a].push_back(b);
      adjacent[b].push_back(a);
    }
  KnnGraph graph;
  graph.offsets.assign(vertexCount + 1, 0);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    auto& list = adjacent[v];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    graph.offsets[v + 1] = graph.offsets[v] + list.size();
  }
  graph.neighbors.reserve(graph.offsets.back());
  for (const auto& list : adjacent)
    graph.neighbors.insert(graph.neighbors.end(), list.begin(), list.end());
  return graph;
}

FeatureCurveResult detectFeatureCurves(const PointCloud& cloud, const FeatureCurveOptions& options,
                                       const ProgressCallback& progress) {
  validateFeatureCurveOptions(options);
  const KnnGraph graph = buildKnnGraph(cloud.positions(), std::size_t(options.graphNeighbors));
  return detectFeatureCurves(cloud, options, cloud.positions(), graph, progress);
}

FeatureCurveResult detectFeatureCurves(const PointCloud& cloud, const FeatureCurveOptions& options,
                                       const std::vector<Vec3>& targets,
                                       const KnnGraph& targetGraph,
                                       const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  validateFeatureCurveOptions(options);
  require(cloud.hasNormals(),
          "detectFeatureCurves: the cloud has no normals (the APSS fits need oriented normals)");
  require(targetGraph.size() == targets.size(),
          "detectFeatureCurves: the target graph has " + std::to_string(targetGraph.size()) +
              " vertices for " + std::to_string(targets.size()) + " targets");
  require(cloud.size() >= 2, "detectFeatureCurves: the cloud needs at least 2 points");

  FeatureCurveResult result;
  result.spacing = options.spacing > 0
                       ? options.spacing
                       : meanKthNeighborDistance(cloud.positions(), options.spacingNeighbors);
  const double e = result.spacing;
  // Zero when every point has spacingNeighbors duplicates or more: a cloud of a few positions
  // repeated (each written once per scan pass) as well as one single position.
  require(e > 0,
          "detectFeatureCurves: every point has " + std::to_string(options.spacingNeighbors) +
              " or more duplicates (the spacing, the mean distance to the " +
              std::to_string(options.spacingNeighbors) +
              "th neighbour, is 0): remove the duplicates or give FeatureCurveOptions::spacing");
  // The cloud's index, shared by the noise estimate, the crease lines and the fold test.
  const bool creaseLines = options.centrelineReach > 0 && options.creaseReach > 0;
  const bool needNoise = options.noiseSalientFactor > 0 || creaseLines;
  const auto cloudIndex =
      needNoise || options.foldBorders ? makeSpatialIndex(cloud.positions()) : nullptr;
  // The noise of the points the lines are traced on (the cloud; a mesh's area samples): the
  // salient floor and the crease sides' flatness and margin scale with it.
  if (needNoise) result.noiseRms = surfaceNoiseRms(cloud.positions(), *cloudIndex);
  result.salientCurvatureFloor =
      std::max(options.minSalientCurvature, options.noiseSalientFactor * result.noiseRms / e);

  // 1-2. Lines per scale and their salient vertices (Sec. 3.4.1).
  std::vector<Vec3> salient;
  std::vector<std::int8_t> salientSign;
  std::vector<std::uint8_t> salientScale;
  const int count = options.scaleCount;
  for (int s = 0; s < count; ++s) {
    const double f = count == 1 ? 0 : double(s) / (count - 1);
    CurvatureLineOptions lineOptions = options.lines;
    lineOptions.scale =
        e * (options.minScaleFactor + (options.maxScaleFactor - options.minScaleFactor) * f);
    ProgressCallback scaleProgress;
    if (progress)
      scaleProgress = [&](double fraction, std::string_view stage) {
        return progress(0.9 * (s + std::min(fraction, 1.0)) / count, stage);
      };
    CurvatureLineSet lines = traceCurvatureLines(cloud, lineOptions, scaleProgress);
    FeatureCurveScale summary;
    summary.scale = lineOptions.scale;
    summary.salientBound = quantile(lines.seedKappa1, options.salientPercentile);
    summary.lines = lines.lines.size();
    if (options.salientBoundFromFinest && s > 0)
      summary.salientBound =
          result.scales.front().salientBound * result.scales.front().scale / lineOptions.scale;
    const double relative = (1 - options.salientThreshold) * summary.salientBound;
    const double floor = result.salientCurvatureFloor / lineOptions.scale;
    const double bound =
        std::max(options.salientBoundCap > 0
                     ? std::min(relative, options.salientBoundCap / lineOptions.scale)
                     : relative,
                 floor);
    summary.vertexBound = bound;
    std::vector<const CurvatureLineVertex*> candidates;
    for (const CurvatureLine& line : lines.lines)
      for (const CurvatureLineVertex& v : line.vertices) {
        ++summary.vertices;
        if (std::abs(v.kappa1) > bound) candidates.push_back(&v);
      }
    const std::vector<std::uint8_t> keep =
        options.ridgeOnly
            ? acrossLineMaxima(candidates, lineOptions.scale, std::max(relative, floor))
            : std::vector<std::uint8_t>(candidates.size(), 1);
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      if (!keep[c]) continue;
      ++summary.salientVertices;
      salient.push_back(candidates[c]->position);
      salientSign.push_back(candidates[c]->kappa1 > 0 ? 1 : -1);
      salientScale.push_back(std::uint8_t(s));
    }
    result.scales.push_back(summary);
    result.lineSets.push_back(std::move(lines));
  }

  // 3. Votes: each target sums the weights of the salient vertices within the vote radius.
  const double radius = options.voteRadiusFactor * e;
  const std::size_t n = targets.size();
  result.votes.assign(n, 0);
  std::vector<std::uint32_t> voters(n, 0);
  if (progress && !progress(0.9, "voting")) throw Cancelled();
  if (!salient.empty()) {
    const auto index = makeSpatialIndex(salient);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
      std::vector<Neighbor> found;
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        index->radiusSearch(targets[i], radius, found);
        // Summed in vertex order: the same total for any thread count.
        std::sort(found.begin(), found.end(),
                  [](const Neighbor& a, const Neighbor& b) { return a.index < b.index; });
        double sum = 0;
        std::uint32_t mask = 0;
        for (const Neighbor& nb : found) {
          const double w = 1 - nb.distSq / (radius * radius);
          sum += salientSign[nb.index] * w * w;
          mask |= std::uint32_t(1) << salientScale[nb.index];
        }
        result.votes[i] = sum;
        voters[i] = mask;
      }
    });
  }
  for (const double v : result.votes) result.maxVote = std::max(result.maxVote, std::abs(v));

  // 4. Regions of same-sign votes above v = voteThreshold * V_max, seeded by decreasing |vote|.
  const double threshold = options.voteThreshold * result.maxVote;
  std::vector<std::uint8_t> eligible(n, 0);
  result.convexity.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (result.maxVote > 0 && std::abs(result.votes[i]) > threshold &&
        __builtin_popcount(voters[i]) >= options.minVotingScales) {
      eligible[i] = 1;
      result.convexity[i] = result.votes[i] > 0 ? 1 : -1;
    }
  if (options.centrelineReach > 0 && !salient.empty()) {
    const auto salientIndex = makeSpatialIndex(salient);
    CreaseBand crease{
        cloud.positions(), cloud.normals(), creaseLines ? *cloudIndex : *salientIndex, {}, 0, {}};
    crease.line.reach = options.creaseReach * e;
    crease.line.maxRms = std::max(options.creaseFlatness * e, 2 * result.noiseRms);
    crease.line.maxGap = 0.25 * e;
    crease.line.splitByPosition = options.creaseSidesByPosition;
    crease.line.sideMargin =
        std::max(0.0, options.creaseSideMargin * e - options.creaseSideNoise * result.noiseRms);
    crease.halfWidth = options.creaseHalfWidth * e;
    if (creaseLines && options.rimLines) {
      crease.rim.reach = options.creaseReach * e;
      crease.rim.maxInset = options.creaseHalfWidth * e;
    }
    trimToCentreline(targets, salient, salientSign, *salientIndex, options.centrelineReach * e,
                     options.bandHalfWidth * e, options.centrelineLinearity, crease, eligible,
                     result.convexity);
  }
  if (options.foldBorders) {
    const std::vector<std::uint8_t> fold =
        foldPoints(cloud, *cloudIndex, targets, eligible, e, options, result.foldSeeThrough);
    result.foldsApplied =
        !(options.foldSeeThroughShare > 0) || result.foldSeeThrough >= options.foldSeeThroughShare;
    for (std::size_t i = 0; i < n; ++i)
      if (fold[i]) {
        eligible[i] = 1;
        result.convexity[i] = 1;
        ++result.foldPoints;
      }
  }
  std::vector<Index> seeds = seedsByIncreasingKey(n, [&](Index i) {
    return eligible[i] ? -std::abs(result.votes[i]) : std::numeric_limits<double>::quiet_NaN();
  });
  Segmentation seg =
      growRegionsFromSeeds(targetGraph, std::move(seeds), eligible, SameSign{result.convexity});
  // Regions spanning less than minPieceExtent * e are dropped first (specks where a line grazed a
  // corner or noise); they neither join nor bridge others.
  const auto extent = [&](const std::vector<Index>& points) {
    Vec3 lo = targets[points.front()], hi = lo;
    for (const Index p : points) {
      lo = lo.cwiseMin(targets[p]);
      hi = hi.cwiseMax(targets[p]);
    }
    return (hi - lo).norm();
  };
  std::vector<std::size_t> pieces;  // region of each piece
  std::vector<std::vector<Index>> pieceRegions;
  std::vector<std::int8_t> pieceSign;
  for (std::size_t c = 0; c < seg.regions.size(); ++c) {
    if (extent(seg.regions[c]) < options.minPieceExtent * e) continue;
    pieces.push_back(c);
    pieceSign.push_back(result.convexity[seg.regions[c].front()]);
    pieceRegions.push_back(std::move(seg.regions[c]));
  }
  // 5. (not in the thesis) Lines stop short of corners (near-umbilic points, sharp turns), so where
  // creases meet the votes leave a gap and the regions cut a connected set of creases into
  // pieces; pieces of the same sign within joinGap * e of each other are one curve. Then the
  // curves spanning less than minCurveExtent * e are dropped: a short piece that joins a crease is
  // part of it, one that joins nothing is a speck. The others keep their order (by decreasing
  // strongest vote of their first piece) and are renumbered.
  std::vector<std::vector<std::size_t>> groups;
  if (options.joinGap > 0)
    groups = curvesWithinGap(targets, pieceRegions, pieceSign, options.joinGap * e);
  else
    for (std::size_t k = 0; k < pieces.size(); ++k) groups.push_back({k});
  std::vector<int> renumber(seg.regions.size(), -1);
  std::vector<std::vector<Index>> kept;
  for (const std::vector<std::size_t>& group : groups) {
    std::vector<Index> merged;
    for (const std::size_t k : group)
      merged.insert(merged.end(), pieceRegions[k].begin(), pieceRegions[k].end());
    if (extent(merged) < options.minCurveExtent * e) continue;
    for (const std::size_t k : group) renumber[pieces[k]] = int(kept.size());
    std::sort(merged.begin(), merged.end());
    kept.push_back(std::move(merged));
  }
  result.curveId = std::move(seg.labels);
  for (std::size_t i = 0; i < n; ++i) {
    if (result.curveId[i] >= 0) result.curveId[i] = renumber[std::size_t(result.curveId[i])];
    if (result.curveId[i] < 0) result.convexity[i] = 0;  // dropped, or in no region
  }
  result.curves.resize(kept.size());
  tbb::parallel_for(std::size_t(0), kept.size(), [&](std::size_t c) {
    FeatureCurve& curve = result.curves[c];
    curve.points = std::move(kept[c]);
    curve.convexity = result.convexity[curve.points.front()];
    for (const Index p : curve.points) curve.scaleMask |= voters[p];
    curve.length = bandLength(targets, curve.points, 2 * e);
  });
  // (not in the thesis) Each curve split into edges at its corners.
  if (options.edgeReach > 0) {
    CurveEdgeOptions edgeOptions;
    edgeOptions.radius = options.edgeReach * e;
    edgeOptions.maxSpread = options.edgeSpread;
    edgeOptions.linkDistance = std::max(1.0, options.joinGap) * e;
    edgeOptions.mergeAngleDegrees = options.edgeRejoinAngle;
    CurveEdges split = splitCurvesAtCorners(targets, targetGraph, result.curveId, edgeOptions);
    result.edgeId = std::move(split.edgeId);
    result.edges.resize(split.points.size());
    for (std::size_t k = 0; k < split.points.size(); ++k) {
      result.edges[k].points = std::move(split.points[k]);
      result.edges[k].curve = split.curveOf[k];
    }
  } else {
    result.edgeId = result.curveId;
    result.edges.resize(result.curves.size());
    for (std::size_t c = 0; c < result.curves.size(); ++c) {
      result.edges[c].points = result.curves[c].points;
      result.edges[c].curve = int(c);
    }
  }
  tbb::parallel_for(std::size_t(0), result.edges.size(), [&](std::size_t k) {
    result.edges[k].length = bandLength(targets, result.edges[k].points, 2 * e);
  });
  if (options.keepVotingDetail) {
    result.voterScales = std::move(voters);
    result.salientPositions = std::move(salient);
    result.salientScales = std::move(salientScale);
    result.salientSigns = std::move(salientSign);
  }
  if (progress && !progress(1, "feature curves")) throw Cancelled();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scalespace

namespace scalespace {

double medianEdgeLength(const TriangleMesh& mesh) {
  std::vector<double> lengths;
  lengths.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    for (int c = 0; c < 3; ++c)
      lengths.push_back((mesh.vertices[t[c]] - mesh.vertices[t[(c + 1) % 3]]).norm());
  if (lengths.empty()) return 0;
  std::nth_element(lengths.begin(), lengths.begin() + std::ptrdiff_t(lengths.size() / 2),
                   lengths.end());
  return lengths[lengths.size() / 2];
}

MeshFeatureCurves detectMeshFeatureCurves(const TriangleMesh& mesh, FeatureCurveOptions options,
                                          std::size_t samplesPerVertex,
                                          const ProgressCallback& progress) {
  validateFeatureCurveOptions(options);
  require(samplesPerVertex >= 1 && samplesPerVertex <= 10000,
          "detectMeshFeatureCurves: samplesPerVertex must be in [1, 10000]");
  require(!mesh.triangles.empty(), "detectMeshFeatureCurves: the mesh has no triangles");
  // Interpolated normals (Sec. 3.4.1) except on triangles at a sharp edge (THESIS_NOTES).
  constexpr double kCreaseAngleDegrees = kMeshCreaseAngleDegrees;
  MeshFeatureCurves out;
  out.samples = sampleMesh(mesh, samplesPerVertex * mesh.vertices.size(), 1, kCreaseAngleDegrees);
  if (options.spacing == 0) {
    options.spacing = medianEdgeLength(mesh);
    out.coarse = options.spacing > 0.05 * out.samples.boundingBoxDiagonal();
  }
  // The votes are cast in the samples' frame: relative to their origin, which is not 0 for a mesh
  // far from the origin (georeferenced coordinates).
  std::vector<Vec3> targets = mesh.vertices;
  for (Vec3& v : targets) v -= out.samples.origin();
  const KnnGraph graph = buildMeshEdgeGraph(mesh.vertices.size(), mesh.triangles);
  out.curves = detectFeatureCurves(out.samples, options, targets, graph, progress);
  return out;
}

}  // namespace scalespace
