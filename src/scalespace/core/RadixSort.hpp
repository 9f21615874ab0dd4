#pragma once
// Stable least-significant-digit radix sort of (64-bit key, index) items: what the drivers sort
// once per call or per scale (Morton codes of a cloud, region-growing seeds by planarity). For
// 1M items it makes 8 linear passes (fewer when a digit is the same for all keys) where a
// comparison sort makes ~20 data-dependent ones.
//
//   std::vector<KeyedIndex> items;   // filled with increasing indices
//   radixSortStable(items);          // now by (key, index)
#include <cstdint>
#include <vector>

#include "scalespace/core/Types.hpp"

namespace scalespace {

struct KeyedIndex {
  std::uint64_t key;
  Index index;
};

/// Sorts by key, keeping the order of equal keys (so items filled with increasing indices end up
/// ordered by (key, index)). Deterministic and single-threaded.
void radixSortStable(std::vector<KeyedIndex>& items);

/// A key whose unsigned order is the order of the doubles (-inf < ... < -0 < +0 < ... < +inf);
/// NaNs go outside (a NaN with the sign bit before -inf, one without past +inf). Exact: every
/// double has its own key.
std::uint64_t orderedKey(double value);

}  // namespace scalespace
