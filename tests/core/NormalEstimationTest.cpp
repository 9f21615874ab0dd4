#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <random>
#include <string>

#include "core/CoreTestClouds.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/Parallel.hpp"

using namespace scalespace;
using scalespace::testclouds::angleDegrees;

namespace {

template <class Truth>
double maxAngle(const std::vector<Vec3>& points, const NormalEstimationResult& r, Truth truth) {
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_TRUE(r.valid[i]) << i;
    EXPECT_NEAR(r.normals[i].norm(), 1.0, 1e-12);
    worst = std::max(worst, angleDegrees(r.normals[i], truth(points[i])));
  }
  return worst;
}

bool allUnitAndFinite(const NormalEstimationResult& r) {
  for (std::size_t i = 0; i < r.normals.size(); ++i)
    if (!r.normals[i].allFinite() || std::abs(r.normals[i].norm() - 1.0) > 1e-12 ||
        !std::isfinite(r.surfaceVariation[i]))
      return false;
  return true;
}

}  // namespace

TEST(NormalEstimation, TiltedPlaneIsExact) {
  const Mat3 rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  std::vector<Vec3> points = testclouds::plane(4000, 1.0, 21);
  for (Vec3& p : points) p = rotation * p + Vec3(5, -3, 2);
  const Vec3 truth = rotation * Vec3::UnitZ();
  const auto r = estimateNormals(points);
  EXPECT_EQ(r.invalidCount, 0u);
  EXPECT_LT(maxAngle(points, r, [&](const Vec3&) { return truth; }), 1e-5);
  for (double v : r.surfaceVariation) EXPECT_LT(v, 1e-12);
  // Radius neighbourhoods give the same normals.
  NormalEstimationOptions byRadius;
  byRadius.radius = 0.05;
  const auto rr = estimateNormals(points, byRadius);
  EXPECT_LT(maxAngle(points, rr, [&](const Vec3&) { return truth; }), 1e-5);
}

TEST(NormalEstimation, SphereAndCylinderWithinTwoDegrees) {
  // Evenly sampled sphere: every normal within 2 degrees.
  const auto even = testclouds::fibonacciSphere(20000);
  const auto re = estimateNormals(even);
  EXPECT_EQ(re.invalidCount, 0u);
  EXPECT_LT(maxAngle(even, re, [](const Vec3& p) { return p; }), 2.0);
  for (double v : re.surfaceVariation) EXPECT_GT(v, 0.0);  // curved everywhere

  // Random (clumpy) sampling: a few one-sided 10-NN neighbourhoods tilt more, the bulk is within
  // 2 degrees.
  auto fractionBelow2 = [](const std::vector<Vec3>& points, const NormalEstimationResult& r,
                           auto truth) {
    std::size_t good = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
      good += angleDegrees(r.normals[i], truth(points[i])) < 2.0 ? 1 : 0;
    return double(good) / double(points.size());
  };
  const auto sphere = testclouds::sphere(20000, 1.0, 22);
  const auto rs = estimateNormals(sphere);
  EXPECT_EQ(rs.invalidCount, 0u);
  EXPECT_GT(fractionBelow2(sphere, rs, [](const Vec3& p) { return p; }), 0.99);
  EXPECT_LT(maxAngle(sphere, rs, [](const Vec3& p) { return p; }), 10.0);

  const auto cyl = testclouds::cylinder(20000, 1.0, 2.0, 23);
  const auto rc = estimateNormals(cyl);
  EXPECT_EQ(rc.invalidCount, 0u);
  const auto radial = [](const Vec3& p) { return Vec3(p.x(), p.y(), 0); };
  EXPECT_GT(fractionBelow2(cyl, rc, radial), 0.99);
  EXPECT_LT(maxAngle(cyl, rc, radial), 10.0);
}

