// Boundary refinement of merged regions (planes/BoundaryRefinement.hpp): a staircase's mean ramp
// takes back the tread edges that a vertical side's region holds, and nothing else moves: not the
// side's own points, not into a region that is no union, not out of a small region, not between
// two regions of one plane.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "scalespace/core/Error.hpp"
#include "scalespace/planes/BoundaryRefinement.hpp"

using namespace scalespace;

namespace {

constexpr double kSpacing = 0.03;
constexpr double kSide = 1.2;  // the staircase spans x in [0, 1.2]; its side wall is x = 1.2

// Points on a grid over the parallelogram corner + [0,1] u + [0,1] v, kSpacing apart, labelled
// by `label(point)`.
template <class Label>
void addFace(std::vector<Vec3>& points, std::vector<int>& labels, const Vec3& corner, const Vec3& u,
             const Vec3& v, Label&& label) {
  const int nu = std::max(1, int(std::round(u.norm() / kSpacing)));
  const int nv = std::max(1, int(std::round(v.norm() / kSpacing)));
  for (int a = 0; a < nu; ++a)
    for (int b = 0; b < nv; ++b) {
      const Vec3 p = corner + (a + 0.5) / nu * u + (b + 0.5) / nv * v;
      labels.push_back(label(p));
      points.push_back(p);
    }
}

Segmentation segmentationOf(const std::vector<int>& labels, int regionCount) {
  Segmentation seg;
  seg.labels = labels;
  seg.regions.resize(std::size_t(regionCount));
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] >= 0) seg.regions[std::size_t(labels[i])].push_back(Index(i));
  return seg;
}

// Six steps 0.3 deep and 0.18 high (region 0, the merged ramp) beside a vertical side wall at
// x = 1.2 (region 1), as the robust fit at t = 0.8 leaves them: the side's region holds the
// treads' and risers' outer `band` along x.
struct Scene {
  std::vector<Vec3> points;
  Segmentation seg;
};

Scene staircaseBesideAWall(double band) {
  Scene s;
  std::vector<int> labels;
  const auto stairLabel = [&](const Vec3& p) { return p.x() > kSide - band ? 1 : 0; };
  for (int k = 0; k < 6; ++k) {
    addFace(s.points, labels, Vec3(0, 0.3 * k, 0.18 * k), Vec3(kSide, 0, 0), Vec3(0, 0, 0.18),
            stairLabel);
    addFace(s.points, labels, Vec3(0, 0.3 * k, 0.18 * (k + 1)), Vec3(kSide, 0, 0), Vec3(0, 0.3, 0),
            stairLabel);
  }
  addFace(s.points, labels, Vec3(kSide, 0, 0), Vec3(0, 1.8, 0), Vec3(0, 0, 1.08),
          [](const Vec3&) { return 1; });
  s.seg = segmentationOf(labels, 2);
  return s;
}

using O = RegionOrigin;
const std::vector<O> kRampMerged = {O::merged, O::large};  // the ramp a union, the wall alone

Segmentation refine(const Scene& s, const std::vector<O>& origins, double t, double noise = 0,
                    const BoundaryRefinementOptions& options = {}) {
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  Segmentation refined = refineRegionBoundaries(s.points, knn, s.seg, origins, t, noise, options);
  // A partition of the same labelled points, labels and lists agreeing.
  std::size_t total = 0;
  for (std::size_t r = 0; r < refined.regions.size(); ++r) {
    total += refined.regions[r].size();
    EXPECT_TRUE(std::is_sorted(refined.regions[r].begin(), refined.regions[r].end()));
    for (const Index i : refined.regions[r]) EXPECT_EQ(refined.labels[i], int(r));
  }
  EXPECT_EQ(total, s.points.size());
  return refined;
}

}  // namespace

