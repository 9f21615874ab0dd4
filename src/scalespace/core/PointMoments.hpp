#pragma once
// The mean and scatter of a point set, kept centred: the covariance of any union of sets in O(1)
// (the pieces of a feature curve joined into edges). Summing
// p p^T and subtracting n mean mean^T at the end cancels catastrophically when the points are
// far from the origin next to their spread, or lie exactly on a line or a plane (the eigenvalues
// that should be 0 come out at eps times the largest); the pairwise update (Chan, Golub and
// LeVeque 1979) keeps every sum about the set's own mean.
#include "scalespace/core/Types.hpp"

namespace scalespace {

struct PointMoments {
  double count = 0;
  Vec3 mean = Vec3::Zero();
  Mat3 scatter = Mat3::Zero();  // sum of (p - mean)(p - mean)^T

  void add(const Vec3& p) {
    count += 1;
    const Vec3 d = p - mean;
    mean += d / count;
    scatter += ((count - 1) / count) * d * d.transpose();
  }
  void add(const PointMoments& o) {
    if (o.count == 0) return;
    if (count == 0) {
      *this = o;
      return;
    }
    const double total = count + o.count;
    const Vec3 d = o.mean - mean;
    scatter += o.scatter + (count * o.count / total) * d * d.transpose();
    mean += (o.count / total) * d;
    count = total;
  }
  /// Population covariance (zero for an empty set).
  Mat3 covariance() const { return count > 0 ? Mat3(scatter / count) : Mat3::Zero(); }
};

}  // namespace scalespace
