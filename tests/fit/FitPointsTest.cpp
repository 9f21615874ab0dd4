// fitPoints: query points that are not cloud points are projected onto the surface and read its
// exact normals and curvatures there; every walk and scale layout gives fitAt's fit for each query;
// results do not depend on the thread count; bad queries are refused before any fit.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>

#include "FitTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/fit/FitPoints.hpp"

using namespace scalespace;
using namespace scalespace::test;

namespace {

/// n points of the sphere of radius r centred at the origin (Fibonacci lattice), outward normals.
std::unique_ptr<TestCloud> fibonacciSphere(std::size_t n, double r) {
  auto c = std::make_unique<TestCloud>();
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1 - 2 * (double(i) + 0.5) / double(n);
    const double rad = std::sqrt(1 - z * z);
    const Vec3 normal(rad * std::cos(golden * double(i)), rad * std::sin(golden * double(i)), z);
    c->positions.push_back(r * normal);
    c->normals.push_back(normal);
  }
  c->build();
  return c;
}

/// A jittered grid of the plane z = 0 over [-1, 1]^2, normals +z.
std::unique_ptr<TestCloud> jitteredPlane(std::size_t side) {
  auto c = std::make_unique<TestCloud>();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  const double h = 2.0 / double(side);
  for (std::size_t i = 0; i < side; ++i)
    for (std::size_t j = 0; j < side; ++j)
      c->positions.emplace_back(-1 + h * (double(i) + 0.5 + jitter(rng)),
                                -1 + h * (double(j) + 0.5 + jitter(rng)), 0.0);
  c->normals.assign(c->positions.size(), Vec3::UnitZ());
  c->build();
  return c;
}

/// Points at distance `offset` off the unit directions `dirs` scaled by r (off the sphere).
std::vector<Vec3> randomDirections(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> dirs(n);
  for (Vec3& d : dirs) d = Vec3(g(rng), g(rng), g(rng)).normalized();
  return dirs;
}

FitPointsOptions mlsW3() {
  FitPointsOptions o;
  o.fit.mls = true;
  o.fit.mlsMaxSteps = 30;
  o.fit.mlsTolerance = 1e-6;
  return o;
}

}  // namespace

TEST(FitPoints, ProjectsPointsOffASphereOntoItWithExactNormalsAndCurvatures) {
  const double r = 2.0;
  const auto sphere = fibonacciSphere(20000, r);
  const std::vector<Vec3> dirs = randomDirections(300, 11);
  std::vector<Vec3> queries;
  for (std::size_t i = 0; i < dirs.size(); ++i)
    queries.push_back((r + (i % 2 ? 0.05 : -0.05)) * dirs[i]);  // outside and inside
  for (bool robust : {false, true}) {
    FitPointsOptions o = mlsW3();
    o.fit.robust = robust;
    FitPointsSummary summary;
    const std::vector<LocalFit> fits =
        fitPoints(sphere->samples(), FitQueries{queries, {0.3}}, o, {}, &summary);
    ASSERT_EQ(fits.size(), queries.size());
    EXPECT_EQ(summary.invalid, 0u);
    for (std::size_t i = 0; i < fits.size(); ++i) {
      const LocalFit& f = fits[i];
      ASSERT_TRUE(f.valid);
      EXPECT_NEAR(f.projection.norm(), r, 1e-6);
      EXPECT_LT((f.projection.normalized() - dirs[i]).norm(), 1e-6);
      EXPECT_LT((f.normal - dirs[i]).norm(), 1e-6);  // oriented like the samples: outward
      EXPECT_NEAR(f.meanCurvature, 1 / r, 1e-6);
      EXPECT_NEAR(f.kMax, 1 / r, 1e-6);
      EXPECT_NEAR(f.kMin, 1 / r, 1e-6);
      EXPECT_GT(f.mlsSteps, 1);  // started off the surface: at least one step moved it
    }
  }
}

