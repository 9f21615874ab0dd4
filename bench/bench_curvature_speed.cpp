// Speed of the per-point fits (issue: W3 <= 2.5 us per point per core at ~40 neighbours,
// neighbour query included), on a sphere and on a noisy scan-like surface, with CGAL's Monge jets
// (degree 2) timed in the same run on the same neighbourhoods as the peer.
//
//   bench_curvature_speed [--points N] [--peer-points M] [--only-w3] [--no-sweep]
//
// --only-w3 times W3 alone and --no-sweep skips the neighbour sweep (quicker profiling runs).
//
// Prints one table per surface: estimator, threads, seconds, us per point per core, and the
// ratio to the peer.
#include <CGAL/Monge_via_jet_fitting.h>
#include <CGAL/Simple_cartesian.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "BenchMain.hpp"
#include "scalespace/core/MemoryReuse.hpp"
#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/CurvatureEstimation.hpp"

using namespace scalespace;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point a) {
  return std::chrono::duration<double>(Clock::now() - a).count();
}

struct Surface {
  std::string name;
  PointCloud cloud;
  double area;  // to choose t for a target neighbour count
};

// Uniform samples on the unit sphere, outward normals.
Surface sphere(std::size_t n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  std::vector<Vec3> p(n), nr(n);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 v(g(rng), g(rng), g(rng));
    v.normalize();
    p[i] = v;
    nr[i] = v;
  }
  Surface s{"sphere (r = 1)", {}, 4 * M_PI};
  s.cloud.setAbsolutePositions(p);
  s.cloud.setNormals(nr);
  return s;
}

// A scan-like height field on [0,4]x[0,4]: waves, a ridge and a step (smoothed), with Gaussian
// noise of 0.2% of the size on the positions and perturbed normals — what a terrestrial scan of a
// facade or a terrain looks like locally. Georeferenced offset to exercise recentring.
Surface scanLike(std::size_t n) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.0, 4.0);
  std::normal_distribution<double> g(0.0, 0.008);
  auto h = [](double x, double y) {
    return 0.15 * std::sin(2.0 * x) * std::cos(1.5 * y) +
           0.3 * std::exp(-8.0 * (x - 2.0) * (x - 2.0)) + 0.2 * std::tanh(10.0 * (y - 2.5));
  };
  std::vector<Vec3> p(n), nr(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng), e = 1e-5;
    const double hx = (h(x + e, y) - h(x - e, y)) / (2 * e),
                 hy = (h(x, y + e) - h(x, y - e)) / (2 * e);
    p[i] = Vec3(652000.0 + x, 5412000.0 + y, 300.0 + h(x, y) + g(rng));
    nr[i] = Vec3(-hx, -hy, 1.0).normalized();
  }
  Surface s{"scan-like height field", {}, 16.0 * 1.15};
  s.cloud.setAbsolutePositions(p);
  s.cloud.setNormals(nr);
  return s;
}

double scaleFor(const Surface& s, double neighbours) {
  return std::sqrt(neighbours * s.area / (M_PI * double(s.cloud.size())));
}

// CGAL Monge jet fitting (degree 2) on the neighbours within t of `m` points, neighbour query
// included (our kd-tree), one thread. Returns seconds per point.
double peerJets(const Surface& s, double t, std::size_t m) {
  using K = CGAL::Simple_cartesian<double>;
  using Fitting = CGAL::Monge_via_jet_fitting<K>;
  const auto& pos = s.cloud.positions();
  const auto index = makeSpatialIndex(pos);
  std::vector<Neighbor> nb;
  std::vector<K::Point_3> pts;
  const std::size_t stride = std::max<std::size_t>(1, pos.size() / m);
  double sink = 0;
  std::size_t count = 0;
  const auto start = Clock::now();
  for (std::size_t i = 0; i < pos.size(); i += stride, ++count) {
    index->radiusSearch(pos[i], t, nb);
    if (nb.size() < 6) continue;
    pts.clear();
    for (const Neighbor& q : nb)
      pts.emplace_back(pos[q.index].x(), pos[q.index].y(), pos[q.index].z());
    Fitting fit;
    const Fitting::Monge_form form = fit(pts.begin(), pts.end(), 2, 2);
    sink += form.principal_curvatures(0);
  }
  const double sec = seconds(start);
  if (sink == 12345.678) std::puts("");  // keep the fits alive
  return sec / double(count);
}

