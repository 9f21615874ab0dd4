// RadixSort: the same order as a stable comparison sort, and keys that order doubles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "scalespace/core/RadixSort.hpp"

using namespace scalespace;

namespace {

void expectSortedLikeStableSort(std::vector<KeyedIndex> items) {
  std::vector<KeyedIndex> expected = items;
  std::stable_sort(expected.begin(), expected.end(),
                   [](const KeyedIndex& a, const KeyedIndex& b) { return a.key < b.key; });
  radixSortStable(items);
  ASSERT_EQ(items.size(), expected.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    ASSERT_EQ(items[i].key, expected[i].key) << i;
    ASSERT_EQ(items[i].index, expected[i].index) << i;
  }
}

}  // namespace

TEST(RadixSort, MatchesStableSortOnWideNarrowAndRepeatedKeys) {
  std::mt19937_64 rng(3);
  for (const std::size_t n : {0, 1, 2, 17, 1000, 100000}) {
    std::vector<KeyedIndex> wide(n), narrow(n), repeated(n);
    for (std::size_t i = 0; i < n; ++i) {
      wide[i] = {rng(), Index(i)};
      narrow[i] = {(rng() & 0xff00u) | (std::uint64_t(1) << 60), Index(i)};  // 2 digits vary
      repeated[i] = {rng() % 5, Index(i)};  // many ties: their index order must survive
    }
    expectSortedLikeStableSort(wide);
    expectSortedLikeStableSort(narrow);
    expectSortedLikeStableSort(repeated);
  }
  std::vector<KeyedIndex> same(50, KeyedIndex{42, 0});
  for (std::size_t i = 0; i < same.size(); ++i) same[i].index = Index(49 - i);
  expectSortedLikeStableSort(same);
}

TEST(RadixSort, OrderedKeysOrderDoubles) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> increasing = {-inf,    -1e300, -2.5, -1.0,
                                          -1e-310, -0.0,   0.0,  1e-310,
                                          1e-300,  0.5,    1.0,  std::nextafter(1.0, 2.0),
                                          3e10,    1e308,  inf};
  for (std::size_t i = 0; i + 1 < increasing.size(); ++i)
    EXPECT_LT(orderedKey(increasing[i]), orderedKey(increasing[i + 1])) << increasing[i];
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g(0, 1e3);
  for (int k = 0; k < 100000; ++k) {
    const double a = g(rng), b = g(rng);
    ASSERT_EQ(a < b, orderedKey(a) < orderedKey(b)) << a << " " << b;
  }
}
