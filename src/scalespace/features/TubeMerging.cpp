#include "scalespace/features/TubeMerging.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <utility>

namespace scalespace {

std::vector<int> tubeOwners(std::size_t pointCount, const std::vector<TubeFit>& tubes,
                            const std::vector<std::vector<Index>>& regions) {
  std::vector<int> owner(pointCount, -1);
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (tubes[r].isTube())
      for (const Index i : regions[r]) owner[i] = int(r);
  return owner;
}

void mergeTouchingTubes(const KnnGraph& graph, const std::vector<Vec3>& positions,
                        const std::vector<Vec3>& normals, const LineAnisotropyField& field,
                        double t, const TubeFitOptions& options, std::vector<TubeFit>& tubes,
                        std::vector<std::vector<Index>>& regions, const std::vector<int>& apart,
                        const TubeSplitOptions& split) {
  const std::vector<int> owner = tubeOwners(positions.size(), tubes, regions);
  std::map<std::pair<int, int>, std::size_t> edges;
  for (std::size_t p = 0; p < positions.size(); ++p) {
    if (owner[p] < 0) continue;
    for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
      const int a = owner[p], b = owner[graph.neighbors[e]];
      if (b >= 0 && a < b) ++edges[{a, b}];
    }
  }
  std::vector<std::pair<std::size_t, std::pair<int, int>>> pairs;
  for (const auto& [ab, count] : edges) pairs.push_back({count, ab});
  std::sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    return x.first != y.first ? x.first > y.first : x.second < y.second;
  });
  std::vector<int> root(regions.size());
  for (std::size_t r = 0; r < root.size(); ++r) root[r] = int(r);
  // The groups each merged set holds (a set inherits its members' groups).
  std::vector<std::vector<int>> groups(regions.size());
  for (std::size_t r = 0; r < apart.size() && r < groups.size(); ++r)
    if (apart[r] >= 0) groups[r].push_back(apart[r]);
  const auto share = [](const std::vector<int>& x, const std::vector<int>& y) {
    for (const int g : x)
      if (std::find(y.begin(), y.end(), g) != y.end()) return true;
    return false;
  };
  auto find = [&](int r) {
    while (root[std::size_t(r)] != r)
      r = root[std::size_t(r)] = root[std::size_t(root[std::size_t(r)])];
    return r;
  };
  for (const auto& [count, ab] : pairs) {
    const int a = find(ab.first), b = find(ab.second);
    if (a == b) continue;
    const TubeFit &ta = tubes[std::size_t(a)], &tb = tubes[std::size_t(b)];
    // Parts of one split region side by side are the strands it was split into, and end to end
    // but aside the runs of two strands a scan from one side sees in turn; where one continues
    // the other, two pieces of one strand that the split's density levels cut.
    const double big = std::max(ta.radius, tb.radius);
    const bool oneSplit = share(groups[std::size_t(a)], groups[std::size_t(b)]);
    if (oneSplit ? !mayBeOneStrand(ta, tb, split) : !radiiAgree(ta, tb, 0.25)) continue;
    std::vector<Index> both;
    both.reserve(regions[std::size_t(a)].size() + regions[std::size_t(b)].size());
    std::merge(regions[std::size_t(a)].begin(), regions[std::size_t(a)].end(),
               regions[std::size_t(b)].begin(), regions[std::size_t(b)].end(),
               std::back_inserter(both));
    TubeFit merged = fitTube(positions, normals, field.normal, field.kappa1, both, t, options);
    if (!merged.isTube() || merged.rms > 1.25 * std::max(ta.rms, tb.rms) + 0.02 * big) continue;
    const int keep = std::min(a, b), gone = std::max(a, b);
    root[std::size_t(gone)] = keep;
    regions[std::size_t(keep)] = std::move(both);
    regions[std::size_t(gone)].clear();
    groups[std::size_t(keep)].insert(groups[std::size_t(keep)].end(),
                                     groups[std::size_t(gone)].begin(),
                                     groups[std::size_t(gone)].end());
    tubes[std::size_t(keep)] = std::move(merged);
    tubes[std::size_t(gone)].rejection = TubeRejection::Merged;
  }
}

}  // namespace scalespace
