// Coplanar merging of the regions of one scale (planes/RegionMerging.hpp): a staircase's treads and
// risers become its mean ramp once the scale is a few steps, and nothing else is merged: pieces
// too far from a common plane, a region large enough to stand alone, a bevel of slivers, merges
// that the noise could explain.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "scalespace/core/Error.hpp"
#include "scalespace/planes/RegionMerging.hpp"

using namespace scalespace;

namespace {

// Points on a grid over the parallelogram corner + [0,1] u + [0,1] v, `spacing` apart, as one
// region appended to `seg` (positions to `points`).
void addFace(std::vector<Vec3>& points, Segmentation& seg, const Vec3& corner, const Vec3& u,
             const Vec3& v, double spacing) {
  const int nu = std::max(1, int(std::round(u.norm() / spacing)));
  const int nv = std::max(1, int(std::round(v.norm() / spacing)));
  std::vector<Index> region;
  for (int a = 0; a < nu; ++a)
    for (int b = 0; b < nv; ++b) {
      region.push_back(Index(points.size()));
      seg.labels.push_back(int(seg.regions.size()));
      points.push_back(corner + (a + 0.5) / nu * u + (b + 0.5) / nv * v);
    }
  seg.regions.push_back(std::move(region));
}

struct Scene {
  std::vector<Vec3> points;
  Segmentation seg;
};

// Six steps 0.3 deep and 0.18 high, 1.2 wide: each tread and riser is a region (what the robust
// fit and the step limit make of a staircase at every scale).
Scene staircase() {
  Scene s;
  for (int k = 0; k < 6; ++k) {
    addFace(s.points, s.seg, Vec3(0, 0.3 * k, 0.18 * k), Vec3(1.2, 0, 0), Vec3(0, 0, 0.18), 0.03);
    addFace(s.points, s.seg, Vec3(0, 0.3 * k, 0.18 * (k + 1)), Vec3(1.2, 0, 0), Vec3(0, 0.3, 0),
            0.03);
  }
  return s;
}

std::size_t regionCount(const Scene& s, double t, double noise = 0,
                        const RegionMergeOptions& options = {}) {
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  const Segmentation merged =
      mergeCoplanarRegions(s.points, knn, s.seg, t, std::pow(2 * t, 2), noise, options);
  // A partition of the same points, labels and lists agreeing.
  std::size_t total = 0;
  for (std::size_t r = 0; r < merged.regions.size(); ++r) {
    total += merged.regions[r].size();
    EXPECT_TRUE(std::is_sorted(merged.regions[r].begin(), merged.regions[r].end()));
    for (const Index i : merged.regions[r]) EXPECT_EQ(merged.labels[i], int(r));
  }
  EXPECT_EQ(total, s.points.size());
  return merged.regions.size();
}

}  // namespace

TEST(RegionMerging, AStaircaseBecomesItsMeanRampAtAScaleOfAFewSteps) {
  const Scene s = staircase();
  // The ramp's sawtooth: RMS 0.18 cos(31 deg) / sqrt(12) = 0.045 from the mean plane.
  EXPECT_EQ(regionCount(s, 0.8), 1u);   // 0.045 <= 0.1 t
  EXPECT_EQ(regionCount(s, 0.3), 12u);  // 0.045 > 0.1 t: treads and risers stay
  RegionMergeOptions thesis;
  thesis.maxRelativeRms = 0;
  EXPECT_EQ(regionCount(s, 0.8, 0, thesis), 12u);
  // Noise that could explain the RMS: nothing merged (2 x 0.05 > 0.1 t).
  EXPECT_EQ(regionCount(s, 0.8, 0.05), 12u);
}

TEST(RegionMerging, TheDeviationBoundIsOnThePointsNotOnTheBoxesAroundThem) {
  // The same staircase, but each tread region also holds the top `strip` of the riser under its
  // nose (what the robust fit gives a tread at its edge). The points stay on the sawtooth, within
  // 0.3 x 0.18 / (2 x 0.35) = 0.077 of the mean ramp (a little more at its two ends); an L-shaped
  // tread's box, along the tread's own plane, has a corner `strip` under the back of the tread,
  // 0.077 + 0.09 cos(31 deg) = 0.154 off the ramp.
  constexpr double strip = 0.09;
  Scene s;
  for (int k = 0; k < 6; ++k) {
    const double y = 0.3 * k, z = 0.18 * k;
    addFace(s.points, s.seg, Vec3(0, y, z), Vec3(1.2, 0, 0), Vec3(0, 0, 0.18 - strip), 0.03);
    addFace(s.points, s.seg, Vec3(0, y, z + 0.18), Vec3(1.2, 0, 0), Vec3(0, 0.3, 0), 0.03);
    Segmentation nose;  // the strip, moved into the tread's region
    addFace(s.points, nose, Vec3(0, y, z + 0.18 - strip), Vec3(1.2, 0, 0), Vec3(0, 0, strip), 0.03);
    for (const Index i : nose.regions.front()) {  // the strip's points were appended last
      s.seg.labels.push_back(int(s.seg.regions.size()) - 1);
      s.seg.regions.back().push_back(i);
    }
  }
  RegionMergeOptions tight;
  tight.maxRelativeDeviation = 0.2;  // 0.1 at t = 0.5: above the points, below the boxes
  EXPECT_EQ(regionCount(s, 0.5, 0, tight), 1u);
  tight.maxRelativeDeviation = 0.1;  // 0.05: below the sawtooth's corners
  EXPECT_EQ(regionCount(s, 0.5, 0, tight), 12u);
}

