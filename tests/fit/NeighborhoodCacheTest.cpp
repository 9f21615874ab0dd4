// NeighborhoodCache: fits that read prefetched samples equal the fits that query the index.
#include <gtest/gtest.h>

#include <cmath>

#include "FitTestClouds.hpp"
#include "scalespace/fit/FitScratch.hpp"
#include "scalespace/fit/LocalFit.hpp"

using namespace scalespace;
using namespace scalespace::test;

TEST(NeighborhoodCache, CachedFitsEqualIndexedFitsForPlainAndRobustMls) {
  const auto cloud = sampleCloud(SurfaceShape::Saddle, Vec3::Zero(), 1.0, 4000, 7);
  const SurfaceSamples samples = cloud->samples();
  const double t = 0.25;
  for (bool robust : {false, true}) {
    FitOptions o;
    o.mls = true;
    o.robust = robust;
    FitWorkspace plain, cached;
    cached.scratch().cache.prefetch(samples, Vec3::Zero(), 0.45);
    for (int i = 0; i < 40; ++i) {
      const Vec3 x = cloud->positions[i] * 0.2;  // within 0.2 of the centre (scaled inwards)
      const LocalFit a = fitAt(x, t, samples, o, plain);
      const LocalFit b = fitAt(x, t, samples, o, cached);
      expectSameFit(a, b);
    }
    EXPECT_EQ(plain.scratch().cache.hits, 0u);
    EXPECT_GT(cached.scratch().cache.hits,
              30u);  // an MLS step moving out of the ball goes to the index
  }
}

TEST(NeighborhoodCache, BallsPokingOutAndOtherSamplesGoToTheIndex) {
  const auto cloud = sampleCloud(SurfaceShape::Sphere, Vec3::Zero(), 1.0, 3000, 3);
  const auto other = sampleCloud(SurfaceShape::Sphere, Vec3::Zero(), 1.0, 3000, 4);
  FitOptions o;
  FitWorkspace plain, cached;
  cached.scratch().cache.prefetch(cloud->samples(), Vec3::Zero(), 0.3);
  // Support 0.3 around the centre: touches the cached sphere, so it must not be served from it.
  expectSameFit(fitAt(Vec3::Zero(), 0.3, cloud->samples(), o, plain),
                fitAt(Vec3::Zero(), 0.3, cloud->samples(), o, cached));
  EXPECT_EQ(cached.scratch().cache.hits, 0u);
  // Another cloud (another index): never served from this cache.
  expectSameFit(fitAt(Vec3::Zero(), 0.1, other->samples(), o, plain),
                fitAt(Vec3::Zero(), 0.1, other->samples(), o, cached));
  EXPECT_EQ(cached.scratch().cache.hits, 0u);
  // Inside: served from the cache.
  expectSameFit(fitAt(Vec3::Zero(), 0.1, cloud->samples(), o, plain),
                fitAt(Vec3::Zero(), 0.1, cloud->samples(), o, cached));
  EXPECT_EQ(cached.scratch().cache.hits, 1u);
  cached.scratch().cache.clear();
  fitAt(Vec3::Zero(), 0.1, cloud->samples(), o, cached);
  EXPECT_EQ(cached.scratch().cache.hits, 1u);
  cached.scratch().cache.prefetch(cloud->samples(), Vec3(NAN, 0, 0), 1.0);  // nothing cached
  fitAt(Vec3::Zero(), 0.1, cloud->samples(), o, cached);
  EXPECT_EQ(cached.scratch().cache.hits, 1u);
}
