#include "scalespace/param/ConformalRelaxation.hpp"

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <type_traits>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/param/LocalMapSample.hpp"
#include "scalespace/param/MapDefects.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

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

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The k-NN graph of the points being relaxed, fixed for every iteration: per point its k
/// neighbours, their tangent-plane offsets a_ij (mirrored when the map is), the kernel weights
/// w_ij, and the map from a 3D offset to those tangent coordinates (for the points placed from
/// a subsample).
struct RelaxationGraph {
  std::size_t n = 0, k = 0;
  std::vector<Index> neighbor;
  std::vector<Vec2> offset;
  std::vector<double> weight;
  std::vector<Eigen::Matrix<double, 2, 3>> toTangent;
};

RelaxationGraph gatherGraph(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                            const DomainMap& domain, std::size_t k, double mirror) {
  RelaxationGraph g;
  g.n = positions.size();
  g.k = k;
  g.neighbor.resize(g.n * k);
  g.offset.resize(g.n * k);
  g.weight.assign(g.n * k, 0.0);
  g.toTangent.resize(g.n);
  const auto index = makeSpatialIndex(positions);
  ProgressTracker gathering({}, "neighbours", g.n);
  forEachLocalMap(positions, normals, *index, domain, k + 1, gathering,
                  [&](std::size_t i, const LocalMapSample& sample, LocalMapSample&) {
                    // A mirrored map is matched by anti-similarities: mirror a first.
                    g.toTangent[i].row(0) = sample.t1.transpose();
                    g.toTangent[i].row(1) = mirror * sample.t2.transpose();
                    std::size_t e = 0;
                    for (std::size_t s = 0; s < sample.index.size() && e < k; ++s) {
                      if (sample.index[s] == i) continue;
                      g.neighbor[i * k + e] = sample.index[s];
                      g.offset[i * k + e] =
                          Vec2(sample.tangent[s].x(), mirror * sample.tangent[s].y());
                      g.weight[i * k + e] = sample.weight[s] + 1e-12;
                      ++e;
                    }
                    for (; e < k; ++e) {  // duplicates of i filled the neighbourhood
                      g.neighbor[i * k + e] = Index(i);
                      g.weight[i * k + e] = 0;
                    }
                  });
  return g;
}

/// The graph Laplacian with edge weights w_ij rho_i: each directed edge i -> j adds w to L_ii,
/// L_jj and -w to L_ij, L_ji; a small diagonal term `pin` pins the translation.
Eigen::SparseMatrix<double> laplacianOf(const RelaxationGraph& g, const std::vector<double>& rho,
                                        double& pin) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(g.n * g.k * 4 + g.n);
  double meanDiagonal = 0;
  for (std::size_t i = 0; i < g.n; ++i)
    for (std::size_t e = 0; e < g.k; ++e) {
      const std::size_t j = g.neighbor[i * g.k + e];
      const double w = g.weight[i * g.k + e] * rho[i];
      if (j == i || !(w > 0)) continue;
      triplets.emplace_back(int(i), int(i), w);
      triplets.emplace_back(int(j), int(j), w);
      triplets.emplace_back(int(i), int(j), -w);
      triplets.emplace_back(int(j), int(i), -w);
      meanDiagonal += 2 * w;
    }
  meanDiagonal /= double(g.n);
  pin = 1e-6 * meanDiagonal;
  for (std::size_t i = 0; i < g.n; ++i) triplets.emplace_back(int(i), int(i), pin);
  Eigen::SparseMatrix<double> laplacian(Eigen::Index(g.n), Eigen::Index(g.n));
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  return laplacian;
}

/// Calls visit(i, j, w, r) for every edge i -> j of the graph, in a fixed order, with its weight
/// w_ij rho_i and the offset S_i a_ij it asks of u_j - u_i (the global step's terms).
template <class Visit>
void forEachTargetOffset(const RelaxationGraph& g, const std::vector<double>& rho,
                         const std::vector<Eigen::Matrix2d>& similarity, Visit visit) {
  for (std::size_t i = 0; i < g.n; ++i)
    for (std::size_t e = 0; e < g.k; ++e) {
      const std::size_t j = g.neighbor[i * g.k + e];
      const double w = g.weight[i * g.k + e] * rho[i];
      if (j == i || !(w > 0)) continue;
      visit(i, j, w, Vec2(similarity[i] * g.offset[i * g.k + e]));
    }
}