TEST(BoundaryRefinement, AMergedRampTakesBackTheTreadEdgesThatItsSideHeld) {
  const Scene s = staircaseBesideAWall(0.25);
  const Segmentation refined = refine(s, kRampMerged, 0.8);
  std::size_t bandPoints = 0, moved = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const double off = kSide - s.points[i].x();
    if (off == 0) {
      EXPECT_EQ(refined.labels[i], 1) << "the wall's own points stay";
    }
    if (s.seg.labels[i] == 0) {
      EXPECT_EQ(refined.labels[i], 0) << "the ramp keeps its points";
    }
    if (s.seg.labels[i] == 1 && off > 0) {
      ++bandPoints;
      moved += refined.labels[i] == 0;
      // The ramp's plane is within 0.08 of every step point (its sawtooth); the margin is
      // 0.05 t = 0.04: a point 0.15 or more off the wall is nearer the ramp by more than that.
      if (off >= 0.15) {
        EXPECT_EQ(refined.labels[i], 0) << "x " << s.points[i].x();
      }
      // Within 0.1 t = 0.08 of the wall (once refitted, its plane is x = 1.2) the wall's plane
      // describes the point: it stays.
      if (off < 0.079) {
        EXPECT_EQ(refined.labels[i], 1) << "x " << s.points[i].x();
      }
    }
  }
  EXPECT_GT(bandPoints, 700u);
  EXPECT_GT(double(moved), 0.55 * double(bandPoints)) << moved;
}

TEST(BoundaryRefinement, OnlyMergedRegionsTakePoints) {
  const Scene s = staircaseBesideAWall(0.25);
  // The wall as the union: the ramp's points are all nearer their own plane and stay. (The band
  // the union holds may go back to the large ramp: AUnionGivesBackThePointsOfALargeRegionsPlane.)
  const Segmentation wallUnion = refine(s, {O::large, O::merged}, 0.8);
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (s.seg.labels[i] == 0) {
      EXPECT_EQ(wallUnion.labels[i], 0);
    }
  BoundaryRefinementOptions noReturn;
  noReturn.largeRegionTolerance = 0;
  EXPECT_EQ(refine(s, {O::large, O::merged}, 0.8, 0, noReturn).labels, s.seg.labels);
  EXPECT_EQ(refine(s, {O::large, O::large}, 0.8).labels, s.seg.labels);
  EXPECT_EQ(refine(s, {}, 0.8).labels, s.seg.labels);
  // A small grown region beside a union keeps its points: it is a piece of another surface.
  EXPECT_EQ(refine(s, {O::merged, O::small}, 0.8).labels, s.seg.labels);
  BoundaryRefinementOptions off;
  off.maxRelativeDistance = 0;
  EXPECT_EQ(refine(s, kRampMerged, 0.8, 0, off).labels, s.seg.labels);
}

TEST(BoundaryRefinement, AUnionGivesBackThePointsOfALargeRegionsPlane) {
  // The ramp (a union) holds the wall's points within 0.15 of its plane, as pieces grown by
  // normals along the crease leave them. Those farther than 0.1 t = 0.08 from the ramp's plane lie
  // on the wall's: they go back to it; the nearer ones, which the ramp's plane describes, stay.
  Scene s = staircaseBesideAWall(0);
  const Vec3 rampNormal = Vec3(0, -0.18, 0.3).normalized();    // rise 0.18 per 0.3 tread
  const double rampOffset = rampNormal.dot(Vec3(0, 0, 0.09));  // through mid-risers and treads
  const auto rampDistance = [&](const Vec3& p) { return std::abs(rampNormal.dot(p) - rampOffset); };
  std::vector<int> labels = s.seg.labels;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (s.points[i].x() == kSide && rampDistance(s.points[i]) < 0.15) labels[i] = 0;
  s.seg = segmentationOf(labels, 2);
  const Segmentation refined = refine(s, kRampMerged, 0.8);
  std::size_t band = 0, back = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (s.points[i].x() != kSide) {
      EXPECT_EQ(refined.labels[i], 0) << "a step point stays in the ramp";
      continue;
    }
    if (labels[i] != 0) {
      EXPECT_EQ(refined.labels[i], 1) << "the wall keeps its points";
      continue;
    }
    ++band;
    back += refined.labels[i] == 1;
    // The ramp's least-squares plane (refitted as the band leaves) lies within 1-2 cm of the one
    // above.
    if (rampDistance(s.points[i]) > 0.11) {
      EXPECT_EQ(refined.labels[i], 1) << i;
    }
    if (rampDistance(s.points[i]) < 0.05) {
      EXPECT_EQ(refined.labels[i], 0) << i;
    }
  }
  EXPECT_GT(band, 100u);
  EXPECT_GT(back, band / 4);
  BoundaryRefinementOptions off;
  off.largeRegionTolerance = 0;
  EXPECT_EQ(refine(s, kRampMerged, 0.8, 0, off).labels, s.seg.labels);
}

