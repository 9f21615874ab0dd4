#pragma once
// Seeded region growing on a k-NN graph (Sec. 2.3.1), generic in what makes a region: the caller
// gives the seeds in the order to try them, which points may join a region at all, and a
// criterion deciding whether a neighbour joins the region of a seed. Planes (planes/RegionGrowing)
// use it with the planarity order and the angle to the seed's normal.
//
//   struct SameValue {                                  // a criterion
//     const std::vector<double>& value;
//     double payload(Index point) const { return value[point]; }
//     bool accept(double seed, double from, double candidate) const { return candidate == seed; }
//   };
//   const Segmentation seg = growRegionsFromSeeds(graph, seeds, eligible, SameValue{value});
//
// A criterion's payload(point) is what accept(seed, from, candidate) reads of a point: the grower
// copies it next to the point's label in the graph's vertex order, so the walk reads one slot per
// neighbour, near the slots it read last (see KnnGraph), instead of the caller's arrays in input
// order.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/core/RadixSort.hpp"
#include "scalespace/core/Types.hpp"

namespace scalespace {

/// A partition of the (eligible) points: labels[i] = region of point i or -1.
struct Segmentation {
  std::vector<int> labels;
  std::vector<std::vector<Index>> regions;  // point indices, increasing; region r began at a seed
                                            // tried before that of region r+1
};

/// The points i < pointCount with a finite keyOf(i), by increasing key, ties by increasing index
/// (a stable radix sort), so the order depends on the keys alone. Points whose key is not finite
/// (NaN, +-inf) are no seeds.
template <class KeyOf>
std::vector<Index> seedsByIncreasingKey(std::size_t pointCount, KeyOf&& keyOf) {
  std::vector<KeyedIndex> keyed;
  keyed.reserve(pointCount);
  for (std::size_t i = 0; i < pointCount; ++i) {
    const double key = keyOf(Index(i));
    if (std::isfinite(key)) keyed.push_back({orderedKey(key), Index(i)});
  }
  radixSortStable(keyed);
  std::vector<Index> seeds(keyed.size());
  for (std::size_t s = 0; s < keyed.size(); ++s) seeds[s] = keyed[s].index;
  return seeds;
}

/// Grows one region from each seed not yet taken, in the order of `seeds` (point indices; taken
/// by value, as the grower renumbers them in place: move them in when done with them): the
/// region takes, through the graph's edges, every free eligible point q reached from a point p of
/// the region with criterion.accept(payload(seed), payload(p), payload(q)) (the seed bounds what
/// the region may become, p what a single step may cross). Points with eligible[i] == 0
/// join no region (label -1); a seed already taken (or ineligible) is skipped. Deterministic:
/// the result depends on the graph, the seeds, `eligible` and the criterion only.
/// Throws OptionError when `eligible` does not have one entry per vertex or a seed is out of
/// range.
template <class Criterion>
Segmentation growRegionsFromSeeds(const KnnGraph& graph, std::vector<Index> seeds,
                                  const std::vector<std::uint8_t>& eligible,
                                  const Criterion& criterion) {
  using Payload = std::decay_t<decltype(criterion.payload(Index(0)))>;
  const std::size_t n = graph.size();
  if (eligible.size() != n)
    throw OptionError("region grower: " + std::to_string(eligible.size()) +
                      " eligibility flags for a graph of " + std::to_string(n) + " points");

  // The walk runs over the graph's vertices: the Morton-ordered copy when there is one (see
  // KnnGraph), so that the per-vertex arrays below are read near where they were last read.
  // The regions (which points, which seed first) are the same in either numbering.
  const bool local =
      graph.order.size() == n && graph.localNeighbors.size() == graph.neighbors.size();
  const std::vector<Index>& adjacency = local ? graph.localNeighbors : graph.neighbors;
  auto pointOf = [&](Index v) { return local ? graph.order[v] : v; };
  // What the walk reads of a free neighbour, its label and payload, in one slot (two cache
  // misses per edge with separate arrays); 32 bytes for the planes' normal.
  struct alignas(32) Vertex {
    Payload payload;
    int label;  // -1 free, -2 ineligible (joins no region), else the region
  };
  std::vector<Vertex> vertex(n);
  // One bit per vertex, set once it is taken (labelled or ineligible): the walk tests it before
  // reading the slot. Most tests are of taken vertices (a vertex has ~k in-edges and is labelled
  // through one; most seeds were reached by an earlier region), and the bits of 1M vertices
  // (125 KB) stay in cache where their slots (32 MB) do not.
  std::vector<std::uint64_t> taken((n + 63) / 64, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, taken.size()), [&](const auto& r) {
    for (std::size_t w = r.begin(); w != r.end(); ++w) {
      std::uint64_t bits = 0;
      for (std::size_t v = 64 * w; v < std::min(n, 64 * w + 64); ++v) {
        const Index i = pointOf(Index(v));
        vertex[v] = {criterion.payload(i), eligible[i] ? -1 : -2};
        if (!eligible[i]) bits |= std::uint64_t(1) << (v - 64 * w);
      }
      taken[w] = bits;
    }
  });
  auto isTaken = [&](Index v) { return (taken[v >> 6] >> (v & 63)) & 1; };
  auto take = [&](Index v, int id) {
    vertex[v].label = id;
    taken[v >> 6] |= std::uint64_t(1) << (v & 63);
  };
  // The seeds as vertices, renumbered in place in one parallel pass (a random read each) before
  // the walk.
  if (!seeds.empty() && *std::max_element(seeds.begin(), seeds.end()) >= n)
    throw OptionError("region grower: a seed is out of range for a graph of " + std::to_string(n) +
                      " points");
  if (local)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seeds.size(), 4096), [&](const auto& r) {
      for (std::size_t s = r.begin(); s != r.end(); ++s) seeds[s] = graph.rank[seeds[s]];
    });

  // The walk labels the regions; their point lists are then filled in one pass over the points
  // in index order, which gives the increasing lists without sorting each region.
  std::vector<Index> frontier;
  std::vector<std::size_t> regionSize;
  // A local copy: the walk's calls (the frontier's growth) cannot change it, so what accept()
  // reads of it (the planes' cos theta) stays in registers.
  const Criterion walkCriterion = criterion;
  for (const Index seed : seeds) {
    if (isTaken(seed)) continue;
    const int id = int(regionSize.size());
    const Payload seedPayload = vertex[seed].payload;
    std::size_t size = 1;
    take(seed, id);
    frontier.assign(1, seed);
    while (!frontier.empty()) {
      const Index p = frontier.back();
      frontier.pop_back();
      for (std::size_t e = graph.offsets[p]; e < graph.offsets[p + 1]; ++e) {
        const Index v = adjacency[e];
        if (isTaken(v) || !walkCriterion.accept(seedPayload, vertex[p].payload, vertex[v].payload))
          continue;
        take(v, id);
        ++size;
        frontier.push_back(v);
      }
    }
    regionSize.push_back(size);
  }
  Segmentation seg;
  seg.labels.assign(n, -1);
  for (std::size_t v = 0; v < n; ++v) seg.labels[pointOf(Index(v))] = std::max(vertex[v].label, -1);
  seg.regions.resize(regionSize.size());
  for (std::size_t r = 0; r < regionSize.size(); ++r) seg.regions[r].reserve(regionSize[r]);
  for (std::size_t i = 0; i < n; ++i)
    if (seg.labels[i] >= 0) seg.regions[std::size_t(seg.labels[i])].push_back(Index(i));
  return seg;
}

}  // namespace scalespace