TEST(RegionMerging, PiecesFarFromACommonPlaneOrLargeEnoughToStandAloneAreNotMerged) {
  Scene s;
  // Two 0.5 x 0.5 plates side by side, one 0.3 higher: the union's RMS is 0.15 > 0.1 t.
  addFace(s.points, s.seg, Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(0, 0.5, 0), 0.025);
  addFace(s.points, s.seg, Vec3(0.5, 0, 0.3), Vec3(0.5, 0, 0), Vec3(0, 0.5, 0), 0.025);
  EXPECT_EQ(regionCount(s, 0.8), 2u);
  // A 2 cm tile on a 3 x 3 roof: coplanar enough, but the roof (9 m2 >= (2t)^2) stands alone.
  Scene roof;
  addFace(roof.points, roof.seg, Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 1.5, 0), 0.05);
  addFace(roof.points, roof.seg, Vec3(0, 1.5, 0.02), Vec3(0.5, 0, 0), Vec3(0, 0.5, 0), 0.05);
  addFace(roof.points, roof.seg, Vec3(0.5, 1.5, 0), Vec3(2.5, 0, 0), Vec3(0, 1.5, 0), 0.05);
  EXPECT_EQ(regionCount(roof, 0.8), 3u);
  // Two small coplanar plates: merged.
  Scene flat;
  addFace(flat.points, flat.seg, Vec3(0, 0, 0), Vec3(0.9, 0, 0), Vec3(0, 0.9, 0), 0.03);
  addFace(flat.points, flat.seg, Vec3(0.9, 0, 0.01), Vec3(0.9, 0, 0), Vec3(0, 0.9, 0), 0.03);
  EXPECT_EQ(regionCount(flat, 0.8), 1u);
}

TEST(RegionMerging, ABevelOfSliversIsUndone) {
  // Two strips 1.5 long and 0.06 wide meeting at a 20 degree crease: their union is planar within
  // 0.1 t but 0.12 wide, far narrower than t = 0.5.
  Scene s;
  const Vec3 across(0, std::cos(0.35), std::sin(0.35));
  addFace(s.points, s.seg, Vec3(0, 0, 0), Vec3(1.5, 0, 0), Vec3(0, -0.06, 0), 0.01);
  addFace(s.points, s.seg, Vec3(0, 0, 0), Vec3(1.5, 0, 0), 0.06 * across, 0.01);
  EXPECT_EQ(regionCount(s, 0.5), 2u);
  RegionMergeOptions anyWidth;
  anyWidth.minRelativeWidth = 0;
  EXPECT_EQ(regionCount(s, 0.5, 0, anyWidth), 1u);
}

TEST(RegionMerging, SameRegionsForAnyThreadCountAndOptionsChecked) {
  Scene s = staircase();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.003);
  for (Vec3& p : s.points) p += Vec3(noise(rng), noise(rng), noise(rng));
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  Segmentation one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = mergeCoplanarRegions(s.points, knn, s.seg, 0.8, 2.56, 0.003);
  }
  two = mergeCoplanarRegions(s.points, knn, s.seg, 0.8, 2.56, 0.003);
  EXPECT_EQ(one.regions, two.regions);
  EXPECT_EQ(one.labels, two.labels);
  EXPECT_EQ(one.regions.size(), 1u);

  RegionMergeOptions bad;
  bad.parallelDegrees = 90;
  EXPECT_THROW(mergeCoplanarRegions(s.points, knn, s.seg, 0.8, 2.56, 0, bad), OptionError);
  bad.parallelDegrees = 5;
  bad.maxRelativeDeviation = -1;
  try {
    mergeCoplanarRegions(s.points, knn, s.seg, 0.8, 2.56, 0, bad);
    FAIL() << "a negative deviation was accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("RegionMergeOptions::maxRelativeDeviation"),
              std::string::npos);
  }
  EXPECT_THROW(mergeCoplanarRegions(s.points, knn, s.seg, 0, 2.56, 0), OptionError);
  EXPECT_THROW(mergeCoplanarRegions(s.points, knn, s.seg, 0.8, 2.56, std::nan("")), OptionError);
  std::vector<Vec3> fewer(s.points.begin(), s.points.end() - 1);
  EXPECT_THROW(mergeCoplanarRegions(fewer, knn, s.seg, 0.8, 2.56, 0), OptionError);
}