TEST(BoundaryRefinement, AUnionTakesTheUnlabelledPointsItsPlaneDescribes) {
  // The two top steps and the wall above 0.7 in no region (their small regions dropped by the
  // filter). The ramp takes the step points within 1.25 times its RMS (about 0.045: its sawtooth
  // is 0.077 deep) of its plane, reached step by step across the treads' edges; not the step
  // corners nor the wall beyond that, and nothing with takeUnlabelled off.
  Scene s = staircaseBesideAWall(0);
  const Vec3 rampNormal = Vec3(0, -0.18, 0.3).normalized();
  const double rampOffset = rampNormal.dot(Vec3(0, 0, 0.09));
  const auto rampDistance = [&](const Vec3& p) { return std::abs(rampNormal.dot(p) - rampOffset); };
  std::vector<int> labels = s.seg.labels;
  const auto topSteps = [](const Vec3& p) { return p.x() < kSide && p.y() > 1.2 - 1e-9; };
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (topSteps(s.points[i]) || (s.points[i].x() == kSide && s.points[i].z() > 0.7))
      labels[i] = -1;
  s.seg = segmentationOf(labels, 2);
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  const Segmentation refined = refineRegionBoundaries(s.points, knn, s.seg, kRampMerged, 0.8, 0);
  std::size_t near = 0, nearTaken = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const double d = rampDistance(s.points[i]);
    if (labels[i] >= 0) {
      EXPECT_EQ(refined.labels[i], labels[i]) << "the labelled points stay where they were";
      continue;
    }
    if (d > 0.07) {
      EXPECT_EQ(refined.labels[i], -1)
          << "beyond the ramp's bound: x " << s.points[i].x() << " z " << s.points[i].z();
    }
    if (topSteps(s.points[i]) && d < 0.035) ++near, nearTaken += refined.labels[i] == 0;
  }
  EXPECT_GT(near, 200u);
  EXPECT_GT(double(nearTaken), 0.9 * double(near)) << nearTaken << " of " << near;
  BoundaryRefinementOptions off;
  off.takeUnlabelled = false;
  EXPECT_EQ(refineRegionBoundaries(s.points, knn, s.seg, kRampMerged, 0.8, 0, off).labels,
            s.seg.labels);
  // The union alone (the wall in no region either): it still takes the same step points.
  std::vector<int> alone = labels;
  for (int& l : alone)
    if (l == 1) l = -1;
  const Segmentation single =
      refineRegionBoundaries(s.points, knn, segmentationOf(alone, 1), {O::merged}, 0.8, 0);
  std::size_t singleTaken = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (topSteps(s.points[i]) && rampDistance(s.points[i]) < 0.035)
      singleTaken += single.labels[i] == 0;
  EXPECT_GT(double(singleTaken), 0.9 * double(near)) << singleTaken << " of " << near;
}