TEST(FitPoints, ProjectsPointsOffAPlaneOntoItWithZeroCurvature) {
  const auto plane = jitteredPlane(120);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<Vec3> queries(200);
  for (Vec3& q : queries) q = Vec3(u(rng), u(rng), 0.15 * u(rng));  // within t of the plane
  for (EstimatorKind kind : {EstimatorKind::W3, EstimatorKind::W2, EstimatorKind::Plane}) {
    FitPointsOptions o = mlsW3();
    o.fit.estimator = kind;
    const std::vector<LocalFit> fits = fitPoints(plane->samples(), FitQueries{queries, {0.2}}, o);
    for (std::size_t i = 0; i < fits.size(); ++i) {
      ASSERT_TRUE(fits[i].valid) << estimatorName(kind);
      EXPECT_NEAR(fits[i].projection.z(), 0.0, 1e-9);
      EXPECT_NEAR(fits[i].projection.x(), queries[i].x(), 1e-9);
      EXPECT_NEAR(fits[i].projection.y(), queries[i].y(), 1e-9);
      EXPECT_LT((fits[i].normal - Vec3::UnitZ()).norm(), 1e-9);
      // The plane estimator's H = 8d/t^2 measures the query's distance d (Table 1.1 "Plane
      // (MLS)"), not the surface: only the APSS fits read the plane's zero curvature.
      if (kind == EstimatorKind::Plane) continue;
      EXPECT_NEAR(fits[i].kMax, 0.0, 1e-7);
      EXPECT_NEAR(fits[i].kMin, 0.0, 1e-7);
    }
  }
}

TEST(FitPoints, EveryWalkAndScaleLayoutGivesEachQueryItsOwnFit) {
  const auto c = sampleCloud(SurfaceShape::Saddle, Vec3::Zero(), 1.0, 4000, 3);
  std::vector<Vec3> queries = c->positions;  // shuffled: the spatial walk must reorder them
  std::shuffle(queries.begin(), queries.end(), std::mt19937_64(5));
  queries.resize(1500);
  std::vector<double> perPoint(queries.size());
  for (std::size_t i = 0; i < perPoint.size(); ++i) perPoint[i] = 0.12 + 0.0001 * double(i % 50);
  for (bool robust : {false, true}) {
    FitPointsOptions o = mlsW3();
    o.fit.mlsTolerance = 1e-3;
    o.fit.robust = robust;
    for (QueryWalk walk : {QueryWalk::Spatial, QueryWalk::AsGiven}) {
      o.walk = walk;
      for (bool oneScale : {true, false}) {
        const std::vector<double> scales = oneScale ? std::vector<double>{0.15} : perPoint;
        std::vector<std::size_t> rankOf(queries.size(), 0);
        std::vector<LocalFit> fits(queries.size());
        std::atomic<std::size_t> visits{0};
        const FitPointsSummary summary =
            fitPoints(c->samples(), FitQueries{queries, scales}, o,
                      [&](std::size_t q, std::size_t rank, const LocalFit& f) {
                        fits[q] = f;
                        rankOf[q] = rank;
                        ++visits;
                      });
        ASSERT_EQ(visits.load(), queries.size());
        ASSERT_EQ(summary.order.size(), walk == QueryWalk::Spatial ? queries.size() : 0u);
        std::size_t invalid = 0;
        for (std::size_t q = 0; q < queries.size(); ++q) {
          const std::size_t expectedRank = walk == QueryWalk::Spatial ? rankOf[q] : q;
          EXPECT_EQ(rankOf[q], expectedRank);
          if (walk == QueryWalk::Spatial) {
            EXPECT_EQ(summary.order[rankOf[q]], q);
          }
          invalid += !fits[q].valid;
          if (q % 5) continue;
          FitWorkspace alone;  // nothing prefetched: the fit queries the index
          const LocalFit f =
              fitAt(queries[q], scales[oneScale ? 0 : q], c->samples(), o.fit, alone);
          if (robust && oneScale) {
            // fitAtBatch's lanes sum in another order: the same fit up to the last bits.
            ASSERT_EQ(fits[q].valid, f.valid);
            EXPECT_LT((fits[q].projection - f.projection).norm(), 1e-9);
            EXPECT_NEAR(fits[q].kMax, f.kMax, 1e-6 * (1 + std::abs(f.kMax)));
          } else {
            expectSameFit(fits[q], f);
          }
        }
        EXPECT_EQ(summary.invalid, invalid);
      }
    }
  }
}

