#pragma once
// Per-scale planar segmentation (Sec. 2.3.1): seeded region growing on the k-NN graph (the
// generic core/RegionGrower.hpp with the planes' seed order and criterion), then the alpha-shape
// filter that drops regions smaller than the scale.
#include <vector>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/core/RegionGrower.hpp"
#include "scalespace/planes/ScaleFeatures.hpp"

namespace scalespace {

struct RegionGrowingOptions {
  double maxAngleDegrees = 5.0;  // theta of Sec. 2.3.1, against the SEED's normal
  /// The largest step, as a fraction of t, that a region may cross along the seed's normal from
  /// one point's projection to its neighbour's (a departure from Sec. 2.3.1, which has the angle
  /// alone: docs/THESIS_NOTES.md, region growing offset). 0: the thesis' criterion.
  double maxStep = 0.0;
};

/// OptionError naming the field unless maxAngleDegrees is in (0, 180) and maxStep finite, >= 0.
void validateRegionGrowingOptions(const RegionGrowingOptions& options);

/// Seeds by decreasing planarity 1/(k1^2 + k2^2), i.e. increasing k1^2 + k2^2 (stable, index
/// tie-break); a region grows through the graph over unassigned valid points whose normal is
/// within theta of the seed's normal (and, with maxStep, whose projection is at most
/// max(maxStep t, |edge| sin theta) from the plane through the neighbour it is reached from,
/// |edge| the distance between the two projections: the rise that a face tilted by theta makes
/// over the edge is no step). Invalid points stay -1.
/// Deterministic.
Segmentation growRegions(const KnnGraph& graph, const ScaleFeatures& scale,
                         const RegionGrowingOptions& options = {});

struct RegionFilterOptions {
  /// The alpha-shape radius and the minimum extent are alphaFactor * t (Sec. 2.3.1: 2t); CGAL's
  /// alpha is the squared radius.
  double alphaFactor = 2.0;
};

/// OptionError naming the field unless alphaFactor > 0 (finite).
void validateRegionFilterOptions(const RegionFilterOptions& options);

/// Keeps the regions (their increasing point lists) with sqrt(alpha-shape area) >= alphaFactor * t
/// (the docs/THESIS_NOTES.md reading of "a < 2t"), in their input order. Regions run in parallel; a
/// large region is usually accepted from the alpha shape of a patch around its middle
/// (alphaShapeAreaAtLeast), so the area itself is not computed (the components compute theirs at
/// their representative level).
std::vector<std::vector<Index>> filterRegions(const std::vector<Vec3>& positions,
                                              const Segmentation& segmentation, double t,
                                              const RegionFilterOptions& options = {},
                                              const ProgressCallback& progress = {});

}  // namespace scalespace