TEST(BoundaryRefinement, TheFillPassesOverASideWithoutTakingIt) {
  // The ramp (region 0) with the two top steps and the whole side wall in no region, and the
  // riser up to the top steps removed: the top steps are reached only along the wall's strip
  // within the ramp's band. The wall's points there are near the ramp's plane but on a surface
  // at 90 degrees to it: the fill passes the band on through them and takes none.
  Scene full = staircaseBesideAWall(0);
  Scene s;
  std::vector<int> labels;
  const auto topSteps = [](const Vec3& p) { return p.x() < kSide && p.y() > 1.2 - 1e-9; };
  for (std::size_t i = 0; i < full.points.size(); ++i) {
    const Vec3& p = full.points[i];
    if (p.x() < kSide && std::abs(p.y() - 1.2) < 1e-9) continue;  // the riser of step 4
    s.points.push_back(p);
    labels.push_back(p.x() == kSide || topSteps(p) ? -1 : 0);
  }
  s.seg = segmentationOf(labels, 1);
  const Vec3 rampNormal = Vec3(0, -0.18, 0.3).normalized();
  const double rampOffset = rampNormal.dot(Vec3(0, 0, 0.09));
  const auto rampDistance = [&](const Vec3& p) { return std::abs(rampNormal.dot(p) - rampOffset); };
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  const auto count = [&](const Segmentation& refined) {
    std::size_t near = 0, taken = 0, wall = 0, wallNear = 0;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      if (s.points[i].x() == kSide) {
        // At the wall's edge along the steps, the k-NN plane is the crease's: not counted.
        double toSteps = INFINITY;
        for (const Vec3& q : s.points)
          if (q.x() < kSide) toSteps = std::min(toSteps, (q - s.points[i]).norm());
        wall += refined.labels[i] == 0 && toSteps > 2 * kSpacing;
        wallNear += rampDistance(s.points[i]) < 0.035;
      } else if (topSteps(s.points[i]) && rampDistance(s.points[i]) < 0.035) {
        ++near, taken += refined.labels[i] == 0;
      }
    }
    EXPECT_GT(near, 200u);
    EXPECT_GT(wallNear, 50u) << "the wall has a strip within the ramp's band";
    return std::array<std::size_t, 3>{near, taken, wall};
  };
  const auto [near, taken, wall] =
      count(refineRegionBoundaries(s.points, knn, s.seg, {O::merged}, 0.8, 0));
  EXPECT_EQ(wall, 0u) << "the wall's points off its edge stay unlabelled";
  EXPECT_GT(double(taken), 0.9 * double(near)) << taken << " of " << near;
  BoundaryRefinementOptions byDistance;
  byDistance.fillMaxAngleDegrees = 90;
  const auto [near90, taken90, wall90] =
      count(refineRegionBoundaries(s.points, knn, s.seg, {O::merged}, 0.8, 0, byDistance));
  EXPECT_GT(wall90, 20u) << "by distance alone the fill takes the wall's strip";
  EXPECT_GT(double(taken90), 0.9 * double(near90));
}

TEST(BoundaryRefinement, TheFillTakesAFloorNoisierThanItsSampling) {
  // A floor sampled every 0.01 with noise of 0.03 across it (a scan's near floor): each point's
  // k-NN plane is the noise's, in any direction, but the neighbours spread across the floor by
  // the noise only, so the union (the left half) still takes the right half's points its plane
  // describes.
  Scene s;
  std::vector<int> labels;
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.03);
  for (int a = 0; a < 120; ++a)
    for (int b = 0; b < 60; ++b) {
      s.points.emplace_back(0.01 * a, 0.01 * b, noise(random));
      labels.push_back(a < 60 ? 0 : -1);
    }
  s.seg = segmentationOf(labels, 1);
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  const Segmentation refined = refineRegionBoundaries(s.points, knn, s.seg, {O::merged}, 0.5, 0.03);
  std::size_t within = 0, taken = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (labels[i] < 0 && std::abs(s.points[i].z()) < 0.06)
      ++within, taken += refined.labels[i] == 0;
  EXPECT_GT(within, 3000u);
  EXPECT_GT(double(taken), 0.98 * double(within)) << taken << " of " << within;
}

TEST(BoundaryRefinement, TwoRegionsOfOnePlaneKeepTheirPoints) {
  // One flat floor cut in two regions, the second fitted a little tilted (its points 1e-3 t off
  // the first's plane at its far end): without a margin, and with every point allowed to move,
  // one would take all of the other.
  Scene s;
  std::vector<int> labels;
  addFace(s.points, labels, Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0),
          [](const Vec3& p) { return p.x() < 1 ? 0 : 1; });
  for (Vec3& p : s.points)
    if (p.x() >= 1) p.z() = 1e-3 * (p.x() - 1);
  s.seg = segmentationOf(labels, 2);
  EXPECT_EQ(refine(s, {O::merged, O::merged}, 1.0).labels, s.seg.labels);
  BoundaryRefinementOptions noMargin;
  noMargin.minRelativeGain = 0;
  noMargin.minRelativeOffset = 0;
  EXPECT_NE(refine(s, {O::merged, O::merged}, 1.0, 0, noMargin).labels, s.seg.labels);
}

