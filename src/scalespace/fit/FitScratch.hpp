#pragma once
// Internal to fit/: the scratch memory behind a FitWorkspace and the eight-point fit that the
// driver (fit/FitPoints) runs on blocks of nearby points. Nothing outside fit/ (and its tests)
// includes this header: the SIMD columns and lanes stay out of the public LocalFit.hpp.
#include <cstddef>
#include <vector>

#include "scalespace/fit/LocalFit.hpp"
#include "scalespace/fit/NeighborhoodCache.hpp"
#include "scalespace/fit/RobustLanes.hpp"

namespace scalespace {

struct FitScratch {
  /// Samples prefetched by the driver for nearby fits (the APSS fits read them when they cover
  /// the support ball, fit/NeighborhoodCache.hpp); empty unless the driver fills it.
  NeighborhoodCache cache;
  std::vector<Neighbor> neighbors;
  NeighborColumns columns;                    // the neighbours of the current fit (p - x, n)
  std::vector<double> weights, trialWeights;  // robust re-weighting factors
  /// fitAtBatch's neighbours and factors, point by point, and the neighbours interleaved.
  NeighborColumns batchColumns[InterleavedColumns::kLanes];
  std::vector<double> batchFactors[InterleavedColumns::kLanes];
  InterleavedColumns interleaved;
};

/// The most points fitAtBatch takes at once.
constexpr std::size_t kFitBatch = InterleavedColumns::kLanes;

/// fitAt at each of xs[0..count) (count <= kFitBatch) into out[0..count). For the robust APSS
/// estimators (no robustTolerance) on CPUs with AVX-512, the first MLS step of every point is
/// made at once, one point per lane (robustSpheresInLanes); each point then goes on alone as in
/// fitAt (derivatives, further MLS steps). The results are fitAt's up to the last bits (the sums
/// are made in another order); options.expectFirstStepConverged is not read (the first step's
/// derivatives are made once it has converged).
void fitAtBatch(const Vec3* xs, std::size_t count, double t, const SurfaceSamples& samples,
                const FitOptions& options, FitWorkspace& workspace, LocalFit* out);

}  // namespace scalespace
