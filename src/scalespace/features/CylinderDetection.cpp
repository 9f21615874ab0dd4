#include "scalespace/features/CylinderDetection.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/RegionGrower.hpp"
#include "scalespace/features/LineAnisotropy.hpp"
#include "scalespace/features/TubeMerging.hpp"
#include "scalespace/features/TubeSplitting.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

namespace {

/// OptionError(message) unless ok: the checks of the options and of the narrow-tube step's inputs.
void require(bool ok, const std::string& message) {
  if (!ok) throw OptionError(message);
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Eq. 3.10 as the region grower's criterion: a neighbour joins when its anisotropy, line
/// direction (unsigned) and normal are all within epsilon of the point it is reached from; with
/// CylinderOptions::oneCurvatureSign, and when it does not curve against the region's seed.
struct AlignedLines {
  struct Payload {
    float normal[3], direction[3], sigma, kappaT;  // kappaT: kappa1 t, signed
  };
  const LineAnisotropyField& field;
  float epsilon, t;
  float signSlack;  // |kappa1| t below which a point's sign is not read; < 0: no sign test
  Payload payload(Index i) const {
    const Vec3& n = field.normal[i];
    const Vec3& v = field.direction[i];
    return {{float(n.x()), float(n.y()), float(n.z())},
            {float(v.x()), float(v.y()), float(v.z())},
            field.sigma[i],
            field.kappa1[i] * t};
  }
  bool againstSeed(const Payload& seed, const Payload& to) const {
    if (signSlack < 0 || std::abs(seed.kappaT) <= signSlack) return false;
    return seed.kappaT > 0 ? to.kappaT < -signSlack : to.kappaT > signSlack;
  }
  bool accept(const Payload& seed, const Payload& from, const Payload& to) const {
    if (againstSeed(seed, to)) return false;
    const float vv = from.direction[0] * to.direction[0] + from.direction[1] * to.direction[1] +
                     from.direction[2] * to.direction[2];
    const float nn = from.normal[0] * to.normal[0] + from.normal[1] * to.normal[1] +
                     from.normal[2] * to.normal[2];
    return std::abs(from.sigma - to.sigma) < epsilon && std::abs(vv) > 1 - epsilon &&
           nn > 1 - epsilon;
  }
};

/// Each tube takes, breadth-first through the k-NN graph from its points, the points of no tube
/// that lie on its surface (|residual| <= max(3 rms, 5% of the radius)) with their own normal
/// along its radial direction: the points the anisotropy missed, next to the border of the lines
/// (the groove between the strands of a cable, the ends of a pipe). Tubes claim in region order.
void extendTubes(const KnnGraph& graph, const std::vector<Vec3>& positions,
                 const std::vector<Vec3>& normals, std::vector<TubeFit>& tubes,
                 std::vector<std::vector<Index>>& regions, const TubeCoverageOptions& coverage) {
  if (!coverage.enabled) return;
  std::vector<int> owner = tubeOwners(positions.size(), tubes, regions);
  const double minCos = std::cos(coverage.maxAngleDegrees * kPi / 180);
  std::vector<Index> frontier;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    TubeFit& tube = tubes[r];
    if (!tube.isTube()) continue;
    const double tolerance =
        std::max(coverage.rmsFactor * tube.rms, coverage.radiusFraction * tube.radius);
    const TubeSurface surface(tube);
    frontier = regions[r];
    while (!frontier.empty()) {
      const Index p = frontier.back();
      frontier.pop_back();
      for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
        const Index q = graph.neighbors[e];
        if (owner[q] >= 0) continue;
        Vec3 radial;
        if (std::abs(surface.residual(positions[q], &radial)) > tolerance ||
            std::abs(radial.dot(normals[q])) < minCos)
          continue;
        owner[q] = int(r);
        regions[r].push_back(q);
        frontier.push_back(q);
      }
    }
    std::sort(regions[r].begin(), regions[r].end());
    tube.pointCount = regions[r].size();
  }
}

