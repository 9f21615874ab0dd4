#pragma once
// Multi-scale region graph and its components (Sec. 2.3.2-2.3.3): nodes are the regions of every
// scale (plain point-index lists, so any primitive's regions fit: the planes' filtered regions),
// an edge joins regions of consecutive scales with Jaccard index > 0.5 (Eq. 2.1). Regions of one
// scale are disjoint, so a node has at most one such successor and one such predecessor: the
// components are chains, each with a birth and a death level.
#include <cstddef>
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
  std::vector<int> regionAt;  // region index at level birthLevel + k
  /// pers(C) = l_d - l_b in levels (Sec. 2.3.3; docs/THESIS_NOTES.md: the one definition we keep).
  int persistence() const { return deathLevel - birthLevel; }
};

struct RegionGraph {
  std::vector<RegionLevel> levels;
  /// successor[j][r]: the region at level j+1 linked to region r of level j, or -1.
  std::vector<std::vector<int>> successor;
  /// componentOf[j][r]: the component holding region r of level j.
  std::vector<std::vector<int>> componentOf;
  /// Ordered by birth level, then by region index at birth.
  std::vector<GraphComponent> components;
  std::size_t pointCount = 0;

  /// Per point, the component of its region at `level` or -1 (regions of a level are disjoint).
  std::vector<int> componentLabels(int level) const;
};

/// Jaccard index |A n B| / |A u B| of two increasing index lists (Eq. 2.1).
double jaccardIndex(const std::vector<Index>& a, const std::vector<Index>& b);

/// Links consecutive levels (J > minJaccard, 0.5 in Sec. 2.3.2) and extracts the chains.
RegionGraph buildRegionGraph(std::vector<RegionLevel> levels, std::size_t pointCount,
                             double minJaccard = 0.5);

}  // namespace scalespace
