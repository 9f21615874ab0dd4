#include "scalespace/param/LocalMapSample.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace scalespace {
namespace {

/// Kernel of Eq. 1.6 at distance d, support r.
double kernelWeight(double d, double r) {
  const double x = 1 - (d * d) / (r * r);
  return x > 0 ? x * x * x * x : 0;
}

void tangentBasisOf(const Vec3& normal, Vec3& t1, Vec3& t2) {
  const Vec3 x = std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  t1 = (x - x.dot(normal) * normal).normalized();
  t2 = normal.cross(t1);
}

}  // namespace

void gatherLocalMap(std::size_t i, std::size_t k, const std::vector<Vec3>& positions,
                    const Vec3& normal, const SpatialIndex& index, const DomainMap& domain,
                    LocalMapSample& sample, std::vector<Neighbor>& neighbors) {
  index.knnSearch(positions[i], k + 1, neighbors);
  const std::size_t count = std::min(k, neighbors.size());
  sample.radius = std::sqrt(neighbors.back().distSq);
  if (neighbors.size() <= k) sample.radius *= 1.0001;  // fewer points than k + 1: keep them all
  Vec3 n = normal;
  if (!(n.squaredNorm() > 0) || !n.allFinite()) {
    Vec3 mean = Vec3::Zero();
    for (std::size_t s = 0; s < count; ++s) mean += positions[neighbors[s].index];
    mean /= double(std::max<std::size_t>(count, 1));
    Mat3 cov = Mat3::Zero();
    for (std::size_t s = 0; s < count; ++s) {
      const Vec3 d = positions[neighbors[s].index] - mean;
      cov += d * d.transpose();
    }
    n = Eigen::SelfAdjointEigenSolver<Mat3>(cov).eigenvectors().col(0);
  }
  Vec3& t1 = sample.t1;
  Vec3& t2 = sample.t2;
  tangentBasisOf(n.normalized(), t1, t2);
  sample.tangent.resize(count);
  sample.domain.resize(count);
  sample.weight.resize(count);
  sample.distance.resize(count);
  sample.index.resize(count);
  for (std::size_t s = 0; s < count; ++s) {
    const Index j = neighbors[s].index;
    const Vec3 d = positions[j] - positions[i];
    sample.tangent[s] = Vec2(d.dot(t1), d.dot(t2));
    sample.domain[s] = domain.localOffset(i, j);
    sample.distance[s] = std::sqrt(neighbors[s].distSq);
    sample.weight[s] = kernelWeight(sample.distance[s], sample.radius);
    sample.index[s] = j;
  }
}

void truncateLocalMap(const LocalMapSample& from, std::size_t k, LocalMapSample& to) {
  const std::size_t count = std::min(k, from.index.size());
  to.t1 = from.t1;
  to.t2 = from.t2;
  to.tangent.assign(from.tangent.begin(), from.tangent.begin() + count);
  to.domain.assign(from.domain.begin(), from.domain.begin() + count);
  to.distance.assign(from.distance.begin(), from.distance.begin() + count);
  to.index.assign(from.index.begin(), from.index.begin() + count);
  // The support just beyond the k-th neighbour: the (k+1)-th's distance when there is one.
  to.radius = count < from.distance.size() ? from.distance[count]
                                           : (count > 0 ? from.distance[count - 1] * 1.0001 : 0);
  if (!(to.radius > 0)) to.radius = 1;
  to.weight.resize(count);
  for (std::size_t s = 0; s < count; ++s) to.weight[s] = kernelWeight(to.distance[s], to.radius);
}

Eigen::Matrix2d weightedCovariance(const std::vector<Vec2>& points,
                                   const std::vector<double>& weights) {
  double sum = 0;
  Vec2 mean = Vec2::Zero();
  for (std::size_t s = 0; s < points.size(); ++s) {
    sum += weights[s];
    mean += weights[s] * points[s];
  }
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  if (!(sum > 0)) return cov;
  mean /= sum;
  for (std::size_t s = 0; s < points.size(); ++s) {
    const Vec2 d = points[s] - mean;
    cov += weights[s] * d * d.transpose();
  }
  return cov / sum;
}

}  // namespace scalespace
