#pragma once
// The meshless distortion measures of Sec. 4.4. Per point and neighbourhood size, the weighted
// covariance of the neighbours in the tangent plane (Eq. 4.1) and of the same neighbours in the
// domain (Eq. 4.2) are read as ellipses: semi-axes lambda_1 >= lambda_2 are the square roots of
// the covariance's eigenvalues (docs/THESIS_NOTES.md: with them "eps_conf = 2" means "twice
// stretched in one direction", as the thesis says), anisotropy sigma = lambda_2 / lambda_1, area
// a = pi lambda_1 lambda_2. Then eps_conf = ratio(sigma3D, sigma2D) (Eq. 4.3) and eps_auth =
// ratio(a3D, c a2D) (Eq. 4.4), ratio(a, b) = max / min.
//
// Area normalisation: a domain has its own units (a unit sphere, a stereographic plane), so
// areas are compared after one global factor per neighbourhood size, c = the median of a3D / a2D
// over the points. eps_auth = 1 at the median point; it measures how areas vary over the map,
// not the size of the domain.
#include <cstdint>
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/param/ParamDomain.hpp"

namespace scalespace {

struct DistortionOptions {
  /// Neighbourhood sizes, as neighbour counts: the neighbourhood adapts to the local spacing
  /// (Sec. 1.5.1's reading of scale), from a few spacings to a region of the surface.
  std::vector<int> neighbors{16, 64, 256};
};

/// OptionError naming the field unless every size is in [3, kMaxNeighborCount] and there is at
/// least one.
void validateDistortionOptions(const DistortionOptions& options);

/// The largest value eps_conf and eps_auth take (a domain ellipse collapsed to a segment or a
/// point would give infinity).
constexpr double kMaxDistortion = 1e6;

struct DistortionAtSize {
  int neighbors = 0;
  /// Per point; 0 where the 3D neighbourhood has no ellipse (collinear or repeated points).
  std::vector<float> conformal, authalic;
  double areaFactor = 0;  // c: the median of a3D / a2D
  double medianConformal = 0, p90Conformal = 0, medianAuthalic = 0, p90Authalic = 0;
  std::size_t undetermined = 0;
};

struct DistortionResult {
  std::vector<DistortionAtSize> sizes;
};

/// Measures the map of `positions` (with oriented `normals`, or none: PCA tangent planes) to
/// `domain`. Throws OptionError on different sizes or invalid options, Cancelled through
/// `progress`. Identical results for any thread count.
DistortionResult measureDistortion(const std::vector<Vec3>& positions,
                                   const std::vector<Vec3>& normals, const DomainMap& domain,
                                   const DistortionOptions& options = {},
                                   const ProgressCallback& progress = {});

/// The quantile q in [0, 1] of the positive values (lower interpolation); 0 when none.
double positiveQuantile(const std::vector<float>& values, double q);

}  // namespace scalespace
