#include "scalespace/planes/RegionMerging.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>
#include <tuple>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/fit/PointSetPlane.hpp"
#include "scalespace/planes/PlaneDescribes.hpp"

namespace scalespace {
namespace {

// First and second moments of a point set: enough for the least-squares plane of any union.
struct Moments {
  double count = 0;
  Vec3 sum = Vec3::Zero();
  Mat3 outer = Mat3::Zero();
  void add(const Moments& o) {
    count += o.count;
    sum += o.sum;
    outer += o.outer;
  }
};

struct UnionPlane {
  Vec3 normal, centroid, axisU, axisV;
  double rms;
};

UnionPlane planeOf(const Moments& m) {
  const Vec3 c = m.sum / m.count;
  const Mat3 cov = m.outer / m.count - c * c.transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(cov);
  return {eig.eigenvectors().col(0), c, eig.eigenvectors().col(1), eig.eigenvectors().col(2),
          std::sqrt(std::max(0.0, eig.eigenvalues()(0)))};
}

using Box = std::array<Vec3, 8>;  // corners

// The box around a grown region along its own plane's axes (through its centroid), its in-plane
// area, and that plane.
Box boxOf(const std::vector<Vec3>& positions, const std::vector<Index>& region, double& area,
          PlaneFit& plane) {
  Box box;
  box.fill(positions[region.front()]);
  area = 0;
  plane = PlaneFit{};
  if (region.size() < 3) return box;  // a point or two: any corner is one of the points
  plane = fitPlane(positions, region);
  const Vec3 axes[3] = {plane.axisU, plane.axisV, plane.normal};
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Index i : region) {
    const Vec3 d = positions[i] - plane.centroid;
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], d.dot(axes[k]));
      hi[k] = std::max(hi[k], d.dot(axes[k]));
    }
  }
  area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
  for (int c = 0; c < 8; ++c) {
    box[std::size_t(c)] = plane.centroid;
    for (int k = 0; k < 3; ++k) box[std::size_t(c)] += ((c >> k) & 1 ? hi[k] : lo[k]) * axes[k];
  }
  return box;
}

// Whether every corner of `boxes` lies within `bound` of the plane through `centroid` with unit
// `normal`: an upper bound on the points inside them, and cheap.
bool boxesWithin(const std::vector<Box>& boxes, const Vec3& normal, const Vec3& centroid,
                 double bound) {
  for (const Box& box : boxes)
    for (const Vec3& corner : box)
      if (std::abs(normal.dot(corner - centroid)) > bound) return false;
  return true;
}

// Whether every point of the grown regions `parts` lies within `bound` of that plane: what the
// boxes bound, decided where they exceed it (a sawtooth's boxes, tilted along its mean plane,
// overstate its deviation by about a third).
bool pointsWithin(const std::vector<Vec3>& positions,
                  const std::vector<std::vector<Index>>& regions, const std::vector<Index>& parts,
                  const Vec3& normal, const Vec3& centroid, double bound) {
  for (const Index m : parts)
    for (const Index i : regions[m])
      if (std::abs(normal.dot(positions[i] - centroid)) > bound) return false;
  return true;
}

}  // namespace

void validate(const RegionMergeOptions& options) {
  if (!(options.maxRelativeRms >= 0) || !std::isfinite(options.maxRelativeRms))
    throw OptionError("RegionMergeOptions::maxRelativeRms must be finite and >= 0");
  if (!(options.maxRelativeDeviation >= 0) || !std::isfinite(options.maxRelativeDeviation))
    throw OptionError("RegionMergeOptions::maxRelativeDeviation must be finite and >= 0");
  if (!(options.noiseFactor >= 0) || !std::isfinite(options.noiseFactor))
    throw OptionError("RegionMergeOptions::noiseFactor must be finite and >= 0");
  if (!(options.parallelDegrees >= 0 && options.parallelDegrees < 90))
    throw OptionError("RegionMergeOptions::parallelDegrees must be in [0, 90)");
}