/// The local step: per point the similarity best taking a_ij to the domain offset y_ij =
/// offsetOf(i, e) of its e-th neighbour, in i's tangent frame of the domain. In complex form
/// S_i = (a + ib) = sum w conj(x) y / sum w |x|^2. With rigidity r > 0 its scale s becomes
/// s^(1 - r): the rotation alone at r = 1 (as rigid as possible), a geometric blend of the
/// conformal and the rigid targets between.
template <class OffsetOf>
void fitSimilarities(const RelaxationGraph& g, OffsetOf offsetOf, double rigidity,
                     std::vector<Eigen::Matrix2d>& similarity) {
  parallelFor(g.n, [&](std::size_t i) {
    double a = 0, b = 0, norm = 0;
    for (std::size_t e = 0; e < g.k; ++e) {
      const double w = g.weight[i * g.k + e];
      const Vec2& x = g.offset[i * g.k + e];
      const Vec2 y = offsetOf(i, e);
      a += w * (x.x() * y.x() + x.y() * y.y());
      b += w * (x.x() * y.y() - x.y() * y.x());
      norm += w * x.squaredNorm();
    }
    if (rigidity > 0) {
      const double length = std::hypot(a, b);
      const double scale =
          rigidity < 1 && norm > 0 && length > 0 ? std::pow(length / norm, 1 - rigidity) : 1.0;
      a = length > 0 ? scale * a / length : 1;
      b = length > 0 ? scale * b / length : 0;
    } else if (norm > 0) {
      a /= norm;
      b /= norm;
    }
    similarity[i] << a, -b, b, a;
  });
}

/// The robust weights for the next round: rho_i = min(1, median / residual_i), at least
/// 1 / maxDownweight, residual_i the point's RMS misfit relative to its offsets' lengths.
template <class OffsetOf>
std::vector<double> robustWeights(const RelaxationGraph& g, OffsetOf offsetOf,
                                  const std::vector<Eigen::Matrix2d>& similarity,
                                  double maxDownweight) {
  std::vector<double> residual(g.n, 0.0);
  parallelFor(g.n, [&](std::size_t i) {
    double misfit = 0, length = 0;
    for (std::size_t e = 0; e < g.k; ++e) {
      const double w = g.weight[i * g.k + e];
      const Vec2& a = g.offset[i * g.k + e];
      misfit += w * (offsetOf(i, e) - similarity[i] * a).squaredNorm();
      length += w * a.squaredNorm();
    }
    residual[i] = length > 0 ? std::sqrt(misfit / length) : 0;
  });
  const double median = lowerMedian(residual);
  std::vector<double> rho(g.n, 1.0);
  if (!(median > 0)) return rho;
  for (std::size_t i = 0; i < g.n; ++i)
    rho[i] = std::max(1.0 / maxDownweight, std::min(1.0, median / residual[i]));
  return rho;
}

/// The rounds of local-global iterations: `step(solver, pin, rho, similarity)` is the global
/// step of the domain at hand (a solve, then the domain's own constraint); it returns why it
/// failed, or an empty string. `similarity` gets the final local similarities. Progress: one
/// step per iteration.
template <class OffsetOf, class GlobalStep>
std::string relaxRounds(const RelaxationGraph& g, const RelaxationOptions& options, double rigidity,
                        const ProgressCallback& progress, OffsetOf offsetOf, GlobalStep step,
                        std::vector<Eigen::Matrix2d>& similarity) {
  ProgressTracker tracker(progress, "relaxation",
                          std::size_t(options.iterations) * std::size_t(options.rounds));
  similarity.assign(g.n, Eigen::Matrix2d::Identity());
  std::vector<double> rho(g.n, 1.0);
  // The matrix's pattern does not change between rounds (every weight stays > 0): ordered once,
  // factorized once per round. (Conjugate gradients from the current map were slower at 100k
  // and at 1M points: the pinned graph Laplacian is badly conditioned, bench/README.md.)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  for (int round = 0; round < options.rounds; ++round) {
    if (round > 0) rho = robustWeights(g, offsetOf, similarity, options.maxDownweight);
    double pin = 0;
    const Eigen::SparseMatrix<double> laplacian = laplacianOf(g, rho, pin);
    if (round == 0) solver.analyzePattern(laplacian);
    solver.factorize(laplacian);
    if (solver.info() != Eigen::Success)
      return "the k-NN graph's Laplacian could not be factorized";
    for (int iteration = 0; iteration < options.iterations; ++iteration) {
      fitSimilarities(g, offsetOf, rigidity, similarity);
      const std::string failure = step(solver, pin, rho, similarity);
      if (!failure.empty()) return failure;
      tracker.advance(1);
    }
  }
  fitSimilarities(g, offsetOf, rigidity, similarity);
  tracker.finish();
  return {};
}

