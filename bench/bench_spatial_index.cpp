// Neighbour queries, spatial order and normal estimation/orientation on 1M points.
//
//   bench_spatial_index [--points N] [--queries Q] [--repeat R] [--no-normals]
//
// Each query row runs the first Q points of the storage order as queries (default 200000), R
// times (default 3), and keeps the fastest run: the machine may be shared, the minimum is the
// least disturbed figure.
// Two surfaces: a uniformly sampled unit sphere and a scan-like height field (ridges, steps and
// 2 mm-ish noise), both generated in random order (the worst case for memory locality, e.g. tiles
// merged from several scans). For each: radius queries with ~40 neighbours and kNN (k = 10, 40),
// kd-tree (KdTreeIndex) on the input order vs after spatialOrder(), 1 thread and all threads;
// BruteForceIndex on a small subset as a sanity check (results compared); kd-tree leaf sizes; and
// normal estimation + MST orientation. Prints us/query (wall time / queries) and ratios.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "BenchMain.hpp"
#include "scalespace/core/KdTreeIndex.hpp"
#include "scalespace/core/MemoryReuse.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialOrder.hpp"

using namespace scalespace;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point a) {
  return std::chrono::duration<double>(Clock::now() - a).count();
}

std::vector<Vec3> sphere(std::size_t n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  std::vector<Vec3> p(n);
  for (Vec3& x : p) {
    Vec3 v;
    do v = Vec3(g(rng), g(rng), g(rng));
    while (v.norm() < 1e-9);
    x = v.normalized();
  }
  return p;
}

// 100 m x 100 m terrain: rolling hills, two sharp ridges, a 1 m step (a wall, sampled too) and
// Gaussian noise of 2 cm; coordinates around 1e3 like a recentred scan.
std::vector<Vec3> scanLike(std::size_t n) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.0, 100.0), w(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<Vec3> p(n);
  for (Vec3& x : p) {
    const double a = u(rng), b = u(rng);
    double h = 2.0 * std::sin(a / 9.0) * std::cos(b / 13.0);
    h += 3.0 * std::max(0.0, 1.0 - std::abs(a - 30.0) / 4.0);  // ridge
    h += 2.0 * std::max(0.0, 1.0 - std::abs(a + b - 120.0) / 3.0);
    if (b > 60.0) h += 1.0;  // step
    if (w(rng) < 0.01) {     // 1% of the points on the vertical face of the step
      x = Vec3(a, 60.0, h - (b > 60.0 ? 1.0 : 0.0) + w(rng));
    } else {
      x = Vec3(a, b, h);
    }
    x += Vec3(noise(rng), noise(rng), noise(rng)) + Vec3(1000, 1000, 100);
  }
  return p;
}

enum class Query { Radius, Knn10, Knn40 };
const char* queryName(Query q) {
  return q == Query::Radius ? "radius~40" : q == Query::Knn10 ? "knn10" : "knn40";
}

// Runs `count` queries centred on points[0..count) (in the given storage order) and returns the
// wall time per query in microseconds; `found` receives the total neighbour count (checksum).
int gRepeat = 3;

double timeQueriesOnce(const SpatialIndex& index, const std::vector<Vec3>& points,
                       std::size_t count, Query query, double radius, std::size_t& found) {
  tbb::enumerable_thread_specific<std::vector<Neighbor>> scratch;
  tbb::enumerable_thread_specific<std::size_t> sums(0);
  const auto start = Clock::now();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      auto& out = scratch.local();
                      std::size_t& s = sums.local();
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        if (query == Query::Radius)
                          index.radiusSearch(points[i], radius, out);
                        else
                          index.knnSearch(points[i], query == Query::Knn10 ? 10 : 40, out);
                        s += out.size();
                      }
                    });
  const double t = seconds(start);
  found = 0;
  for (std::size_t s : sums) found += s;
  return 1e6 * t / double(count);
}

