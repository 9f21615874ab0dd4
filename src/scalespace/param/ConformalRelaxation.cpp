#include "scalespace/param/ConformalRelaxation.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <chrono>
#include <cmath>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/param/LocalMapSample.hpp"
#include "scalespace/param/MapDefects.hpp"

namespace scalespace {
namespace {

/// The RMS distance of the domain points to their centroid, and the centroid.
double spread(const std::vector<Vec2>& uv, Vec2& centroid) {
  centroid = Vec2::Zero();
  for (const Vec2& p : uv) centroid += p;
  centroid /= double(uv.size());
  double sum = 0;
  for (const Vec2& p : uv) sum += (p - centroid).squaredNorm();
  return std::sqrt(sum / double(uv.size()));
}

}  // namespace

void validateRelaxationOptions(const RelaxationOptions& options) {
  if (options.iterations < 0) throw OptionError("RelaxationOptions::iterations must be >= 0");
  if (options.neighbors < 3 || options.neighbors > 64)
    throw OptionError("RelaxationOptions::neighbors must be in [3, 64]");
}

RelaxationResult relaxConformally(const std::vector<Vec3>& positions,
                                  const std::vector<Vec3>& normals, DomainMap& domain,
                                  const RelaxationOptions& options,
                                  const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  validateRelaxationOptions(options);
  const std::size_t n = positions.size();
  if (domain.size() != n || (!normals.empty() && normals.size() != n))
    throw OptionError("the cloud and its parametrization have different point counts");
  RelaxationResult result;
  if (domain.kind != DomainKind::Plane) {
    result.reason = "the relaxation applies to plane domains";
    return result;
  }
  if (options.iterations == 0 || n < std::size_t(options.neighbors) + 1) {
    result.reason = options.iterations == 0 ? "no iteration asked" : "too few points";
    return result;
  }
  const MapDefects before = findMapDefects(positions, normals, domain);
  result.foldsBefore = before.folds;
  const double mirror = before.majoritySign < 0 ? -1.0 : 1.0;

  // The k-NN graph with the tangent offsets a_ij and weights w_ij (fixed for every iteration).
  const std::size_t k = std::size_t(options.neighbors);
  std::vector<Index> neighbor(n * k);
  std::vector<Vec2> offset(n * k);
  std::vector<double> weight(n * k, 0.0);
  {
    const auto index = makeSpatialIndex(positions);
    ProgressTracker gathering({}, "neighbours", n);
    forEachLocalMap(positions, normals, *index, domain, k + 1, gathering,
                    [&](std::size_t i, const LocalMapSample& sample, LocalMapSample&) {
                      std::size_t e = 0;
                      for (std::size_t s = 0; s < sample.index.size() && e < k; ++s) {
                        if (sample.index[s] == i) continue;
                        neighbor[i * k + e] = sample.index[s];
                        // A mirrored map is matched by anti-similarities: mirror a first.
                        offset[i * k + e] =
                            Vec2(sample.tangent[s].x(), mirror * sample.tangent[s].y());
                        weight[i * k + e] = sample.weight[s] + 1e-12;
                        ++e;
                      }
                      for (; e < k; ++e) {  // duplicates of i filled the neighbourhood
                        neighbor[i * k + e] = Index(i);
                        weight[i * k + e] = 0;
                      }
                    });
  }
  // L u = rhs: each directed edge i -> j adds w to L_ii, L_jj and -w to L_ij, L_ji; a small
  // diagonal term pins the translation (the rhs gets the same times the current position).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(n * k * 4 + n);
  double meanDiagonal = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t e = 0; e < k; ++e) {
      const std::size_t j = neighbor[i * k + e];
      const double w = weight[i * k + e];
      if (j == i || !(w > 0)) continue;
      triplets.emplace_back(int(i), int(i), w);
      triplets.emplace_back(int(j), int(j), w);
      triplets.emplace_back(int(i), int(j), -w);
      triplets.emplace_back(int(j), int(i), -w);
      meanDiagonal += 2 * w;
    }
  meanDiagonal /= double(n);
  const double pin = 1e-6 * meanDiagonal;
  for (std::size_t i = 0; i < n; ++i) triplets.emplace_back(int(i), int(i), pin);
  const Eigen::Index rows = Eigen::Index(n);
  Eigen::SparseMatrix<double> laplacian(rows, rows);
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  triplets = {};
  // The matrix does not change between iterations: factorized once. (Conjugate gradients from
  // the current map were slower at 100k and at 1M points: the pinned graph Laplacian is badly
  // conditioned, bench/README.md.)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(laplacian);
  if (solver.info() != Eigen::Success) {
    result.reason = "the k-NN graph's Laplacian could not be factorized";
    return result;
  }