TEST(RegionMerging, AUnionJoinsALargeRegionThatDescribesItAsWellAsItsOwnPoints) {
  // Ten steps: the lower seven one grown region (the fit gave them the ramp's normal: a sawtooth
  // 2.1 m along, larger than (2t)^2 at t = 0.8), the upper three a tread and a riser each. The
  // three steps merge into a union with the lower region's sawtooth, which then joins it.
  Scene s;
  for (int k = 0; k < 10; ++k) {
    addFace(s.points, s.seg, Vec3(0, 0.3 * k, 0.18 * k), Vec3(1.2, 0, 0), Vec3(0, 0, 0.18), 0.03);
    addFace(s.points, s.seg, Vec3(0, 0.3 * k, 0.18 * (k + 1)), Vec3(1.2, 0, 0), Vec3(0, 0.3, 0),
            0.03);
  }
  const auto asOneRegion = [&](std::size_t firstRegions) {
    Segmentation seg;
    seg.labels.assign(s.points.size(), -1);
    for (std::size_t r = 0; r < s.seg.regions.size(); ++r) {
      const int label = r < firstRegions ? 0 : int(r - firstRegions + 1);
      if (std::size_t(label) >= seg.regions.size()) seg.regions.resize(std::size_t(label) + 1);
      for (const Index i : s.seg.regions[r]) seg.labels[i] = label;
    }
    for (std::size_t i = 0; i < seg.labels.size(); ++i)
      seg.regions[std::size_t(seg.labels[i])].push_back(Index(i));
    return seg;
  };
  Scene lowerGrown{s.points, asOneRegion(14)};
  std::vector<RegionOrigin> origins;
  const KnnGraph knn = buildKnnGraph(s.points, 10);
  const Segmentation merged =
      mergeCoplanarRegions(s.points, knn, lowerGrown.seg, 0.8, std::pow(1.6, 2), 0, {}, &origins);
  ASSERT_EQ(merged.regions.size(), 1u);
  EXPECT_EQ(origins, std::vector<RegionOrigin>{RegionOrigin::merged});
  EXPECT_EQ(regionCount(lowerGrown, 0.8), 1u);

  // An exact plate does not take a union 1 cm off its plane (its own RMS is 0): the face of a box
  // keeps out the bands along its edges. Parallel to the plate and that near it, the union is not
  // a second plane either: it is undone (parallelDegrees), its two pieces left as they were grown.
  Scene plate;
  addFace(plate.points, plate.seg, Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 2, 0), 0.05);
  addFace(plate.points, plate.seg, Vec3(3, 0, 0.01), Vec3(0.45, 0, 0), Vec3(0, 1, 0), 0.05);
  addFace(plate.points, plate.seg, Vec3(3.45, 0, 0.01), Vec3(0.45, 0, 0), Vec3(0, 1, 0), 0.05);
  std::vector<RegionOrigin> plateOrigins;
  const Segmentation undone =
      mergeCoplanarRegions(plate.points, buildKnnGraph(plate.points, 10), plate.seg, 0.8,
                           std::pow(1.6, 2), 0, {}, &plateOrigins);
  EXPECT_EQ(undone.regions, plate.seg.regions);
  EXPECT_EQ(plateOrigins, (std::vector<RegionOrigin>{RegionOrigin::large, RegionOrigin::small,
                                                     RegionOrigin::small}));
  RegionMergeOptions keepParallel;
  keepParallel.parallelDegrees = 0;
  EXPECT_EQ(regionCount(plate, 0.8, 0, keepParallel), 2u);
  // Tilted by 10 degrees away from the plate, the same union is a plane of its own and stays.
  Scene tilted;
  const Vec3 up(0.45 * std::cos(0.1745), 0, 0.45 * std::sin(0.1745));
  addFace(tilted.points, tilted.seg, Vec3(0, 0, 0), Vec3(3, 0, 0), Vec3(0, 2, 0), 0.05);
  addFace(tilted.points, tilted.seg, Vec3(3, 0, 0.01), up, Vec3(0, 1, 0), 0.05);
  addFace(tilted.points, tilted.seg, Vec3(3, 0, 0.01) + up, up, Vec3(0, 1, 0), 0.05);
  EXPECT_EQ(regionCount(tilted, 0.8), 2u);
}
