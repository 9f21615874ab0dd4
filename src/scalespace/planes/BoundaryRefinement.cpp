#include "scalespace/planes/BoundaryRefinement.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "scalespace/core/Error.hpp"
#include "scalespace/fit/PointSetPlane.hpp"
#include "scalespace/planes/PlaneDescribes.hpp"

namespace scalespace {
namespace {
constexpr int kPasses = 3;  // plane fits: the first, then two refits
// A large region's tolerance never goes below this share of t: an exact face (RMS 0, no noise)
// still takes back points lying on its plane up to rounding.
constexpr double kMinRelativeTolerance = 1e-3;

// The plane of a point's k-NN (itself included) and their spread across another plane: the
// point's own surface at the finest scale there is.
struct Neighbourhood {
  std::vector<Index> points;
  PlaneFit plane;
};
Neighbourhood neighbourhoodOf(const std::vector<Vec3>& positions, const KnnGraph& knn, Index i) {
  Neighbourhood h;
  h.points.push_back(i);
  for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e)
    h.points.push_back(knn.neighbors[e]);
  h.plane = fitPlane(positions, h.points);
  return h;
}

// Whether the point's own surface crosses the plane of unit normal `normal`: its k-NN plane turns
// more than acos(minCos) from it and the neighbours spread across it by more than minSpread (RMS).
// Where the sensor noise exceeds the sampling (the near floor of a scan), the k-NN plane is the
// noise's and any direction; such neighbours spread across the plane no more than the noise.
bool crosses(const std::vector<Vec3>& positions, const Neighbourhood& h, const Vec3& normal,
             double minCos, double minSpread) {
  if (!h.plane.valid || std::abs(h.plane.normal.dot(normal)) >= minCos) return false;
  double sum = 0;
  for (const Index j : h.points) sum += std::pow(normal.dot(positions[j] - h.plane.centroid), 2);
  return sum > minSpread * minSpread * double(h.points.size());
}

// The unions take the unlabelled points next to them, round after round (each round decides on
// the labels it began with), while a point lies within planeDescribesBound of the union's plane
// (kPlaneDescribesTolerance times its RMS, or the noise floor); among several unions, the nearest
// plane (ties: the first union). A point whose own surface crosses the union's plane (crosses(),
// the fill's angle) is not taken but passes the union's band on (a bridge): the strip of a
// staircase's side within the ramp's band is the side's, yet the top tread lies beyond it.
void takeUnlabelledPoints(const std::vector<Vec3>& positions, const KnnGraph& knn,
                          const std::vector<std::uint8_t>& takes, std::vector<int>& labels,
                          std::vector<std::vector<Index>>& regions, double noiseFloor,
                          double maxAngleDegrees) {
  const double minCos =
      maxAngleDegrees >= 90 ? -1.0 : std::cos(maxAngleDegrees * std::acos(-1.0) / 180);
  const std::size_t n = labels.size();
  std::vector<PlaneFit> planes(regions.size());
  std::vector<double> bound(regions.size(), -1.0);  // < 0: takes nothing
  tbb::parallel_for(std::size_t(0), regions.size(), [&](std::size_t r) {
    if (!takes[r] || regions[r].size() < 3) return;
    planes[r] = fitPlane(positions, regions[r]);
    if (!planes[r].valid) return;
    bound[r] = planeDescribesBound(planes[r].rms, noiseFloor);
  });
  const auto nextToTaker = [&](Index i) {
    for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
      const int r = labels[knn.neighbors[e]];
      if (r >= 0 && bound[std::size_t(r)] >= 0) return true;
    }
    return false;
  };
  std::vector<Index> frontier;
  for (std::size_t i = 0; i < n; ++i)
    if (labels[i] < 0 && nextToTaker(Index(i))) frontier.push_back(Index(i));
  std::vector<std::uint8_t> queued(n, 0);
  std::vector<std::uint8_t> touched(regions.size(), 0);
  // bridge[i]: the union whose band reached the unlabelled point i, whose own surface turns away
  // from the union's plane; the band goes on through it, the point stays unlabelled.
  std::vector<int> bridge(n, -1);
  const auto bandOf = [&](Index j) { return labels[j] >= 0 ? labels[j] : bridge[j]; };
  std::vector<int> target, crossing;
  while (!frontier.empty()) {
    target.assign(frontier.size(), -1);
    crossing.assign(frontier.size(), -1);
    tbb::parallel_for(std::size_t(0), frontier.size(), [&](std::size_t f) {
      const Index i = frontier[f];
      std::optional<Neighbourhood> around;  // computed for the first plane in reach
      double best = std::numeric_limits<double>::infinity(), bestCrossing = best;
      for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
        const int r = bandOf(knn.neighbors[e]);
        if (r < 0 || bound[std::size_t(r)] < 0) continue;
        const PlaneFit& plane = planes[std::size_t(r)];
        const double d = std::abs(plane.normal.dot(positions[i]) - plane.offset);
        if (d > bound[std::size_t(r)]) continue;
        if (minCos >= 0 && !around) around = neighbourhoodOf(positions, knn, i);
        if (minCos >= 0 && crosses(positions, *around, plane.normal, minCos, noiseFloor)) {
          if (d < bestCrossing || (d == bestCrossing && r < crossing[f]))
            bestCrossing = d, crossing[f] = r;
        } else if (d < best || (d == best && r < target[f])) {
          best = d, target[f] = r;
        }
      }
    });
    std::vector<Index> moved;
    for (std::size_t f = 0; f < frontier.size(); ++f) {
      if (target[f] >= 0) {
        labels[frontier[f]] = target[f];
        regions[std::size_t(target[f])].push_back(frontier[f]);
        touched[std::size_t(target[f])] = 1;
        moved.push_back(frontier[f]);
      } else if (crossing[f] >= 0) {
        bridge[frontier[f]] = crossing[f];
        moved.push_back(frontier[f]);
      }
    }
    std::vector<Index> next;
    for (const Index i : moved)
      for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
        const Index j = knn.neighbors[e];
        if (labels[j] < 0 && bridge[j] < 0 && !queued[j]) queued[j] = 1, next.push_back(j);
      }
    for (const Index i : next) queued[i] = 0;
    std::sort(next.begin(), next.end());
    frontier = std::move(next);
  }
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (touched[r]) std::sort(regions[r].begin(), regions[r].end());
}
}  // namespace

