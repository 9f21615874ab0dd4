#include "scalespace/core/RegionGraph.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>

#include "scalespace/core/Error.hpp"

namespace scalespace {

PointMembership pointMembership(const RegionGraph& graph) {
  PointMembership m;
  m.pointCount = graph.pointCount;
  m.levelCount = int(graph.levels.size());
  m.ids.reserve(graph.pointCount * graph.levels.size());
  for (int j = 0; j < m.levelCount; ++j) {
    const std::vector<int> labels = graph.componentLabels(j);
    m.ids.insert(m.ids.end(), labels.begin(), labels.end());
  }
  return m;
}

std::vector<int> labelsByPersistence(const PointMembership& membership,
                                     const std::vector<int>& persistence, int minPersistence,
                                     const std::vector<std::uint8_t>* preferred) {
  if (preferred && preferred->size() != persistence.size())
    throw OptionError("labelsByPersistence: one preference per component is needed");
  const auto rank = [&](int c) {
    return std::pair<int, int>(preferred ? int((*preferred)[std::size_t(c)] != 0) : 0,
                               persistence[std::size_t(c)]);
  };
  std::vector<int> labels(membership.pointCount, -1);
  for (int j = 0; j < membership.levelCount; ++j)
    for (std::size_t i = 0; i < membership.pointCount; ++i) {
      const int c = membership.at(j, i);
      if (c < 0 || persistence[std::size_t(c)] < minPersistence) continue;
      const int b = labels[i];
      // Preferred, then higher persistence, then lower id.
      if (b < 0 || rank(c) > rank(b) || (rank(c) == rank(b) && c < b)) labels[i] = c;
    }
  return labels;
}

std::vector<int> labelsAtLevel(const PointMembership& membership,
                               const std::vector<int>& persistence, int level, int minPersistence) {
  if (level < 0 || level >= membership.levelCount)
    throw OptionError("level " + std::to_string(level) + " is outside [0, " +
                      std::to_string(membership.levelCount) + ")");
  std::vector<int> labels(membership.pointCount, -1);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const int c = membership.at(level, i);
    if (c >= 0 && persistence[std::size_t(c)] >= minPersistence) labels[i] = c;
  }
  return labels;
}

int nearestScaleIndex(const std::vector<double>& scales, double t) {
  if (scales.empty()) throw OptionError("there are no scales");
  if (!(t > 0) || !std::isfinite(t)) throw OptionError("the scale t must be finite and > 0");
  int best = 0;
  for (int j = 1; j < int(scales.size()); ++j)
    if (std::abs(std::log(scales[std::size_t(j)] / t)) <
        std::abs(std::log(scales[std::size_t(best)] / t)))
      best = j;
  return best;
}

double jaccardIndex(const std::vector<Index>& a, const std::vector<Index>& b) {
  std::size_t common = 0;
  for (std::size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    if (a[i] < b[j])
      ++i;
    else if (b[j] < a[i])
      ++j;
    else
      ++common, ++i, ++j;
  }
  const std::size_t unionSize = a.size() + b.size() - common;
  return unionSize == 0 ? 0.0 : double(common) / double(unionSize);
}

namespace {
std::vector<int> regionLabels(const RegionLevel& level, std::size_t pointCount) {
  std::vector<int> labels(pointCount, -1);
  for (std::size_t r = 0; r < level.regions.size(); ++r)
    for (Index i : level.regions[r]) {
      if (i >= pointCount) throw OptionError("region graph: a region holds a point out of range");
      if (labels[i] >= 0) throw OptionError("region graph: regions of one level overlap");
      labels[i] = int(r);
    }
  return labels;
}
}  // namespace

std::vector<int> RegionGraph::componentLabels(int level) const {
  std::vector<int> labels(pointCount, -1);
  const auto& regions = levels.at(std::size_t(level)).regions;
  for (std::size_t r = 0; r < regions.size(); ++r)
    for (Index i : regions[r]) labels[i] = componentOf[std::size_t(level)][r];
  return labels;
}

