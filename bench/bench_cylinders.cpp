// Cylinders across scales (Sec. 3.5) against CGAL's Efficient RANSAC [Schnabel 2007] (planes and
// cylinders: the peer users reach for), on the pipe rack of `scalespace generate pipes` or the
// poles of `scalespace generate poles` (ground truth per point: core/PipeScene.hpp), full and
// one-sided ("half-pipe") scans, noise 0 and 1e-3 of the diagonal.
//
//   bench_cylinders [--scene rack|poles (rack)]
//                   [--points N (rack 1000000; poles 216000, a 2 cm spacing, where the box's
//                   edges round into tubes)] [--noise F (that noise alone)]
//                   [--no-peers] [--clean-only] [--scan full|one-sided]
//                   [--scales M (ours: 8)] [--tmin T (ours: automatic)] [--seed S]
//                   [--curved-seeds-first] (ours: CurvatureLineOptions::curvedSeedsFirst on,
//                   the features' seed order; the cylinders' default is the random order)
//                   [--one-curvature-sign] (ours: CylinderOptions::oneCurvatureSign on)
//                   [--estimate-normals] (every method gets normals estimated from the positions
//                   as `scalespace cylinders` does for a file without them:
//                   cylinderNormalOptions(), sheet normals signed by the PCA normals oriented by
//                   the MST with the visibility correction, facing the one-sided scan's scanner.
//                   Default: the scene's exact normals)
//                   [--pca-normals] (with --estimate-normals: PCA normals, oriented by their own
//                   tree, as `cylinders` did before 2026-11-30)
//                   [--normal-k K] (with --estimate-normals: K neighbours, fixed; default: 10,
//                   doubled under heavy noise as the CLI does, NormalEstimationOptions::maxK)
//                   [--min-line-length F] [--max-line-curvature F] [--max-line-variation F]
//                   (ours: LineFilterOptions::minLengthFactor, maxCurvatureFactor,
//                   maxMeanVariation)
//                   [--min-persistence P] (ours: only the regions of components living at
//                   least P scale steps are scored, as `cylinders --min-persistence P` labels;
//                   default 0, every region)
//                   [--min-arc DEGREES] (ours: TubeFitOptions::minArcDegrees)
//                   [--max-section-shape S] (ours: TubeFitOptions::maxSectionShapeShare; 1: off)
//                   [--max-face-sectors N] (ours: TubeFitOptions::maxFaceSectors; 36: off)
//                   [--noisy-only] (the scans with noise 1e-3 alone)
//                   [--no-split] (ours: TubeSplitOptions::enabled off, Eq. 3.10's regions as
//                   grown) [--split-cell F] [--split-density F] [--split-steps N]
//                   [--split-link F] (TubeSplitOptions::cellFactor, minDensity, densitySteps,
//                   linkRadius)
//                   [--no-junction-trim] (ours: TubeTrimOptions::enabled off)
//
// Scores, per scene and method:
//   - per pipe (the rack: thin, medium, thick, bent, tapering, cable; the poles: four straight
//     poles): the best IoU with one detected set
//     (ours: a component's points at one scale, any scale; RANSAC: one cylinder's points); found
//     when >= 0.8;
//   - the rack's cable read both ways: each strand found (IoU >= 0.8; seen from one side, a
//     strand is the runs along the cable where the others do not hide it, each to be found) and
//     the whole cable found;
//   - on the straight pipes, the radius error (%) and axis angle (degrees) of the best match;
//   - false cylinders: detected sets whose points lie mostly (> 50%) on the floor, wall and box
//     (their persistence, ours, where a component holds the set).
// Timings are the detection alone (k-NN graph and every scale for ours; detect() for RANSAC), on
// all cores.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "BenchMain.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/OrientedNormals.hpp"
#include "scalespace/core/PipeScene.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/features/CylinderDetection.hpp"

using namespace scalespace;

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// One detected set: points (cloud indices, increasing) and, when straight, its axis and radius.
struct Detected {
  std::vector<Index> points;
  bool straight = false;
  Vec3 direction = Vec3::UnitX();
  double radius = 0;
  std::string where;     // "t=0.025" or "ransac"
  int persistence = -1;  // ours: its component's
};