void validate(const BoundaryRefinementOptions& options) {
  if (!(options.maxRelativeDistance >= 0) || !std::isfinite(options.maxRelativeDistance))
    throw OptionError("BoundaryRefinementOptions::maxRelativeDistance must be finite and >= 0");
  if (!(options.minRelativeGain >= 0) || !std::isfinite(options.minRelativeGain))
    throw OptionError("BoundaryRefinementOptions::minRelativeGain must be finite and >= 0");
  if (!(options.minRelativeOffset >= 0) || !std::isfinite(options.minRelativeOffset))
    throw OptionError("BoundaryRefinementOptions::minRelativeOffset must be finite and >= 0");
  if (!(options.noiseFactor >= 0) || !std::isfinite(options.noiseFactor))
    throw OptionError("BoundaryRefinementOptions::noiseFactor must be finite and >= 0");
  if (!(options.largeRegionTolerance >= 0) || !std::isfinite(options.largeRegionTolerance))
    throw OptionError("BoundaryRefinementOptions::largeRegionTolerance must be finite and >= 0");
  if (!(options.fillMaxAngleDegrees > 0 && options.fillMaxAngleDegrees <= 90))
    throw OptionError("BoundaryRefinementOptions::fillMaxAngleDegrees must be in (0, 90]");
}