namespace {
struct NestedCandidate {
  std::size_t common = 0;
  int region = 0, laterRegion = 0;
};

struct LevelLinks {
  std::vector<int> byJaccard;  // per region of level `from`: the region with J > minJaccard, or -1
  std::vector<NestedCandidate> nested;  // options.nestedAllowed's, largest overlaps first
};

// Whether regions of sizes a and b sharing `common` points may link as nested ones.
bool nestedSizes(std::size_t a, std::size_t b, std::size_t common,
                 const RegionLinkOptions& options) {
  const double smaller = double(std::min(a, b)), larger = double(std::max(a, b));
  return double(common) > options.minJaccard * smaller &&
         smaller >= options.nestedMinSizeRatio * larger;
}

// For each region r of level `from` with wanted[r], the open region of level `to` (of the same
// kind) with Jaccard index > minJaccard: regions of a level are disjoint, so J > 0.5 holds for at
// most one and the answer does not depend on the order of the search. With nestedAllowed and no
// such region, the open regions sharing with it more than minJaccard of the smaller one's points
// (nestedSizes) that the test accepts.
LevelLinks linkLevels(const RegionGraph& graph, std::size_t from, std::size_t to,
                      const RegionLinkOptions& options, const std::vector<char>& wanted,
                      const std::vector<char>& open) {
  const std::vector<int> toLabels = regionLabels(graph.levels[to], graph.pointCount);
  const auto& here = graph.levels[from].regions;
  const auto& there = graph.levels[to].regions;
  LevelLinks links;
  links.byJaccard.assign(here.size(), -1);
  std::vector<std::vector<NestedCandidate>> nested(here.size());
  tbb::parallel_for(std::size_t(0), here.size(), [&](std::size_t r) {
    if (!wanted[r]) return;
    std::unordered_map<int, std::size_t> overlap;
    for (Index i : here[r])
      if (toLabels[i] >= 0) ++overlap[toLabels[i]];
    const auto linkable = [&](int s) {
      return open[std::size_t(s)] &&
             (!options.kinds || (*options.kinds)[from][r] == (*options.kinds)[to][std::size_t(s)]);
    };
    for (const auto& [s, common] : overlap)
      if (linkable(s) &&
          double(common) >
              options.minJaccard * double(here[r].size() + there[std::size_t(s)].size() - common))
        links.byJaccard[r] = s;  // Eq. 2.1
    if (links.byJaccard[r] >= 0 || !options.nestedAllowed) return;
    for (const auto& [s, common] : overlap)
      if (linkable(s) &&
          nestedSizes(here[r].size(), there[std::size_t(s)].size(), common, options) &&
          options.nestedAllowed(graph.levels, int(from), int(r), int(to), s))
        nested[r].push_back({common, int(r), s});
  });
  for (const auto& candidates : nested)
    links.nested.insert(links.nested.end(), candidates.begin(), candidates.end());
  std::sort(links.nested.begin(), links.nested.end(),
            [](const NestedCandidate& a, const NestedCandidate& b) {
              if (a.common != b.common) return a.common > b.common;
              return a.region != b.region ? a.region < b.region : a.laterRegion < b.laterRegion;
            });
  return links;
}
}  // namespace

