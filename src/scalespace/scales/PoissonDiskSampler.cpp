#include "scalespace/scales/PoissonDiskSampler.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"

namespace scalespace {
namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

constexpr int kCellBits = 21;  // per axis, packed into a 63-bit key
constexpr std::int64_t kCellMax = (std::int64_t(1) << kCellBits) - 4;

struct Candidate {
  std::uint64_t cell;   // packed cell coordinates
  std::uint64_t order;  // seeded random key inside the cell
  Index point;
};

std::uint64_t packCell(std::int64_t x, std::int64_t y, std::int64_t z) {
  return (std::uint64_t(x) << (2 * kCellBits)) | (std::uint64_t(y) << kCellBits) | std::uint64_t(z);
}

/// The occupied cells among the 27 around a cell, as indices into the sorted keys of the occupied
/// cells. For fixed (dx, dy) the keys of z - 1, z, z + 1 are consecutive, so 9 searches suffice,
/// and their targets grow with the cell's own key: asked for cells of increasing key (one colour
/// of a task's range), each search gallops forward from where it ended for the previous cell.
/// Cheaper than 9 binary searches over all cells per cell: at the first levels a cell holds about
/// one point, so there are about as many cells as points (sampling time of bench/fig_1_10
/// --mode timing).
class NeighbourCells {
 public:
  explicit NeighbourCells(const std::vector<std::uint64_t>& keys) : keys_(keys) {}

  int find(std::int64_t x, std::int64_t y, std::int64_t z, std::size_t* near) {
    int count = 0, s = 0;
    const std::size_t n = keys_.size();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy, ++s) {
        const std::uint64_t first = packCell(x + dx, y + dy, z - 1);
        const std::uint64_t last = packCell(x + dx, y + dy, z + 1);
        std::size_t k = cursor_[s] = firstNotBelow(cursor_[s], first);
        for (; k < n && keys_[k] <= last; ++k) near[count++] = k;
      }
    return count;
  }

 private:
  /// The first k >= from with keys_[k] >= v (keys_.size() if none): exponential then binary search.
  std::size_t firstNotBelow(std::size_t from, std::uint64_t v) const {
    const std::size_t n = keys_.size();
    if (from >= n || keys_[from] >= v) return from;
    std::size_t below = from, step = 1;  // keys_[below] < v
    while (below + step < n && keys_[below + step] < v) below += step, step *= 2;
    const auto end = keys_.begin() + std::ptrdiff_t(std::min(n, below + step));
    return std::size_t(std::lower_bound(keys_.begin() + std::ptrdiff_t(below) + 1, end, v) -
                       keys_.begin());
  }