TEST(FitPoints, IdenticalForOneAndTwoThreads) {
  const auto c = sampleCloud(SurfaceShape::Torus, Vec3(1.5, 0, 0), 1.2, 5000, 5);
  FitPointsOptions o = mlsW3();
  o.fit.robust = true;
  o.fit.mlsTolerance = 1e-3;
  std::vector<LocalFit> one, two;
  {
    ThreadLimit limit(1);
    one = fitPoints(c->samples(), FitQueries{c->positions, {0.2}}, o);
  }
  {
    ThreadLimit limit(2);
    two = fitPoints(c->samples(), FitQueries{c->positions, {0.2}}, o);
  }
  for (std::size_t i = 0; i < one.size(); ++i) {
    ASSERT_EQ(one[i].valid, two[i].valid);
    EXPECT_EQ(one[i].projection, two[i].projection);
    EXPECT_EQ(one[i].normal, two[i].normal);
    EXPECT_EQ(one[i].kMax, two[i].kMax);
    EXPECT_EQ(one[i].kMin, two[i].kMin);
  }
}

TEST(FitPoints, ZeroScaleNonFiniteQueryAndEmptyQueriesGiveInvalidFitsOrNothing) {
  const auto c = fibonacciSphere(2000, 1.0);
  const std::vector<Vec3> queries = {c->positions[0], Vec3(NAN, 0, 0), c->positions[1]};
  const std::vector<double> scales = {0.0, 0.2, 0.2};
  FitPointsSummary summary;
  const std::vector<LocalFit> fits =
      fitPoints(c->samples(), FitQueries{queries, scales}, FitPointsOptions{}, {}, &summary);
  EXPECT_FALSE(fits[0].valid);  // no support (duplicates at a per-point scale)
  EXPECT_FALSE(fits[1].valid);
  EXPECT_TRUE(fits[2].valid);
  EXPECT_EQ(summary.invalid, 2u);
  const std::vector<Vec3> none;
  EXPECT_TRUE(fitPoints(c->samples(), FitQueries{none, {0.2}}, FitPointsOptions{}).empty());
}

TEST(FitPoints, RefusesBadQueriesAndOptionsBeforeAnyFitAndCancels) {
  const auto c = fibonacciSphere(2000, 1.0);
  const std::vector<Vec3>& q = c->positions;
  auto message = [&](const std::vector<double>& scales, FitPointsOptions o = {},
                     const std::vector<std::uint8_t>* hints = nullptr) -> std::string {
    std::size_t visits = 0;
    try {
      fitPoints(c->samples(), FitQueries{q, scales, hints}, o,
                [&](std::size_t, std::size_t, const LocalFit&) { ++visits; });
    } catch (const OptionError& e) {
      EXPECT_EQ(visits, 0u);
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({}).find("FitQueries::scales"), std::string::npos);
  EXPECT_NE(message({0.1, 0.2}).find("FitQueries::scales"), std::string::npos);
  EXPECT_NE(message({-0.1}).find("FitQueries::scales"), std::string::npos);
  EXPECT_NE(message({NAN}).find("FitQueries::scales"), std::string::npos);
  const std::vector<std::uint8_t> hints(3, 1);
  EXPECT_NE(message({0.1}, {}, &hints).find("FitQueries::convergedAtFirstStep"), std::string::npos);
  FitPointsOptions o;
  o.fit.mlsMaxSteps = 0;
  EXPECT_NE(message({0.1}, o).find("FitOptions::mlsMaxSteps"), std::string::npos);
  o = {};
  o.fit.minNeighbors = 0;
  EXPECT_NE(message({0.1}, o).find("FitOptions::minNeighbors"), std::string::npos);
  o = {};
  o.fit.robustTolerance = NAN;
  EXPECT_NE(message({0.1}, o).find("FitOptions::robustTolerance"), std::string::npos);
  const std::vector<Vec3> noNormals;
  const SurfaceSamples bare{c->positions, noNormals, *c->index};
  EXPECT_THROW(fitPoints(bare, FitQueries{q, {0.1}}, FitPointsOptions{}), OptionError);

  const ProgressCallback stop = [](double, std::string_view) { return false; };
  EXPECT_THROW(fitPoints(c->samples(), FitQueries{q, {0.1}}, FitPointsOptions{}, stop), Cancelled);
}
