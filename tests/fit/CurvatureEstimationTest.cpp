// CurvatureEstimation: the whole-cloud driver gives, for every point, the fit that fitAt gives
// alone (its prefetched blocks only change the order of the sums), for any thread count.
#include <gtest/gtest.h>

#include <cmath>

#include "FitTestClouds.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/fit/CurvatureEstimation.hpp"

using namespace scalespace;
using namespace scalespace::test;

namespace {

PointCloud cloudOf(const TestCloud& c) {
  PointCloud cloud;
  cloud.setAbsolutePositions(c.positions);
  cloud.setNormals(c.normals);
  return cloud;
}

}  // namespace

TEST(CurvatureEstimation, EveryPointGetsTheFitOfItsOwnQuery) {
  const auto c = sampleCloud(SurfaceShape::Saddle, Vec3::Zero(), 1.0, 3000, 3);
  const PointCloud cloud = cloudOf(*c);
  for (bool mls : {false, true}) {
    CurvatureOptions o;
    o.scale = 0.15;  // ~50 neighbours: blocks of several points share one prefetched ball
    o.fit.mls = mls;
    CurvatureSummary summary;
    const std::vector<LocalFit> fits = fitAllPoints(cloud, o, {}, &summary);
    ASSERT_EQ(fits.size(), c->positions.size());
    for (std::size_t i = 0; i < fits.size(); i += 7) {
      FitWorkspace alone;  // no prefetched samples: every fit queries the index
      expectSameFit(fits[i], fitAt(c->positions[i], o.scale, c->samples(), o.fit, alone));
    }
    EXPECT_GT(summary.meanNeighbors, 30);
    EXPECT_GE(summary.seconds, summary.setupSeconds + summary.fitSeconds);
  }
}

TEST(CurvatureEstimation, IdenticalForOneAndTwoThreads) {
  const auto c = sampleCloud(SurfaceShape::Torus, Vec3(1.5, 0, 0), 1.2, 4000, 5);
  PointCloud one = cloudOf(*c), two = cloudOf(*c);
  CurvatureOptions o;
  o.scale = 0.2;
  {
    ThreadLimit limit(1);
    computeCurvatureColumns(one, o);
  }
  {
    ThreadLimit limit(2);
    computeCurvatureColumns(two, o);
  }
  for (const std::string& name : curvatureColumnNames()) {
    const auto* a = one.findAttribute(name);
    const auto* b = two.findAttribute(name);
    ASSERT_TRUE(a && b) << name;
    ASSERT_EQ(a->values.size(), b->values.size());
    for (std::size_t i = 0; i < a->values.size(); ++i)
      ASSERT_EQ(a->values[i], b->values[i]) << name << " point " << i;  // bitwise
  }
}

TEST(CurvatureEstimation, AScaleReachingTheDiagonalIsWarnedOf) {
  const auto c = sampleCloud(SurfaceShape::Saddle, Vec3::Zero(), 1.0, 500, 3);
  const PointCloud cloud = cloudOf(*c);
  const double diagonal = cloud.boundingBoxDiagonal();
  CurvatureOptions o;
  o.scale = 0.9 * diagonal;
  EXPECT_TRUE(curvatureScaleWarnings(cloud, o).empty());
  CurvatureSummary summary;
  fitAllPoints(cloud, o, {}, &summary);
  EXPECT_TRUE(summary.warnings.empty());
  o.scale = 1e6;
  const std::vector<std::string> warnings = curvatureScaleWarnings(cloud, o);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("whole cloud (500 points per fit)"), std::string::npos) << warnings[0];
  fitAllPoints(cloud, o, {}, &summary);
  ASSERT_FALSE(summary.warnings.empty());
  EXPECT_EQ(summary.warnings[0], warnings[0]);
  o.scale = 0;
  o.scaleK = 16;  // a neighbour count is never the whole cloud's business
  EXPECT_TRUE(curvatureScaleWarnings(cloud, o).empty());
}
