#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include "PlanesTestScenes.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/planes/PlaneDetection.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/planes/PlaneQueries.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

using namespace scalespace;

namespace {
struct BoxRun {
  PointCloud cloud;
  std::vector<int> gt;
  PlaneDetection detection;
};

// Box 4 x 2 x 1 at 12 scales from 0.06 (alpha radius 0.12, above the sample spacing of ~0.07)
// to 2 (beyond every face).
BoxRun runBox(std::size_t points = 6000) {
  BoxRun run;
  SceneOptions opt;
  opt.pointCount = points;
  opt.boxSize = Vec3(4, 2, 1);
  run.cloud = generateScene(SceneKind::Box, opt);
  for (double v : run.cloud.findAttribute("gt_face")->values) run.gt.push_back(int(v));
  const auto scales = test::boxFeatures(run.cloud, opt.boxSize, test::logScales(0.06, 2.0, 12));
  const KnnGraph knn = buildKnnGraph(run.cloud.positions(), 10);
  run.detection = detectPlanes(run.cloud.positions(), knn, scales);
  return run;
}

// The component holding most of face `face`'s points at `level`, and the fraction it holds.
std::pair<int, double> dominantComponent(const BoxRun& run, int face, int level) {
  const std::vector<int> labels = run.detection.graph.componentLabels(level);
  std::map<int, int> count;
  int total = 0;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (run.gt[i] == face) {
      ++total;
      if (labels[i] >= 0) ++count[labels[i]];
    }
  std::pair<int, double> best{-1, 0.0};
  for (const auto& [c, k] : count)
    if (k > best.second * total) best = {c, double(k) / total};
  return best;
}
}  // namespace

TEST(RegionGrowing, SeedNormalCriterionAndDeterminism) {
  // A line of 6 points whose normals turn by 3 degrees each: with theta = 5 degrees against the
  // SEED's normal (not the neighbour's), a region can span at most 3 consecutive points.
  std::vector<Vec3> pts;
  ScaleFeatures f;
  f.t = 1;
  for (int i = 0; i < 6; ++i) {
    pts.emplace_back(i, 0, 0);
    const double a = i * 3.0 * M_PI / 180.0;
    f.normals.emplace_back(std::sin(a), 0, std::cos(a));
    f.kMax.push_back(i == 0 ? 0.f : 1.f);  // point 0 is the most planar: the first seed
    f.kMin.push_back(0.f);
    f.valid.push_back(1);
  }
  f.valid[4] = 0;
  const KnnGraph knn = buildKnnGraph(pts, 2);
  const Segmentation seg = growRegions(knn, f);
  EXPECT_EQ(seg.labels[0], 0);
  EXPECT_EQ(seg.labels[1], 0);
  EXPECT_NE(seg.labels[2], 0);   // 6 degrees from the seed even though 3 from its neighbour
  EXPECT_EQ(seg.labels[4], -1);  // invalid points join nothing
  EXPECT_EQ(seg.regions[0], (std::vector<Index>{0, 1}));
  std::size_t assigned = 0;
  for (const auto& r : seg.regions) assigned += r.size();
  EXPECT_EQ(assigned, 5u);
}

// Two terraces with the same normal, the upper 0.02 above the lower, side by side: the k-NN
// edges span the step, so the angle alone makes one region; a step limit of 0.1 t = 0.01 (with
// t = 0.1) splits them, and the lower terrace stays whole.
TEST(RegionGrowing, StepLimitSeparatesParallelFacesOffsetByLessThanTheGraphSpan) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> pts;
  ScaleFeatures f;
  f.t = 0.1;
  for (int i = 0; i < 2000; ++i) {
    const double x = 2 * u(rng), y = u(rng);
    pts.emplace_back(x, y, x < 1 ? 0.0 : 0.02);
    f.normals.push_back(Vec3::UnitZ());
    f.kMax.push_back(0.f);
    f.kMin.push_back(0.f);
    f.valid.push_back(1);
  }
  f.projections = pts;
  const KnnGraph knn = buildKnnGraph(pts, 10);
  EXPECT_EQ(growRegions(knn, f).regions.size(), 1u);
  RegionGrowingOptions options;
  options.maxStep = 0.1;
  const Segmentation seg = growRegions(knn, f, options);
  ASSERT_EQ(seg.regions.size(), 2u);
  for (const auto& region : seg.regions)
    for (const Index i : region) EXPECT_EQ(pts[i].x() < 1, pts[region[0]].x() < 1);
  f.projections.clear();
  EXPECT_THROW(growRegions(knn, f, options), OptionError);  // the limit needs the projections
}