RegionGraph buildRegionGraph(std::vector<RegionLevel> levels, std::size_t pointCount,
                             const RegionLinkOptions& options) {
  if (!(options.minJaccard >= 0.5 && options.minJaccard < 1))
    throw OptionError("the Jaccard threshold must be in [0.5, 1): below 0.5 links are ambiguous");
  if (options.maxGap < 0)
    throw OptionError("region graph: the largest bridged gap must be >= 0 levels");
  if (!(options.nestedMinSizeRatio > 0 && options.nestedMinSizeRatio <= 1))
    throw OptionError("region graph: the nested regions' size ratio must be in (0, 1]");
  if (const auto* kinds = options.kinds) {
    bool sized = kinds->size() == levels.size();
    for (std::size_t j = 0; sized && j < levels.size(); ++j)
      sized = (*kinds)[j].size() == levels[j].regions.size();
    if (!sized) throw OptionError("region graph: the region kinds and the levels differ in size");
  }
  RegionGraph graph;
  graph.pointCount = pointCount;
  graph.levels = std::move(levels);
  const std::size_t m = graph.levels.size();
  graph.successor.resize(m);
  graph.bridge.resize(m);
  graph.componentOf.resize(m);
  std::vector<std::vector<int>> predecessor(m);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t count = graph.levels[j].regions.size();
    graph.successor[j].assign(count, -1);
    graph.bridge[j].assign(count, {-1, -1});
    graph.componentOf[j].assign(count, -1);
    predecessor[j].assign(count, -1);
  }
  // Edges between consecutive levels: the candidates of region r at level j are the regions of
  // level j+1 holding its points; J > 0.5 holds for at most one of them (and, symmetrically, for
  // at most one region of level j per region of level j+1). Nested links take what J left free.
  for (std::size_t j = 0; j + 1 < m; ++j) {
    const LevelLinks links =
        linkLevels(graph, j, j + 1, options, std::vector<char>(graph.levels[j].regions.size(), 1),
                   std::vector<char>(graph.levels[j + 1].regions.size(), 1));
    graph.successor[j] = links.byJaccard;
    for (std::size_t r = 0; r < graph.successor[j].size(); ++r)
      if (graph.successor[j][r] >= 0)
        predecessor[j + 1][std::size_t(graph.successor[j][r])] = int(r);
    for (const NestedCandidate& c : links.nested) {
      int& successor = graph.successor[j][std::size_t(c.region)];
      int& before = predecessor[j + 1][std::size_t(c.laterRegion)];
      if (successor >= 0 || before >= 0) continue;
      successor = c.laterRegion;
      before = c.region;
    }
  }
  // Bridges: chain ends to chain starts 1..maxGap levels further, shorter gaps first. Two ends of
  // one level cannot both pass J > 0.5 with one start; an end of an earlier level that would,
  // finds the start taken (one bridge per start, the first in this order). Nested bridges take
  // what J left free at each gap and level.
  for (int gap = 1; gap <= options.maxGap; ++gap)
    for (std::size_t j = 0; j + std::size_t(gap) + 1 < m; ++j) {
      const std::size_t k = j + std::size_t(gap) + 1;
      std::vector<char> ends(graph.levels[j].regions.size()),
          starts(graph.levels[k].regions.size());
      for (std::size_t r = 0; r < ends.size(); ++r)
        ends[r] = graph.successor[j][r] < 0 && graph.bridge[j][r].first < 0;
      for (std::size_t s = 0; s < starts.size(); ++s) starts[s] = predecessor[k][s] < 0;
      if (std::find(ends.begin(), ends.end(), 1) == ends.end()) continue;
      const LevelLinks links = linkLevels(graph, j, k, options, ends, starts);
      const auto bridge = [&](int r, int s) {
        graph.bridge[j][std::size_t(r)] = {int(k), s};
        predecessor[k][std::size_t(s)] = r;
      };
      for (std::size_t r = 0; r < links.byJaccard.size(); ++r) {
        const int s = links.byJaccard[r];
        if (s < 0 || predecessor[k][std::size_t(s)] >= 0) continue;
        if (options.bridgeAllowed &&
            !options.bridgeAllowed(graph.levels, int(j), int(r), int(k), s))
          continue;
        bridge(int(r), s);
      }
      for (const NestedCandidate& c : links.nested)
        if (graph.bridge[j][std::size_t(c.region)].first < 0 &&
            predecessor[k][std::size_t(c.laterRegion)] < 0)
          bridge(c.region, c.laterRegion);
    }
  // Chains start at the nodes without predecessor; levels and region indices increase, so the
  // component order (birth level, then region index) is deterministic.
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t r = 0; r < graph.levels[j].regions.size(); ++r) {
      if (predecessor[j][r] >= 0) continue;
      GraphComponent c;
      c.birthLevel = int(j);
      const int id = int(graph.components.size());
      std::size_t level = j;
      int region = int(r);
      while (true) {
        c.regionAt.push_back(region);
        graph.componentOf[level][std::size_t(region)] = id;
        const int s = graph.successor[level][std::size_t(region)];
        if (s >= 0) {
          region = s;
          ++level;
          continue;
        }
        const auto [bridgeLevel, bridgeRegion] = graph.bridge[level][std::size_t(region)];
        if (bridgeRegion < 0) break;
        for (std::size_t g = level + 1; g < std::size_t(bridgeLevel); ++g) {
          c.regionAt.push_back(-1);
          ++c.gapLevels;
        }
        level = std::size_t(bridgeLevel);
        region = bridgeRegion;
      }
      c.deathLevel = int(level);
      c.birthScale = graph.levels[j].t;
      c.deathScale = graph.levels[level].t;
      graph.components.push_back(std::move(c));
    }
  return graph;
}

}  // namespace scalespace
