#include "scalespace/features/LineAnisotropy.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scalespace/core/SpatialIndex.hpp"

namespace scalespace {

LineAnisotropyField lineAnisotropy(const std::vector<Vec3>& positions,
                                   const std::vector<Vec3>& normals,
                                   const std::vector<const CurvatureLine*>& lines, double t,
                                   const ProgressCallback& progress) {
  struct Vertex {
    Vec3 tangent, normal;
    double weight, kappa1;  // 1 - tanh(nu)
  };
  std::vector<Vec3> where;
  std::vector<Vertex> vertices;
  for (const CurvatureLine* line : lines)
    for (const CurvatureLineVertex& v : line->vertices) {
      where.push_back(v.position);
      vertices.push_back({v.tangent, v.normal, 1 - std::tanh(v.geometricVariation), v.kappa1});
    }
  const std::size_t n = positions.size();
  LineAnisotropyField field;
  field.scale = t;
  field.sigma.assign(n, std::numeric_limits<float>::quiet_NaN());
  field.direction.assign(n, Vec3::Zero());
  field.normal.assign(n, Vec3::Zero());
  field.kappa1.assign(n, 0.f);
  if (vertices.empty()) return field;
  const auto index = makeSpatialIndex(where);
  const double invT2 = 1 / (t * t);
  ProgressTracker tracker(progress, "anisotropy", n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& range) {
    std::vector<Neighbor> near;
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      index->radiusSearch(positions[i], t, near);
      // The kd-tree is built the same way whatever the thread count and returns a query's
      // neighbours in the same order: the sums below do not depend on the threads.
      Mat3 sigma = Mat3::Zero();
      Vec3 normal = Vec3::Zero();
      double weightSum = 0, kappa = 0;
      for (const Neighbor& nb : near) {
        const Vertex& v = vertices[nb.index];
        if (v.normal.dot(normals[i]) <= 0) continue;  // the other side of the surface
        const double x = 1 - nb.distSq * invT2;       // Eq. 1.6: (r^2/t^2 - 1)^2
        const double w = v.weight * x * x;
        if (!(w > 0)) continue;
        sigma += w * v.tangent * v.tangent.transpose();
        normal += w * v.normal;
        kappa += w * v.kappa1;
        weightSum += w;
      }
      if (!(weightSum > 0) || normal.squaredNorm() == 0) continue;
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(sigma);
      const Vec3 l = eig.eigenvalues().cwiseMax(0.0);  // increasing
      const double trace = l.sum();
      if (!(trace > 0)) continue;
      field.sigma[i] = float((l[2] - l[1]) / trace);
      field.direction[i] = eig.eigenvectors().col(2).normalized();
      field.normal[i] = normal.normalized();
      field.kappa1[i] = float(kappa / weightSum);
    }
    tracker.advance(range.size());
  });
  tracker.finish();
  return field;
}

}  // namespace scalespace