// A gently curved sheet (a cylinder of radius 28.7: normals within +-2 degrees): every normal is
// within theta = 5 degrees of any seed's, and a k-NN edge of length d rises by up to d sin(4
// degrees) along the seed's normal. A step limit far below that rise (0.001 t) must not cut the
// sheet: the rise of a face tilted within theta is no step.
TEST(RegionGrowing, StepLimitAllowsTheRiseOfAFaceTiltedWithinTheta) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const double radius = 1 / std::sin(2 * M_PI / 180);
  std::vector<Vec3> pts;
  ScaleFeatures f;
  f.t = 0.1;
  for (int i = 0; i < 3000; ++i) {
    const double x = u(rng), y = u(rng) / 2;
    const double z = radius - std::sqrt(radius * radius - x * x);
    pts.emplace_back(x, y, z);
    f.normals.push_back(Vec3(-x, 0, radius - z).normalized());
    f.kMax.push_back(float(1 / radius));
    f.kMin.push_back(0.f);
    f.valid.push_back(1);
  }
  f.projections = pts;
  const KnnGraph knn = buildKnnGraph(pts, 10);
  RegionGrowingOptions options;
  options.maxStep = 0.001;
  EXPECT_EQ(growRegions(knn, f, options).regions.size(), 1u);
}

// A flat patch and a cap of a sphere of radius 1 (sagitta ~0.1 over a width of 0.9): at t = 0.1
// the patch is planar (RMS 0 <= 5% of t), the cap is not (RMS ~0.03); a noise floor above the
// cap's RMS makes it planar too. A chain from the patch into patch + cap splits there: the cap's
// component is flagged, and the persistence labels prefer the planar one.
TEST(RegionPlanarity, NonPlanarRegionsSplitTheirChainAndAreFlagged) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-0.45, 0.45);
  std::vector<Vec3> pts;
  std::vector<std::vector<Index>> regions(2);
  for (int i = 0; i < 3000; ++i) {
    const double x = u(rng), y = u(rng);
    const bool cap = i % 2;
    pts.emplace_back(cap ? x + 3 : x, y, cap ? std::sqrt(1 - x * x - y * y) : 0.0);
    regions[std::size_t(cap)].push_back(Index(i));
  }
  RegionLevel level;
  level.t = 0.1;
  level.regions = regions;
  EXPECT_EQ(regionPlanarity(pts, {level}, 0.0), (std::vector<std::vector<std::uint8_t>>{{1, 0}}));
  EXPECT_EQ(regionPlanarity(pts, {level}, 0.05), (std::vector<std::vector<std::uint8_t>>{{1, 1}}));
  PlanarityOptions thesis;
  thesis.maxRelativeRms = 0;
  EXPECT_EQ(regionPlanarity(pts, {level}, 0.0, thesis),
            (std::vector<std::vector<std::uint8_t>>{{1, 1}}));
  PlanarityOptions bad;
  bad.noiseFactor = -1;
  EXPECT_THROW(regionPlanarity(pts, {level}, 0.0, bad), OptionError);

  // Level 0: the patch; level 1: the patch and 900 cap points (J = 1500/2400 > 0.5).
  std::vector<RegionLevel> levels(2);
  levels[0].t = 0.1;
  levels[0].regions = {regions[0]};
  levels[1].t = 0.2;
  std::vector<Index> merged = regions[0];
  merged.insert(merged.end(), regions[1].begin(), regions[1].begin() + 900);
  std::sort(merged.begin(), merged.end());
  levels[1].regions = {merged};
  PlaneDetectionOptions options;
  options.outlines = false;
  const PlaneDetection split = buildPlaneDetection(pts, levels, 0.0, options, {});
  ASSERT_EQ(split.components.size(), 2u);
  EXPECT_EQ(split.nonPlanarRegions, 1u);
  EXPECT_TRUE(split.components[0].planar);
  EXPECT_EQ(split.components[0].deathLevel, 0);
  EXPECT_FALSE(split.components[1].planar);
  const PlaneModel model = makePlaneModel(split);
  EXPECT_TRUE(model.planaritySplit);
  const std::vector<int> labels = labelsByPersistence(model, 0);
  EXPECT_EQ(labels[0], 0);  // a patch point: the planar component, not the flagged chain
  EXPECT_EQ(labels[1], 1);  // a cap point: only the flagged one holds it
  options.planarity.maxRelativeRms = 0;  // the thesis: one chain, flagged by its plane's RMS
  const PlaneDetection chained = buildPlaneDetection(pts, levels, 0.0, options, {});
  ASSERT_EQ(chained.components.size(), 1u);
  EXPECT_FALSE(chained.components[0].planar);
  EXPECT_FALSE(makePlaneModel(chained).planaritySplit);  // Sec. 2.4.1's labels, no preference
  EXPECT_THROW(buildPlaneDetection(pts, levels, -1.0, options, {}), OptionError);
  EXPECT_EQ(chained.components[0].persistence, 1);
}

