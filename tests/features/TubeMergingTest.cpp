// Merging the touching tubes of one scale (features/TubeMerging): two pieces of one pipe become
// one tube, two strands side by side and a step in radius stay apart.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/features/TubeMerging.hpp"

using namespace scalespace;

namespace {

struct Scene {
  std::vector<Vec3> positions, normals;
  std::vector<float> kappa1;
  std::vector<int> part;  // which region each point starts in
};

/// Points of a tube of radius r around the axis through `centre` along x, for x in [x0, x1),
/// with exact outward normals and kappa1 = 1 / r (convex).
void addTube(Scene& s, const Vec3& centre, double r, double x0, double x1, int part,
             std::size_t count, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  for (std::size_t k = 0; k < count; ++k) {
    const double a = 2 * kPi * u(rng), x = x0 + (x1 - x0) * u(rng);
    const Vec3 n(0, std::cos(a), std::sin(a));
    s.positions.push_back(centre + Vec3(x, 0, 0) + r * n);
    s.normals.push_back(n);
    s.kappa1.push_back(float(1 / r));
    s.part.push_back(part);
  }
}

struct Merged {
  std::vector<TubeFit> tubes;
  std::vector<std::vector<Index>> regions;
};

/// One region per part, a tube fitted to each, then the merge (`groups`: mergeTouchingTubes'
/// `apart`).
Merged fitAndMerge(const Scene& s, int parts, double t, const std::vector<int>& groups = {}) {
  LineAnisotropyField field;
  field.scale = t;
  field.normal = s.normals;
  field.kappa1 = s.kappa1;
  Merged m;
  m.regions.resize(std::size_t(parts));
  for (std::size_t i = 0; i < s.part.size(); ++i)
    m.regions[std::size_t(s.part[i])].push_back(Index(i));
  for (const auto& region : m.regions)
    m.tubes.push_back(fitTube(s.positions, s.normals, field.normal, field.kappa1, region, t));
  for (const TubeFit& tube : m.tubes)
    EXPECT_TRUE(tube.isTube()) << tubeRejectionName(tube.rejection);
  const KnnGraph graph = buildKnnGraph(s.positions, 10);
  mergeTouchingTubes(graph, s.positions, s.normals, field, t, {}, m.tubes, m.regions, groups);
  return m;
}

}  // namespace

TEST(TubeMerging, TwoPiecesOfOnePipeBecomeOneTube) {
  std::mt19937_64 rng(1);
  Scene s;
  addTube(s, Vec3::Zero(), 0.1, -0.6, 0.0, 0, 4000, rng);
  addTube(s, Vec3::Zero(), 0.1, 0.0, 0.6, 1, 4000, rng);
  const Merged m = fitAndMerge(s, 2, 0.05);
  EXPECT_TRUE(m.tubes[0].isTube());
  EXPECT_EQ(m.tubes[1].rejection, TubeRejection::Merged);
  EXPECT_EQ(m.regions[0].size(), 8000u);
  EXPECT_TRUE(m.regions[1].empty());
  EXPECT_TRUE(std::is_sorted(m.regions[0].begin(), m.regions[0].end()));
  EXPECT_NEAR(m.tubes[0].radius, 0.1, 0.002);
  EXPECT_NEAR(m.tubes[0].length, 1.2, 0.05);
  const std::vector<int> owner = tubeOwners(s.positions.size(), m.tubes, m.regions);
  EXPECT_EQ(std::count(owner.begin(), owner.end(), 0), 8000);
}