/// Each region that splits into tubes thinner than its own (features/TubeSplitting) gives its
/// points to those tubes, appended after the regions (TubeRejection::Split; the points of no tube
/// are left free, for extendTubes). `splitFrom` gets, per region, the region it was split from (-1:
/// none). Tried on the tubes as well as the rough regions: the strands grown into one region at a
/// scale where each is a tube can, fitted as one tube of the cable's radius, pass the RMS test.
void splitRegionsByAxes(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                        const LineAnisotropyField& field, double t, const CylinderOptions& options,
                        std::vector<TubeFit>& tubes, std::vector<std::vector<Index>>& regions,
                        std::vector<int>& splitFrom) {
  const std::size_t count = regions.size();
  splitFrom.assign(count, -1);
  std::vector<std::vector<ThinTube>> parts(count);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1), [&](const auto& range) {
    for (std::size_t r = range.begin(); r != range.end(); ++r)
      parts[r] = splitIntoThinnerTubes(positions, normals, field.normal, field.kappa1, regions[r],
                                       tubes[r], t, options.tube, options.split);
  });
  for (std::size_t r = 0; r < count; ++r) {
    if (parts[r].empty()) continue;
    tubes[r].rejection = TubeRejection::Split;
    regions[r].clear();
    for (ThinTube& part : parts[r]) {
      regions.push_back(std::move(part.points));
      tubes.push_back(std::move(part.tube));
      splitFrom.push_back(int(r));
    }
  }
}

/// Each region turned down as flat, rough, narrow-arc or faceted, and not split, that trims to a
/// tube (features/TubeTrimming) keeps only the trimmed points, with that tube; so does each tube
/// of which TubeTrimOptions::tubeMinAgainstShare of the points curve against it, where the
/// trimmed points' tube fits twice as well. The rest are left free (extendTubes may give them
/// back to it where they lie on it).
void trimRejectedRegions(const KnnGraph& graph, const std::vector<Vec3>& positions,
                         const std::vector<Vec3>& normals, const LineAnisotropyField& field,
                         double t, const CylinderOptions& options, std::vector<TubeFit>& tubes,
                         std::vector<std::vector<Index>>& regions) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, regions.size(), 1), [&](const auto& range) {
    for (std::size_t r = range.begin(); r != range.end(); ++r) {
      const TubeRejection why = tubes[r].rejection;
      if (why != TubeRejection::None && why != TubeRejection::Flat && why != TubeRejection::Rough &&
          why != TubeRejection::NarrowArc && why != TubeRejection::Faceted)
        continue;
      std::vector<Index> core = trimToOneCurvatureSign(
          graph, field.kappa1, regions[r], t, options.tube.minCurvatureFactor,
          options.tube.minPoints, options.trim,
          why == TubeRejection::None ? options.trim.tubeMinAgainstShare : 0);
      if (core.empty()) continue;
      TubeFit fit = fitTube(positions, normals, field.normal, field.kappa1, core, t, options.tube);
      if (!fit.isTube() || !(fit.radius >= options.trim.minRadiusScales * t)) continue;
      if (tubes[r].isTube() && !(fit.rms * tubes[r].radius <= 0.5 * tubes[r].rms * fit.radius))
        continue;
      regions[r] = std::move(core);
      tubes[r] = std::move(fit);
    }
  });
}

/// Whether the points of every region of `c` lie on the best-fitting tube of the chain (lowest RMS
/// over radius): the median of their distances to its surface within `tolerance` of its radius.
bool liesOnItsBestTube(const RegionGraph& graph, const GraphComponent& c,
                       const std::vector<Vec3>& positions, const std::vector<CylinderLevel>& levels,
                       double tolerance) {
  const auto tubeAt = [&](std::size_t k) -> const TubeFit& {
    return levels[std::size_t(c.birthLevel) + k].tubes[std::size_t(c.regionAt[k])];
  };
  const TubeFit* best = nullptr;
  for (std::size_t k = 0; k < c.regionAt.size(); ++k)
    if (c.regionAt[k] >= 0 &&
        (!best || tubeAt(k).rms * best->radius < best->rms * tubeAt(k).radius))
      best = &tubeAt(k);
  for (std::size_t k = 0; k < c.regionAt.size(); ++k) {
    if (c.regionAt[k] < 0) continue;
    const auto& points =
        graph.levels[std::size_t(c.birthLevel) + k].regions[std::size_t(c.regionAt[k])];
    if (!(medianRelativeResidual(positions, points, *best) <= tolerance)) return false;
  }
  return best != nullptr;
}