// A noisy flat patch at a scale below 20 sigma is planar by the noise bound only: noise_limited.
// The same patch at a coarse scale is planar within 5% of t, and a cap is neither.
TEST(PlaneComponents, APlanePlanarOnlyByTheNoiseBoundIsMarkedNoiseLimited) {
  const double sigma = 0.01;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Vec3> pts;
  std::vector<Index> fine, coarse, cap;
  for (int i = 0; i < 3000; ++i) {
    const double x = u(rng), y = u(rng);
    switch (i % 3) {
      case 0:
        fine.push_back(Index(pts.size())), pts.emplace_back(x, y, noise(rng));
        break;
      case 1:
        coarse.push_back(Index(pts.size())), pts.emplace_back(x + 3, y, noise(rng));
        break;
      default:
        cap.push_back(Index(pts.size()));
        pts.emplace_back(x - 0.5 + 6, y - 0.5,
                         std::sqrt(1.0 - (x - 0.5) * (x - 0.5) - (y - 0.5) * (y - 0.5)));
    }
  }
  // Disjoint regions: three one-level components. 5% of t: 0.005 < sigma at t = 0.1 (fine, cap);
  // 0.02 > sigma at t = 0.4 (coarse).
  std::vector<RegionLevel> levels(2);
  levels[0].t = 0.1;
  levels[0].regions = {fine, cap};
  levels[1].t = 0.4;
  levels[1].regions = {coarse};
  PlaneDetectionOptions options;
  options.outlines = false;
  const PlaneDetection d = buildPlaneDetection(pts, levels, sigma, options, {});
  ASSERT_EQ(d.components.size(), 3u);
  // Components by their first point: the fine patch's is 0, the coarse one's 1, the cap's 2.
  std::map<Index, const PlaneComponent*> byFirst;
  for (const PlaneComponent& c : d.components)
    byFirst[componentPointsAt(d.graph, c.id, c.representativeLevel).front()] = &c;
  const PlaneComponent &fineC = *byFirst.at(0), &coarseC = *byFirst.at(1), &capC = *byFirst.at(2);
  EXPECT_NEAR(fineC.plane.rms, sigma, 0.1 * sigma);
  EXPECT_TRUE(fineC.planar);
  EXPECT_TRUE(fineC.noiseLimited);
  EXPECT_TRUE(coarseC.planar);
  EXPECT_FALSE(coarseC.noiseLimited);
  EXPECT_FALSE(capC.planar);
  EXPECT_FALSE(capC.noiseLimited);
  // The mark is written and read back (components.json), and is a column of components.csv.
  const auto dir = std::filesystem::temp_directory_path() / "scalespace_noise_limited";
  std::filesystem::remove_all(dir);
  writePlaneModel(makePlaneModel(d), Vec3::Zero(), "in.ply", dir.string());
  const PlaneModel back = readPlaneModel(dir.string());
  for (const PlaneComponent& c : d.components)
    EXPECT_EQ(back.components.at(std::size_t(c.id)).noiseLimited, c.noiseLimited);
  std::ifstream csv(dir / "components.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",planar,noise_limited"), std::string::npos);
  std::filesystem::remove_all(dir);
  // Without the noise bound the fine patch is not planar, hence not noise-limited either.
  const PlaneDetection strict = buildPlaneDetection(pts, levels, 0.0, options, {});
  for (const PlaneComponent& c : strict.components) {
    EXPECT_FALSE(c.noiseLimited);
    EXPECT_EQ(c.planar, c.representativeScale == 0.4);
  }
}

// The graph's distance to the k-th neighbour is knnRadii's (brute force), so the stack can take
// its automatic t_min from it; a graph of k points or fewer has none.
TEST(KnnGraph, KthDistanceIsTheKnnRadius) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> pts;
  for (int i = 0; i < 500; ++i) pts.emplace_back(u(rng), u(rng), 0.1 * u(rng));
  pts.push_back(pts[7]);  // a duplicate
  const KnnGraph graph = buildKnnGraph(pts, 10);
  const BruteForceIndex brute(pts);
  const std::vector<double> radii = knnRadii(pts, brute, 10);
  ASSERT_EQ(graph.kthDistance.size(), pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(graph.kthDistance[i], radii[i]) << i;
  EXPECT_EQ(lowerMedian(graph.kthDistance), medianKnnRadius(pts, brute, 10));
  const std::vector<Vec3> few(pts.begin(), pts.begin() + 10);
  EXPECT_TRUE(buildKnnGraph(few, 10).kthDistance.empty());
}

TEST(RegionGrowing, MortonOrderedWalkGivesTheSameRegions) {
  // buildKnnGraph adds a Morton-ordered copy of the graph that growRegions walks; without it the
  // walk runs in input order. Same regions, same labels, in the same order.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> pts;
  ScaleFeatures f;
  f.t = 0.1;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p(u(rng), u(rng), 0.3 * std::round(2 * u(rng)));  // three terraces, shuffled
    pts.push_back(p);
    f.normals.push_back(Vec3(0.05 * u(rng), 0.05 * u(rng), 1).normalized());
    f.kMax.push_back(float(std::abs(u(rng))));
    f.kMin.push_back(float(i % 7 == 0 ? 0.0 : 0.1 * u(rng)));  // ties in the planarity key
    f.valid.push_back(i % 11 != 0);
  }
  const KnnGraph local = buildKnnGraph(pts, 10);
  ASSERT_EQ(local.order.size(), pts.size());
  KnnGraph plain = local;
  plain.order.clear();
  plain.rank.clear();
  plain.localNeighbors.clear();
  RegionGrowingOptions options;
  options.maxAngleDegrees = 3;
  const Segmentation a = growRegions(local, f, options), b = growRegions(plain, f, options);
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.regions, b.regions);
  EXPECT_GT(a.regions.size(), 3u);
}

