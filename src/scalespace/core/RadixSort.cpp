#include "scalespace/core/RadixSort.hpp"

#include <array>
#include <cstring>

namespace scalespace {

void radixSortStable(std::vector<KeyedIndex>& items) {
  constexpr int kDigits = 8;  // of 8 bits: 256 buckets per pass stay in L1
  const std::size_t n = items.size();
  if (n < 2) return;
  // The histograms of all digits in one pass over the keys.
  std::vector<std::array<std::size_t, 256>> count(kDigits);
  for (auto& c : count) c.fill(0);
  for (const KeyedIndex& item : items)
    for (int d = 0; d < kDigits; ++d) ++count[std::size_t(d)][(item.key >> (8 * d)) & 0xffu];
  std::vector<KeyedIndex> buffer(n);
  std::vector<KeyedIndex>* from = &items;
  std::vector<KeyedIndex>* to = &buffer;
  for (int d = 0; d < kDigits; ++d) {
    std::array<std::size_t, 256>& c = count[std::size_t(d)];
    const unsigned digit0 = unsigned(((*from)[0].key >> (8 * d)) & 0xffu);
    if (c[digit0] == n) continue;  // the same digit for every key: the pass would copy
    std::size_t start = 0;
    for (std::size_t& bucket : c) {  // counts -> first slot of each bucket
      const std::size_t size = bucket;
      bucket = start;
      start += size;
    }
    const KeyedIndex* in = from->data();
    KeyedIndex* out = to->data();
    for (std::size_t i = 0; i < n; ++i) out[c[(in[i].key >> (8 * d)) & 0xffu]++] = in[i];
    std::swap(from, to);
  }
  if (from != &items) items.swap(buffer);
}

std::uint64_t orderedKey(double value) {
  std::uint64_t bits;
  std::memcpy(&bits, &value, 8);
  // Negative doubles order backwards by their bits: flip them all; positive ones: set the sign bit.
  return (bits >> 63) ? ~bits : bits | (std::uint64_t(1) << 63);
}

}  // namespace scalespace