  const std::vector<std::uint64_t>& keys_;
  std::size_t cursor_[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
};

/// The accepted samples of every cell (accepted[cellBegin[q] .. + count[q])) in increasing index
/// order. When they are a sizeable share of the cloud's `n` points a flag per point is scanned
/// instead of sorting (the first levels keep ~90% of the points: a serial sort of 0.9M indices).
std::vector<Index> increasingIndices(const std::vector<Index>& accepted,
                                     const std::vector<std::size_t>& cellBegin,
                                     const std::vector<std::uint32_t>& count, std::size_t n) {
  std::size_t total = 0;
  for (std::uint32_t k : count) total += k;
  std::vector<Index> out;
  out.reserve(total);
  if (total < n / 16) {
    for (std::size_t q = 0; q < count.size(); ++q)
      out.insert(out.end(), accepted.begin() + std::ptrdiff_t(cellBegin[q]),
                 accepted.begin() + std::ptrdiff_t(cellBegin[q] + count[q]));
    std::sort(out.begin(), out.end());
    return out;
  }
  std::vector<std::uint8_t> kept(n, 0);
  for (std::size_t q = 0; q < count.size(); ++q)
    for (std::size_t a = cellBegin[q]; a < cellBegin[q] + count[q]; ++a) kept[accepted[a]] = 1;
  for (std::size_t i = 0; i < n; ++i)
    if (kept[i]) out.push_back(Index(i));
  return out;
}

// r(i, k) of the rejection rule: the larger separation (homogeneous: the separation).
template <class RadiusOf>
std::vector<Index> gridSample(const std::vector<Vec3>& positions,
                              const std::vector<Index>& candidates, double maxSeparation,
                              const RadiusOf& separationOf, std::uint64_t seed) {
  if (candidates.empty()) return {};
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Index i : candidates) {
    lo = lo.cwiseMin(positions[i]);
    hi = hi.cwiseMax(positions[i]);
  }
  // A cell of size >= r keeps every conflict within the 27 neighbouring cells; grow it when the
  // grid would overflow the 21-bit cell coordinates (still correct, just more points per cell).
  const double extent = (hi - lo).maxCoeff();
  const double cell = std::max(maxSeparation, extent / double(kCellMax));
  std::vector<Candidate> c(candidates.size());
  parallelFor(candidates.size(), [&](std::size_t k) {
    const Index i = candidates[k];
    const Vec3 g = (positions[i] - lo) / cell;
    c[k] = {packCell(std::int64_t(g.x()) + 1, std::int64_t(g.y()) + 1, std::int64_t(g.z()) + 1),
            sampleOrderKey(seed, i), i};
  });
  // (cell, order, point) is a total order, so the parallel sort is deterministic.
  tbb::parallel_sort(c.begin(), c.end(), [](const Candidate& a, const Candidate& b) {
    return a.cell != b.cell     ? a.cell < b.cell
           : a.order != b.order ? a.order < b.order
                                : a.point < b.point;
  });
  // Cells as runs of the sorted array (keys in cellKey, increasing), grouped by colour (parity
  // of the three coordinates).
  std::vector<std::size_t> cellBegin;
  std::vector<std::uint64_t> cellKey;
  for (std::size_t k = 0; k < c.size(); ++k)
    if (k == 0 || c[k].cell != c[k - 1].cell) cellBegin.push_back(k), cellKey.push_back(c[k].cell);
  const std::size_t cellCount = cellBegin.size();
  cellBegin.push_back(c.size());
  std::vector<std::vector<std::size_t>> byColour(8);
  const std::uint64_t mask = (std::uint64_t(1) << kCellBits) - 1;
  for (std::size_t q = 0; q < cellCount; ++q) {
    const std::uint64_t key = cellKey[q];
    const int colour =
        int(((key >> (2 * kCellBits)) & 1) | (((key >> kCellBits) & 1) << 1) | ((key & 1) << 2));
    byColour[std::size_t(colour)].push_back(q);
  }
  // Accepted samples of cell q are kept compactly in accepted[cellBegin[q] .. + acceptedCount[q]):
  // a cell of size >= r holds a bounded number of samples, so checking a candidate costs O(1)
  // however many candidates the neighbouring cells hold. A cell is written only by its own task,
  // and cells of the same colour are never neighbours, so there is no race.
  std::vector<Index> accepted(c.size());
  std::vector<std::uint32_t> acceptedCount(cellCount, 0);
  for (const auto& cells : byColour) {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, cells.size(), 16),
        [&](const tbb::blocked_range<std::size_t>& range) {
          NeighbourCells neighbours(cellKey);
          for (std::size_t ci = range.begin(); ci != range.end(); ++ci) {
            const std::size_t q = cells[ci];
            const std::uint64_t key = cellKey[q];
            std::size_t near[27];
            const int nearCount = neighbours.find(std::int64_t((key >> (2 * kCellBits)) & mask),
                                                  std::int64_t((key >> kCellBits) & mask),
                                                  std::int64_t(key & mask), near);
            for (std::size_t k = cellBegin[q]; k < cellBegin[q + 1]; ++k) {
              const Index candidate = c[k].point;
              const Vec3& p = positions[candidate];
              bool free = true;
              for (int nb = 0; nb < nearCount && free; ++nb) {
                const std::size_t f = near[nb];
                for (std::size_t a = cellBegin[f]; a < cellBegin[f] + acceptedCount[f]; ++a) {
                  const double r = separationOf(candidate, accepted[a]);
                  if ((positions[accepted[a]] - p).squaredNorm() < r * r) {
                    free = false;
                    break;
                  }
                }
              }
              if (free) accepted[cellBegin[q] + acceptedCount[q]++] = candidate;
            }
          }
        });
  }
  return increasingIndices(accepted, cellBegin, acceptedCount, positions.size());
}

}  // namespace

std::uint64_t sampleOrderKey(std::uint64_t seed, Index i) {
  return splitmix64(splitmix64(seed) ^ std::uint64_t(i));
}

double poissonDiskSeparation(double alpha, double t) { return 2 * alpha * t; }

std::uint64_t pyramidLevelSeed(std::uint64_t seed, std::size_t level) {
  // Each level gets its own seed so that visiting orders are not correlated across levels.
  return seed + 0x632be59bd9b4e019ULL * (level + 1);
}