/// The domain offsets of plane coordinates.
auto planeOffsets(const RelaxationGraph& g, const std::vector<Vec2>& uv) {
  return [&g, &uv](std::size_t i, std::size_t e) -> Vec2 {
    return uv[g.neighbor[i * g.k + e]] - uv[i];
  };
}

/// A tangent basis of the unit sphere at d (e1 x e2 = d).
Eigen::Matrix<double, 3, 2> sphereBasis(const Vec3& d) {
  const Vec3 a = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 e1 = (a - a.dot(d) * d).normalized();
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = e1;
  basis.col(1) = d.cross(e1);
  return basis;
}

/// Relaxes plane coordinates `uv` (the graph's points) in place; `similarity` gets the final
/// local similarities. Returns an empty string, or why the relaxation could not run.
std::string relaxOnGraph(const RelaxationGraph& g, const RelaxationOptions& options,
                         std::vector<Vec2>& uv, std::vector<Eigen::Matrix2d>& similarity,
                         const ProgressCallback& progress) {
  Vec2 centroid;
  const double size = spread(uv, centroid);
  const auto step = [&](const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& solver,
                        double pin, const std::vector<double>& rho,
                        const std::vector<Eigen::Matrix2d>& s) -> std::string {
    // Global: rhs_m = sum_{i->m} w rho_i S_i a_im - sum_{m->j} w rho_m S_m a_mj (+ pin u_m).
    Eigen::MatrixXd rhs(int(g.n), 2);
    for (std::size_t i = 0; i < g.n; ++i) rhs.row(int(i)) = pin * uv[i].transpose();
    forEachTargetOffset(g, rho, s, [&](std::size_t i, std::size_t j, double w, const Vec2& r) {
      rhs.row(int(j)) += w * r.transpose();
      rhs.row(int(i)) -= w * r.transpose();
    });
    const Eigen::MatrixXd solved = solver.solve(rhs);
    // The similarity energy has no scale of its own: keep the domain's spread and centroid
    // (with some rigidity it takes the surface's lengths).
    std::vector<Vec2> next(g.n);
    for (std::size_t i = 0; i < g.n; ++i) next[i] = solved.row(int(i)).transpose();
    Vec2 c;
    const double spreadNow = spread(next, c);
    if (!(spreadNow > 0) || !std::isfinite(spreadNow)) return "the relaxation collapsed the domain";
    const double factor = options.rigidity > 0 ? 1.0 : size / spreadNow;
    for (std::size_t i = 0; i < g.n; ++i) uv[i] = centroid + (next[i] - c) * factor;
    return {};
  };
  return relaxRounds(g, options, options.rigidity, progress, planeOffsets(g, uv), step, similarity);
}

/// The points x_i = R d_i of a sphere domain, on the sphere of radius R about the origin (the
/// sphere's centre), with the tangent bases E_i at them that the local step reads offsets in.
struct SpherePoints {
  double radius = 1;
  std::vector<Vec3> x;
  std::vector<Eigen::Matrix<double, 3, 2>> basis;

  SpherePoints() = default;
  SpherePoints(const std::vector<Vec3>& directions, double r) : radius(r), x(directions.size()) {
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = r * directions[i];
    basis.resize(x.size());
    project();
  }
  /// Every point back on the sphere (a point at the centre stays there), its basis refreshed.
  void project() {
    parallelFor(x.size(), [&](std::size_t i) {
      if (x[i].norm() > 0) x[i] = radius * x[i].normalized();
      basis[i] = sphereBasis(x[i].normalized());
    });
  }
  /// The offset of i's e-th neighbour in g, in i's tangent plane.
  auto offsets(const RelaxationGraph& g) const {
    return [this, &g](std::size_t i, std::size_t e) -> Vec2 {
      return basis[i].transpose() * (x[g.neighbor[i * g.k + e]] - x[i]);
    };
  }
  /// The chord of the sphere from x_i whose tangent part is r (it dips by |r|^2 / 2R below the
  /// tangent plane): an exact sphere is then a fixed point.
  Vec3 lift(std::size_t i, const Vec2& r) const {
    return basis[i] * r - (r.squaredNorm() / (2 * radius)) * x[i].normalized();
  }
};