struct Method {
  std::string name;
  std::vector<Detected> sets;
  double seconds = 0;
};

double iou(const std::vector<Index>& a, const std::vector<Index>& b) {
  std::size_t i = 0, j = 0, both = 0;
  while (i < a.size() && j < b.size()) {
    if (a[i] < b[j])
      ++i;
    else if (b[j] < a[i])
      ++j;
    else
      ++both, ++i, ++j;
  }
  return double(both) / double(a.size() + b.size() - both);
}

Method runOurs(const PointCloud& cloud, const CylinderOptions& options, int minPersistence) {
  Method m;
  m.name = "scalespace";
  const auto start = std::chrono::steady_clock::now();
  const CylinderDetection d = detectCylinders(cloud, options);
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (int level = 0; level < d.scaleCount(); ++level) {
    const auto& regions = d.graph.levels[std::size_t(level)].regions;
    for (std::size_t r = 0; r < regions.size(); ++r) {
      const TubeFit& tube = d.levels[std::size_t(level)].tubes[r];
      char where[32];
      std::snprintf(where, sizeof where, "t=%.3g", d.levels[std::size_t(level)].scale);
      const int component = d.graph.componentOf[std::size_t(level)][r];
      if (d.components[std::size_t(component)].persistence < minPersistence) continue;
      m.sets.push_back({regions[r], tube.straight, tube.direction, tube.radius, where,
                        d.components[std::size_t(component)].persistence});
    }
  }
  std::printf(
      "  scalespace: %zu components over %d scales (%zu regions%s)\n", d.components.size(),
      d.scaleCount(), m.sets.size(),
      minPersistence > 0
          ? (", of components living " + std::to_string(minPersistence) + " steps or more").c_str()
          : "");
  return m;
}

// Efficient RANSAC with planes and cylinders; `tuned` sets epsilon and cluster epsilon from the
// sampling (3 x the mean spacing, not 1% of the box) and min points to 0.1% of the cloud.
Method runRansac(const PointCloud& cloud, bool tuned, double spacing) {
  using Item = std::tuple<Kernel::Point_3, Kernel::Vector_3, std::size_t>;
  using Items = std::vector<Item>;
  using Traits =
      CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, Items,
                                                     CGAL::Nth_of_tuple_property_map<0, Item>,
                                                     CGAL::Nth_of_tuple_property_map<1, Item>>;
  using Ransac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;
  Items items;
  items.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.positions()[i];
    const Vec3& n = cloud.normals()[i];
    items.emplace_back(Kernel::Point_3(p.x(), p.y(), p.z()), Kernel::Vector_3(n.x(), n.y(), n.z()),
                       i);
  }
  Method m;
  m.name = tuned ? "RANSAC tuned" : "RANSAC defaults";
  const auto start = std::chrono::steady_clock::now();
  Ransac ransac;
  ransac.set_input(items);
  ransac.add_shape_factory<CGAL::Shape_detection::Plane<Traits>>();
  ransac.add_shape_factory<CGAL::Shape_detection::Cylinder<Traits>>();
  Ransac::Parameters parameters;
  if (tuned) {
    parameters.epsilon = 3 * spacing;
    parameters.cluster_epsilon = 3 * spacing;
    parameters.min_points = std::max<std::size_t>(50, cloud.size() / 1000);
  }
  ransac.detect(parameters);
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::size_t planes = 0;
  for (const auto& shape : ransac.shapes()) {
    const auto* cylinder =
        dynamic_cast<const CGAL::Shape_detection::Cylinder<Traits>*>(shape.get());
    if (!cylinder) {
      ++planes;
      continue;
    }
    Detected d;
    for (const std::size_t i : shape->indices_of_assigned_points())
      d.points.push_back(Index(std::get<2>(items[i])));
    std::sort(d.points.begin(), d.points.end());
    const auto dir = cylinder->axis().to_vector();
    d.straight = true;
    d.direction = Vec3(dir.x(), dir.y(), dir.z()).normalized();
    d.radius = cylinder->radius();
    d.where = "ransac";
    m.sets.push_back(std::move(d));
  }
  std::printf("  %s: %zu planes, %zu cylinders\n", m.name.c_str(), planes, m.sets.size());
  return m;
}

