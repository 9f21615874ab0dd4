#pragma once
// The robust APSS spheres of up to eight fits at once, one fit per AVX-512 lane (the first MLS
// step of eight nearby points, fit/FitScratch.hpp fitAtBatch): the neighbours interleaved, no
// horizontal sums, eight solves in one, and eight independent chains where one fit waits on its
// own pass and solve.
#include <cstddef>
#include <vector>

#include "scalespace/fit/AlgebraicSphere.hpp"
#include "scalespace/fit/NeighborColumns.hpp"
#include "scalespace/fit/RobustReweighting.hpp"
#include "scalespace/fit/SimdKernel.hpp"

namespace scalespace {

/// The neighbours of up to kLanes fits side by side, for robustSpheresInLanes: entry k of fit l
/// is at [kLanes k + l], and past a fit's own count every entry is zero (kernel weight 0).
struct InterleavedColumns {
  static constexpr int kLanes = 8;
  Column qx, qy, qz, nx, ny, nz, d2, weight;
  std::size_t length = 0;  // the largest count: kLanes * length entries are valid
  int fits = 0;
  int count[kLanes] = {};  // each fit's neighbours
  /// Interleaves fits[0..count) (count <= kLanes).
  void assign(const NeighborColumns* const* fits, int count);
};

/// What robustSpheresInLanes gives for each fit.
struct LaneSphere {
  bool valid = false;  // the kernel-weighted fit was valid (sphereFromSums with minNeighbors)
  int neighbors = 0;   // samples of positive kernel weight
  AlgebraicSphere sphere;
};

/// The robust APSS sphere of each interleaved fit, on AVX-512 lanes, one fit per lane: the
/// kernel-weighted fit, then `passes` re-weightings (reweight against the current sphere, then
/// sphereFromSums on the new sums) as fit/LocalFit's robustSphere makes them without derivatives,
/// a lane stopping where it stops (an invalid kernel fit; a failed solve keeps the lane's previous
/// sphere and factors). factors[l] receives fit l's factors of its returned sphere (its count
/// entries), or is emptied when no re-weighting was kept (every factor 1). The fits run in
/// lockstep: no horizontal sums, eight solves in one, and eight independent chains where one fit
/// waits on its own pass and solve (fit/LocalFit uses it for blocks of nearby points). The sums
/// are made in another order than reweight's, so results differ from it in the last bits.
/// Without AVX-512 (or with SimdKernel::Portable) the fits are made one after the other.
void robustSpheresInLanes(const InterleavedColumns& columns, double t, int passes, int minNeighbors,
                          double invSr2, double invSn2, LaneSphere* out,
                          std::vector<double>* factors, SimdKernel kernel = SimdKernel::Auto);

}  // namespace scalespace