std::vector<double> resolveScales(const PointCloud& cloud, const KnnGraph& graph,
                                  const CylinderOptions& options) {
  if (!options.scales.empty()) return options.scales;
  double tMin = options.tMin, tMax = options.tMax;
  if ((tMin == 0 || tMax == 0) && !(cloud.boundingBoxDiagonal() > 0))
    throw OptionError("all " + std::to_string(cloud.size()) +
                      " points coincide: there is no surface, and no automatic scale");
  if (tMin == 0) {
    if (graph.kthDistance.empty())
      throw OptionError("the cloud has " + std::to_string(cloud.size()) +
                        " points; the automatic CylinderOptions::tMin needs more than " +
                        std::to_string(options.graphNeighbors) + " (a distance to the " +
                        std::to_string(options.graphNeighbors) + "th neighbour)");
    tMin = 2 * lowerMedian(graph.kthDistance);
    if (!(tMin > 0))
      throw OptionError("most points have " + std::to_string(options.graphNeighbors) +
                        " duplicates: the automatic CylinderOptions::tMin is 0 (remove the "
                        "duplicates or give CylinderOptions::tMin)");
  }
  if (tMax == 0) tMax = cloud.boundingBoxDiagonal() / 10;
  if (!(tMax > tMin)) {
    // Say which bound was computed, and from what: a user who gave neither reads two values
    // they never set (a sparse cloud: its neighbour spacing is over a tenth of its diagonal).
    const auto bound = [](const char* field, double value, bool automatic,
                          const std::string& rule) {
      std::string text = automatic ? "the automatic " : "";
      text += field;
      text += " (" + (automatic ? rule + ", " : std::string()) + std::to_string(value) + ")";
      return text;
    };
    const bool autoMin = options.tMin == 0, autoMax = options.tMax == 0;
    std::string message = bound("CylinderOptions::tMax", tMax, autoMax, "a tenth of the diagonal") +
                          " must be > " +
                          bound("CylinderOptions::tMin", tMin, autoMin,
                                "twice the median distance to the " +
                                    std::to_string(options.graphNeighbors) + "th neighbour");
    if (autoMin || autoMax)
      message +=
          ": the points are too sparse for the automatic scales; give CylinderOptions::tMin and "
          "CylinderOptions::tMax";
    throw OptionError(message);
  }
  return scaleSeries(tMin, tMax, options.scaleCount, ScaleSpacing::Log);
}

}  // namespace