/// The same on a sphere domain: the local step reads the domain offsets in the sphere's tangent
/// planes, the global step solves for 3D points with the chords whose tangent parts are S_i a_ij,
/// which are then put back on the sphere (with any rigidity, of the radius their mean distance
/// gives: the surface's units).
std::string relaxOnSphere(const RelaxationGraph& g, const RelaxationOptions& options,
                          SpherePoints& sphere, std::vector<Eigen::Matrix2d>& similarity,
                          const ProgressCallback& progress) {
  const auto step = [&](const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& solver,
                        double pin, const std::vector<double>& rho,
                        const std::vector<Eigen::Matrix2d>& s) -> std::string {
    Eigen::MatrixXd rhs(int(g.n), 3);
    for (std::size_t i = 0; i < g.n; ++i) rhs.row(int(i)) = pin * sphere.x[i].transpose();
    forEachTargetOffset(g, rho, s, [&](std::size_t i, std::size_t j, double w, const Vec2& r) {
      const Vec3 lifted = sphere.lift(i, r);
      rhs.row(int(j)) += w * lifted.transpose();
      rhs.row(int(i)) -= w * lifted.transpose();
    });
    // Back onto the sphere about its own centre (the pin keeps it where it was: the points'
    // centroid is not the centre when they do not cover the sphere evenly).
    const Eigen::MatrixXd solved = solver.solve(rhs);
    double mean = 0;
    for (std::size_t i = 0; i < g.n; ++i) mean += solved.row(int(i)).norm();
    mean /= double(g.n);
    if (!(mean > 0) || !std::isfinite(mean)) return "the relaxation collapsed the domain";
    if (options.sphereRigidity > 0) sphere.radius = mean;
    for (std::size_t i = 0; i < g.n; ++i) sphere.x[i] = solved.row(int(i)).transpose();
    sphere.project();
    return {};
  };
  return relaxRounds(g, options, options.sphereRigidity, progress, sphere.offsets(g), step,
                     similarity);
}

/// Per point the linear map (any 2 x 2) that best takes a_ij to y_ij: the relaxed map's
/// own Jacobian, scale and shear included, which places the points between samples
/// consistently with where the samples landed.
template <class OffsetOf>
std::vector<Eigen::Matrix2d> localJacobians(const RelaxationGraph& g, OffsetOf offsetOf) {
  std::vector<Eigen::Matrix2d> jacobian(g.n);
  parallelFor(g.n, [&](std::size_t i) {
    Eigen::Matrix2d xx = Eigen::Matrix2d::Zero(), yx = Eigen::Matrix2d::Zero();
    for (std::size_t e = 0; e < g.k; ++e) {
      const double w = g.weight[i * g.k + e];
      const Vec2& x = g.offset[i * g.k + e];
      xx += w * x * x.transpose();
      yx += w * offsetOf(i, e) * x.transpose();
    }
    // xx is symmetric positive semi-definite: its inverse in closed form, when it has one.
    const double det = xx(0, 0) * xx(1, 1) - xx(0, 1) * xx(1, 0);
    if (!(det > 1e-12 * xx.squaredNorm())) {
      jacobian[i] = Eigen::Matrix2d::Identity();
      return;
    }
    Eigen::Matrix2d inverse;
    inverse << xx(1, 1), -xx(0, 1), -xx(1, 0), xx(0, 0);
    jacobian[i] = yx * (inverse / det);
  });
  return jacobian;
}

/// Local-global iterations whose global step is `sweeps` damped Jacobi sweeps of the system from
/// the current map instead of a solve: after the placement from a subsample, they remove the
/// error finer than the samples' spacing (a smoother's job: a two-grid scheme), at the cost of a
/// few passes over the edges. Deterministic (sequential accumulation). Generic in the domain:
/// `offsetOf(i, e)` reads a neighbour's offset in i's tangent frame of the domain (the local
/// step's input), `lift(i, r)` is the domain offset a tangent offset r asks of a neighbour of i
/// (the plane's r itself; a sphere's chord) and `project()` puts the points back on the domain
/// after each sweep (and refreshes what offsetOf and lift read).
constexpr int kSmoothingIterations = 2, kSmoothingSweeps = 3;

