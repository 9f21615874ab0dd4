#pragma once
// Multi-scale region graph and its components (Sec. 2.3.2-2.3.3): nodes are the regions of every
// scale (plain point-index lists, so any primitive's regions fit: the planes' filtered regions),
// an edge joins regions of consecutive scales with Jaccard index > 0.5 (Eq. 2.1). Regions of one
// scale are disjoint, so a node has at most one such successor and one such predecessor: the
// components are chains, each with a birth and a death level. Optionally (not in the thesis) a
// chain may bridge a gap: a region with no successor links, by the same rule, to a region of a
// later level with no predecessor, when the levels between found nothing there (a pipe whose two
// walls one scale's region growing joins into one rough region, then separates again).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

/// The regions of one scale: disjoint lists of point indices, each increasing.
struct RegionLevel {
  double t = 0.0;
  std::vector<std::vector<Index>> regions;
};

/// A component: the chain of regions regionAt[0..] at levels birthLevel..deathLevel.
struct GraphComponent {
  int birthLevel = 0;
  int deathLevel = 0;
  double birthScale = 0.0;
  double deathScale = 0.0;
  std::vector<int> regionAt;  // region index at level birthLevel + k; -1 in a bridged gap
  int gapLevels = 0;          // levels inside [birthLevel, deathLevel] where it has no region
  /// pers(C) = l_d - l_b in levels (Sec. 2.3.3; docs/THESIS_NOTES.md: the one definition we keep),
  /// less the levels of its bridged gaps: only the levels where it was found count.
  int persistence() const { return deathLevel - birthLevel - gapLevels; }
};

struct RegionGraph {
  std::vector<RegionLevel> levels;
  /// successor[j][r]: the region at level j+1 linked to region r of level j, or -1.
  std::vector<std::vector<int>> successor;
  /// bridge[j][r]: (level, region) beyond a gap linked to region r of level j (its successor is
  /// -1), or (-1, -1).
  std::vector<std::vector<std::pair<int, int>>> bridge;
  /// componentOf[j][r]: the component holding region r of level j.
  std::vector<std::vector<int>> componentOf;
  /// Ordered by birth level, then by region index at birth.
  std::vector<GraphComponent> components;
  std::size_t pointCount = 0;

  /// Per point, the component of its region at `level` or -1 (regions of a level are disjoint).
  std::vector<int> componentLabels(int level) const;
};

/// Per level and point, the component holding the point: ids[level * pointCount + i], or -1. What
/// the label queries of Sec. 2.4.1-2.4.2 read, for any primitive, and what results save (planes
/// and cylinders write it as membership.bin, planes/PlaneExport.hpp).
struct PointMembership {
  std::size_t pointCount = 0;
  int levelCount = 0;
  std::vector<int> ids;
  int at(int level, std::size_t i) const { return ids[std::size_t(level) * pointCount + i]; }
};

/// The membership of every level of `graph` (componentLabels, level after level).
PointMembership pointMembership(const RegionGraph& graph);

/// Sec. 2.4.1: per point, the most persistent component (persistence[c], lower id on ties) with
/// persistence >= minPersistence holding it at any level, or -1. With `preferred` (per
/// component), a preferred component beats any other whatever their persistence (the planes:
/// planar components before the flagged ones, planes/RegionPlanarity.hpp).
std::vector<int> labelsByPersistence(const PointMembership& membership,
                                     const std::vector<int>& persistence, int minPersistence,
                                     const std::vector<std::uint8_t>* preferred = nullptr);

/// Sec. 2.4.2: per point, the component holding it at `level` if its persistence is >=
/// minPersistence, else -1. Throws OptionError for a level out of range.
std::vector<int> labelsAtLevel(const PointMembership& membership,
                               const std::vector<int>& persistence, int level,
                               int minPersistence = 0);

/// The index of the scale nearest to t on a log scale (the scales are log-spaced, Eq. 1.40).
/// Throws OptionError when `scales` is empty or t is not finite and > 0.
int nearestScaleIndex(const std::vector<double>& scales, double t);

/// Jaccard index |A n B| / |A u B| of two increasing index lists (Eq. 2.1).
double jaccardIndex(const std::vector<Index>& a, const std::vector<Index>& b);

/// Whether two regions of the graph being built hold one primitive: (levels, level, region,
/// later level, later region). Called from several threads at once: it must only read.
using LinkTest = std::function<bool(const std::vector<RegionLevel>&, int, int, int, int)>;

struct RegionLinkOptions {
  double minJaccard = 0.5;  // Eq. 2.1; in [0.5, 1)
  /// kinds[j][r] per region: only regions of the same kind are linked, a chain never mixes them
  /// (planes/RegionPlanarity.hpp: planar and non-planar regions).
  const std::vector<std::vector<std::uint8_t>>* kinds = nullptr;
  /// A chain's last region also links to the first region of a chain starting up to maxGap + 1
  /// levels later (J > minJaccard; shorter gaps first, then lower levels and region indices), if
  /// bridgeAllowed (when given) agrees: the primitives fitted to both must be one (the same tube
  /// radius), since nothing between them vouches for it.
  int maxGap = 0;
  LinkTest bridgeAllowed;
  /// (Not in the thesis.) Only when nestedAllowed is set: two regions that did not link by J, one
  /// holding more than minJaccard of the other's points (|A n B| > minJaccard min(|A|, |B|)) and
  /// the smaller at least nestedMinSizeRatio times as many points as the larger, link when
  /// nestedAllowed agrees, between consecutive levels and across gaps alike (bridgeAllowed is not
  /// asked: nestedAllowed is the test): a scale that finds a large piece of the primitive the next
  /// one finds whole. Such links are made after the J links of the same levels, the largest
  /// overlaps first (then lower region indices), one successor and one predecessor per region as
  /// ever; the consecutive ones before any bridge, so a nested link may take an end or a start
  /// that a bridge would have used.
  LinkTest nestedAllowed;
  double nestedMinSizeRatio = 0.25;  // in (0, 1]
};

/// Links consecutive levels (J > minJaccard, 0.5 in Sec. 2.3.2), then bridges and nested links as
/// `options` asks, and extracts the chains. Throws OptionError on options out of range, kinds not
/// one per region, or regions of a level that overlap or hold points out of range.
RegionGraph buildRegionGraph(std::vector<RegionLevel> levels, std::size_t pointCount,
                             const RegionLinkOptions& options = {});

}  // namespace scalespace