bool dropUnconfirmedNarrowTubes(const RegionGraph& graph, const NarrowTubeOptions& options,
                                const std::vector<Vec3>& positions, double onTubeTolerance,
                                std::vector<CylinderLevel>& levels,
                                std::vector<RegionLevel>& regionLevels) {
  require(levels.size() == graph.levels.size() && regionLevels.size() == graph.levels.size(),
          "dropUnconfirmedNarrowTubes: one CylinderLevel and one RegionLevel per graph level");
  for (std::size_t j = 0; j < levels.size(); ++j)
    require(levels[j].tubes.size() == graph.levels[j].regions.size() &&
                levels[j].narrow.size() == levels[j].tubes.size() &&
                regionLevels[j].regions.size() == levels[j].tubes.size(),
            "dropUnconfirmedNarrowTubes: one tube and one narrow flag per region of each level");
  require(onTubeTolerance <= 0 || !positions.empty(),
          "dropUnconfirmedNarrowTubes: the points' positions are needed with onTubeTolerance");
  std::vector<std::vector<std::uint8_t>> drop(levels.size());
  for (std::size_t j = 0; j < levels.size(); ++j) drop[j].assign(levels[j].tubes.size(), 0);
  bool any = false;
  for (const GraphComponent& c : graph.components) {
    bool allNarrow = true;
    double smallest = std::numeric_limits<double>::infinity(), largest = 0;
    for (std::size_t k = 0; k < c.regionAt.size(); ++k) {
      if (c.regionAt[k] < 0) continue;
      const CylinderLevel& level = levels[std::size_t(c.birthLevel) + k];
      allNarrow = allNarrow && level.narrow[std::size_t(c.regionAt[k])];
      const double radius = level.tubes[std::size_t(c.regionAt[k])].radius;
      smallest = std::min(smallest, radius);
      largest = std::max(largest, radius);
    }
    if (!allNarrow) continue;
    // The span, gaps included: its first and last scales lie at least that many steps apart
    // (python3-pcl's mug at 12 scales: found at levels 2 and 5 only, persistence 1, span 3).
    if (c.deathLevel - c.birthLevel >= options.minPersistence) {
      if (largest <= (1 + options.maxRadiusSpread) * smallest) continue;
      if (onTubeTolerance > 0 && liesOnItsBestTube(graph, c, positions, levels, onTubeTolerance))
        continue;
    }
    for (std::size_t k = 0; k < c.regionAt.size(); ++k)
      if (c.regionAt[k] >= 0) drop[std::size_t(c.birthLevel) + k][std::size_t(c.regionAt[k])] = 1;
    any = true;
  }
  if (!any) return false;
  for (std::size_t j = 0; j < levels.size(); ++j) {
    std::size_t kept = 0;
    for (std::size_t r = 0; r < drop[j].size(); ++r) {
      if (drop[j][r]) continue;
      if (kept != r) {  // a self-move would empty them
        levels[j].tubes[kept] = std::move(levels[j].tubes[r]);
        levels[j].narrow[kept] = levels[j].narrow[r];
        regionLevels[j].regions[kept] = std::move(regionLevels[j].regions[r]);
      }
      ++kept;
    }
    levels[j].tubes.resize(kept);
    levels[j].narrow.resize(kept);
    regionLevels[j].regions.resize(kept);
  }
  return true;
}

OrientedNormalsOptions cylinderNormalOptions() {
  OrientedNormalsOptions options;
  options.estimation.sheetTolerance = 0.05;
  options.sheetSign = SheetSign::FromPlanes;
  return options;
}

void validateCylinderOptions(const CylinderOptions& options) {
  for (std::size_t k = 0; k < options.scales.size(); ++k) {
    require(std::isfinite(options.scales[k]) && options.scales[k] > 0,
            "CylinderOptions::scales must be finite and > 0");
    require(k == 0 || options.scales[k] > options.scales[k - 1],
            "CylinderOptions::scales must be increasing");
  }
  require(options.scaleCount >= 1 && options.scaleCount <= 1000,
          "CylinderOptions::scaleCount must be in [1, 1000]");
  require(std::isfinite(options.tMin) && options.tMin >= 0,
          "CylinderOptions::tMin must be finite and >= 0");
  require(std::isfinite(options.tMax) && options.tMax >= 0,
          "CylinderOptions::tMax must be finite and >= 0");
  require(options.epsilon > 0 && options.epsilon < 1, "CylinderOptions::epsilon must be in (0, 1)");
  require(options.minAnisotropy >= 0 && options.minAnisotropy <= 1,
          "CylinderOptions::minAnisotropy must be in [0, 1]");
  require(options.graphNeighbors >= 1 && options.graphNeighbors <= 100,
          "CylinderOptions::graphNeighbors must be in [1, 100]");
  require(options.minJaccard >= 0.5 && options.minJaccard < 1,
          "CylinderOptions::minJaccard must be in [0.5, 1)");
  require(options.maxGapLevels >= 0, "CylinderOptions::maxGapLevels must be >= 0");
  require(options.bridgeRadiusTolerance >= 0 && options.bridgeRadiusTolerance < 1,
          "CylinderOptions::bridgeRadiusTolerance must be in [0, 1)");
  require(options.nestedLinkTolerance >= 0 && options.nestedLinkTolerance < 1,
          "CylinderOptions::nestedLinkTolerance must be in [0, 1) (0: off)");
  validateLineFilterOptions(options.filter);
  validateTubeFitOptions(options.tube);
  validateTubeSplitOptions(options.split);
  validateTubeTrimOptions(options.trim);
  require(options.narrow.minArcDegrees >= 0 && options.narrow.minArcDegrees <= 360,
          "NarrowTubeOptions::minArcDegrees must be in [0, 360]");
  require(options.narrow.minPersistence >= 0, "NarrowTubeOptions::minPersistence must be >= 0");
  require(std::isfinite(options.narrow.maxRadiusSpread) && options.narrow.maxRadiusSpread >= 0,
          "NarrowTubeOptions::maxRadiusSpread must be finite and >= 0");
  require(std::isfinite(options.coverage.rmsFactor) && options.coverage.rmsFactor >= 0,
          "TubeCoverageOptions::rmsFactor must be finite and >= 0");
  require(std::isfinite(options.coverage.radiusFraction) && options.coverage.radiusFraction >= 0,
          "TubeCoverageOptions::radiusFraction must be finite and >= 0");
  require(options.coverage.maxAngleDegrees >= 0 && options.coverage.maxAngleDegrees <= 90,
          "TubeCoverageOptions::maxAngleDegrees must be in [0, 90]");
  CurvatureLineOptions lines = options.lines;
  lines.scale = 1;  // set per level
  validateCurvatureLineOptions(lines);
}