TEST(PlaneDetection, CleanBoxEveryFaceIsOneComponentAndPersistenceGrowsWithSize) {
  const BoxRun run = runBox();
  const auto& comps = run.detection.components;
  std::set<int> faceComponents;
  std::map<int, int> persistenceOfFace;
  for (int face = 0; face < 6; ++face) {
    const auto [c, fraction] = dominantComponent(run, face, 0);
    ASSERT_GE(c, 0) << "face " << face;
    // Points closer to an edge than ~0.9 t (bent normals) are outside: 1 - 6 * 0.055 / 2 on the
    // smallest face.
    EXPECT_GT(fraction, 0.8) << "face " << face;
    EXPECT_EQ(comps[std::size_t(c)].birthLevel, 0);
    faceComponents.insert(c);
    persistenceOfFace[face] = comps[std::size_t(c)].persistence;
    // The plane of the component is the face's plane.
    const Vec3 n =
        run.cloud
            .normals()[std::size_t(std::find(run.gt.begin(), run.gt.end(), face) - run.gt.begin())];
    EXPECT_GT(std::abs(comps[std::size_t(c)].plane.normal.dot(n)), 1 - 1e-9);
    EXPECT_LT(comps[std::size_t(c)].plane.rms, 1e-7);  // eigenvalue round-off only
  }
  EXPECT_EQ(faceComponents.size(), 6u);  // one component per face
  // Faces: x normal 2 x 1, y normal 4 x 1, z normal 4 x 2 (labels 0,1: x; 2,3: y; 4,5: z).
  EXPECT_EQ(persistenceOfFace[0], persistenceOfFace[1]);
  EXPECT_EQ(persistenceOfFace[4], persistenceOfFace[5]);
  EXPECT_LT(persistenceOfFace[0], persistenceOfFace[2]);
  EXPECT_LT(persistenceOfFace[2], persistenceOfFace[4]);
  EXPECT_LT(persistenceOfFace[4], 11);  // even the largest face dies before t = 2
  // Representative level: most points, and the area there is close to the face area minus the
  // bent band along the edges.
  const auto [top, f] = dominantComponent(run, 4, 0);
  const PlaneComponent& c = comps[std::size_t(top)];
  EXPECT_LE(c.area, 8.0 + 1e-9);
  EXPECT_GT(c.area, 0.8 * (4 - 0.11) * (2 - 0.11));
  EXPECT_FALSE(c.outlines.empty());
}