struct Score {
  int found = 0, strandsFound = 0;
  bool cableWhole = false;
  double worstRadiusError = 0, worstAngle = 0;
  int falseCylinders = 0, falsePersistence = -1;  // the most persistent false one's (ours)
};

Score score(const Method& m, const PointCloud& cloud, const std::vector<PipeTruth>& truth,
            bool print) {
  const auto& pipe = cloud.findAttribute("gt_pipe")->values;
  const auto& part = cloud.findAttribute("gt_part")->values;
  const bool cable = std::any_of(truth.begin(), truth.end(),
                                 [](const PipeTruth& t) { return t.kind == PipeKind::Cable; });
  std::vector<std::vector<Index>> gt(truth.size()), strands(cable ? 3 : 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int p = int(pipe[i]);
    if (p >= 0) gt[std::size_t(p)].push_back(Index(i));
    if (cable && p == 5) strands[std::size_t(part[i])].push_back(Index(i));
  }
  Score s;
  auto best = [&](const std::vector<Index>& target, std::size_t& which) {
    double b = 0;
    which = m.sets.size();
    for (std::size_t k = 0; k < m.sets.size(); ++k) {
      const double j = iou(target, m.sets[k].points);
      if (j > b) b = j, which = k;
    }
    return b;
  };
  for (const PipeTruth& t : truth) {
    std::size_t k = 0;
    const double j = best(gt[std::size_t(t.id)], k);
    const bool found = j >= 0.8;
    s.found += found;
    if (t.kind == PipeKind::Cable) s.cableWhole = found;
    std::string errors;
    if (t.kind == PipeKind::Straight && k < m.sets.size() && j >= 0.5) {
      const double radiusError = 100 * std::abs(m.sets[k].radius - t.radius) / t.radius;
      const double angle =
          std::acos(std::min(1.0, std::abs(m.sets[k].direction.dot(t.axisDirection)))) * 180 / M_PI;
      s.worstRadiusError = std::max(s.worstRadiusError, radiusError);
      s.worstAngle = std::max(s.worstAngle, angle);
      char text[96];
      std::snprintf(text, sizeof text, "  radius error %.2f%%, axis %.2f deg", radiusError, angle);
      errors = text;
    }
    if (print)
      std::printf("    %-9s IoU %.3f %s%s%s\n", t.name.c_str(), j, found ? "found" : "MISSED",
                  k < m.sets.size() ? (" (" + m.sets[k].where + ")").c_str() : "", errors.c_str());
    if (print && !found && k < m.sets.size()) {  // the best set: too small, or spilling over
      const std::vector<Index>& target = gt[std::size_t(t.id)];
      std::size_t common = 0, elsewhere = 0;
      for (const Index i : m.sets[k].points) {
        const bool mine = int(pipe[i]) == t.id;
        common += mine;
        elsewhere += !mine;
      }
      std::printf("      %zu of its %zu points in a set of %zu (%s): %zu elsewhere\n", common,
                  target.size(), m.sets[k].points.size(), m.sets[k].where.c_str(), elsewhere);
    }
  }
  for (int k = 0; k < int(strands.size()); ++k) {
    // What a scan sees of a strand: one piece all round, or, seen from one side, the runs along
    // the cable where the strand is not under the others (cut at gaps of 5 cm along x; runs under
    // 2% of the strand's points are dropped). Found when each run is (IoU >= 0.8).
    std::vector<Index> byX = strands[std::size_t(k)];
    std::sort(byX.begin(), byX.end(), [&](Index a, Index b) {
      return cloud.positions()[a].x() < cloud.positions()[b].x();
    });
    std::vector<std::vector<Index>> runs(1);
    for (std::size_t r = 0; r < byX.size(); ++r) {
      if (r > 0 && cloud.positions()[byX[r]].x() - cloud.positions()[byX[r - 1]].x() > 0.05)
        runs.emplace_back();
      runs.back().push_back(byX[r]);
    }
    std::size_t runsFound = 0, runsCounted = 0;
    double j = 1;
    std::size_t which = m.sets.size();
    for (std::vector<Index>& run : runs) {
      if (50 * run.size() < byX.size()) continue;
      std::sort(run.begin(), run.end());
      std::size_t w = 0;
      const double jr = best(run, w);
      ++runsCounted;
      runsFound += jr >= 0.8;
      if (jr < j) j = jr, which = w;
    }
    const bool found = runsCounted > 0 && runsFound == runsCounted;
    s.strandsFound += found;
    if (print)
      std::printf("    strand %d  %zu of %zu runs found, worst IoU %.3f %s%s\n", k, runsFound,
                  runsCounted, j, found ? "found" : "MISSED",
                  which < m.sets.size() ? (" (" + m.sets[which].where + ")").c_str() : "");
    if (print && !found) {
      // Where a missed strand is: the sets holding at least 10% of it (its points in the set /
      // the set's size), and which pipe or strand the rest of each set is on.
      const std::vector<Index>& target = strands[std::size_t(k)];
      for (const Detected& d : m.sets) {
        std::vector<Index> common;
        std::set_intersection(target.begin(), target.end(), d.points.begin(), d.points.end(),
                              std::back_inserter(common));
        if (10 * common.size() < target.size()) continue;
        std::size_t otherStrands = 0, otherPipes = 0;
        for (const Index i : d.points) {
          if (pipe[i] == 5 && int(part[i]) != k) ++otherStrands;
          if (pipe[i] != 5) ++otherPipes;
        }
        std::printf(
            "      %zu of its %zu points in a set of %zu (%s): %zu on other strands, %zu "
            "elsewhere\n",
            common.size(), target.size(), d.points.size(), d.where.c_str(), otherStrands,
            otherPipes);
      }
    }
  }
  for (const Detected& d : m.sets) {
    std::size_t onPlanes = 0;
    for (const Index i : d.points) onPlanes += pipe[i] < 0;
    if (2 * onPlanes <= d.points.size()) continue;
    ++s.falseCylinders;
    s.falsePersistence = std::max(s.falsePersistence, d.persistence);
    if (print) {
      Vec3 centre = Vec3::Zero();
      for (const Index i : d.points) centre += cloud.absolutePosition(i);
      centre /= double(d.points.size());
      std::printf("    false cylinder (%s): %zu points around (%.2f, %.2f, %.2f), radius %.3g",
                  d.where.c_str(), d.points.size(), centre.x(), centre.y(), centre.z(), d.radius);
      if (d.persistence >= 0) std::printf(", persistence %d", d.persistence);
      std::printf("\n");
    }
  }
  return s;
}