  std::vector<Vec2> uv = domain.uv;
  Vec2 centroid;
  const double size = spread(uv, centroid);
  ProgressTracker tracker(progress, "relaxation", std::size_t(options.iterations));
  std::vector<Eigen::Matrix2d> similarity(n);
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    // Local: S_i = [[a, -b], [b, a]], (a + ib) = sum w conj(x) y / sum w |x|^2 in complex form.
    parallelFor(n, [&](std::size_t i) {
      double a = 0, b = 0, norm = 0;
      for (std::size_t e = 0; e < k; ++e) {
        const double w = weight[i * k + e];
        const Vec2& x = offset[i * k + e];
        const Vec2 y = uv[neighbor[i * k + e]] - uv[i];
        a += w * (x.x() * y.x() + x.y() * y.y());
        b += w * (x.x() * y.y() - x.y() * y.x());
        norm += w * x.squaredNorm();
      }
      Eigen::Matrix2d s;
      if (options.rigid) {
        // The rotation of the similarity (its angle), at unit scale: as rigid as possible.
        const double length = std::hypot(a, b);
        a = length > 0 ? a / length : 1;
        b = length > 0 ? b / length : 0;
      } else if (norm > 0) {
        a /= norm;
        b /= norm;
      }
      s << a, -b, b, a;
      similarity[i] = s;
    });
    // Global: rhs_m = sum_{i->m} w S_i a_im - sum_{m->j} w S_m a_mj (+ pin u_m).
    Eigen::MatrixXd rhs(int(n), 2);
    for (std::size_t i = 0; i < n; ++i) rhs.row(int(i)) = pin * uv[i].transpose();
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t e = 0; e < k; ++e) {
        const std::size_t j = neighbor[i * k + e];
        const double w = weight[i * k + e];
        if (j == i || !(w > 0)) continue;
        const Vec2 r = similarity[i] * offset[i * k + e];
        rhs.row(int(j)) += w * r.transpose();
        rhs.row(int(i)) -= w * r.transpose();
      }
    const Eigen::MatrixXd solved = solver.solve(rhs);
    // The similarity energy has no scale of its own: keep the domain's spread and centroid
    // (the rigid one takes the surface's lengths).
    std::vector<Vec2> next(n);
    for (std::size_t i = 0; i < n; ++i) next[i] = solved.row(int(i)).transpose();
    Vec2 c;
    const double s = spread(next, c);
    if (!(s > 0) || !std::isfinite(s)) {
      result.reason = "the relaxation collapsed the domain";
      return result;
    }
    const double factor = options.rigid ? 1.0 : size / s;
    for (std::size_t i = 0; i < n; ++i) uv[i] = centroid + (next[i] - c) * factor;
    tracker.advance(1);
  }
  tracker.finish();

  DomainMap relaxed = domain;
  relaxed.uv = std::move(uv);
  const MapDefects after = findMapDefects(positions, normals, relaxed);
  result.foldsAfter = after.folds;
  if (after.folds + after.overlaps > before.folds + before.overlaps) {
    result.reason = "the relaxation would add folds or overlaps (" +
                    std::to_string(after.folds + after.overlaps) + " points against " +
                    std::to_string(before.folds + before.overlaps) + ")";
    return result;
  }
  domain = std::move(relaxed);
  result.applied = true;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scalespace