TEST(PlaneDetection, PointBelongsToSeveralComponentsAcrossScales) {
  // Fig. 2.3: on stairs, a tread point is in its tread's component at small scales and in the
  // component of the whole ramp at large scales. The ramp (area sqrt2) lives while
  // sqrt(area) >= 2t, i.e. up to t = 0.59: the largest scale is 0.55.
  SceneOptions opt;
  opt.pointCount = 6000;
  opt.stairSteps = 4;
  const PointCloud cloud = generateScene(SceneKind::Stairs, opt);
  const auto scales = test::stairsFeatures(cloud, 4, test::logScales(0.01, 0.55, 16));
  const PlaneDetection det =
      detectPlanes(cloud.positions(), buildKnnGraph(cloud.positions()), scales);
  const auto low = det.graph.componentLabels(0);
  const auto high = det.graph.componentLabels(det.scaleCount() - 1);
  std::size_t several = 0;
  std::set<int> lowComponents;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (low[i] >= 0 && high[i] >= 0 && low[i] != high[i]) {
      ++several;
      lowComponents.insert(low[i]);
    }
  EXPECT_GT(several, cloud.size() / 2);
  EXPECT_EQ(lowComponents.size(), 8u);  // 4 treads + 4 risers at small scales
  std::set<int> highComponents(high.begin(), high.end());
  EXPECT_EQ(highComponents.size(), 1u);  // one ramp at the largest scale
  const PlaneComponent& ramp = det.components[std::size_t(high[0])];
  EXPECT_GT(ramp.persistence, 0);
  EXPECT_NEAR(std::abs(ramp.plane.normal.dot(Vec3(0, -1, 1).normalized())), 1.0, 0.02);
}

TEST(PlaneDetection, SameResultForOneAndTwoThreads) {
  auto run = [](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    return runBox(3000);
  };
  const BoxRun a = run(1), b = run(2);
  ASSERT_EQ(a.detection.components.size(), b.detection.components.size());
  for (int level = 0; level < a.detection.scaleCount(); ++level)
    EXPECT_EQ(a.detection.graph.componentLabels(level), b.detection.graph.componentLabels(level));
  for (std::size_t c = 0; c < a.detection.components.size(); ++c) {
    EXPECT_EQ(a.detection.components[c].area, b.detection.components[c].area);
    EXPECT_EQ(a.detection.components[c].plane.normal, b.detection.components[c].plane.normal);
  }
}

