#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "scales/ScalesTestClouds.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"
#include "scalespace/scales/ScaleSpace.hpp"

namespace scalespace {
namespace {

ScaleSpaceOptions smallOptions(int scales) {
  ScaleSpaceOptions o;
  o.series.count = scales;
  return o;
}

TEST(ScaleSpace, SphereProjectionsStayOnTheSphere) {
  const double r = 1.0;
  const PointCloud cloud = test::sphereCloud(2000, r);
  ScaleSpaceOptions o = smallOptions(6);
  o.series.tMax = 1.0;  // up to the radius: larger supports see the whole sphere (still exact)
  const ScaleStack stack = computeScaleStackInMemory(cloud, o);
  ASSERT_EQ(stack.layers.size(), 6u);
  for (std::size_t j = 0; j < stack.layers.size(); ++j) {
    const ScaleLayer& L = stack.layers[j];
    const double t = stack.summary.series.scales[j];
    std::size_t valid = 0;
    double worst = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (!L.valid[i]) continue;
      ++valid;
      const Vec3 p = Vec3(L.projection[3 * i], L.projection[3 * i + 1], L.projection[3 * i + 2]) +
                     cloud.origin();
      worst = std::max(worst, std::abs(p.norm() - r) / t);
      const Vec3 n(L.normal[3 * i], L.normal[3 * i + 1], L.normal[3 * i + 2]);
      EXPECT_GT(n.dot(p.normalized()), 0.99);
      EXPECT_NEAR(L.meanCurvature[i], 1.0 / r, 0.05);
    }
    EXPECT_EQ(valid, cloud.size()) << "scale " << j;
    EXPECT_LT(worst, 0.01) << "scale " << j;
  }
}

/// RMS height of the projections of the interior points (away from the border effects).
std::vector<double> interiorRmsHeights(const PointCloud& cloud, const ScaleStack& stack) {
  std::vector<double> out;
  for (const ScaleLayer& L : stack.layers) {
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec3 p = cloud.absolutePosition(i);
      if (p.x() < 0.35 || p.x() > 0.65 || p.y() < 0.35 || p.y() > 0.65 || !L.valid[i]) continue;
      const double z = L.projection[3 * i + 2] + cloud.origin().z();
      sum += z * z;
      ++count;
    }
    out.push_back(std::sqrt(sum / double(count)));
  }
  return out;
}

TEST(ScaleSpace, NoisyPlaneGetsFlatterWithScale) {
  const double noise = 0.01;
  const PointCloud cloud = test::noisyPlane(50, 1.0, noise, 3);
  ScaleSpaceOptions o = smallOptions(5);
  o.series.tMax = 0.25;  // supports around the interior stay inside the square
  // Without decimation (alpha = 0) every scale averages more samples: strictly flatter.
  o.alpha = 0;
  const std::vector<double> full = interiorRmsHeights(cloud, computeScaleStackInMemory(cloud, o));
  for (std::size_t j = 1; j < full.size(); ++j) EXPECT_LT(full[j], full[j - 1]) << "scale " << j;
  EXPECT_LT(full.front(), noise);
  EXPECT_LT(full.back(), 0.1 * noise);
  // With the pyramid (alpha = 0.1) a support holds a roughly constant number of samples (14-38 in
  // the thesis, Fig. 1.11), so the smoothing levels off (Sec. 1.5.2, the balance between
  // decimation and smoothing) but stays well below the noise at every scale.
  o.alpha = 0.1;
  const std::vector<double> pyramid =
      interiorRmsHeights(cloud, computeScaleStackInMemory(cloud, o));
  EXPECT_DOUBLE_EQ(pyramid[0], full[0]);  // the finest level keeps every point
  for (std::size_t j = 0; j < pyramid.size(); ++j)
    EXPECT_LT(pyramid[j], 0.5 * noise) << "scale " << j;
}

TEST(ScaleSpace, IdenticalForOneAndTwoThreads) {
  const PointCloud cloud = test::noisyPlane(40, 1.0, 0.02, 8);
  ScaleSpaceOptions o = smallOptions(4);
  o.threads = 1;
  const ScaleStack a = computeScaleStackInMemory(cloud, o);
  o.threads = 2;
  const ScaleStack b = computeScaleStackInMemory(cloud, o);
  ASSERT_EQ(a.layers.size(), b.layers.size());
  for (std::size_t j = 0; j < a.layers.size(); ++j) {
    EXPECT_EQ(a.layers[j].projection, b.layers[j].projection);
    EXPECT_EQ(a.layers[j].kMax, b.layers[j].kMax);
    EXPECT_EQ(a.layers[j].neighbors, b.layers[j].neighbors);
    EXPECT_EQ(a.summary.stats[j].samples, b.summary.stats[j].samples);
  }
}