CylinderDetection detectCylinders(const PointCloud& cloud, const CylinderOptions& options,
                                  const ProgressCallback& progress) {
  validateCylinderOptions(options);
  if (!cloud.hasNormals())
    throw OptionError("cylinders need oriented normals (estimate them first)");
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Vec3>& positions = cloud.positions();
  const std::size_t n = positions.size();
  if (progress && !progress(0, "k-NN graph")) throw Cancelled();
  const KnnGraph graph = buildKnnGraph(positions, std::size_t(options.graphNeighbors));
  const std::vector<double> scales = resolveScales(cloud, graph, options);
  const int count = int(scales.size());

  CylinderDetection result;
  std::vector<RegionLevel> regionLevels;
  for (int s = 0; s < count; ++s) {
    const auto levelStart = std::chrono::steady_clock::now();
    const double t = scales[std::size_t(s)];
    const std::string stage = "cylinders t=" + std::to_string(t);
    auto sub = [&](double from, double to) -> ProgressCallback {
      if (!progress) return {};
      return [&progress, &stage, s, count, from, to](double f, std::string_view) {
        return progress((s + from + (to - from) * std::min(f, 1.0)) / count, stage);
      };
    };
    CurvatureLineOptions lineOptions = options.lines;
    lineOptions.scale = t;
    const CurvatureLineSet lines = traceCurvatureLines(cloud, lineOptions, sub(0, 0.7));
    std::vector<const CurvatureLine*> regular;
    for (const CurvatureLine& line : lines.lines)
      if (isRegularLine(line, t, options.filter)) regular.push_back(&line);
    const LineAnisotropyField field =
        lineAnisotropy(positions, cloud.normals(), regular, t, sub(0.7, 0.9));

    std::vector<std::uint8_t> eligible(n, 0);
    for (std::size_t i = 0; i < n; ++i) eligible[i] = field.sigma[i] >= options.minAnisotropy;
    std::vector<Index> seeds = seedsByIncreasingKey(n, [&](Index i) {
      return eligible[i] ? -double(field.sigma[i]) : std::numeric_limits<double>::quiet_NaN();
    });
    Segmentation seg = growRegionsFromSeeds(
        graph, std::move(seeds), eligible,
        AlignedLines{field, float(options.epsilon), float(t),
                     options.oneCurvatureSign ? float(options.tube.minCurvatureFactor) : -1.f});
    std::vector<TubeFit> tubes(seg.regions.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seg.regions.size(), 1),
                      [&](const auto& range) {
                        for (std::size_t r = range.begin(); r != range.end(); ++r)
                          tubes[r] = fitTube(positions, cloud.normals(), field.normal, field.kappa1,
                                             seg.regions[r], t, options.tube);
                      });
    std::vector<int> splitFrom;
    splitRegionsByAxes(positions, cloud.normals(), field, t, options, tubes, seg.regions,
                       splitFrom);
    trimRejectedRegions(graph, positions, cloud.normals(), field, t, options, tubes, seg.regions);
    mergeTouchingTubes(graph, positions, cloud.normals(), field, t, options.tube, tubes,
                       seg.regions, splitFrom, options.split);
    extendTubes(graph, positions, cloud.normals(), tubes, seg.regions, options.coverage);
    CylinderLevel level;
    level.scale = t;
    level.lines = lines.lines.size();
    level.regularLines = regular.size();
    level.regions = seg.regions.size();
    level.rejections.assign(std::size_t(TubeRejection::Split) + 1, 0);
    for (const TubeFit& tube : tubes)
      if (!tube.isTube()) ++level.rejections[std::size_t(tube.rejection)];
    RegionLevel regionLevel;
    regionLevel.t = t;
    TubeFitOptions narrowArc = options.tube;
    narrowArc.minArcDegrees = std::min(narrowArc.minArcDegrees, options.narrow.minArcDegrees);
    // The tubes took free points next to them (extendTubes): a narrow-arc region keeps the rest.
    const std::vector<int> owner = tubeOwners(n, tubes, seg.regions);
    for (std::size_t r = 0; r < tubes.size(); ++r) {
      bool narrow = options.narrow.enabled && tubes[r].rejection == TubeRejection::NarrowArc &&
                    judgeTube(tubes[r], t, narrowArc) == TubeRejection::None;
      if (narrow) {
        std::vector<Index>& points = seg.regions[r];
        const std::size_t before = points.size();
        points.erase(
            std::remove_if(points.begin(), points.end(), [&](Index i) { return owner[i] >= 0; }),
            points.end());
        if (points.size() != before) {  // its tube is that of the points it keeps
          tubes[r] = points.size() >= options.tube.minPoints
                         ? fitTube(positions, cloud.normals(), field.normal, field.kappa1, points,
                                   t, narrowArc)
                         : TubeFit{};
          narrow = tubes[r].isTube();
        }
      }
      if (tubes[r].isTube() || narrow) {
        if (narrow) tubes[r].rejection = TubeRejection::None;
        regionLevel.regions.push_back(std::move(seg.regions[r]));
        level.tubes.push_back(std::move(tubes[r]));
        level.narrow.push_back(narrow);
      }
    }
    level.anisotropy = field.sigma;
    level.seconds = secondsSince(levelStart);
    result.levels.push_back(std::move(level));
    regionLevels.push_back(std::move(regionLevel));
    if (progress && !progress(double(s + 1) / count, stage)) throw Cancelled();
  }

  // Across a gap the two tubes of a J link must agree in radius (bridgeRadiusTolerance): a region
  // that swallowed both walls of a thick pipe at one scale (radius between them) shares most of
  // its points with the outer wall's tube of a later scale. A nested link is vouched for by its
  // points instead: the walls of libcgal-demo's pipe.off lie at 0.17 and 0.31, so the outer
  // wall's points lie (0.31 - r) / r off a tube of radius r between them, 24% for r = 0.25.
  RegionLinkOptions linking;
  linking.minJaccard = options.minJaccard;
  linking.maxGap = options.maxGapLevels;
  linking.bridgeAllowed = [&](const std::vector<RegionLevel>&, int j, int r, int k, int s) {
    return radiiAgree(result.levels[std::size_t(j)].tubes[std::size_t(r)],
                      result.levels[std::size_t(k)].tubes[std::size_t(s)],
                      options.bridgeRadiusTolerance);
  };
  if (options.nestedLinkTolerance > 0)
    linking.nestedAllowed = [&](const std::vector<RegionLevel>& regions, int j, int r, int k,
                                int s) {
      const std::vector<Index>& a = regions[std::size_t(j)].regions[std::size_t(r)];
      const std::vector<Index>& b = regions[std::size_t(k)].regions[std::size_t(s)];
      const bool aOnB = a.size() <= b.size();
      const TubeFit& tube = aOnB ? result.levels[std::size_t(k)].tubes[std::size_t(s)]
                                 : result.levels[std::size_t(j)].tubes[std::size_t(r)];
      return medianRelativeResidual(positions, aOnB ? a : b, tube) <= options.nestedLinkTolerance;
    };
  result.graph = buildRegionGraph(std::move(regionLevels), n, linking);
  if (dropUnconfirmedNarrowTubes(result.graph, options.narrow, positions,
                                 options.nestedLinkTolerance, result.levels, result.graph.levels)) {
    std::vector<RegionLevel> kept = std::move(result.graph.levels);
    result.graph = buildRegionGraph(std::move(kept), n, linking);
  }
  for (std::size_t c = 0; c < result.graph.components.size(); ++c) {
    const GraphComponent& g = result.graph.components[c];
    CylinderComponent component;
    component.id = int(c);
    component.birthLevel = g.birthLevel;
    component.deathLevel = g.deathLevel;
    component.birthScale = g.birthScale;
    component.deathScale = g.deathScale;
    component.gapLevels = g.gapLevels;
    component.persistence = g.persistence();
    // The representative tube: of the levels holding at least 80% of the component's largest
    // set, the one whose tube fits best (lowest RMS over radius; the lower level on ties). The
    // largest set alone is often the coarsest level, whose fits, at a scale above the radius,
    // round the tube's junctions into it (a table leg read 0.044 m there, 0.025 m below).
    const auto sizeAt = [&](std::size_t k) {
      return result.graph.levels[std::size_t(g.birthLevel) + k]
          .regions[std::size_t(g.regionAt[k])]
          .size();
    };
    const auto tubeAt = [&](std::size_t k) -> const TubeFit& {
      return result.levels[std::size_t(g.birthLevel) + k].tubes[std::size_t(g.regionAt[k])];
    };
    std::size_t largest = 0;  // a chain starts and ends with a region; gaps (-1) lie between
    for (std::size_t k = 1; k < g.regionAt.size(); ++k)
      if (g.regionAt[k] >= 0 && sizeAt(k) > sizeAt(largest)) largest = k;
    std::size_t chosen = largest;
    double bestFit = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < g.regionAt.size(); ++k) {
      if (g.regionAt[k] < 0 || 10 * sizeAt(k) < 8 * sizeAt(largest)) continue;
      const TubeFit& tube = tubeAt(k);
      const double fit = tube.rms / tube.radius;
      if (fit < bestFit) bestFit = fit, chosen = k;
    }
    component.representativeLevel = g.birthLevel + int(chosen);
    component.tube = tubeAt(chosen);
    result.components.push_back(std::move(component));
  }
  result.seconds = secondsSince(start);
  return result;
}

