#pragma once
// Beyond the thesis (its Sec. 4.5 future work): a relaxation of a parametrization (plane or
// sphere domain) that lowers its distortion. The thesis suggests moving points to match the 3D and
// 2D ellipses of Eq. 4.1-4.2; here that idea is the local-global "as similar as possible" scheme
// (the energy LSCM minimizes on meshes) on the point cloud's k-NN graph:
//   local:  per point, the similarity S_i (rotation and scale, or an anti-similarity where the
//           map is mirrored) that best takes its neighbours' tangent-plane offsets a_ij to their
//           domain offsets u_j - u_i;
//   global: the domain positions minimizing sum_i rho_i sum_j w_ij |u_j - u_i - S_i a_ij|^2, a
//           sparse Laplacian system whose matrix does not change between the iterations of a
//           round (factorized once per round).
// Robust rounds (iteratively re-weighted least squares): after each round a point whose
// residual exceeds the median weighs rho_i = median / residual (at least 1 / maxDownweight).
// A least-squares energy spreads the misfit of a curved patch (a bump's excess area) as shear
// over the whole domain; the re-weighting keeps it on the patch, so the rest of the map stays
// a similarity where the surface is flat (bench/README.md, bench_parametrize).
// Large clouds: the system is solved on a Poisson-disk subsample of about maxSolvePoints
// points (the factorization's fill grows faster than the point count), and every other point
// is placed by the local similarities of its nearest samples.
// Sphere domains: the same on the domain points R d_i in 3D, the offsets read in the sphere's
// tangent planes, the solved points put back on the sphere (above maxSolvePoints, on a subsample,
// only when asked: largeSpheres).
// The domain's size is kept (RMS distance to the centroid; a sphere's radius) so the scale-free
// energy cannot shrink it; rotations give it the surface's units. A relaxation that would add folds
// or overlaps (MapDefects) is retried with one plain round, then not applied.
#include <vector>

#include "scalespace/core/Progress.hpp"
#include "scalespace/core/Types.hpp"
#include "scalespace/param/MapDefects.hpp"
#include "scalespace/param/ParamDomain.hpp"

namespace scalespace {

struct RelaxationOptions {
  int iterations = 5;  // local-global iterations per round (0: no relaxation)
  int neighbors = 10;  // k of the k-NN graph
  /// Rounds of robust re-weighting (1: plain least squares, as the first relaxation was).
  int rounds = 3;
  /// The smallest robust weight is 1 / maxDownweight (>= 1).
  double maxDownweight = 10;
  /// Above this many points the system is solved on a Poisson-disk subsample of about this
  /// size (>= 1000).
  std::size_t maxSolvePoints = 100000;
  /// How rigid the local maps of a plane domain are: 1, rotations ("as rigid as possible": the
  /// map also keeps the surface's lengths where it can, which lowers the authalic distortion as
  /// well, and gives the domain the surface's units); 0, similarities (the conformal energy
  /// alone: areas drift); between, a similarity whose scale s is pulled to s^(1 - rigidity).
  /// A disk-like surface is nearly developable where it is not bumpy, so rotations keep both
  /// angles and areas there.
  double rigidity = 1.0;
  /// The same for a sphere domain. A closed surface differs in Gauss curvature from the sphere
  /// almost everywhere (an ellipsoid's poles and equator), so no map keeps lengths: rotations
  /// keep the areas of close neighbours and push the mismatch into shear over a few dozen
  /// neighbours, where the conformal distortion then exceeds the thesis map's. Mostly conformal
  /// with a tenth of rigidity, both distortions stay below the radial projection's at 16 and 64
  /// neighbours and, but for a near tie, below the thesis map's (bench/README.md,
  /// bench_parametrize).
  double sphereRigidity = 0.1;
  /// A sphere domain above maxSolvePoints is relaxed too, on a subsample (placed from it and
  /// smoothed at full resolution, as a plane's). Off by default: at 1M points it adds about a
  /// third of the flattening's time, beyond the budget of a minute (docs/THESIS_NOTES.md,
  /// "Relaxation").
  bool largeSpheres = false;
  /// The fold and overlap check of the map before and after (a relaxation that adds defects is
  /// not applied).
  MapDefectOptions defects;
};

/// OptionError naming the field unless iterations >= 0, 3 <= neighbors <= 64, 1 <= rounds <= 20,
/// maxDownweight >= 1 (finite), rigidity and sphereRigidity are in [0, 1] and maxSolvePoints >=
/// 1000.
void validateRelaxationOptions(const RelaxationOptions& options);

struct RelaxationResult {
  bool applied = false;          // false: not a plane domain, no iteration, or it would add folds
  std::string reason;            // why not, when not applied
  std::size_t solvedPoints = 0;  // the points of the system (a subsample of a large cloud)
  /// The robust rounds of the map applied: RelaxationOptions::rounds, or 1 when those would
  /// have added folds or overlaps and one plain round did not (0: not applied).
  int roundsApplied = 0;
  /// The defects of the map left in `domain` (relaxed or not); empty when that map was not
  /// checked (no iteration, the relaxation failed).
  MapDefects defects;
  double seconds = 0;
};

/// Relaxes `domain` (a parametrization of `positions`, with oriented `normals` or none) in place.
/// Throws OptionError on different sizes or invalid options, Cancelled through `progress`.
/// Identical results for any thread count.
RelaxationResult relaxConformally(const std::vector<Vec3>& positions,
                                  const std::vector<Vec3>& normals, DomainMap& domain,
                                  const RelaxationOptions& options = {},
                                  const ProgressCallback& progress = {});

}  // namespace scalespace