template <class Point, class OffsetOf, class Lift, class Project>
void smoothOnGraph(const RelaxationGraph& g, const RelaxationOptions& options, double rigidity,
                   int iterations, int sweeps, std::vector<Point>& x, OffsetOf offsetOf, Lift lift,
                   Project project) {
  std::vector<Eigen::Matrix2d> similarity(g.n, Eigen::Matrix2d::Identity());
  fitSimilarities(g, offsetOf, rigidity, similarity);
  const std::vector<double> rho =
      options.rounds > 1 ? robustWeights(g, offsetOf, similarity, options.maxDownweight)
                         : std::vector<double>(g.n, 1.0);
  std::vector<double> diagonal(g.n, 0.0);
  for (std::size_t i = 0; i < g.n; ++i)
    for (std::size_t e = 0; e < g.k; ++e) {
      const std::size_t j = g.neighbor[i * g.k + e];
      const double w = g.weight[i * g.k + e] * rho[i];
      if (j == i || !(w > 0)) continue;
      diagonal[i] += w;
      diagonal[j] += w;
    }
  constexpr double kDamping = 0.7;
  std::vector<Point> sum(g.n);
  for (int iteration = 0; iteration < iterations; ++iteration) {
    if (iteration > 0) fitSimilarities(g, offsetOf, rigidity, similarity);
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      // Row m of L x = rhs solved for x_m: x_m = (rhs_m + sum_{edges m-j} w x_j) / L_mm.
      std::fill(sum.begin(), sum.end(), Point::Zero());
      forEachTargetOffset(g, rho, similarity,
                          [&](std::size_t i, std::size_t j, double w, const Vec2& r) {
                            const Point d = lift(i, r);
                            sum[j] += w * (x[i] + d);
                            sum[i] += w * (x[j] - d);
                          });
      for (std::size_t i = 0; i < g.n; ++i)
        if (diagonal[i] > 0) x[i] += kDamping * (sum[i] / diagonal[i] - x[i]);
      project();
    }
  }
}

/// The plane's smoothing keeps the domain's centroid, and its spread without rigidity.
void smoothPlane(const RelaxationGraph& g, const RelaxationOptions& options,
                 std::vector<Vec2>& uv) {
  Vec2 centroid;
  const double size = spread(uv, centroid);
  smoothOnGraph(
      g, options, options.rigidity, kSmoothingIterations, kSmoothingSweeps, uv, planeOffsets(g, uv),
      [](std::size_t, const Vec2& r) { return r; }, [] {});
  Vec2 c;
  const double s = spread(uv, c);
  const double factor = options.rigidity > 0 || !(s > 0) ? 1.0 : size / s;
  for (Vec2& p : uv) p = centroid + (p - c) * factor;
}

/// The sign of the determinant of most of the local maps (+1 on ties).
double majorityDeterminantSign(const std::vector<Eigen::Matrix2d>& jacobian) {
  std::size_t negative = 0, positive = 0;
  for (const Eigen::Matrix2d& a : jacobian) {
    const double det = a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
    negative += det < 0;
    positive += det > 0;
  }
  return negative > positive ? -1.0 : 1.0;
}

/// The graph's tangent coordinates mirrored (y -> -y).
void mirrorGraph(RelaxationGraph& g) {
  for (Vec2& a : g.offset) a.y() = -a.y();
  for (auto& t : g.toTangent) t.row(1) = -t.row(1);
}

/// A mirrored map (most local maps reverse the orientation) is matched by anti-similarities:
/// the graph is mirrored when it is. Returns the orientation (-1: mirrored).
template <class OffsetOf>
double orientGraph(RelaxationGraph& g, OffsetOf offsetOf) {
  const double sign = majorityDeterminantSign(localJacobians(g, offsetOf));
  if (sign < 0) mirrorGraph(g);
  return sign;
}

