#pragma once
// The query tools of Sec. 2.4 (persistence threshold, scale-based segmentation, brush ranking,
// similarity search) and the coverage extension of Sec. 2.5.1, on a PlaneModel: the components
// plus, per level and point, the component holding the point.
#include <vector>

#include "scalespace/planes/PlaneDetection.hpp"

namespace scalespace {

/// What the tools need, and what `scalespace planes` saves (PlaneExport.hpp).
struct PlaneModel {
  std::vector<double> scales;  // t_j, increasing
  std::vector<PlaneComponent> components;
  PointMembership membership;
  /// Whether the chains were split by planarity (PlaneDetection::planaritySplit): then the
  /// persistence labels prefer planar components. False for the thesis' graph and for results
  /// written before the split existed (components.json "planarity_split").
  bool planaritySplit = false;
  int scaleCount() const { return int(scales.size()); }
};

PlaneModel makePlaneModel(const PlaneDetection& detection);

/// Sec. 2.4.1: per point, the most persistent component with pers >= minPersistence holding it
/// at any level (lower id on ties), or -1. With the planarity split (model.planaritySplit) a
/// planar component beats a flagged one (a departure: docs/THESIS_NOTES.md, planarity split).
std::vector<int> labelsByPersistence(const PlaneModel& model, int minPersistence);

/// Level whose scale is nearest to t on a log scale (the scales are log-spaced, Eq. 1.40).
int nearestLevel(const PlaneModel& model, double t);

/// Sec. 2.4.2: per point, the component holding it at the level nearest to t (regions of one
/// level are disjoint, so it is the only, hence the most persistent, one), if its persistence is
/// >= minPersistence; else -1.
std::vector<int> labelsAtScale(const PlaneModel& model, double t, int minPersistence = 0);

struct BrushMatch {
  int component = -1;
  double overlap = 0.0;  // |P_Q n P_C| / |P_Q|
  double score = 0.0;    // Eq. 2.2: overlap * pers(C) / M
};

/// Sec. 2.4.3: every component holding a query point (P_C = its points over all its levels),
/// ranked by decreasing score, then increasing id. Throws OptionError on an index out of range.
std::vector<BrushMatch> rankByBrush(const PlaneModel& model, const std::vector<Index>& query);

/// Per point, the first of `ids` (in the order given) whose points at its representative level
/// (where its plane and outline were computed) hold the point, or -1: what `segment --brush` and
/// `--similar` label, and what the viewer shows for a selection. Throws OptionError naming the id
/// when one is not a component.
std::vector<int> labelsOfComponents(const PlaneModel& model, const std::vector<int>& ids);

/// Sec. 2.4.4 criteria. Defaults are the parameters of Fig. B.15 (5, 5, 100 %, 90 degrees).
struct SimilarityOptions {
  int birthTolerance = 5;        // |l_b(C) - l_b(Q)| <= this (levels)
  int deathTolerance = 5;        // |l_d(C) - l_d(Q)| <= this
  double maxAreaDifference = 1;  // |a(C) - a(Q)| <= this * a(Q)
  double maxAngleDegrees = 90;   // angle between the (unoriented) plane normals
};
/// OptionError naming the field unless the tolerances are >= 0 (finite) and the angle in [0, 90].
void validate(const SimilarityOptions& options);

/// Components holding a point of `domain` that match component `query` (itself included when in
/// the domain), by increasing id.
std::vector<int> findSimilar(const PlaneModel& model, int query, const std::vector<Index>& domain,
                             const SimilarityOptions& options = {});

/// Sec. 2.5.1 (Fig. 2.10: 20 % of the diagonal, 45 degrees).
struct CoverageOptions {
  double maxDistanceFraction = 0.2;  // of the bounding-box diagonal, point to component plane
  double maxAngleDegrees = 45;       // point normal vs. plane normal (unoriented)
};
/// OptionError naming the field unless maxDistanceFraction is finite and >= 0 and
/// maxAngleDegrees is in [0, 90] (normals are compared unoriented).
void validate(const CoverageOptions& options);

/// Extends `labels` (component ids, -1 unlabelled): an unlabelled point next (in the k-NN graph)
/// to a point of component C joins C if it is close to C's plane with a compatible normal; this
/// repeats breadth-first, so labels spread over connected surface only, never across gaps.
/// Points reached by several components at once take the lowest distance, then the lowest id.
std::vector<int> extendCoverage(const PlaneModel& model, const std::vector<int>& labels,
                                const std::vector<Vec3>& positions,
                                const std::vector<Vec3>& normals, const KnnGraph& knn,
                                const CoverageOptions& options = {});

}  // namespace scalespace
