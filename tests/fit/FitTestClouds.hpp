#pragma once
// Sampled analytic surfaces with an index, shared by the fit tests.
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

}  // namespace scalespace::test
