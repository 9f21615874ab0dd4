#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "CoreTestClouds.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/SheetBorder.hpp"

namespace scalespace {
namespace {

// A unit square of the plane z = 0, sampled uniformly, tilted so that no axis is special.
std::vector<Vec3> tiltedSquare(std::size_t n, std::uint64_t seed, double noise) {
  std::vector<Vec3> p = testclouds::plane(n, 1.0, seed);
  std::mt19937_64 rng(seed + 1);
  std::normal_distribution<double> g(0.0, noise > 0 ? noise : 1.0);
  const Mat3 turn = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())).toRotationMatrix();
  for (Vec3& x : p) {
    if (noise > 0) x += Vec3(g(rng), g(rng), g(rng));
    x = turn * x;
  }
  return p;
}

TEST(SheetBorder, HalfADiscOnABorderAndNothingInside) {
  const std::vector<Vec3> p = tiltedSquare(200000, 7, 0);
  const auto index = makeSpatialIndex(p);
  const Mat3 turn = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())).toRotationMatrix();
  const double r = 0.05;
  // Inside, on a straight border (x = 0), at half the radius in and at a corner.
  const std::vector<Vec3> q{turn * Vec3(0.5, 0.5, 0), turn * Vec3(0, 0.5, 0),
                            turn * Vec3(0.025, 0.5, 0), turn * Vec3(0, 0, 0)};
  const std::vector<float> share = sheetBorderShare(p, *index, q, SheetBorderOptions{r, 8});
  EXPECT_LT(share[0], 0.1);
  EXPECT_NEAR(share[1], 4 / (3 * M_PI), 0.03);  // a half disc's centroid
  EXPECT_NEAR(share[2], 0.17, 0.03);            // a disc cut at half its radius
  EXPECT_GT(share[3], share[1]);                // a quarter disc: farther still
}

TEST(SheetBorder, NoiseAcrossTheSheetKeepsTheInsideLow) {
  // Noise of a fifth of the radius, across and along: the plane is the neighbours' best fit, so
  // the spread across it does not read as an offset; along it the mean of ~100 points stays small.
  const std::vector<Vec3> p = tiltedSquare(40000, 8, 0.01);
  const auto index = makeSpatialIndex(p);
  const std::vector<float> share = sheetBorderShare(p, *index, p, SheetBorderOptions{0.05, 8});
  const Mat3 back =
      (Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())).toRotationMatrix().transpose();
  std::size_t inside = 0, insideHigh = 0, rim = 0, rimHigh = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 x = back * p[i];
    const double toBorder = std::min({x.x(), 1 - x.x(), x.y(), 1 - x.y()});
    if (toBorder > 0.06) {
      ++inside;
      insideHigh += share[i] >= 0.2;
    } else if (toBorder < 0.01) {
      ++rim;
      rimHigh += share[i] >= 0.2;
    }
  }
  EXPECT_LT(double(insideHigh), 0.002 * double(inside));
  EXPECT_GT(double(rimHigh), 0.9 * double(rim));
}

TEST(SheetBorder, TooFewNeighboursReadZeroAndBadOptionsAreRefused) {
  const std::vector<Vec3> p{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const auto index = makeSpatialIndex(p);
  EXPECT_EQ(sheetBorderShare(p, *index, p, SheetBorderOptions{2, 8}), std::vector<float>(3, 0.0f));
  EXPECT_THROW(sheetBorderShare(p, *index, p, SheetBorderOptions{0, 8}), OptionError);
  EXPECT_THROW(sheetBorderShare(p, *index, p, SheetBorderOptions{1, 2}), OptionError);
  EXPECT_THROW(sheetBorderShare(p, *index, p, SheetBorderOptions{1, 8, 1.5}), OptionError);
}

TEST(SheetBorder, AVolumeHasNoBorderInsideNorAlongItsFaces) {
  // Points filling a cube. Inside, the neighbours fill a ball (surface variation 1/3: no sheet).
  // Along a face they fill a half ball, flat enough to pass (0.13), but its centroid lies off
  // along the plane's normal, which is projected out. (Along the cube's edges a quarter ball
  // reads as a border.)
  const std::vector<Vec3> p = testclouds::uniformCube(20000, 9);
  const auto index = makeSpatialIndex(p);
  const double r = 0.1;
  const std::vector<float> share = sheetBorderShare(p, *index, p, SheetBorderOptions{r, 8});
  std::size_t checked = 0, border = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    int nearFaces = 0;
    for (int a = 0; a < 3; ++a) nearFaces += p[i][a] < r || p[i][a] > 1 - r;
    if (nearFaces > 1) continue;
    ++checked;
    border += share[i] >= 0.25f;
  }
  EXPECT_GT(checked, 10000u);
  EXPECT_LE(border, checked / 1000);  // a chance reading here and there
}

}  // namespace
}  // namespace scalespace