std::vector<Index> poissonDiskSample(const std::vector<Vec3>& positions, double separation,
                                     std::uint64_t seed) {
  std::vector<Index> all(positions.size());
  std::iota(all.begin(), all.end(), Index(0));
  return poissonDiskSample(positions, all, separation, seed);
}

std::vector<Index> poissonDiskSample(const std::vector<Vec3>& positions,
                                     const std::vector<Index>& candidates, double separation,
                                     std::uint64_t seed) {
  if (!std::isfinite(separation)) throw OptionError("Poisson-disk separation must be finite");
  if (separation <= 0) {
    std::vector<Index> all = candidates;
    std::sort(all.begin(), all.end());
    return all;
  }
  return gridSample(
      positions, candidates, separation, [separation](Index, Index) { return separation; }, seed);
}

std::vector<Index> poissonDiskSampleAdaptive(const std::vector<Vec3>& positions,
                                             const std::vector<Index>& candidates,
                                             const std::vector<double>& separations,
                                             std::uint64_t seed) {
  if (separations.size() != positions.size())
    throw OptionError("adaptive Poisson-disk sampling: " + std::to_string(separations.size()) +
                      " separations for " + std::to_string(positions.size()) + " points");
  double maxSeparation = 0;
  for (Index i : candidates) {
    if (!std::isfinite(separations[i]) || separations[i] < 0)
      throw OptionError("adaptive Poisson-disk separation of point " + std::to_string(i) +
                        " must be finite and >= 0");
    maxSeparation = std::max(maxSeparation, separations[i]);
  }
  if (maxSeparation <= 0) {
    std::vector<Index> all = candidates;
    std::sort(all.begin(), all.end());
    return all;
  }
  return gridSample(
      positions, candidates, maxSeparation,
      [&separations](Index a, Index b) { return std::max(separations[a], separations[b]); }, seed);
}

std::vector<Index> poissonDiskSampleGreedy(const std::vector<Vec3>& positions,
                                           const std::vector<Index>& candidates, double separation,
                                           std::uint64_t seed) {
  if (separation <= 0) {
    std::vector<Index> all = candidates;
    std::sort(all.begin(), all.end());
    return all;
  }
  std::vector<Vec3> pts;
  pts.reserve(candidates.size());
  for (Index i : candidates) pts.push_back(positions[i]);
  auto index = makeSpatialIndex(pts);
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto ka = sampleOrderKey(seed, candidates[a]), kb = sampleOrderKey(seed, candidates[b]);
    return ka != kb ? ka < kb : candidates[a] < candidates[b];
  });
  std::vector<std::uint8_t> removed(candidates.size(), 0);
  std::vector<Neighbor> nb;
  std::vector<Index> out;
  for (std::size_t k : order) {
    if (removed[k]) continue;
    out.push_back(candidates[k]);
    index->radiusSearch(pts[k], separation, nb);
    for (const Neighbor& n : nb) removed[n.index] = 1;
  }
  std::sort(out.begin(), out.end());
  return out;
}

void validatePyramidAlpha(double alpha) {
  if (!(alpha >= 0) || !std::isfinite(alpha))
    throw OptionError(
        "ScaleSpaceOptions::alpha (Poisson-disk radius / scale) must be finite and >= 0, got " +
        std::to_string(alpha));
}

std::vector<Index> samplePyramidLevel(const std::vector<Vec3>& positions,
                                      const std::vector<Index>& previous, double alpha, double t,
                                      std::uint64_t seed, std::size_t level) {
  validatePyramidAlpha(alpha);
  return poissonDiskSample(positions, previous, poissonDiskSeparation(alpha, t),
                           pyramidLevelSeed(seed, level));
}

SamplePyramid buildSamplePyramid(const std::vector<Vec3>& positions,
                                 const std::vector<double>& scales, double alpha,
                                 std::uint64_t seed, const ProgressCallback& progress) {
  validatePyramidAlpha(alpha);
  SamplePyramid pyramid;
  std::vector<Index> previous(positions.size());
  std::iota(previous.begin(), previous.end(), Index(0));
  for (std::size_t j = 0; j < scales.size(); ++j) {
    std::vector<Index> level = samplePyramidLevel(positions, previous, alpha, scales[j], seed, j);
    pyramid.radii.push_back(alpha * scales[j]);
    pyramid.levels.push_back(level);
    previous = std::move(level);
    if (progress && !progress(double(j + 1) / double(scales.size()), "Poisson-disk pyramid"))
      throw Cancelled();
  }
  return pyramid;
}

}  // namespace scalespace
