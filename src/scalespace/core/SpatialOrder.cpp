#include "scalespace/core/SpatialOrder.hpp"

#include <tbb/parallel_for.h>

#include <limits>
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

}  // namespace

std::uint64_t mortonCode(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  return spreadBits(x) | spreadBits(y) << 1 | spreadBits(z) << 2;
}

std::vector<Index> spatialOrder(const std::vector<Vec3>& points) {
  const std::size_t n = points.size();
  if (n > std::size_t(std::numeric_limits<Index>::max()))
    throw OptionError("spatialOrder: at most 2^32 - 1 points");
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
      keyed[i] = {std::numeric_limits<std::uint64_t>::max(), Index(i)};
      return;
    }
    const Vec3 c = ((p - lo) * scale).array().floor().min(kCells - 1.0).max(0.0);
    keyed[i] = {mortonCode(std::uint32_t(c.x()), std::uint32_t(c.y()), std::uint32_t(c.z())),
                Index(i)};
  });
  // Stable by code over increasing indices: ties are broken by index.
  radixSortStable(keyed);
  std::vector<Index> order(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { order[i] = keyed[i].index; });
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