// What a user without normals gets: the CLI's estimation and orientation (cli/ensureNormals), a
// one-sided scan facing its scanner. Prints how many normals face away from the exact ones.
void estimateSceneNormals(PointCloud& cloud, const std::vector<PipeTruth>& truth,
                          const Vec3* scanner, std::size_t k, bool pca) {
  const std::vector<Vec3> exact = cloud.normals();
  OrientedNormalsOptions options = pca ? OrientedNormalsOptions{} : cylinderNormalOptions();
  if (k > 0) options.estimation.k = options.estimation.maxK = k;
  if (scanner) options.orientation.faceViewpoint = true, options.orientation.viewpoint = *scanner;
  const auto index = makeSpatialIndex(cloud.positions());
  OrientedNormals estimated = estimateOrientedNormals(cloud.positions(), *index, options);
  std::size_t against = 0, off = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    const double c = exact[i].dot(estimated.normals[i]);
    against += c < 0;
    off += std::abs(c) < std::cos(30 * kPi / 180);
  }
  std::printf(
      "  estimated normals (%s, k = %zu): %.2f%% against the exact ones, %.2f%% more than 30 deg "
      "off\n",
      pca ? "PCA" : "sheet planes signed by PCA", estimated.estimation.k,
      100.0 * double(against) / double(exact.size()), 100.0 * double(off) / double(exact.size()));
  // Per object: the pipes by name, the planes (floor, wall, box) as one.
  const auto& pipe = cloud.findAttribute("gt_pipe")->values;
  std::map<int, std::pair<std::size_t, std::size_t>> per;  // pipe (-1: planes) -> (against, all)
  for (std::size_t i = 0; i < exact.size(); ++i) {
    auto& [a, all] = per[int(pipe[i])];
    a += exact[i].dot(estimated.normals[i]) < 0;
    ++all;
  }
  std::printf("   against, per object:");
  for (const auto& [p, counts] : per)
    std::printf(" %s %.1f%%", p < 0 ? "planes" : truth[std::size_t(p)].name.c_str(),
                100.0 * double(counts.first) / double(counts.second));
  std::printf("\n");
  cloud.setNormals(std::move(estimated.normals));
}

}  // namespace