TEST(NormalEstimation, DegenerateNeighbourhoodsAreFlaggedNeverNaN) {
  // Colinear: every neighbourhood is a segment; the normal is orthogonal to it but flagged.
  std::vector<Vec3> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(0.1 * i, 0.2 * i, 0.3 * i);
  const auto rl = estimateNormals(line);
  EXPECT_EQ(rl.invalidCount, line.size());
  EXPECT_TRUE(allUnitAndFinite(rl));
  for (const Vec3& n : rl.normals) EXPECT_NEAR(n.dot(Vec3(1, 2, 3).normalized()), 0.0, 1e-6);

  // All identical points, and a 2-point cloud.
  const auto rd = estimateNormals(std::vector<Vec3>(20, Vec3(1, 1, 1)));
  EXPECT_EQ(rd.invalidCount, 20u);
  EXPECT_TRUE(allUnitAndFinite(rd));
  const auto r2 = estimateNormals({Vec3(0, 0, 0), Vec3(1, 0, 0)});
  EXPECT_EQ(r2.invalidCount, 2u);
  EXPECT_TRUE(allUnitAndFinite(r2));
  EXPECT_EQ(estimateNormals(std::vector<Vec3>{}).normals.size(), 0u);

  // Only 2 distinct points among the 10 nearest (duplicates): flagged.
  std::vector<Vec3> dup(8, Vec3(0, 0, 0));
  dup.insert(dup.end(), 8, Vec3(1, 0, 0));
  const auto rdup = estimateNormals(dup);
  EXPECT_EQ(rdup.invalidCount, dup.size());

  // A non-finite point is flagged; its neighbours are unaffected.
  std::vector<Vec3> plane = testclouds::plane(500, 1.0, 24);
  plane[7] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  const auto rp = estimateNormals(plane);
  EXPECT_EQ(rp.invalidCount, 1u);
  EXPECT_FALSE(rp.valid[7]);
  EXPECT_TRUE(allUnitAndFinite(rp));
}

TEST(NormalEstimation, IdenticalForOneAndTwoThreads) {
  const auto points = testclouds::sphere(8000, 2.0, 25);
  for (const double sheet : {0.0, 0.05}) {
    NormalEstimationOptions options;
    options.sheetTolerance = sheet;
    NormalEstimationResult one, two;
    {
      ThreadLimit limit(1);
      one = estimateNormals(points, options);
    }
    {
      ThreadLimit limit(2);
      two = estimateNormals(points, options);
    }
    ASSERT_EQ(one.normals.size(), two.normals.size());
    for (std::size_t i = 0; i < one.normals.size(); ++i) {
      EXPECT_EQ(one.normals[i], two.normals[i]);
      EXPECT_EQ(one.surfaceVariation[i], two.surfaceVariation[i]);
    }
    EXPECT_EQ(one.valid, two.valid);
    EXPECT_EQ(one.noiseRms, two.noiseRms);
  }
}

TEST(NormalEstimation, OptionsAndCancellation) {
  const auto points = testclouds::plane(3000, 1.0, 26);
  NormalEstimationOptions bad;
  bad.k = 2;
  EXPECT_THROW(estimateNormals(points, bad), OptionError);
  bad.k = kMaxNeighborCount + 1;  // k^2 per query: 10^5 ran for minutes
  EXPECT_THROW(estimateNormals(points, bad), OptionError);
  bad.k = 10;
  bad.radius = -1;
  EXPECT_THROW(estimateNormals(points, bad), OptionError);
  const std::vector<Vec3> other(5, Vec3::Zero());
  const BruteForceIndex wrong(other);
  EXPECT_THROW(estimateNormals(points, wrong), OptionError);

  const ProgressCallback stop = [](double, std::string_view) { return false; };
  EXPECT_THROW(estimateNormals(points, {}, stop), Cancelled);
  double last = -1;
  const ProgressCallback record = [&](double f, std::string_view) {
    last = f;
    return true;
  };
  estimateNormals(points, {}, record);
  EXPECT_EQ(last, 1.0);
}