TEST(ScaleSpace, NormalAndCurvatureLayersHoldTheSameValues) {
  const PointCloud cloud = test::noisyPlane(40, 1.0, 0.02, 9);
  ScaleSpaceOptions o = smallOptions(3);
  const ScaleStack all = computeScaleStackInMemory(cloud, o);
  o.layerContents = LayerContents::NormalAndCurvatures;
  const ScaleStack some = computeScaleStackInMemory(cloud, o);
  ASSERT_EQ(all.layers.size(), some.layers.size());
  for (std::size_t j = 0; j < all.layers.size(); ++j) {
    const ScaleLayer &a = all.layers[j], &b = some.layers[j];
    EXPECT_EQ(a.normal, b.normal);
    EXPECT_EQ(a.meanCurvature, b.meanCurvature);
    EXPECT_EQ(a.kMax, b.kMax);
    EXPECT_EQ(a.kMin, b.kMin);
    EXPECT_EQ(a.valid, b.valid);
    EXPECT_EQ(b.size(), cloud.size());
    EXPECT_TRUE(b.projection.empty() && b.dirMax.empty() && b.tau.empty() && b.neighbors.empty());
    EXPECT_EQ(all.summary.stats[j].validPoints, some.summary.stats[j].validPoints);
  }
  // In processing order too: the same five arrays, permuted, and nothing else.
  o.layerOrder = LayerOrder::Processing;
  const ScaleStack processing = computeScaleStackInMemory(cloud, o);
  for (std::size_t j = 0; j < all.layers.size(); ++j) {
    const ScaleLayer &a = all.layers[j], &p = processing.layers[j];
    ASSERT_EQ(p.inputIndex.size(), cloud.size());
    EXPECT_TRUE(p.projection.empty() && p.dirMin.empty() && p.fitness.empty());
    for (std::size_t k = 0; k < p.size(); ++k) {
      const std::size_t i = p.inputIndex[k];
      EXPECT_EQ(p.kMax[k], a.kMax[i]);
      EXPECT_EQ(p.valid[k], a.valid[i]);
      EXPECT_EQ(p.normal[3 * k + 2], a.normal[3 * i + 2]);
    }
  }
}

TEST(ScaleSpace, ProcessingOrderLayersAreTheInputOrderLayersPermuted) {
  const PointCloud cloud = test::sphereCloud(800, 1.0);
  ScaleSpaceOptions o = smallOptions(3);
  const ScaleStack input = computeScaleStackInMemory(cloud, o);
  o.layerOrder = LayerOrder::Processing;
  const ScaleStack processing = computeScaleStackInMemory(cloud, o);
  ASSERT_EQ(input.layers.size(), processing.layers.size());
  for (std::size_t j = 0; j < input.layers.size(); ++j) {
    const ScaleLayer &a = input.layers[j], &b = processing.layers[j];
    EXPECT_TRUE(a.inputIndex.empty());
    ASSERT_EQ(b.inputIndex.size(), cloud.size());
    ASSERT_TRUE(b.complete());
    // A permutation, and not the identity (a sphere sampled at random is not in Morton order).
    std::vector<int> seen(cloud.size(), 0);
    bool identity = true;
    for (std::size_t k = 0; k < b.size(); ++k) {
      ++seen[b.inputIndex[k]];
      identity = identity && b.inputIndex[k] == k;
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(cloud.size()));
    EXPECT_FALSE(identity);
    for (std::size_t k = 0; k < b.size(); k += 37) {
      const std::size_t i = b.inputIndex[k];
      EXPECT_EQ(b.projection[3 * k + 1], a.projection[3 * i + 1]);
      EXPECT_EQ(b.dirMin[3 * k + 2], a.dirMin[3 * i + 2]);
      EXPECT_EQ(b.kMax[k], a.kMax[i]);
      EXPECT_EQ(b.neighbors[k], a.neighbors[i]);
    }
    const ScaleLayer c = inInputOrder(b);
    EXPECT_TRUE(c.inputIndex.empty());
    for (auto [x, y] : {std::pair{&a.projection, &c.projection},
                        {&a.normal, &c.normal},
                        {&a.dirMax, &c.dirMax},
                        {&a.dirMin, &c.dirMin},
                        {&a.meanCurvature, &c.meanCurvature},
                        {&a.kMax, &c.kMax},
                        {&a.kMin, &c.kMin},
                        {&a.tau, &c.tau},
                        {&a.kappa, &c.kappa},
                        {&a.fitness, &c.fitness},
                        {&a.anisotropy, &c.anisotropy},
                        {&a.geometricVariation, &c.geometricVariation}})
      EXPECT_EQ(*x, *y);
    EXPECT_EQ(a.neighbors, c.neighbors);
    EXPECT_EQ(a.valid, c.valid);
    EXPECT_EQ(input.summary.stats[j].validPoints, processing.summary.stats[j].validPoints);
  }
}