double timeQueries(const SpatialIndex& index, const std::vector<Vec3>& points, std::size_t count,
                   Query query, double radius, std::size_t& found) {
  double best = timeQueriesOnce(index, points, count, query, radius, found);
  for (int r = 1; r < gRepeat; ++r)
    best = std::min(best, timeQueriesOnce(index, points, count, query, radius, found));
  return best;
}

// The radius for ~40 neighbours: median distance of the 40th neighbour over a sample.
double radiusFor40(const SpatialIndex& index, const std::vector<Vec3>& points) {
  std::vector<double> d;
  std::vector<Neighbor> out;
  for (std::size_t i = 0; i < points.size(); i += std::max<std::size_t>(1, points.size() / 2000)) {
    index.knnSearch(points[i], 40, out);
    d.push_back(std::sqrt(out.back().distSq));
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

void benchSurface(const std::string& name, const std::vector<Vec3>& input, std::size_t queries,
                  bool normals) {
  const std::size_t n = input.size();
  queries = std::min(queries, n);
  std::printf("\n== %s: %zu points, %zu queries per row ==\n", name.c_str(), n, queries);

  auto t0 = Clock::now();
  const std::vector<Index> order = spatialOrder(input);
  const double tOrder = seconds(t0);
  t0 = Clock::now();
  const std::vector<Vec3> sorted = applyPermutation(input, order);
  const double tApply = seconds(t0);
  t0 = Clock::now();
  const KdTreeIndex inputTree(input);
  const double tBuildInput = seconds(t0);
  t0 = Clock::now();
  const KdTreeIndex sortedTree(sorted);
  const double tBuildSorted = seconds(t0);
  std::printf(
      "spatialOrder %.3f s, apply %.3f s; kd-tree build %.3f s (input order), %.3f s "
      "(sorted)\n",
      tOrder, tApply, tBuildInput, tBuildSorted);
  const double radius = radiusFor40(sortedTree, sorted);
  std::printf("radius for ~40 neighbours: %.5g\n", radius);

  const std::size_t all = tbb::info::default_concurrency();
  std::printf("%-10s %-8s %7s %12s %12s %10s\n", "query", "order", "threads", "us/query",
              "neighbours", "vs input");
  for (Query q : {Query::Radius, Query::Knn10, Query::Knn40}) {
    for (std::size_t threads : {std::size_t(1), all}) {
      ThreadLimit limit(static_cast<int>(threads));
      std::size_t foundInput = 0, foundSorted = 0;
      const double tIn = timeQueries(inputTree, input, queries, q, radius, foundInput);
      const double tSo = timeQueries(sortedTree, sorted, queries, q, radius, foundSorted);
      std::printf("%-10s %-8s %7zu %12.3f %12.2f %10s\n", queryName(q), "input", threads, tIn,
                  double(foundInput) / double(queries), "1.00");
      std::printf("%-10s %-8s %7zu %12.3f %12.2f %9.2fx\n", queryName(q), "sorted", threads, tSo,
                  double(foundSorted) / double(queries), tIn / tSo);
    }
  }

  // Leaf size (sorted order, all threads).
  std::printf(
      "leaf size (sorted order, %zu threads): us/query radius~40 / knn10 / knn40, build s\n", all);
  for (std::size_t leaf : {4, 10, 16, 20, 32, 64}) {
    t0 = Clock::now();
    const KdTreeIndex tree(sorted, KdTreeOptions{leaf});
    const double tb = seconds(t0);
    std::size_t f;
    const double r = timeQueries(tree, sorted, queries, Query::Radius, radius, f);
    const double k10 = timeQueries(tree, sorted, queries, Query::Knn10, radius, f);
    const double k40 = timeQueries(tree, sorted, queries, Query::Knn40, radius, f);
    std::printf("  leaf %3zu: %8.3f %8.3f %8.3f   build %.3f\n", leaf, r, k10, k40, tb);
  }

  // Brute force sanity check on a small subset of queries (the cloud is complete).
  {
    const BruteForceIndex brute(sorted);
    const std::size_t m = 50;
    std::vector<Neighbor> a, b;
    std::size_t mismatches = 0;
    t0 = Clock::now();
    for (std::size_t i = 0; i < m; ++i) brute.knnSearch(sorted[i * (n / m)], 10, a);
    const double tBrute = 1e6 * seconds(t0) / double(m);
    for (std::size_t i = 0; i < m; ++i) {
      const Vec3& q = sorted[i * (n / m)];
      brute.knnSearch(q, 40, a);
      sortedTree.knnSearch(q, 40, b);
      for (std::size_t j = 0; j < a.size(); ++j)
        mismatches += (j >= b.size() || a[j].index != b[j].index || a[j].distSq != b[j].distSq);
      brute.radiusSearch(q, radius, a);
      sortedTree.radiusSearch(q, radius, b);
      mismatches += a.size() != b.size();
    }
    // The kd-tree on the same scattered queries, one thread, best of 20 runs (so warm caches).
    double tTree = 1e30;
    for (int rep = 0; rep < 20; ++rep) {
      t0 = Clock::now();
      for (std::size_t i = 0; i < m; ++i) sortedTree.knnSearch(sorted[i * (n / m)], 10, b);
      tTree = std::min(tTree, 1e6 * seconds(t0) / double(m));
    }
    std::printf(
        "brute force knn10: %.1f us/query over %zu queries (kd-tree %.3f us on the same "
        "queries, %.0fx); kd-tree vs brute force mismatches (knn40 + radius): %zu\n",
        tBrute, m, tTree, tBrute / tTree, mismatches);
  }

  if (!normals) return;
  for (const bool useSorted : {false, true}) {
    const std::vector<Vec3>& pts = useSorted ? sorted : input;
    const KdTreeIndex& tree = useSorted ? sortedTree : inputTree;
    for (std::size_t threads : {std::size_t(1), all}) {
      ThreadLimit limit(static_cast<int>(threads));
      t0 = Clock::now();
      NormalEstimationResult est = estimateNormals(pts, tree);
      const double tEst = seconds(t0);
      t0 = Clock::now();
      const NormalOrientationResult ori = orientNormals(pts, est.normals, tree, {}, est.valid);
      const double tOri = seconds(t0);
      std::size_t outward = 0;
      if (name == "sphere")
        for (std::size_t i = 0; i < n; ++i) outward += est.normals[i].dot(pts[i]) > 0;
      std::printf(
          "normals (%s order, %zu thr): estimate %.2f s (%.2f us/pt), invalid %zu; MST "
          "orientation %.2f s, components %zu, unreliable %zu, flipped %zu",
          useSorted ? "sorted" : "input", threads, tEst, 1e6 * tEst / double(n), est.invalidCount,
          tOri, ori.componentCount, ori.unreliableCount, ori.flippedCount);
      if (name == "sphere") std::printf(", outward %.4f%%", 100.0 * double(outward) / double(n));
      std::printf("\n");
    }
  }
}

}  // namespace

static int run(int argc, char** argv) {
  scalespace::retainFreedMemory();  // as the CLI does (core/MemoryReuse.hpp)
  std::size_t points = 1000000, queries = 0;
  bool normals = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--points") && i + 1 < argc)
      points = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--queries") && i + 1 < argc)
      queries = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
      gRepeat = std::max(1, scalespace::bench::integerArgument(argv, ++i));
    else if (!std::strcmp(argv[i], "--no-normals"))
      normals = false;
    else {
      std::fprintf(stderr, "usage: %s [--points N] [--queries Q] [--repeat R] [--no-normals]\n",
                   argv[0]);
      return 2;
    }
  }
  if (queries == 0) queries = std::min<std::size_t>(points, 200000);
  std::printf("bench_spatial_index: %zu points, %zu queries x best of %d, %d hardware threads\n",
              points, queries, gRepeat, tbb::info::default_concurrency());
  benchSurface("sphere", sphere(points), queries, normals);
  benchSurface("scan-like", scanLike(points), queries, normals);
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("bench_spatial_index", [&] { return run(argc, argv); });
}