/// About `target` points of the cloud, Poisson-disk spaced. The separation comes from the
/// points' density (10 neighbours within the median 10-NN radius) and a random packing's count
/// (about 0.7 area / separation^2); it is widened until the sample fits.
std::vector<Index> solveSubsample(const std::vector<Vec3>& positions, std::size_t target) {
  const std::size_t n = positions.size();
  const auto index = makeSpatialIndex(positions);
  const std::size_t stride = std::max<std::size_t>(1, n / 20000);
  std::vector<double> radii;
  std::vector<Neighbor> neighbors;
  for (std::size_t i = 0; i < n; i += stride) {
    index->knnSearch(positions[i], 11, neighbors);
    radii.push_back(std::sqrt(neighbors.back().distSq));
  }
  const double r10 = lowerMedian(radii);
  const double area = double(n) * std::acos(-1.0) * r10 * r10 / 10;
  double separation = std::sqrt(0.7 * area / (0.8 * double(target)));
  std::vector<Index> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = Index(i);
  std::vector<Index> sample;
  for (int attempt = 0; attempt < 8; ++attempt) {
    sample = poissonDiskSample(positions, all, separation, 1);
    if (sample.size() <= target) break;
    separation *= std::sqrt(double(sample.size()) / (0.8 * double(target)));
  }
  return sample;
}

/// Every point placed by the local maps of its 4 nearest samples: x = sum_s w_s predict(s, p -
/// p_s) / sum_s w_s, with the kernel of Eq. 1.6 over 1.5 x the 4th distance; the samples keep
/// their own positions. Point: Vec2 (plane coordinates) or Vec3 (a sphere's points, which the
/// caller puts back on it).
template <class Predict, class Point = std::decay_t<std::invoke_result_t<Predict, Index, Vec3>>>
std::vector<Point> placeFromSamples(const std::vector<Vec3>& positions,
                                    const std::vector<Index>& sample,
                                    const std::vector<Vec3>& samplePositions,
                                    const std::vector<Point>& samplePoints, Predict predict) {
  const auto index = makeSpatialIndex(samplePositions);
  std::vector<Point> out(positions.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<Neighbor> near;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        index->knnSearch(positions[i], 4, near);
                        const double r2 = 2.25 * near.back().distSq;
                        Point sum = Point::Zero();
                        double total = 0;
                        for (const Neighbor& s : near) {
                          const double x = r2 > 0 ? 1 - s.distSq / r2 : 1;
                          const double w = x * x * x * x + 1e-300;
                          sum += w * predict(s.index, positions[i] - samplePositions[s.index]);
                          total += w;
                        }
                        out[i] = sum / total;
                      }
                    });
  for (std::size_t s = 0; s < sample.size(); ++s) out[sample[s]] = samplePoints[s];
  return out;
}

/// The points of the system: all of them, or a Poisson-disk subsample of a large cloud.
struct SolveSet {
  bool subsampled = false;
  std::vector<Index> sample;
  std::vector<Vec3> positions, normals;
};

SolveSet solveSetOf(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                    const RelaxationOptions& options) {
  SolveSet set;
  set.subsampled = positions.size() > options.maxSolvePoints;
  if (!set.subsampled) return set;
  set.sample = solveSubsample(positions, options.maxSolvePoints);
  for (Index i : set.sample) {
    set.positions.push_back(positions[i]);
    if (!normals.empty()) set.normals.push_back(normals[i]);
  }
  return set;
}

/// What the system is solved on: the points (a subsample above maxSolvePoints), the map
/// restricted to them, and their graph.
struct SolveSystem {
  SolveSet set;
  DomainMap domain;  // the map at the samples (subsampled only)
  RelaxationGraph graph;
  const DomainMap& map(const DomainMap& all) const { return set.subsampled ? domain : all; }
};

/// Fills `system` and `solved` (its point count); false when it has too few points for the graph.
bool buildSolveSystem(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                      const DomainMap& map, const RelaxationOptions& options, SolveSystem& system,
                      std::size_t& solved) {
  system.set = solveSetOf(positions, normals, options);
  if (system.set.subsampled) {
    system.domain.kind = map.kind;
    system.domain.radius = map.radius;
    system.domain.centre = map.centre;
    system.domain.orientation = map.orientation;
    for (Index i : system.set.sample) {
      if (map.kind == DomainKind::Plane)
        system.domain.uv.push_back(map.uv[i]);
      else
        system.domain.direction.push_back(map.direction[i]);
    }
  }
  const std::vector<Vec3>& p = system.set.subsampled ? system.set.positions : positions;
  if (p.size() < std::size_t(options.neighbors) + 1) return false;
  solved = p.size();
  system.graph = gatherGraph(p, system.set.subsampled ? system.set.normals : normals,
                             system.map(map), std::size_t(options.neighbors), 1.0);
  return true;
}