TEST(BoundaryRefinement, NoiseWithinTheMarginMovesNothingAndFarPlanesAreOutOfReach) {
  const Scene s = staircaseBesideAWall(0.25);
  // A margin of 2 sigma = 0.3 (sigma 0.15) exceeds every gain in the band.
  EXPECT_EQ(refine(s, kRampMerged, 0.8, 0.15).labels, s.seg.labels);
  // The ramp's plane beyond the reach (0.01 t = 0.008, below its sawtooth) of most band points.
  BoundaryRefinementOptions shortReach;
  shortReach.maxRelativeDistance = 0.01;
  const Segmentation refined = refine(s, kRampMerged, 0.8, 0, shortReach);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) moved += refined.labels[i] != s.seg.labels[i];
  EXPECT_LT(moved, 200u);
}

TEST(BoundaryRefinement, SameResultForAnyThreadCount) {
  const Scene s = staircaseBesideAWall(0.25);
  Segmentation one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = refine(s, kRampMerged, 0.8);
  }
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  const Segmentation two = refine(s, kRampMerged, 0.8);
  EXPECT_EQ(one.labels, two.labels);
  EXPECT_EQ(one.regions, two.regions);
}

TEST(BoundaryRefinement, BadOptionsAndInputsNameWhatIsWrong) {
  const Scene s = staircaseBesideAWall(0.25);
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  const auto message = [&](const BoundaryRefinementOptions& o, const std::vector<O>& origins,
                           double t) {
    try {
      refineRegionBoundaries(s.points, knn, s.seg, origins, t, 0, o);
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  BoundaryRefinementOptions o;
  o.maxRelativeDistance = -1;
  EXPECT_NE(message(o, kRampMerged, 0.8).find("maxRelativeDistance"), std::string::npos);
  o = {};
  o.minRelativeGain = std::nan("");
  EXPECT_NE(message(o, kRampMerged, 0.8).find("minRelativeGain"), std::string::npos);
  o = {};
  o.noiseFactor = INFINITY;
  EXPECT_NE(message(o, kRampMerged, 0.8).find("noiseFactor"), std::string::npos);
  o = {};
  o.minRelativeOffset = -0.1;
  EXPECT_NE(message(o, kRampMerged, 0.8).find("minRelativeOffset"), std::string::npos);
  o = {};
  o.largeRegionTolerance = -1;
  EXPECT_NE(message(o, kRampMerged, 0.8).find("largeRegionTolerance"), std::string::npos);
  for (const double angle : {0.0, -5.0, 91.0, double(NAN)}) {
    o = {};
    o.fillMaxAngleDegrees = angle;
    EXPECT_NE(message(o, kRampMerged, 0.8).find("fillMaxAngleDegrees"), std::string::npos);
  }
  EXPECT_NE(message({}, {O::merged}, 0.8).find("origin"), std::string::npos);
  EXPECT_NE(message({}, kRampMerged, 0).find("scale"), std::string::npos);
}

TEST(BoundaryRefinement, AnEmptiedRegionIsDropped) {
  // A two-point region (no plane; reported large, so that it gives) beside the ramp: both points
  // join the ramp, the region goes.
  Scene s = staircaseBesideAWall(0);
  s.points.push_back(Vec3(0.6, 0.45, 0.36 + 1e-3));
  s.points.push_back(Vec3(0.63, 0.45, 0.36 + 1e-3));
  std::vector<int> labels = s.seg.labels;
  labels.push_back(2);
  labels.push_back(2);
  s.seg = segmentationOf(labels, 3);
  const Segmentation refined = refine(s, {O::merged, O::large, O::large}, 0.8);
  EXPECT_EQ(refined.regions.size(), 2u);
  EXPECT_EQ(refined.labels[s.points.size() - 1], 0);
  EXPECT_EQ(refined.labels[s.points.size() - 2], 0);
}
