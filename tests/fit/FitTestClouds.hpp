#pragma once
// Sampled analytic surfaces with an index, shared by the fit tests.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "scalespace/core/AnalyticSurface.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/LocalFit.hpp"

namespace scalespace::test {

struct TestCloud {
  std::vector<Vec3> positions, normals;
  std::unique_ptr<SpatialIndex> index;
  void build() { index = makeSpatialIndex(positions); }
  SurfaceSamples samples() const { return SurfaceSamples{positions, normals, *index}; }
};

inline std::unique_ptr<TestCloud> sampleCloud(SurfaceShape shape, const Vec3& centre, double radius,
                                              std::size_t count, std::uint64_t seed = 1) {
  auto c = std::make_unique<TestCloud>();
  for (const SurfacePoint& p : sampleInBall(shape, centre, radius, count, seed)) {
    c->positions.push_back(p.position);
    c->normals.push_back(p.normal);
  }
  c->build();
  return c;
}

inline LocalFit fitWith(const TestCloud& c, const Vec3& x, double t, EstimatorKind kind,
                        bool mls = false, bool robust = false) {
  FitOptions o;
  o.estimator = kind;
  o.mls = mls;
  o.robust = robust;
  FitWorkspace ws;
  return fitAt(x, t, c.samples(), o, ws);
}

/// The same neighbours summed in another order (prefetched blocks, other drivers): equal fits up
/// to rounding.
inline void expectSameFit(const LocalFit& a, const LocalFit& b) {
  ASSERT_EQ(a.valid, b.valid);
  EXPECT_EQ(a.neighbors, b.neighbors);
  EXPECT_EQ(a.mlsSteps, b.mlsSteps);
  EXPECT_LT((a.projection - b.projection).norm(), 1e-12);
  EXPECT_LT((a.normal - b.normal).norm(), 1e-10);
  EXPECT_NEAR(a.kMax, b.kMax, 1e-8 * (1 + std::abs(a.kMax)));
  EXPECT_NEAR(a.kMin, b.kMin, 1e-8 * (1 + std::abs(a.kMin)));
  EXPECT_NEAR(a.geometricVariation, b.geometricVariation, 1e-8);
}

}  // namespace scalespace::test
