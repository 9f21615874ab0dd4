#pragma once
// Beyond the thesis (its Sec. 4.5 future work): a relaxation of a plane parametrization that
// lowers the conformal distortion. The thesis suggests moving points to match the 3D and 2D
// ellipses of Eq. 4.1-4.2; here that idea is the local-global "as similar as possible" scheme
// (the energy LSCM minimizes on meshes) on the point cloud's k-NN graph:
//   local:  per point, the similarity S_i (rotation and scale, or an anti-similarity where the
//           map is mirrored) that best takes its neighbours' tangent-plane offsets a_ij to their
//           domain offsets u_j - u_i;
//   global: the domain positions minimizing sum_i sum_j w_ij |u_j - u_i - S_i a_ij|^2, a sparse
//           Laplacian system whose matrix does not change between iterations (factorized once;
//           about 1.5 s at 100k points, 96 s at 1M: meant for clouds up to a few 100k points).
// The domain's size is kept (RMS distance to the centroid) so the scale-free energy cannot
// shrink it. A relaxation that would add folds (MapDefects) is not applied.
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/param/ParamDomain.hpp"

namespace scalespace {

struct RelaxationOptions {
  int iterations = 5;  // local-global iterations (0: none)
  int neighbors = 10;  // k of the k-NN graph
  /// Rotations instead of similarities ("as rigid as possible"): the map then also keeps the
  /// surface's lengths where it can, which lowers the authalic distortion as well on nearly
  /// developable surfaces, and gives the domain the surface's units.
  bool rigid = false;
};

/// OptionError naming the field unless iterations >= 0 and 3 <= neighbors <= 64.
void validateRelaxationOptions(const RelaxationOptions& options);

struct RelaxationResult {
  bool applied = false;  // false: not a plane domain, no iteration, or it would add folds
  std::string reason;    // why not, when not applied
  std::size_t foldsBefore = 0, foldsAfter = 0;
  double seconds = 0;
};

/// Relaxes `domain` (a plane domain of `positions`, with oriented `normals` or none) in place.
/// Throws OptionError on different sizes or invalid options, Cancelled through `progress`.
/// Identical results for any thread count.
RelaxationResult relaxConformally(const std::vector<Vec3>& positions,
                                  const std::vector<Vec3>& normals, DomainMap& domain,
                                  const RelaxationOptions& options = {},
                                  const ProgressCallback& progress = {});

}  // namespace scalespace