namespace {
// Two faces meeting at a right-angle edge along y: z = 0 for x < 0, x = 0 for z > 0 (the outside
// of a box's corner), sampled every `spacing`.
std::vector<Vec3> rightAngleEdge(double spacing) {
  std::vector<Vec3> points;
  for (int a = 0; a < 40; ++a)
    for (int b = 0; b < 40; ++b) {
      points.emplace_back(-(a + 0.5) * spacing, b * spacing, 0.0);
      points.emplace_back(0.0, b * spacing, (a + 0.5) * spacing);
    }
  return points;
}
}  // namespace

TEST(NormalEstimation, SheetNormalsKeepEachSideOfACrease) {
  // PCA mixes both faces within a spacing or two of the edge; the sheet plane is the point's
  // own face's.
  const double spacing = 0.01;
  const auto points = rightAngleEdge(spacing);
  NormalEstimationOptions sheet;
  sheet.sheetTolerance = 0.05;
  const auto pca = estimateNormals(points);
  const auto sheets = estimateNormals(points, sheet);
  double worstPca = 0, worstSheet = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    if (p.y() < 3 * spacing || p.y() > 36 * spacing) continue;  // the sample's own border
    // The rows half a spacing from the edge have their nearest neighbours across it: a plane
    // through both rows is as good a sheet as their own face.
    if (std::max(-p.x(), p.z()) < spacing) continue;
    const Vec3 face = p.z() == 0 ? Vec3::UnitZ() : Vec3::UnitX();
    worstPca = std::max(worstPca, angleDegrees(pca.normals[i], face));
    worstSheet = std::max(worstSheet, angleDegrees(sheets.normals[i], face));
  }
  EXPECT_GT(worstPca, 3.0) << "PCA mixes the faces near the edge";
  EXPECT_LT(worstSheet, 1e-6);
  EXPECT_EQ(sheets.valid, pca.valid);
  EXPECT_EQ(sheets.surfaceVariation, pca.surfaceVariation) << "PCA's, documented";
}

TEST(NormalEstimation, SheetNormalsFollowThePcaOnesUnderNoise) {
  // Noise of 3 mm on a plane sampled every 1 cm: the noise band (8 noise RMS) holds most
  // neighbours, so the sheet normals are as good as the PCA ones; noiseRms reads the noise (the
  // RMS to a plane fitted to 10 points is below sigma).
  std::vector<Vec3> points;
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int a = 0; a < 60; ++a)
    for (int b = 0; b < 60; ++b) points.emplace_back(0.01 * a, 0.01 * b, noise(random));
  NormalEstimationOptions sheet;
  sheet.sheetTolerance = 0.05;
  const auto pca = estimateNormals(points);
  const auto sheets = estimateNormals(points, sheet);
  EXPECT_GT(pca.noiseRms, 0.0015);
  EXPECT_LT(pca.noiseRms, 0.003);
  EXPECT_EQ(sheets.noiseRms, pca.noiseRms);
  const auto meanAngle = [&](const NormalEstimationResult& r) {
    double sum = 0;
    for (const Vec3& n : r.normals) sum += angleDegrees(n, Vec3::UnitZ());
    return sum / double(r.normals.size());
  };
  EXPECT_LT(meanAngle(sheets), 1.2 * meanAngle(pca)) << meanAngle(pca);
  // Without the noise band the 0.05-spacing band holds a few points and the normals scatter.
  sheet.sheetNoiseFactor = 0;
  EXPECT_GT(meanAngle(estimateNormals(points, sheet)), 3 * meanAngle(pca));
}

TEST(NormalEstimation, SheetOptionsAreChecked) {
  const auto points = testclouds::plane(500, 1.0, 27);
  NormalEstimationOptions bad;
  bad.sheetTolerance = -0.1;
  try {
    estimateNormals(points, bad);
    FAIL();
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("sheetTolerance"), std::string::npos);
  }
  bad = {};
  bad.sheetNoiseFactor = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(estimateNormals(points, bad), OptionError);
}