TEST(ScaleSpace, SamplesShrinkAndStatsAreFilled) {
  const PointCloud cloud = test::sphereCloud(3000, 1.0);
  const ScaleStack s = computeScaleStackInMemory(cloud, smallOptions(5));
  ASSERT_EQ(s.summary.stats.size(), 5u);
  EXPECT_EQ(s.summary.stats[0].t, s.summary.series.scales[0]);
  for (std::size_t j = 1; j < 5; ++j)
    EXPECT_LE(s.summary.stats[j].samples, s.summary.stats[j - 1].samples);
  EXPECT_LT(s.summary.stats.back().samples, cloud.size() / 10);
  for (const auto& st : s.summary.stats) EXPECT_GE(st.meanNeighbors, 6.0);
  EXPECT_NE(s.summary.inputChecksum, 0u);
}

// The stack draws its pyramid level by level (each while the previous scale projects) with the
// function buildSamplePyramid runs: over the Morton-ordered cloud, the same levels.
TEST(ScaleSpace, TheStackDrawsTheTestedPyramid) {
  const PointCloud cloud = test::sphereCloud(4000, 1.0);
  ScaleSpaceOptions o = smallOptions(6);
  o.alpha = 0.2;
  const ScaleStack s = computeScaleStackInMemory(cloud, o);
  const std::vector<Vec3> sorted =
      applyPermutation(cloud.positions(), spatialOrder(cloud.positions()));
  const SamplePyramid pyramid =
      buildSamplePyramid(sorted, s.summary.series.scales, o.alpha, o.seed);
  ASSERT_EQ(pyramid.levels.size(), s.summary.stats.size());
  for (std::size_t j = 0; j < pyramid.levels.size(); ++j)
    EXPECT_EQ(pyramid.levels[j].size(), s.summary.stats[j].samples) << j;
  EXPECT_LT(pyramid.levels.back().size(), pyramid.levels.front().size());
}

TEST(ScaleSpace, OptionsAreValidatedBeforeAnyWorkNamingTheField) {
  const PointCloud cloud = test::sphereCloud(500, 1.0);
  auto messageOf = [&](const ScaleSpaceOptions& o) -> std::string {
    try {
      validateScaleSpaceOptions(o);
    } catch (const OptionError& e) {
      EXPECT_THROW(computeScaleStackInMemory(cloud, o), OptionError);
      return e.what();
    }
    return "";
  };
  ScaleSpaceOptions o = smallOptions(3);
  EXPECT_EQ(messageOf(o), "");
  o.alpha = -1;
  EXPECT_NE(messageOf(o).find("ScaleSpaceOptions::alpha"), std::string::npos);
  o = smallOptions(3);
  o.fit.mls = false;
  EXPECT_NE(messageOf(o).find("ScaleSpaceOptions::fit.mls"), std::string::npos);
  o = smallOptions(3);
  o.fit.mlsMaxSteps = 0;
  EXPECT_NE(messageOf(o).find("FitOptions::mlsMaxSteps"), std::string::npos);
  o = smallOptions(0);
  EXPECT_NE(messageOf(o).find("ScaleSeriesOptions::count"), std::string::npos);
}

TEST(ScaleSpace, NeedsNormalsAndCanBeCancelled) {
  PointCloud cloud = test::sphereCloud(500, 1.0);
  EXPECT_THROW(computeScaleStackInMemory(cloud, smallOptions(3),
                                         [](double, std::string_view) { return false; }),
               Cancelled);
  cloud.setNormals({});
  EXPECT_THROW(computeScaleStackInMemory(cloud, smallOptions(3)), OptionError);
}

// The next pyramid level is drawn in a task while a scale projects: a cancelled projection or a
// failing sink must wait for it before unwinding (the ASan build would catch a task outliving
// the frame), and the stack runs again afterwards with the same result.
TEST(ScaleSpace, StopsCleanlyWhileTheNextLevelIsPrepared) {
  const PointCloud cloud = test::sphereCloud(3000, 1.0);
  const ScaleStack reference = computeScaleStackInMemory(cloud, smallOptions(6));
  for (std::size_t failAt : {0u, 2u, 5u}) {
    const auto failing = [&](std::size_t j, const ScaleLayer&, const ScaleStats&) {
      if (j == failAt) throw Error("the sink failed at scale " + std::to_string(j));
    };
    EXPECT_THROW(runScaleSpace(cloud, smallOptions(6), failing), Error) << failAt;
  }
  for (double stopAt : {0.1, 0.5, 0.9}) {
    const auto cancel = [&](double f, std::string_view) { return f < stopAt; };
    EXPECT_THROW(computeScaleStackInMemory(cloud, smallOptions(6), cancel), Cancelled) << stopAt;
  }
  const ScaleStack again = computeScaleStackInMemory(cloud, smallOptions(6));
  ASSERT_EQ(again.layers.size(), reference.layers.size());
  for (std::size_t j = 0; j < again.layers.size(); ++j) {
    EXPECT_EQ(again.summary.stats[j].samples, reference.summary.stats[j].samples);
    EXPECT_EQ(again.layers[j].normal, reference.layers[j].normal) << j;
  }
}

}  // namespace
}  // namespace scalespace
