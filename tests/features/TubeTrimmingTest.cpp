// Trimming a region to the points curving one way (features/TubeTrimming): a tube's wall grown
// over the concave junction onto the noisy surface it stands on comes back as the wall alone;
// a region that curves one way throughout is left as it is.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/features/TubeTrimming.hpp"

using namespace scalespace;

namespace {

/// A strip of a grid, x in [0, 3), y in [0, 1), spacing 0.05, read at t = 1: the wall (x < 1)
/// curves by kappa1 t = +0.3, the junction (1 <= x < 1.3) by -1.4 against it, the support beyond
/// by noise in [-0.15, 0.15].
struct Strip {
  std::vector<Vec3> positions;
  std::vector<float> kappa1;
  std::vector<Index> all, wall;
};

Strip wallJunctionAndSupport(float sign = 1) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> noise(-0.15f, 0.15f);
  Strip s;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 20; ++j) {
      const double x = 0.05 * i;
      const Index index = Index(s.positions.size());
      s.positions.emplace_back(x, 0.05 * j, 0);
      s.all.push_back(index);
      if (x < 1 - 1e-9) {
        s.kappa1.push_back(sign * 0.3f);
        s.wall.push_back(index);
      } else if (x < 1.3 - 1e-9) {
        s.kappa1.push_back(sign * -1.4f);
      } else {
        s.kappa1.push_back(noise(rng));
      }
    }
  return s;
}

}  // namespace

TEST(TubeTrimming, AWallGrownOverAConcaveJunctionIsTrimmedBackToTheWall) {
  const Strip s = wallJunctionAndSupport();
  const KnnGraph graph = buildKnnGraph(s.positions, 10);
  EXPECT_EQ(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 30), s.wall);
  // The sign is only the normals' orientation: a region curving the other way trims the same.
  const Strip flipped = wallJunctionAndSupport(-1);
  EXPECT_EQ(trimToOneCurvatureSign(graph, flipped.kappa1, flipped.all, 1, 0.02, 30), s.wall);
  // An accepted tube is tried only where enough of its points curve against it by at least
  // half the kept side's median (0.15 here): the junction alone, 120 of the 1,200 points.
  EXPECT_EQ(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 30, {}, 0.09), s.wall);
  EXPECT_TRUE(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 30, {}, 0.11).empty());
  // Indices beyond the graph are refused, not read.
  std::vector<Index> beyond = s.all;
  beyond.push_back(Index(s.positions.size()));
  EXPECT_THROW(trimToOneCurvatureSign(graph, s.kappa1, beyond, 1, 0.02, 30), OptionError);
  // Off, or a wall under minPoints: nothing.
  TubeTrimOptions off;
  off.enabled = false;
  EXPECT_TRUE(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 30, off).empty());
  EXPECT_TRUE(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 401).empty());
}

TEST(TubeTrimming, ARegionCurvingOneWayIsLeftAsItIs) {
  Strip s = wallJunctionAndSupport();
  for (float& k : s.kappa1) k = 0.3f;
  const KnnGraph graph = buildKnnGraph(s.positions, 10);
  EXPECT_TRUE(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 30).empty());
  // Flat (all under minCurvatureFactor): nothing to read a sign from.
  for (float& k : s.kappa1) k = 0.01f;
  EXPECT_TRUE(trimToOneCurvatureSign(graph, s.kappa1, s.all, 1, 0.02, 30).empty());
}

TEST(TubeTrimming, OptionsAreChecked) {
  TubeTrimOptions options;
  EXPECT_NO_THROW(validateTubeTrimOptions(options));
  for (const double bad : {-0.1, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    options = {};
    options.keepFraction = bad;
    EXPECT_THROW(validateTubeTrimOptions(options), OptionError) << bad;
    options = {};
    options.tubeMinAgainstShare = bad;
    EXPECT_THROW(validateTubeTrimOptions(options), OptionError) << bad;
  }
  options = {};
  options.minRadiusScales = std::numeric_limits<double>::infinity();
  EXPECT_THROW(validateTubeTrimOptions(options), OptionError);
}