TEST(TubeMerging, StrandsSideBySideAndAStepInRadiusStayApart) {
  std::mt19937_64 rng(2);
  Scene strands;  // two touching strands of radius 0.05, axes 0.1 apart
  addTube(strands, Vec3(0, -0.05, 0), 0.05, -0.5, 0.5, 0, 4000, rng);
  addTube(strands, Vec3(0, 0.05, 0), 0.05, -0.5, 0.5, 1, 4000, rng);
  const Merged a = fitAndMerge(strands, 2, 0.03);
  EXPECT_TRUE(a.tubes[0].isTube());
  EXPECT_TRUE(a.tubes[1].isTube());
  EXPECT_EQ(a.regions[1].size(), 4000u);

  Scene step;  // radius 0.1 then 0.06 along one axis: 40% apart
  addTube(step, Vec3::Zero(), 0.1, -0.6, 0.0, 0, 4000, rng);
  addTube(step, Vec3::Zero(), 0.06, 0.0, 0.6, 1, 4000, rng);
  const Merged b = fitAndMerge(step, 2, 0.04);
  EXPECT_TRUE(b.tubes[0].isTube());
  EXPECT_TRUE(b.tubes[1].isTube());
  EXPECT_NEAR(b.tubes[1].radius, 0.06, 0.002);
}

TEST(TubeMerging, PiecesOfOneSplitRegionEndToEndMerge) {
  // Parts of one region split by their axes (features/TubeSplitting) share a group: end to end
  // they are pieces of one strand and merge. (Side by side, strands, they stay apart even where a
  // curved axis zigzagging between them lets their union pass as one tube: seen on the noisy pipe
  // rack, bench_cylinders, not built here.)
  std::mt19937_64 rng(5);
  Scene ends;  // three pieces of one pipe, end to end; the first two of one split
  addTube(ends, Vec3::Zero(), 0.1, -0.6, 0.0, 0, 4000, rng);
  addTube(ends, Vec3::Zero(), 0.1, 0.0, 0.6, 1, 4000, rng);
  addTube(ends, Vec3::Zero(), 0.1, 0.6, 1.2, 2, 4000, rng);
  const Merged a = fitAndMerge(ends, 3, 0.03, {7, 7, -1});
  EXPECT_TRUE(a.tubes[0].isTube());
  EXPECT_EQ(a.regions[0].size(), 12000u);
  EXPECT_EQ(a.tubes[1].rejection, TubeRejection::Merged);
  EXPECT_EQ(a.tubes[2].rejection, TubeRejection::Merged);
}

TEST(TubeMerging, PartsOfOneSplitMergeOnlyWhereTheyMayBeOneStrand) {
  // A cable scanned from one side shows its strands in turn: the run of one strand ends where the
  // next strand's begins, two radii aside. Of one split, such parts are two strands; two pieces of
  // one pipe end to end are one (mayBeOneStrand, features/TubeSplitting).
  std::mt19937_64 rng(7);
  Scene runs, pieces;
  addTube(runs, Vec3(0, -0.05, 0), 0.05, -0.4, 0.0, 0, 3000, rng);
  addTube(runs, Vec3(0, 0.05, 0), 0.05, 0.0, 0.4, 1, 3000, rng);
  addTube(pieces, Vec3::Zero(), 0.05, -0.4, 0.0, 0, 3000, rng);
  addTube(pieces, Vec3::Zero(), 0.05, 0.0, 0.4, 1, 3000, rng);
  const double t = 0.03;
  const Merged apart = fitAndMerge(runs, 2, t, {3, 3});
  EXPECT_FALSE(mayBeOneStrand(apart.tubes[0], apart.tubes[1]));
  EXPECT_TRUE(apart.tubes[0].isTube());
  EXPECT_TRUE(apart.tubes[1].isTube());
  EXPECT_EQ(apart.regions[1].size(), 3000u);
  const auto fitPart = [&](int part) {
    std::vector<Index> region;
    for (std::size_t i = 0; i < pieces.part.size(); ++i)
      if (pieces.part[i] == part) region.push_back(Index(i));
    return fitTube(pieces.positions, pieces.normals, pieces.normals, pieces.kappa1, region, t);
  };
  EXPECT_TRUE(mayBeOneStrand(fitPart(0), fitPart(1)));
  const Merged one = fitAndMerge(pieces, 2, t, {3, 3});
  EXPECT_EQ(one.tubes[1].rejection, TubeRejection::Merged);
  EXPECT_EQ(one.regions[0].size(), 6000u);
}