Segmentation refineRegionBoundaries(const std::vector<Vec3>& positions, const KnnGraph& knn,
                                    Segmentation segmentation,
                                    const std::vector<RegionOrigin>& origins, double t,
                                    double noiseRms, const BoundaryRefinementOptions& options) {
  validate(options);
  if (!(t > 0)) throw OptionError("boundary refinement: the scale t must be positive");
  if (!(noiseRms >= 0) || !std::isfinite(noiseRms))
    throw OptionError("boundary refinement: the noise RMS must be finite and >= 0");
  const std::size_t n = segmentation.labels.size();
  if (positions.size() != n || knn.size() != n)
    throw OptionError("boundary refinement: positions, labels and the k-NN graph differ in size");
  const std::size_t regionCount = segmentation.regions.size();
  if (!origins.empty() && origins.size() != regionCount)
    throw OptionError("boundary refinement: one origin per region is needed");
  // Unions take points; they and the regions large enough to stand alone give them. A small
  // grown region next to a union keeps its points: it was not merged, so it is a piece of
  // another surface (a box's side under its top), not an overhang of one.
  std::vector<std::uint8_t> takes(regionCount, 0), gives(regionCount, 0), large(regionCount, 0);
  for (std::size_t r = 0; r < origins.size(); ++r) {
    takes[r] = origins[r] == RegionOrigin::merged;
    gives[r] = origins[r] != RegionOrigin::small;
    large[r] = origins[r] == RegionOrigin::large && options.largeRegionTolerance > 0;
  }
  // Whether a point of region `own` may move to region `r`: any giver's to a union, a union's
  // back to a large grown region (within that region's tolerance, below).
  const auto receives = [&](int own, int r) {
    return r != own &&
           (takes[std::size_t(r)] || (takes[std::size_t(own)] && large[std::size_t(r)]));
  };
  const double reach = options.maxRelativeDistance * t;
  const double margin = std::max(options.minRelativeGain * t, options.noiseFactor * noiseRms);
  const double minOffset = options.minRelativeOffset * t;
  // A large region's tolerance, and the unions' bound on the unlabelled points they take.
  const double noiseFloor = std::max(options.noiseFactor * noiseRms, kMinRelativeTolerance * t);
  // (One region alone moves nothing, but a union still takes the unlabelled points.)
  if (reach == 0 || std::none_of(takes.begin(), takes.end(), [](std::uint8_t x) { return x != 0; }))
    return segmentation;

  std::vector<int>& labels = segmentation.labels;
  std::vector<std::vector<Index>> regions = std::move(segmentation.regions);
  std::vector<PlaneFit> planes(regionCount);
  std::vector<double> tolerance(regionCount, 0.0);  // a large region's reach (the union's: reach)
  const auto distance = [&](Index i, int r) {
    const PlaneFit& plane = planes[std::size_t(r)];
    return plane.valid ? std::abs(plane.normal.dot(positions[i]) - plane.offset)
                       : std::numeric_limits<double>::infinity();
  };
  std::vector<int> target(n, -1);
  std::vector<std::uint8_t> queued(n, 0);
  for (int pass = 0; pass < kPasses; ++pass) {
    // The planes, fixed through a pass's rounds so that a move only ever lowers a point's distance
    // to its region's plane (by more than the margin) and the rounds end; refitted between passes,
    // since the points a region gave away had tilted and shifted its plane.
    tbb::parallel_for(std::size_t(0), regionCount, [&](std::size_t r) {
      planes[r] = fitPlane(positions, regions[r]);
      tolerance[r] = planeDescribesBound(planes[r].rms, noiseFloor, options.largeRegionTolerance);
    });
    // The points to look at: the labelled points next to a target's point in the first round,
    // then the moved points' neighbours and the moved points themselves.
    std::vector<Index> frontier;
    for (std::size_t i = 0; i < n; ++i) {
      if (labels[i] < 0 || !gives[std::size_t(labels[i])]) continue;
      for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
        const int r = labels[knn.neighbors[e]];
        if (r >= 0 && receives(labels[i], r)) {
          frontier.push_back(Index(i));
          break;
        }
      }
    }
    bool anyMoved = false;
    while (!frontier.empty()) {
      tbb::parallel_for(std::size_t(0), frontier.size(), [&](std::size_t f) {
        const Index i = frontier[f];
        const int own = labels[i];
        const double offset = distance(i, own);
        target[i] = own;
        if (!gives[std::size_t(own)] || !(offset > minOffset)) return;
        double best = offset - margin;
        int bestRegion = own;
        for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
          const int r = labels[knn.neighbors[e]];
          if (r < 0 || !receives(own, r)) continue;
          const double d = distance(i, r);
          const double within = takes[std::size_t(r)] ? reach : tolerance[std::size_t(r)];
          if (d <= within && (d < best || (d == best && bestRegion != own && r < bestRegion)))
            best = d, bestRegion = r;
        }
        target[i] = bestRegion;
      });
      std::vector<Index> moved;
      for (const Index i : frontier)
        if (target[i] != labels[i]) moved.push_back(i);
      for (const Index i : moved) labels[i] = target[i];
      anyMoved = anyMoved || !moved.empty();
      std::vector<Index> next;
      for (const Index i : moved) {
        if (!queued[i]) queued[i] = 1, next.push_back(i);
        for (std::size_t e = knn.offsets[i]; e < knn.offsets[i + 1]; ++e) {
          const Index j = knn.neighbors[e];
          if (labels[j] >= 0 && !queued[j]) queued[j] = 1, next.push_back(j);
        }
      }
      for (const Index i : next) queued[i] = 0;
      std::sort(next.begin(), next.end());
      frontier = std::move(next);
    }
    if (!anyMoved) break;
    for (std::vector<Index>& points : regions) points.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (labels[i] >= 0) regions[std::size_t(labels[i])].push_back(Index(i));
  }

  if (options.takeUnlabelled)
    takeUnlabelledPoints(positions, knn, takes, labels, regions, noiseFloor,
                         options.fillMaxAngleDegrees);

  // The regions in their order, the emptied ones dropped.
  Segmentation refined;
  refined.labels.assign(n, -1);
  for (std::vector<Index>& points : regions) {
    if (points.empty()) continue;
    for (const Index i : points) refined.labels[i] = int(refined.regions.size());
    refined.regions.push_back(std::move(points));
  }
  return refined;
}

}  // namespace scalespace
