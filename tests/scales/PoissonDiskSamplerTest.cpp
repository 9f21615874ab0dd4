#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "scales/ScalesTestClouds.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"

namespace scalespace {
namespace {

std::vector<Index> all(std::size_t n) {
  std::vector<Index> v(n);
  std::iota(v.begin(), v.end(), Index(0));
  return v;
}

// Separation and coverage by brute force: no two samples closer than r(a, b); every candidate
// within r(c, s) of some sample s.
template <class R>
void expectPoissonDisk(const std::vector<Vec3>& p, const std::vector<Index>& candidates,
                       const std::vector<Index>& sample, const R& radius) {
  ASSERT_TRUE(std::is_sorted(sample.begin(), sample.end()));
  ASSERT_TRUE(std::includes(candidates.begin(), candidates.end(), sample.begin(), sample.end()));
  for (std::size_t a = 0; a < sample.size(); ++a)
    for (std::size_t b = a + 1; b < sample.size(); ++b)
      ASSERT_GE((p[sample[a]] - p[sample[b]]).norm(), radius(sample[a], sample[b]))
          << sample[a] << " " << sample[b];
  for (Index c : candidates) {
    bool covered = false;
    for (Index s : sample)
      if ((p[c] - p[s]).norm() < radius(c, s) || c == s) {
        covered = true;
        break;
      }
    ASSERT_TRUE(covered) << "candidate " << c << " is not covered";
  }
}

TEST(PoissonDisk, SeparationAndCoverageOnRandomAndClusteredClouds) {
  for (const auto& p : {test::randomCube(3000, 1), test::clusteredCloud(3000, 2)}) {
    for (double r : {0.01, 0.05, 0.2}) {
      const auto cand = all(p.size());
      const auto s = poissonDiskSample(p, cand, r, 7);
      expectPoissonDisk(p, cand, s, [r](Index, Index) { return r; });
      EXPECT_LT(s.size(), p.size());
      EXPECT_GT(s.size(), 0u);
      // The greedy reference obeys the same rule.
      const auto g = poissonDiskSampleGreedy(p, cand, r, 7);
      expectPoissonDisk(p, cand, g, [r](Index, Index) { return r; });
    }
  }
}

TEST(PoissonDisk, AdaptiveRadii) {
  const auto p = test::clusteredCloud(2000, 5);
  std::vector<double> radii(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) radii[i] = 0.01 + 0.2 * double(i % 7) / 7.0;
  const auto cand = all(p.size());
  const auto s = poissonDiskSampleAdaptive(p, cand, radii, 3);
  expectPoissonDisk(p, cand, s, [&](Index a, Index b) { return std::max(radii[a], radii[b]); });
}

TEST(PoissonDisk, ZeroRadiusKeepsEverything) {
  const auto p = test::randomCube(100, 1);
  std::vector<Index> cand = {5, 3, 9};
  EXPECT_EQ(poissonDiskSample(p, cand, 0.0, 1), (std::vector<Index>{3, 5, 9}));
}

TEST(PoissonDisk, DeterministicAcrossThreadCountsAndSeeded) {
  const auto p = test::clusteredCloud(20000, 9);
  const auto cand = all(p.size());
  std::vector<Index> one, two;
  {
    ThreadLimit limit(1);
    one = poissonDiskSample(p, cand, 0.03, 11);
  }
  {
    ThreadLimit limit(2);
    two = poissonDiskSample(p, cand, 0.03, 11);
  }
  EXPECT_EQ(one, two);
  EXPECT_EQ(poissonDiskSample(p, cand, 0.03, 11), one);
  EXPECT_NE(poissonDiskSample(p, cand, 0.03, 12), one);  // another seed, another sample
}

TEST(PoissonDisk, PyramidIsNestedAndEachLevelIsADiskSampleOfThePrevious) {
  const auto p = test::randomCube(2000, 4);
  const std::vector<double> scales = {0.05, 0.1, 0.2, 0.4, 0.8};
  const auto pyr = buildSamplePyramid(p, scales, 0.25, 3);
  ASSERT_EQ(pyr.levels.size(), scales.size());
  std::vector<Index> previous = all(p.size());
  for (std::size_t j = 0; j < scales.size(); ++j) {
    EXPECT_DOUBLE_EQ(pyr.radii[j], 0.25 * scales[j]);
    // Disks of radius r_j do not overlap: separation and coverage 2 r_j (Sec. 1.5.2).
    const double r = 2 * pyr.radii[j];
    expectPoissonDisk(p, previous, pyr.levels[j], [r](Index, Index) { return r; });
    EXPECT_LE(pyr.levels[j].size(), previous.size());
    previous = pyr.levels[j];
  }
  EXPECT_LT(pyr.levels.back().size(), 100u);
  EXPECT_EQ(buildSamplePyramid(p, scales, 0.0, 3).levels.back().size(), p.size());
  EXPECT_THROW(buildSamplePyramid(p, scales, -0.1, 3), OptionError);
}

TEST(PoissonDisk, HugeExtentDoesNotOverflowTheGrid) {
  std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1e-9, 0, 0), Vec3(1e6, 0, 0), Vec3(1e6, 1e-9, 0)};
  const auto s = poissonDiskSample(p, all(4), 1e-6, 1);
  EXPECT_EQ(s.size(), 2u);
}

}  // namespace
}  // namespace scalespace