struct Run {
  double seconds;
  CurvatureSummary summary;
};

Run runFits(Surface& s, EstimatorKind kind, double t, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  CurvatureOptions o;
  o.fit.estimator = kind;
  o.scale = t;
  const auto start = Clock::now();
  CurvatureSummary summary = computeCurvatureColumns(s.cloud, o);
  return {seconds(start), summary};
}

}  // namespace

static int run(int argc, char** argv) {
  scalespace::retainFreedMemory();  // as the CLI does (core/MemoryReuse.hpp)
  std::size_t n = 1000000, peerPoints = 20000;
  bool onlyW3 = false, sweep = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--points") && i + 1 < argc)
      n = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--peer-points") && i + 1 < argc)
      peerPoints = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--only-w3"))
      onlyW3 = true;
    else if (!std::strcmp(argv[i], "--no-sweep"))
      sweep = false;
    else {
      std::fprintf(stderr, "unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  const int cores = tbb::info::default_concurrency();
  std::printf(
      "bench_curvature_speed: %zu points, %d cores, peer = CGAL Monge jets (degree 2) on %zu "
      "points\n",
      n, cores, peerPoints);
  for (Surface s : {sphere(n), scanLike(n)}) {
    const double t40 = scaleFor(s, 40);
    std::printf("\n== %s, t = %.5g (about 40 neighbours)\n", s.name.c_str(), t40);
    std::printf("%-9s %7s %9s %12s %14s %10s %15s\n", "estimator", "threads", "seconds",
                "neighbours", "us/point/core", "vs peer", "fits us/pt/core");
    const double peer = peerJets(s, t40, peerPoints);
    for (EstimatorKind kind : {EstimatorKind::W1, EstimatorKind::W2, EstimatorKind::W3}) {
      if (onlyW3 && kind != EstimatorKind::W3) continue;
      for (int threads : {1, cores}) {
        const Run r = runFits(s, kind, t40, threads);
        const double us = r.seconds * threads / double(n) * 1e6;
        std::printf("%-9s %7d %9.3f %12.1f %14.3f %9.1fx %15.3f\n", estimatorName(kind), threads,
                    r.seconds, r.summary.meanNeighbors, us, peer * 1e6 / us,
                    r.summary.fitSeconds * threads / double(n) * 1e6);
        if (threads == cores && cores == 1) break;
      }
    }
    std::printf("%-9s %7d %9s %12s %14.3f %10s\n", "cgal-jet", 1, "-", "~40", peer * 1e6, "1.0x");
    if (!sweep) continue;

    std::printf("\n   neighbour sweep (W3, %d threads; peer on %zu points)\n", cores,
                peerPoints / 4);
    std::printf("%12s %12s %14s %16s %10s\n", "target", "neighbours", "us/point/core",
                "cgal us/point", "ratio");
    for (double k : {10.0, 50.0, 200.0, 1000.0}) {
      const double t = scaleFor(s, k);
      const Run r = runFits(s, EstimatorKind::W3, t, cores);
      const double us = r.seconds * cores / double(n) * 1e6;
      const double p = peerJets(s, t, peerPoints / 4) * 1e6;
      std::printf("%12.0f %12.1f %14.3f %16.3f %9.1fx\n", k, r.summary.meanNeighbors, us, p,
                  p / us);
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("bench_curvature_speed", [&] { return run(argc, argv); });
}