/// Relaxes the plane coordinates of `map`; returns why it could not, or an empty string.
std::string relaxPlane(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                       DomainMap& map, const RelaxationOptions& options,
                       const ProgressCallback& progress, std::size_t& solved) {
  SolveSystem system;
  if (!buildSolveSystem(positions, normals, map, options, system, solved)) return "too few points";
  RelaxationGraph& graph = system.graph;
  std::vector<Vec2> uv = system.map(map).uv;
  const double mirror = orientGraph(graph, planeOffsets(graph, uv));
  std::vector<Eigen::Matrix2d> similarity;
  std::string failure = relaxOnGraph(graph, options, uv, similarity, progress);
  if (!failure.empty()) return failure;
  if (!system.set.subsampled) {
    map.uv = std::move(uv);
    return {};
  }
  const std::vector<Eigen::Matrix2d> jacobian = localJacobians(graph, planeOffsets(graph, uv));
  map.uv = placeFromSamples(positions, system.set.sample, system.set.positions, uv,
                            [&](Index s, const Vec3& offset) {
                              return Vec2(uv[s] + jacobian[s] * (graph.toTangent[s] * offset));
                            });
  const RelaxationGraph fine =
      gatherGraph(positions, normals, map, std::size_t(options.neighbors), mirror);
  smoothPlane(fine, options, map.uv);
  return {};
}

/// Relaxes the sphere directions of `map` (and its radius: the surface's units for rotations).
/// Above maxSolvePoints, on a subsample: every other point is placed from the samples' local
/// maps (in their tangent planes, then put back on the sphere) and smoothed at full resolution,
/// as the plane's are.
std::string relaxSphere(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                        DomainMap& map, const RelaxationOptions& options,
                        const ProgressCallback& progress, std::size_t& solved) {
  SolveSystem system;
  if (!buildSolveSystem(positions, normals, map, options, system, solved)) return "too few points";
  RelaxationGraph& graph = system.graph;
  SpherePoints sphere(system.map(map).direction, map.radius > 0 ? map.radius : 1.0);
  const double mirror = orientGraph(graph, sphere.offsets(graph));
  std::vector<Eigen::Matrix2d> similarity;
  std::string failure = relaxOnSphere(graph, options, sphere, similarity, progress);
  if (!failure.empty()) return failure;
  if (system.set.subsampled) {
    const std::vector<Eigen::Matrix2d> jacobian = localJacobians(graph, sphere.offsets(graph));
    SpherePoints full;
    full.radius = sphere.radius;
    full.x = placeFromSamples(
        positions, system.set.sample, system.set.positions, sphere.x,
        [&](Index s, const Vec3& offset) {
          return Vec3(sphere.x[s] +
                      sphere.basis[s] * (jacobian[s] * (graph.toTangent[s] * offset)));
        });
    full.basis.resize(full.x.size());
    full.project();
    DomainMap fineMap = map;
    for (std::size_t i = 0; i < full.x.size(); ++i) fineMap.direction[i] = full.x[i].normalized();
    const RelaxationGraph fine =
        gatherGraph(positions, normals, fineMap, std::size_t(options.neighbors), mirror);
    smoothOnGraph(
        fine, options, options.sphereRigidity, kSmoothingIterations, kSmoothingSweeps, full.x,
        full.offsets(fine), [&](std::size_t i, const Vec2& r) { return full.lift(i, r); },
        [&] { full.project(); });
    sphere = std::move(full);
  }
  constexpr double kDegrees = 180 / kPi;
  for (std::size_t i = 0; i < sphere.x.size(); ++i) {
    if (!(sphere.x[i].norm() > 0)) return "the relaxation put a point at the sphere's centre";
    const Vec3 dir = sphere.x[i].normalized();
    map.direction[i] = dir;
    map.longitude[i] = std::atan2(dir.y(), dir.x()) * kDegrees;
    map.latitude[i] = std::asin(std::clamp(dir.z(), -1.0, 1.0)) * kDegrees;
  }
  map.radius = sphere.radius;
  return {};
}

}  // namespace