Segmentation mergeCoplanarRegions(const std::vector<Vec3>& positions, const KnnGraph& knn,
                                  Segmentation segmentation, double t, double smallArea,
                                  double noiseRms, const RegionMergeOptions& options,
                                  std::vector<RegionOrigin>* origins) {
  validate(options);
  if (origins) origins->clear();
  if (!(t > 0)) throw OptionError("region merging: the scale t must be positive");
  if (!(noiseRms >= 0) || !std::isfinite(noiseRms))
    throw OptionError("region merging: the noise RMS must be finite and >= 0");
  const std::size_t n = segmentation.labels.size();
  if (positions.size() != n || knn.size() != n)
    throw OptionError("region merging: positions, labels and the k-NN graph differ in size");
  const std::size_t regionCount = segmentation.regions.size();
  const double maxRms = options.maxRelativeRms * t;
  const double maxDeviation = options.maxRelativeDeviation * t;
  const double minWidth = options.minRelativeWidth * t;
  const double parallelCos = std::cos(options.parallelDegrees * M_PI / 180.0);
  if (maxRms == 0 || maxRms < options.noiseFactor * noiseRms || regionCount < 2)
    return segmentation;

  // Each grown region: its box and in-plane area; the small ones' moments.
  std::vector<Moments> moments(regionCount);
  std::vector<std::vector<Box>> boxes(regionCount);
  std::vector<double> area(regionCount);
  std::vector<PlaneFit> ownPlane(regionCount);
  std::vector<std::uint8_t> small(regionCount);
  tbb::parallel_for(std::size_t(0), regionCount, [&](std::size_t r) {
    boxes[r] = {boxOf(positions, segmentation.regions[r], area[r], ownPlane[r])};
    small[r] = area[r] < smallArea;
    if (!small[r]) return;
    for (const Index i : segmentation.regions[r]) {
      const Vec3& p = positions[i];
      moments[r].count += 1;
      moments[r].sum += p;
      moments[r].outer += p * p.transpose();
    }
  });

  // Adjacency of the small regions: joined by a k-NN edge (collected per thread, then sorted: the
  // same set for any thread count).
  tbb::enumerable_thread_specific<std::vector<std::pair<Index, Index>>> found;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, regionCount, 64), [&](const auto& range) {
    auto& pairs = found.local();
    for (std::size_t a = range.begin(); a != range.end(); ++a) {
      if (!small[a]) continue;
      for (const Index i : segmentation.regions[a])
        for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
          const int b = segmentation.labels[knn.neighbors[e]];
          if (b > int(a) && small[std::size_t(b)] &&
              (pairs.empty() || pairs.back() != std::pair(Index(a), Index(b))))
            pairs.emplace_back(Index(a), Index(b));
        }
    }
  });
  std::vector<std::pair<Index, Index>> edges;
  for (const auto& pairs : found) edges.insert(edges.end(), pairs.begin(), pairs.end());
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<std::vector<Index>> adjacent(regionCount);
  for (const auto& [a, b] : edges) {
    adjacent[a].push_back(b);
    adjacent[b].push_back(a);
  }

  // Greedy merging, the smallest union RMS first; a merged region keeps the smaller index.
  std::vector<Index> version(regionCount, 0);
  std::vector<std::uint8_t> alive(regionCount, 1);
  std::vector<std::vector<Index>> members(regionCount);
  for (std::size_t r = 0; r < regionCount; ++r) members[r] = {Index(r)};
  // rms, a, b, their versions, and whether the points must still be checked against the
  // deviation bound: where the boxes exceed it, the points decide once the pair comes out of the
  // queue still current (most candidates are outdated by then).
  using Candidate = std::tuple<double, Index, Index, Index, Index, bool>;
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> queue;
  const auto unionPlane = [&](Index a, Index b) {
    Moments m = moments[a];
    m.add(moments[b]);
    return planeOf(m);
  };
  const auto consider = [&](Index a, Index b) {
    if (a > b) std::swap(a, b);
    const UnionPlane plane = unionPlane(a, b);
    if (!(plane.rms <= maxRms)) return;
    const bool bounded = boxesWithin(boxes[a], plane.normal, plane.centroid, maxDeviation) &&
                         boxesWithin(boxes[b], plane.normal, plane.centroid, maxDeviation);
    queue.emplace(plane.rms, a, b, version[a], version[b], !bounded);
  };
  for (const auto& [a, b] : edges) consider(a, b);
  while (!queue.empty()) {
    const auto [rms, a, b, va, vb, check] = queue.top();
    queue.pop();
    if (!alive[a] || !alive[b] || version[a] != va || version[b] != vb) continue;
    if (check) {
      const UnionPlane plane = unionPlane(a, b);
      if (!pointsWithin(positions, segmentation.regions, members[a], plane.normal, plane.centroid,
                        maxDeviation) ||
          !pointsWithin(positions, segmentation.regions, members[b], plane.normal, plane.centroid,
                        maxDeviation))
        continue;
    }
    moments[a].add(moments[b]);
    boxes[a].insert(boxes[a].end(), boxes[b].begin(), boxes[b].end());
    members[a].insert(members[a].end(), members[b].begin(), members[b].end());
    alive[b] = 0;
    ++version[a];
    std::vector<Index> joined;
    for (const Index r : {a, b})
      for (const Index c : adjacent[r])
        if (c != a && c != b && alive[c]) joined.push_back(c);
    std::sort(joined.begin(), joined.end());
    joined.erase(std::unique(joined.begin(), joined.end()), joined.end());
    for (const Index c : joined) {
      auto& back = adjacent[c];
      std::replace(back.begin(), back.end(), b, a);
      std::sort(back.begin(), back.end());
      back.erase(std::unique(back.begin(), back.end()), back.end());
    }
    adjacent[a] = joined;
    adjacent[b].clear();
    for (const Index c : joined) consider(a, c);
  }

  // A union narrower than minWidth in its plane (bounded by its boxes' corners) is undone: the
  // slivers along a crease make such a bevel.
  std::vector<std::pair<Index, std::vector<Index>>> kept;  // first grown region, members
  for (std::size_t r = 0; r < regionCount; ++r) {
    if (!alive[r]) continue;
    bool wide = members[r].size() == 1;
    if (!wide) {
      const UnionPlane plane = planeOf(moments[r]);
      Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      for (const Box& box : boxes[r])
        for (const Vec3& corner : box) {
          const Vec2 q((corner - plane.centroid).dot(plane.axisU),
                       (corner - plane.centroid).dot(plane.axisV));
          lo = lo.cwiseMin(q);
          hi = hi.cwiseMax(q);
        }
      wide = (hi - lo).minCoeff() >= minWidth;
    }
    if (wide) {
      kept.emplace_back(Index(r), members[r]);
    } else {
      for (const Index m : members[r]) kept.emplace_back(m, std::vector<Index>{m});
    }
  }
  std::sort(kept.begin(), kept.end());

  // A union that a large region next to it describes as well as its own points joins it: where
  // the fit gives part of a staircase the ramp's normal (1M points, noise 5e-5 of the diagonal),
  // region growing makes one large region of the lower steps, a sawtooth around the mean ramp,
  // and the merging a union of the upper ones. Within the same bounds, against the large region's
  // own plane (its points would make any union's RMS small), and only when the union's RMS to
  // that plane is within the large region's own RMS (or the noise floor) and
  // kPlaneDescribesTolerance: the exact face of a box does not take a union of the bent normals
  // along its edge, which carries points of the next face.
  std::vector<int> keptOf(regionCount, -1);
  for (std::size_t k = 0; k < kept.size(); ++k)
    for (const Index m : kept[k].second) keptOf[m] = int(k);
  std::vector<int> joinTo(kept.size(), -1);
  std::vector<std::uint8_t> twin(kept.size(), 0);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const auto& [survivor, parts] = kept[k];
    if (parts.size() < 2) continue;
    std::vector<Index> large;  // the large grown regions next to the union
    for (const Index m : parts)
      for (const Index i : segmentation.regions[m])
        for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
          const int g = segmentation.labels[knn.neighbors[e]];
          if (g >= 0 && !small[std::size_t(g)]) large.push_back(Index(g));
        }
    std::sort(large.begin(), large.end());
    large.erase(std::unique(large.begin(), large.end()), large.end());
    const Moments& m = moments[survivor];
    const Vec3 mean = m.sum / m.count;
    const Mat3 covariance = m.outer / m.count - mean * mean.transpose();
    double best = std::numeric_limits<double>::infinity();
    const Vec3 unionNormal = planeOf(m).normal;  // the union's own plane
    for (const Index g : large) {
      const PlaneFit& plane = ownPlane[g];
      if (!plane.valid) continue;
      const double offset = plane.normal.dot(mean - plane.centroid);
      twin[k] = twin[k] || (options.parallelDegrees > 0 &&
                            std::abs(unionNormal.dot(plane.normal)) >= parallelCos &&
                            std::abs(offset) <= maxDeviation);
      const double rms =
          std::sqrt(std::max(0.0, plane.normal.dot(covariance * plane.normal) + offset * offset));
      const double describes = planeDescribesBound(plane.rms, 2 * noiseRms);
      const bool within =
          rms <= maxRms && rms <= describes && rms < best &&
          (boxesWithin(boxes[survivor], plane.normal, plane.centroid, maxDeviation) ||
           pointsWithin(positions, segmentation.regions, parts, plane.normal, plane.centroid,
                        maxDeviation));
      if (within) best = rms, joinTo[k] = keptOf[g];
    }
  }
  // A union parallel to a large region next to it and within the deviation bound of its plane,
  // which that plane does not describe well enough to join, is undone: it is that region's surface
  // (a floor's far corner among clutter, a table top's rounded rim), cut off by the step limit, and
  // would stand beside it as a second plane taking its points in the boundary refinement.
  const std::size_t unionCount = kept.size();
  for (std::size_t k = 0; k < unionCount; ++k) {
    if (joinTo[k] >= 0 || !twin[k]) continue;
    for (std::size_t p = 1; p < kept[k].second.size(); ++p) {
      const Index part = kept[k].second[p];
      kept.emplace_back(part, std::vector<Index>{part});
      joinTo.push_back(-1);
    }
    kept[k].second.resize(1);
  }
  for (std::size_t k = 0; k < kept.size(); ++k)
    if (joinTo[k] >= 0) {
      auto& into = kept[std::size_t(joinTo[k])].second;
      into.insert(into.end(), kept[k].second.begin(), kept[k].second.end());
      kept[k].second.clear();
    }
  kept.erase(
      std::remove_if(kept.begin(), kept.end(), [](const auto& e) { return e.second.empty(); }),
      kept.end());
  std::sort(kept.begin(), kept.end());

  // The merged regions, in the order of their first grown region.
  Segmentation merged;
  merged.labels.assign(n, -1);
  for (const auto& [first, parts] : kept) {
    if (origins)
      origins->push_back(parts.size() > 1       ? RegionOrigin::merged
                         : small[parts.front()] ? RegionOrigin::small
                                                : RegionOrigin::large);
    std::vector<Index> points;
    for (const Index m : parts)
      points.insert(points.end(), segmentation.regions[m].begin(), segmentation.regions[m].end());
    std::sort(points.begin(), points.end());
    for (const Index i : points) merged.labels[i] = int(merged.regions.size());
    merged.regions.push_back(std::move(points));
  }
  return merged;
}

}  // namespace scalespace