TEST(NormalEstimation, SheetNormalsOfLargeNeighbourhoodsChooseAmongTheNearest) {
  // k = 300: the candidate planes come from the 16 nearest neighbours (pairs x neighbours per
  // point); every pair of all 300 would take about 4e10 steps here. Near the edge each point's
  // own face, which holds most of its 300 neighbours, still wins; farther, where a few of the
  // other face's points tilt the PCA plane by less than the band, the PCA normal is kept.
  const double spacing = 0.01;
  const auto points = rightAngleEdge(spacing);
  NormalEstimationOptions options;
  options.k = 300;
  const auto pca = estimateNormals(points, options);
  options.sheetTolerance = 0.05;
  const auto r = estimateNormals(points, options);
  double worst = 0, worstPca = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    if (p.y() < 12 * spacing || p.y() > 27 * spacing || std::max(-p.x(), p.z()) < spacing) continue;
    const Vec3 face = p.z() == 0 ? Vec3::UnitZ() : Vec3::UnitX();
    worst = std::max(worst, angleDegrees(r.normals[i], face));
    worstPca = std::max(worstPca, angleDegrees(pca.normals[i], face));
  }
  EXPECT_LT(worst, 1.0);
  EXPECT_GT(worstPca, 10.0);
}

TEST(NormalEstimation, SheetNormalsOfSmoothSurfacesAreThePcaOnes) {
  // On a sphere the plane with the most neighbours within the band is a tangent plane off the
  // point; the PCA plane holds the neighbourhood within the band, so it is kept.
  const auto points = testclouds::fibonacciSphere(20000);
  NormalEstimationOptions sheet;
  sheet.sheetTolerance = 0.05;
  const auto pca = estimateNormals(points);
  EXPECT_EQ(estimateNormals(points, sheet).normals, pca.normals);
  // A band too thin for the curvature: the planes are chosen, and tilt.
  sheet.sheetTolerance = 1e-4;
  sheet.sheetNoiseFactor = 0;
  double worst = 0;
  const auto thin = estimateNormals(points, sheet);
  for (std::size_t i = 0; i < points.size(); ++i)
    worst = std::max(worst, angleDegrees(thin.normals[i], pca.normals[i]));
  EXPECT_GT(worst, 1.0);
}

// Noise comparable to the sampling: a plane with Gaussian noise 0.8 spacings. Ten neighbours' PCA
// planes follow the noise; k doubles (NormalEstimationOptions::maxK) until the normals of k and 2k
// agree, the same for any thread count. A clean plane and maxK = k keep k.
TEST(NormalEstimation, NoiseComparableToTheSamplingDoublesK) {
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.004);
  std::vector<Vec3> points(40000);
  for (Vec3& p : points) p = Vec3(u(rng), u(rng), noise(rng));  // spacing 0.005
  const auto medianError = [&](const NormalEstimationResult& r) {
    std::vector<double> angles;
    for (const Vec3& n : r.normals)
      angles.push_back(std::min(angleDegrees(n, Vec3::UnitZ()), angleDegrees(-n, Vec3::UnitZ())));
    std::nth_element(angles.begin(), angles.begin() + std::ptrdiff_t(angles.size() / 2),
                     angles.end());
    return angles[angles.size() / 2];
  };
  NormalEstimationOptions fixed;
  fixed.maxK = fixed.k;
  const NormalEstimationResult ten = estimateNormals(points, fixed);
  NormalEstimationResult adapted, adaptedOneThread;
  adapted = estimateNormals(points);
  {
    const ThreadLimit one(1);
    adaptedOneThread = estimateNormals(points);
  }
  EXPECT_EQ(ten.k, 10u);
  EXPECT_GE(adapted.k, 20u);
  EXPECT_LE(adapted.k, NormalEstimationOptions{}.maxK);
  EXPECT_GT(medianError(ten), 20.0);
  EXPECT_LT(medianError(adapted), 15.0);
  EXPECT_EQ(adapted.k, adaptedOneThread.k);
  EXPECT_EQ(adapted.normals, adaptedOneThread.normals);
  EXPECT_EQ(estimateNormals(testclouds::plane(40000, 1.0, 62)).k, 10u);
  NormalEstimationOptions bad;
  bad.maxNoiseAngleDegrees = 0;
  EXPECT_THROW(estimateNormals(points, bad), OptionError);
}
