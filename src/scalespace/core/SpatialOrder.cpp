#include "scalespace/core/SpatialOrder.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <string>

#include "scalespace/core/RadixSort.hpp"

namespace scalespace {
namespace {

// Spreads the low 21 bits of v so that there are two zero bits between consecutive bits.
std::uint64_t spreadBits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

constexpr std::uint64_t kNonFinite = std::numeric_limits<std::uint64_t>::max();

// (Morton code, index) of every point, sorted by code then index.
std::vector<KeyedIndex> sortedMortonCodes(const std::vector<Vec3>& points, const char* caller) {
  const std::size_t n = points.size();
  if (n > std::size_t(std::numeric_limits<Index>::max()))
    throw OptionError(std::string(caller) + ": at most 2^32 - 1 points");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : points)
    if (p.allFinite()) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  // One cubic cell size for all axes keeps the curve's cells cubes (a flat cloud stays local).
  const double extent = (hi - lo).maxCoeff();
  constexpr double kCells = double(1u << 21);
  const double scale = extent > 0.0 ? (kCells - 1.0) / extent : 0.0;
  std::vector<KeyedIndex> keyed(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    const Vec3& p = points[i];
    if (!p.allFinite()) {
      keyed[i] = {kNonFinite, Index(i)};
      return;
    }
    const Vec3 c = ((p - lo) * scale).array().floor().min(kCells - 1.0).max(0.0);
    keyed[i] = {mortonCode(std::uint32_t(c.x()), std::uint32_t(c.y()), std::uint32_t(c.z())),
                Index(i)};
  });
  // Stable by code over increasing indices: ties are broken by index.
  radixSortStable(keyed);
  return keyed;
}

std::vector<Index> indicesOf(const std::vector<KeyedIndex>& keyed) {
  std::vector<Index> order(keyed.size());
  tbb::parallel_for(std::size_t(0), keyed.size(),
                    [&](std::size_t i) { order[i] = keyed[i].index; });
  return order;
}

}  // namespace

std::uint64_t mortonCode(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return spreadBits(x) | spreadBits(y) << 1 | spreadBits(z) << 2;
}

std::vector<Index> spatialOrder(const std::vector<Vec3>& points) {
  return indicesOf(sortedMortonCodes(points, "spatialOrder"));
}

std::vector<Index> coarseToFineOrder(const std::vector<Vec3>& points) {
  const std::vector<KeyedIndex> sorted = sortedMortonCodes(points, "coarseToFineOrder");
  const std::size_t n = sorted.size();
  // Along the curve, a point is the first of its cell at level L (cells 2^-L of the cube wide)
  // exactly when it shares no level-L cell with the point before it: its level is one more than
  // the deepest level they share (21 bits per axis: levels 0..21; 22 for a repeated finest cell).
  constexpr std::size_t kRepeated = 22, kLast = 23, kLevels = 24;
  std::vector<std::uint8_t> level(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    const std::uint64_t code = sorted[i].key;
    std::size_t l = 0;
    if (code == kNonFinite) {
      l = kLast;
    } else if (i > 0) {
      const std::uint64_t differ = code ^ sorted[i - 1].key;
      l = differ == 0 ? kRepeated : 21 - std::size_t(63 - __builtin_clzll(differ)) / 3;
    }
    level[i] = std::uint8_t(l);
  });
  // Group by level, each level in curve order (a counting sort)...
  std::array<std::size_t, kLevels + 1> start{};
  for (std::uint8_t l : level) ++start[l + 1];
  for (std::size_t l = 0; l < kLevels; ++l) start[l + 1] += start[l];
  std::vector<Index> byLevel(n);
  std::array<std::size_t, kLevels> next{};
  std::copy(start.begin(), start.begin() + kLevels, next.begin());
  for (std::size_t i = 0; i < n; ++i) byLevel[next[level[i]]++] = sorted[i].index;
  // ... then within a level the k-th point is the (k * stride mod count)-th along the curve, a
  // stride near count / golden ratio and prime to count: any prefix of a level visits the curve
  // evenly (a Kronecker sequence), without a second sort.
  std::vector<Index> order(n);
  for (std::size_t l = 0; l < kLevels; ++l) {
    const std::size_t first = start[l], count = start[l + 1] - start[l];
    if (count == 0) continue;
    std::size_t stride = std::max<std::size_t>(1, std::size_t(double(count) * 0.6180339887498949));
    while (std::gcd(stride, count) != 1) ++stride;
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t k) {
      order[first + k] = byLevel[first + (k * stride) % count];
    });
  }
  return order;
}

std::vector<Index> invertPermutation(const std::vector<Index>& order) {
  const std::size_t n = order.size();
  constexpr Index kUnset = std::numeric_limits<Index>::max();
  std::vector<Index> inverse(n, kUnset);
  for (std::size_t i = 0; i < n; ++i) {
    if (order[i] >= n || inverse[order[i]] != kUnset)
      throw OptionError("invertPermutation: entry " + std::to_string(i) + " (" +
                        std::to_string(order[i]) + ") makes this not a permutation of 0.." +
                        std::to_string(n == 0 ? 0 : n - 1));
    inverse[order[i]] = Index(i);
  }
  return inverse;
}

}  // namespace scalespace
