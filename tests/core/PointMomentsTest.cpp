// Centred moments of point sets (core/PointMoments): a union's covariance equals the covariance of
// all its points, and points exactly on a line far from the origin keep a zero width.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "scalespace/core/PointMoments.hpp"

using namespace scalespace;

namespace {

Mat3 directCovariance(const std::vector<Vec3>& points) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  mean /= double(points.size());
  Mat3 c = Mat3::Zero();
  for (const Vec3& p : points) c += (p - mean) * (p - mean).transpose();
  return c / double(points.size());
}

}  // namespace

TEST(PointMoments, AUnionIsTheSetOfAllItsPoints) {
  std::vector<Vec3> all;
  PointMoments a, b, c, empty;
  for (int i = 0; i < 40; ++i) {
    const Vec3 p(std::sin(1.3 * i), 0.5 * std::cos(0.7 * i), 0.01 * i * i);
    all.push_back(p);
    (i < 10 ? a : i < 25 ? b : c).add(p);
  }
  PointMoments both = a;
  both.add(empty);  // an empty set changes nothing, either way round
  both.add(b);
  both.add(c);
  PointMoments fromEmpty;
  fromEmpty.add(both);
  EXPECT_EQ(fromEmpty.count, 40);
  EXPECT_LT((fromEmpty.covariance() - directCovariance(all)).norm(), 1e-12);
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : all) mean += p / 40.0;
  EXPECT_LT((both.mean - mean).norm(), 1e-12);
  EXPECT_EQ(empty.covariance(), Mat3::Zero());
}

TEST(PointMoments, PointsOnALineFarFromTheOriginKeepNoWidth) {
  // Two runs of one line 1e4 away from the origin: summing p p^T and subtracting the mean's
  // square at the end loses the line's width to cancellation; the centred sums do not.
  const Vec3 origin(1e4, -2e4, 3e4), direction(0.6, 0.64, 0.48);
  PointMoments first, second;
  for (int i = 0; i < 200; ++i) (i < 100 ? first : second).add(origin + 0.01 * i * direction);
  first.add(second);
  const Mat3 c = first.covariance();
  const double along = direction.dot(c * direction);
  EXPECT_NEAR(along, 0.01 * 0.01 * (200.0 * 200.0 - 1) / 12, 1e-9);
  // Across the line: rounding of the covariance's entries only (about sqrt(eps) of the spread);
  // the uncentred sums would leave about 1e-4.
  const Vec3 u = direction.cross(Vec3::UnitZ()).normalized(), v = direction.cross(u);
  EXPECT_LT(std::sqrt(std::abs(u.dot(c * u)) + std::abs(v.dot(c * v))), 1e-7 * std::sqrt(along));
}