namespace {
std::vector<int> persistenceOf(const CylinderDetection& detection) {
  std::vector<int> p;
  for (const CylinderComponent& c : detection.components) p.push_back(c.persistence);
  return p;
}
}  // namespace

int nearestCylinderLevel(const CylinderDetection& detection, double t) {
  std::vector<double> scales;
  for (const CylinderLevel& level : detection.levels) scales.push_back(level.scale);
  return nearestScaleIndex(scales, t);
}

std::vector<int> cylinderLabelsAtLevel(const CylinderDetection& detection, int level,
                                       int minPersistence) {
  if (level < 0 || level >= detection.scaleCount())
    throw OptionError("level " + std::to_string(level) + " is outside [0, " +
                      std::to_string(detection.scaleCount()) + ")");
  // The one level as a membership of one level: core's query does the rest.
  const PointMembership one{detection.graph.pointCount, 1, detection.graph.componentLabels(level)};
  return labelsAtLevel(one, persistenceOf(detection), 0, minPersistence);
}

std::vector<int> cylinderLabelsByPersistence(const CylinderDetection& detection,
                                             int minPersistence) {
  return labelsByPersistence(pointMembership(detection.graph), persistenceOf(detection),
                             minPersistence);
}

std::vector<int> cylinderPersistence(const CylinderDetection& detection) {
  return persistenceOf(detection);
}

}  // namespace scalespace