static int run(int argc, char** argv) {
  std::size_t points = 1000000;
  bool peers = true, cleanOnly = false, noisyOnly = false, estimate = false, pcaNormals = false;
  std::size_t normalK = 0;  // NormalEstimationOptions' defaults
  int minPersistence = 0;   // ours: score every region
  std::string only;         // "full" or "one-sided": that scan alone
  CylinderOptions ours;
  std::uint64_t seed = 1;
  std::string scene = "rack";
  double onlyNoise = -1;  // every default level
  bool pointsGiven = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--points" && i + 1 < argc)
      points = scalespace::bench::countArgument(argv, ++i), pointsGiven = true;
    else if (a == "--scene" && i + 1 < argc &&
             (argv[i + 1] == std::string("rack") || argv[i + 1] == std::string("poles")))
      scene = argv[++i];
    else if (a == "--noise" && i + 1 < argc)
      onlyNoise = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--seed" && i + 1 < argc)
      seed = scalespace::bench::countArgument(argv, ++i);
    else if (a == "--no-peers")
      peers = false;
    else if (a == "--clean-only")
      cleanOnly = true;
    else if (a == "--noisy-only")
      noisyOnly = true;
    else if (a == "--no-split")
      ours.split.enabled = false;
    else if (a == "--no-junction-trim")
      ours.trim.enabled = false;
    else if (a == "--split-cell" && i + 1 < argc)
      ours.split.cellFactor = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--split-density" && i + 1 < argc)
      ours.split.minDensity = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--split-link" && i + 1 < argc)
      ours.split.linkRadius = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--split-steps" && i + 1 < argc)
      ours.split.densitySteps = scalespace::bench::integerArgument(argv, ++i);
    else if (a == "--scan" && i + 1 < argc)
      only = argv[++i];
    else if (a == "--scales" && i + 1 < argc)
      ours.scaleCount = scalespace::bench::integerArgument(argv, ++i);
    else if (a == "--tmin" && i + 1 < argc)
      ours.tMin = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--curved-seeds-first")
      ours.lines.curvedSeedsFirst = true;
    else if (a == "--one-curvature-sign")
      ours.oneCurvatureSign = true;
    else if (a == "--estimate-normals")
      estimate = true;
    else if (a == "--pca-normals")
      pcaNormals = true;
    else if (a == "--max-line-variation" && i + 1 < argc)
      ours.filter.maxMeanVariation = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--max-line-curvature" && i + 1 < argc)
      ours.filter.maxCurvatureFactor = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--min-line-length" && i + 1 < argc)
      ours.filter.minLengthFactor = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--min-arc" && i + 1 < argc)
      ours.tube.minArcDegrees = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--max-face-sectors" && i + 1 < argc)
      ours.tube.maxFaceSectors = scalespace::bench::integerArgument(argv, ++i);
    else if (a == "--max-section-shape" && i + 1 < argc)
      ours.tube.maxSectionShapeShare = scalespace::bench::numberArgument(argv, ++i);
    else if (a == "--min-persistence" && i + 1 < argc)
      minPersistence = scalespace::bench::integerArgument(argv, ++i);
    else if (a == "--max-gap" && i + 1 < argc)
      ours.maxGapLevels = scalespace::bench::integerArgument(argv, ++i);
    else if (a == "--normal-k" && i + 1 < argc)
      normalK = scalespace::bench::countArgument(argv, ++i);
    else {
      std::fprintf(
          stderr,
          "usage: bench_cylinders [--scene rack|poles] [--points N] [--noise F] [--no-peers] "
          "[--clean-only] [--noisy-only] "
          "[--scan full|one-sided] [--scales M] [--tmin T] [--seed S] "
          "[--curved-seeds-first] [--one-curvature-sign] [--estimate-normals] "
          "[--min-line-length F] [--max-line-curvature F] [--max-line-variation F] "
          "[--pca-normals] [--normal-k K] [--min-arc DEGREES] [--max-section-shape S] "
          "[--max-face-sectors N] "
          "[--max-gap LEVELS] [--min-persistence P] "
          "[--no-split] [--split-cell F] [--split-density F] [--split-steps N] [--split-link F] "
          "[--no-junction-trim]\n");
      return 2;
    }
  }
  const PipeLayout layout = scene == "poles" ? PipeLayout::Poles : PipeLayout::Rack;
  if (layout == PipeLayout::Poles && !pointsGiven) points = 216000;
  const std::vector<PipeTruth> truth = pipeSceneTruth(layout);
  std::printf("bench_cylinders: %s, %zu points, seed %llu\n",
              layout == PipeLayout::Poles ? "poles" : "pipe rack", points,
              (unsigned long long)seed);
  std::vector<double> noises{0.0, 1e-3};
  if (onlyNoise >= 0) noises = {onlyNoise};
  std::map<std::string, std::vector<Score>> totals;
  for (const bool oneSided : {false, true})
    for (const double noise : noises) {
      if ((cleanOnly && noise > 0) || (noisyOnly && noise == 0) ||
          (!only.empty() && only != (oneSided ? "one-sided" : "full")))
        continue;
      PipeSceneOptions options;
      options.layout = layout;
      options.pointCount = points;
      options.noise = noise;
      options.oneSided = oneSided;
      options.seed = seed;
      PointCloud cloud = generatePipeScene(options);
      std::printf("\n%s scan, noise %g of the diagonal (%zu points)\n",
                  oneSided ? "one-sided" : "full", noise, cloud.size());
      if (estimate) {
        const Vec3 scanner = cloud.viewpoint().value_or(Vec3::Zero()) - cloud.origin();
        estimateSceneNormals(cloud, truth, cloud.viewpoint() ? &scanner : nullptr, normalK,
                             pcaNormals);
      }
      std::vector<Method> methods{runOurs(cloud, ours, minPersistence)};
      if (peers) {
        // Mean spacing of an area-uniform sample: sqrt(area / n), the scene's area ~52 m^2 (the
        // rack), ~77 m^2 (the poles).
        const double area = layout == PipeLayout::Poles ? 77.0 : 52.0;
        const double spacing = std::sqrt(area / double(cloud.size()));
        methods.push_back(runRansac(cloud, false, spacing));
        methods.push_back(runRansac(cloud, true, spacing));
      }
      for (const Method& m : methods) {
        std::printf("  %s (%.2f s)\n", m.name.c_str(), m.seconds);
        const Score s = score(m, cloud, truth, true);
        std::printf("    => pipes found %d/%zu, ", s.found, truth.size());
        if (layout == PipeLayout::Rack)
          std::printf("strands %d/3, cable whole %s, ", s.strandsFound,
                      s.cableWhole ? "yes" : "no");
        std::printf(
            "worst straight radius error %.2f%%, axis %.2f deg, false cylinders on planes %d",
            s.worstRadiusError, s.worstAngle, s.falseCylinders);
        if (s.falsePersistence >= 0) std::printf(" (most persistent %d)", s.falsePersistence);
        std::printf("\n");
        totals[m.name].push_back(s);
      }
    }
  if (layout == PipeLayout::Rack)
    std::printf("\nsummary (per scene: pipes found /6, strands /3, false cylinders)\n");
  else
    std::printf("\nsummary (per scene: poles found /4, false cylinders)\n");
  for (const auto& [name, scores] : totals) {
    std::printf("  %-16s", name.c_str());
    for (const Score& s : scores) {
      std::printf("  %d/%zu", s.found, truth.size());
      if (layout == PipeLayout::Rack) std::printf(" %d/3", s.strandsFound);
      std::printf(" %d", s.falseCylinders);
    }
    std::printf("\n");
  }
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("bench_cylinders", [&] { return run(argc, argv); });
}