TEST(PlaneDetection, RejectsMismatchedInputs) {
  std::vector<Vec3> pts{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  ScaleFeatures f;
  f.t = 1;
  f.normals.assign(2, Vec3::UnitZ());
  f.kMax.assign(2, 0.f);
  f.kMin.assign(2, 0.f);
  f.valid.assign(2, 1);
  EXPECT_THROW(detectPlanes(pts, buildKnnGraph(pts, 2), {f}), OptionError);
}

// Ten steps 0.3 deep and 0.18 high between two walls (x = 0 and x = 1.6, 3.3 m long, 2.2 m
// tall), with the normals the robust fit gives at t = 0.8: the treads' and risers' own, but the
// walls' on the outer 0.25 m of every step. The treads and risers merge into the mean ramp; the
// boundary refinement gives the ramp back its edges, and no point is unlabelled by it.
TEST(PlaneDetection, TheBoundaryRefinementGivesAStaircaseBetweenWallsItsEdges) {
  constexpr double t = 0.8, spacing = 0.03, width = 1.6, band = 0.25;
  std::vector<Vec3> points;
  ScaleFeatures scale;
  scale.t = t;
  std::vector<bool> onStairs;
  const auto addFace = [&](const Vec3& corner, const Vec3& u, const Vec3& v, const Vec3& normal,
                           bool stairs) {
    const int nu = int(std::round(u.norm() / spacing)), nv = int(std::round(v.norm() / spacing));
    for (int a = 0; a < nu; ++a)
      for (int b = 0; b < nv; ++b) {
        const Vec3 p = corner + (a + 0.5) / nu * u + (b + 0.5) / nv * v;
        points.push_back(p);
        onStairs.push_back(stairs);
        const bool nearWall = stairs && (p.x() < band || p.x() > width - band);
        scale.normals.push_back(nearWall ? Vec3(p.x() < band ? 1 : -1, 0, 0) : normal);
      }
  };
  for (int k = 0; k < 10; ++k) {
    addFace(Vec3(0, 0.3 * k, 0.18 * k), Vec3(width, 0, 0), Vec3(0, 0, 0.18), Vec3(0, -1, 0), true);
    addFace(Vec3(0, 0.3 * k, 0.18 * (k + 1)), Vec3(width, 0, 0), Vec3(0, 0.3, 0), Vec3(0, 0, 1),
            true);
  }
  addFace(Vec3(0, 0, 0), Vec3(0, 3.3, 0), Vec3(0, 0, 2.2), Vec3(1, 0, 0), false);
  addFace(Vec3(width, 0, 0), Vec3(0, 3.3, 0), Vec3(0, 0, 2.2), Vec3(-1, 0, 0), false);
  const std::size_t n = points.size();
  scale.kMax.assign(n, 0);
  scale.kMin.assign(n, 0);
  scale.valid.assign(n, 1);
  scale.projections = points;
  const KnnGraph knn = buildKnnGraph(points, 10);

  const auto run = [&](double refineDistance, std::size_t& labelled) {
    PlaneDetectionOptions options;
    options.refinement.maxRelativeDistance = refineDistance;
    PlaneDetectionTimings timings;
    const RegionLevel level = segmentScale(points, knn, scale, 0, options, timings);
    labelled = 0;
    double best = 0;
    const std::size_t stairs = std::size_t(std::count(onStairs.begin(), onStairs.end(), true));
    for (const std::vector<Index>& region : level.regions) {
      labelled += region.size();
      std::size_t common = 0;
      for (const Index i : region) common += onStairs[i];
      best = std::max(best, double(common) / double(region.size() + stairs - common));
    }
    return best;
  };
  std::size_t labelledAsGrown = 0, labelledRefined = 0;
  const double asGrown = run(0, labelledAsGrown), refined = run(0.3, labelledRefined);
  // The merged ramp without its bands (1.1 of the 1.6 m width): IoU 0.70; refined 0.88.
  EXPECT_LT(asGrown, 0.75);
  EXPECT_GT(refined, 0.85);
  EXPECT_EQ(labelledRefined, labelledAsGrown);
}