void validateRelaxationOptions(const RelaxationOptions& options) {
  if (options.iterations < 0) throw OptionError("RelaxationOptions::iterations must be >= 0");
  if (options.neighbors < 3 || options.neighbors > 64)
    throw OptionError("RelaxationOptions::neighbors must be in [3, 64]");
  if (options.rounds < 1 || options.rounds > 20)
    throw OptionError("RelaxationOptions::rounds must be in [1, 20]");
  if (!(options.maxDownweight >= 1) || !std::isfinite(options.maxDownweight))
    throw OptionError("RelaxationOptions::maxDownweight must be finite and >= 1");
  if (!(options.rigidity >= 0 && options.rigidity <= 1))
    throw OptionError("RelaxationOptions::rigidity must be in [0, 1]");
  if (!(options.sphereRigidity >= 0 && options.sphereRigidity <= 1))
    throw OptionError("RelaxationOptions::sphereRigidity must be in [0, 1]");
  if (options.maxSolvePoints < 1000)
    throw OptionError("RelaxationOptions::maxSolvePoints must be >= 1000");
  validateMapDefectOptions(options.defects);
}

namespace {

/// relaxConformally with the defects of `domain` as given, when the caller knows them already
/// (`knownBefore`, else null: checked when needed).
RelaxationResult relaxChecked(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                              DomainMap& domain, const RelaxationOptions& options,
                              const ProgressCallback& progress, const MapDefects* knownBefore) {
  const auto start = std::chrono::steady_clock::now();
  validateRelaxationOptions(options);
  const std::size_t n = positions.size();
  if (domain.size() != n || (!normals.empty() && normals.size() != n))
    throw OptionError("the cloud and its parametrization have different point counts");
  RelaxationResult result;
  if (options.iterations == 0 || n < std::size_t(options.neighbors) + 1) {
    result.reason = options.iterations == 0 ? "no iteration asked" : "too few points";
    return result;
  }
  if (domain.kind == DomainKind::Sphere && n > options.maxSolvePoints && !options.largeSpheres) {
    result.reason = "a sphere domain is relaxed up to RelaxationOptions::maxSolvePoints = " +
                    std::to_string(options.maxSolvePoints) +
                    " points unless RelaxationOptions::largeSpheres";
    return result;
  }
  // Progress: the relaxation [0, 0.6], the check after [0.6, 0.8], the one before (only when
  // the relaxed map has defects) [0.8, 1].
  DomainMap relaxed = domain;
  result.reason = domain.kind == DomainKind::Plane
                      ? relaxPlane(positions, normals, relaxed, options,
                                   subProgress(progress, 0, 0.6), result.solvedPoints)
                      : relaxSphere(positions, normals, relaxed, options,
                                    subProgress(progress, 0, 0.6), result.solvedPoints);
  if (!result.reason.empty()) return result;
  MapDefects after =
      findMapDefects(positions, normals, relaxed, options.defects, subProgress(progress, 0.6, 0.8));
  // The map before is checked only when the relaxed one has defects: it cannot have fewer than
  // none (the check costs as much as the relaxation's solve at 1M points).
  if (after.folds + after.overlaps > 0) {
    MapDefects before = knownBefore ? *knownBefore
                                    : findMapDefects(positions, normals, domain, options.defects,
                                                     subProgress(progress, 0.8, 1));
    if (after.folds + after.overlaps > before.folds + before.overlaps) {
      const std::string added = "would add folds or overlaps (" +
                                std::to_string(after.folds + after.overlaps) + " points against " +
                                std::to_string(before.folds + before.overlaps) + ")";
      // A point the robust rounds weighed down can fold where the plain least squares keeps
      // it in place (CGAL's nefertiti: 1 point of 100k): retried with one round.
      if (options.rounds > 1) {
        RelaxationOptions plain = options;
        plain.rounds = 1;
        RelaxationResult retry =
            relaxChecked(positions, normals, domain, plain, subProgress(progress, 0.8, 1), &before);
        retry.reason =
            retry.applied ? "" : "the relaxation " + added + "; with one round, " + retry.reason;
        retry.seconds = secondsSince(start);
        return retry;
      }
      result.reason = "the relaxation " + added;
      result.defects = std::move(before);
      return result;
    }
  }
  if (progress && !progress(1.0, "relaxation")) throw Cancelled();
  domain = std::move(relaxed);
  result.defects = std::move(after);
  result.applied = true;
  result.roundsApplied = options.rounds;
  result.seconds = secondsSince(start);
  return result;
}

}  // namespace

RelaxationResult relaxConformally(const std::vector<Vec3>& positions,
                                  const std::vector<Vec3>& normals, DomainMap& domain,
                                  const RelaxationOptions& options,
                                  const ProgressCallback& progress) {
  return relaxChecked(positions, normals, domain, options, progress, nullptr);
}

}  // namespace scalespace
