// Figures 1.10 and 1.11 of the thesis and the speed target of the scales layer.
//
//   fig_1_10 [--points N] [--scales M] [--out DIR] [--mode all|sampler|timing|fig10]
//            [--mls-steps S] [--fig10-points N] [--threads T] [--robust 0|1]
//
// sampler: parallel grid Poisson-disk sampler vs the greedy sequential one (same rule).
// timing:  the whole stack (N points x M scales) streamed to DIR/bench.stack: wall time, per-scale
//          split sampling / index / projection, neighbours per projection, samples per level
//          (Fig. 1.11, written as fig_1_11_*.svg), stack size, and the ratio to one single-scale
//          W3 pass over the same cloud.
// fig10:   alpha in {0.025, 0.05, 0.1, 0.2} against alpha = 0 on a random 1% of the points:
//          median position error / t and median normal error (degrees) per scale, total time
//          (Fig. 1.10, written as fig_1_10_*.svg).
// The cloud is a scan-like height field over [0, 10]^2: steps, a ridge, waves, Gaussian noise.
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "BenchMain.hpp"
#include "scalespace/core/MemoryReuse.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"
#include "scalespace/scales/ScaleStackCompute.hpp"

using namespace scalespace;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// z = steps + ridge + waves; normals from the analytic gradient (steps: vertical faces ignored,
// the sampling is uniform in x, y as from a nadir scanner).
PointCloud scanLikeCloud(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 10);
  std::normal_distribution<double> noise(0, 0.002);
  std::vector<Vec3> p(n), nn(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng);
    const double step = 0.3 * std::floor(x / 2.5);
    const double ridge = 0.8 * std::max(0.0, 1.0 - std::abs(y - 5.0) / 1.5);
    const double wave = 0.1 * std::sin(3 * x) * std::cos(2 * y);
    const double dzdx = 0.3 * std::cos(3 * x) * std::cos(2 * y);
    const double dzdy = -0.2 * std::sin(3 * x) * std::sin(2 * y) +
                        (std::abs(y - 5.0) < 1.5 ? -0.8 / 1.5 * (y > 5 ? 1 : -1) : 0.0);
    p[i] = Vec3(x, y, step + ridge + wave + noise(rng));
    nn[i] = Vec3(-dzdx, -dzdy, 1).normalized();
  }
  PointCloud cloud;
  cloud.setAbsolutePositions(p);
  cloud.setNormals(nn);
  return cloud;
}

struct Series {
  std::string name;
  std::vector<double> x, y;
};

// A minimal SVG line plot (log x optional).
void writeSvg(const std::string& path, const std::string& title, const std::string& xLabel,
              const std::string& yLabel, const std::vector<Series>& series, bool logX, bool logY) {
  const double W = 640, H = 400, L = 70, R = 150, T = 40, B = 50;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  auto fx = [&](double v) { return logX ? std::log10(v) : v; };
  auto fy = [&](double v) { return logY ? std::log10(std::max(v, 1e-12)) : v; };
  for (const auto& s : series)
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      x0 = std::min(x0, fx(s.x[k])), x1 = std::max(x1, fx(s.x[k]));
      y0 = std::min(y0, fy(s.y[k])), y1 = std::max(y1, fy(s.y[k]));
    }
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  auto px = [&](double v) { return L + (fx(v) - x0) / (x1 - x0) * (W - L - R); };
  auto py = [&](double v) { return H - B - (fy(v) - y0) / (y1 - y0) * (H - T - B); };
  std::ofstream out(path);
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
         "fill='white'/>\n";
  out << "<text x='" << W / 2 << "' y='20' text-anchor='middle'>" << title << "</text>\n";
  out << "<line x1='" << L << "' y1='" << H - B << "' x2='" << W - R << "' y2='" << H - B
      << "' stroke='black'/><line x1='" << L << "' y1='" << T << "' x2='" << L << "' y2='" << H - B
      << "' stroke='black'/>\n";
  char buf[64];
  for (int k = 0; k <= 4; ++k) {
    const double vx = x0 + (x1 - x0) * k / 4, vy = y0 + (y1 - y0) * k / 4;
    std::snprintf(buf, sizeof buf, "%.3g", logX ? std::pow(10, vx) : vx);
    out << "<text x='" << L + (W - L - R) * k / 4 << "' y='" << H - B + 15
        << "' text-anchor='middle'>" << buf << "</text>\n";
    std::snprintf(buf, sizeof buf, "%.3g", logY ? std::pow(10, vy) : vy);
    out << "<text x='" << L - 5 << "' y='" << H - B - (H - T - B) * k / 4 + 4
        << "' text-anchor='end'>" << buf << "</text>\n";
  }
  out << "<text x='" << (W - R + L) / 2 << "' y='" << H - 10 << "' text-anchor='middle'>" << xLabel
      << "</text>\n";
  out << "<text x='15' y='" << H / 2 << "' transform='rotate(-90 15 " << H / 2
      << ")' text-anchor='middle'>" << yLabel << "</text>\n";
  const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"};
  for (std::size_t s = 0; s < series.size(); ++s) {
    out << "<polyline fill='none' stroke='" << colours[s % 6] << "' stroke-width='1.5' points='";
    for (std::size_t k = 0; k < series[s].x.size(); ++k)
      out << px(series[s].x[k]) << ',' << py(series[s].y[k]) << ' ';
    out << "'/>\n<text x='" << W - R + 10 << "' y='" << T + 15 * s << "' fill='" << colours[s % 6]
        << "'>" << series[s].name << "</text>\n";
  }
  out << "</svg>\n";
}

std::uint64_t directorySize(const fs::path& p) {
  std::uint64_t total = 0;
  for (const auto& e : fs::recursive_directory_iterator(p))
    if (e.is_regular_file()) total += e.file_size();
  return total;
}

void samplerBench(const PointCloud& cloud, double tMin) {
  std::vector<Index> all(cloud.size());
  std::iota(all.begin(), all.end(), Index(0));
  std::printf("\n== Poisson-disk sampler on %zu points: parallel grid vs greedy sequential ==\n",
              cloud.size());
  std::printf("%10s %10s %12s %12s %8s\n", "radius", "samples", "grid_s", "greedy_s", "speedup");
  for (double r : {0.1 * tMin, tMin, 10 * tMin, 100 * tMin}) {
    auto t0 = Clock::now();
    const auto a = poissonDiskSample(cloud.positions(), all, r, 1);
    const double ta = seconds(t0);
    t0 = Clock::now();
    const auto b = poissonDiskSampleGreedy(cloud.positions(), all, r, 1);
    const double tb = seconds(t0);
    std::printf("%10.4g %10zu %12.3f %12.3f %8.1f   (greedy samples %zu)\n", r, a.size(), ta, tb,
                tb / ta, b.size());
  }
}

void timingBench(const PointCloud& cloud, const ScaleSpaceOptions& options, const fs::path& out) {
  const fs::path stackPath = out / "bench.stack";
  std::printf(
      "\n== Stack: %zu points x %d scales, alpha %.3g, robust %d, mls steps %d, %zu threads ==\n",
      cloud.size(), options.series.count, options.alpha, int(options.fit.robust),
      options.fit.mlsMaxSteps, ThreadLimit::active());
  auto t0 = Clock::now();
  const ScaleSpaceSummary s = computeScaleStackToDisk(cloud, options, stackPath.string());
  const double total = seconds(t0);
  double sampling = 0, index = 0, projection = 0;
  std::printf("%5s %10s %9s %10s %9s %9s %9s %9s\n", "j", "t", "samples", "nbrs/proj", "mls_steps",
              "sample_s", "index_s", "proj_s");
  Series samples{"samples", {}, {}}, nbrs{"neighbours / projection", {}, {}};
  Series ts{"sampling", {}, {}}, ti{"index build", {}, {}}, tp{"projection", {}, {}};
  for (std::size_t j = 0; j < s.stats.size(); ++j) {
    const ScaleStats& st = s.stats[j];
    std::printf("%5zu %10.4g %9zu %10.1f %9.2f %9.4f %9.4f %9.4f\n", j, st.t, st.samples,
                st.meanNeighbors, st.meanMlsSteps, st.samplingSeconds, st.indexSeconds,
                st.projectionSeconds);
    sampling += st.samplingSeconds, index += st.indexSeconds, projection += st.projectionSeconds;
    samples.x.push_back(st.t), samples.y.push_back(double(st.samples));
    nbrs.x.push_back(st.t), nbrs.y.push_back(st.meanNeighbors);
    ts.x.push_back(st.t), ts.y.push_back(std::max(st.samplingSeconds, 1e-5));
    ti.x.push_back(st.t), ti.y.push_back(std::max(st.indexSeconds, 1e-5));
    tp.x.push_back(st.t), tp.y.push_back(std::max(st.projectionSeconds, 1e-5));
  }
  const std::uint64_t bytes = directorySize(stackPath);
  std::printf(
      "total %.2f s (sampling %.2f, index %.2f, projection %.2f, rest incl. writing %.2f)\n", total,
      sampling, index, projection, total - sampling - index - projection);
  std::printf(
      "%.3f us per point per scale per thread\n",
      total * double(ThreadLimit::active()) * 1e6 / double(cloud.size()) / double(s.stats.size()));
  std::printf("stack size %.1f MB (%.1f bytes per point per scale)\n", double(bytes) / 1e6,
              double(bytes) / double(cloud.size()) / double(s.stats.size()));
  writeSvg((out / "fig_1_11_time.svg").string(), "Fig. 1.11: time per scale", "t", "seconds",
           {ts, ti, tp}, true, true);
  writeSvg((out / "fig_1_11_samples.svg").string(), "Fig. 1.11: samples per level", "t", "samples",
           {samples}, true, true);
  writeSvg((out / "fig_1_11_neighbors.svg").string(), "Fig. 1.11: neighbours per projection", "t",
           "neighbours", {nbrs}, true, false);

  // One single-scale W3 pass over the same cloud (all points as samples, same robust and MLS
  // options) at the first scale t_min, where the pyramid keeps (almost) every point: the stack's
  // cost in "passes" (a full-resolution pass at a coarse scale would cost far more: Fig. 1.10).
  const double t = s.series.scales.front();
  auto idx = makeSpatialIndex(cloud.positions());
  const SurfaceSamples samplesRef{cloud.positions(), cloud.normals(), *idx};
  const FitOptions fit = options.fit;
  tbb::enumerable_thread_specific<FitWorkspace> ws;
  t0 = Clock::now();
  std::vector<std::uint8_t> valid(cloud.size());
  parallelFor(cloud.size(), [&](std::size_t i) {
    valid[i] = fitAt(cloud.positions()[i], t, samplesRef, fit, ws.local()).valid;
  });
  const double single = seconds(t0);
  std::printf("single-scale W3 pass at t = %.4g: %.2f s; stack / single pass = %.1f\n", t, single,
              total / single);
  fs::remove_all(stackPath);
}

void fig10Bench(const PointCloud& cloud, ScaleSpaceOptions options, const fs::path& out,
                std::size_t subsetSize) {
  // Reference alpha = 0 on a random subset: every input point is a sample at every scale.
  std::mt19937_64 rng(5);
  std::vector<Index> subset(cloud.size());
  std::iota(subset.begin(), subset.end(), Index(0));
  std::shuffle(subset.begin(), subset.end(), rng);
  subset.resize(std::min(subsetSize, cloud.size()));
  std::sort(subset.begin(), subset.end());
  const auto series = makeScaleSeries(cloud.positions(), options.series);
  const std::size_t m = series.scales.size();
  std::printf(
      "\n== Fig. 1.10: %zu points, %zu scales (t = %.4g .. %.4g), reference alpha = 0 on %zu "
      "points ==\n",
      cloud.size(), m, series.tMin, series.tMax, subset.size());
  auto index = makeSpatialIndex(cloud.positions());
  const SurfaceSamples all{cloud.positions(), cloud.normals(), *index};
  const FitOptions fit = options.fit;
  std::vector<std::vector<Vec3>> refP(m, std::vector<Vec3>(subset.size())), refN = refP;
  std::vector<Vec3> current(subset.size());
  for (std::size_t k = 0; k < subset.size(); ++k) current[k] = cloud.positions()[subset[k]];
  tbb::enumerable_thread_specific<FitWorkspace> ws;
  auto t0 = Clock::now();
  for (std::size_t j = 0; j < m; ++j)
    parallelFor(
        subset.size(),
        [&](std::size_t k) {
          const LocalFit f = fitAt(current[k], series.scales[j], all, fit, ws.local());
          if (f.valid) current[k] = f.projection;
          refP[j][k] = current[k];
          refN[j][k] = f.normal;
        },
        16);
  std::printf("alpha = 0 reference on the subset: %.2f s (%.0f s extrapolated to all points)\n",
              seconds(t0), seconds(t0) * double(cloud.size()) / double(subset.size()));
  std::vector<Series> posErr, nrmErr;
  std::printf("%7s %9s %14s %16s %18s\n", "alpha", "time_s", "median_pos/t", "median_normal_deg",
              "(over scales: max)");
  for (double alpha : {0.025, 0.05, 0.1, 0.2}) {
    options.alpha = alpha;
    Series pe{"alpha " + std::to_string(alpha).substr(0, 5), {}, {}}, ne = pe;
    double medPosAll = 0, medNrmAll = 0, maxPos = 0, maxNrm = 0;
    t0 = Clock::now();
    runScaleSpace(cloud, options, [&](std::size_t j, const ScaleLayer& L, const ScaleStats& st) {
      std::vector<double> dp, dn;
      for (std::size_t k = 0; k < subset.size(); ++k) {
        const std::size_t i = subset[k];
        if (!L.valid[i]) continue;
        const Vec3 p(L.projection[3 * i], L.projection[3 * i + 1], L.projection[3 * i + 2]);
        const Vec3 n(L.normal[3 * i], L.normal[3 * i + 1], L.normal[3 * i + 2]);
        dp.push_back((p - refP[j][k]).norm() / st.t);
        dn.push_back(
            std::acos(std::clamp(n.dot(refN[j][k]) / std::max(1e-12, n.norm() * refN[j][k].norm()),
                                 -1.0, 1.0)) *
            180 / M_PI);
      }
      if (dp.empty()) return;
      std::nth_element(dp.begin(), dp.begin() + dp.size() / 2, dp.end());
      std::nth_element(dn.begin(), dn.begin() + dn.size() / 2, dn.end());
      pe.x.push_back(st.t), pe.y.push_back(std::max(dp[dp.size() / 2], 1e-7));
      ne.x.push_back(st.t), ne.y.push_back(std::max(dn[dn.size() / 2], 1e-5));
      medPosAll += dp[dp.size() / 2] / double(m), medNrmAll += dn[dn.size() / 2] / double(m);
      maxPos = std::max(maxPos, dp[dp.size() / 2]), maxNrm = std::max(maxNrm, dn[dn.size() / 2]);
    });
    std::printf("%7.3f %9.2f %14.5f %16.3f    max %.5f / %.3f deg\n", alpha, seconds(t0), medPosAll,
                medNrmAll, maxPos, maxNrm);
    posErr.push_back(pe), nrmErr.push_back(ne);
  }
  writeSvg((out / "fig_1_10_position.svg").string(),
           "Fig. 1.10: median position error / t vs alpha = 0", "t", "median |p - p0| / t", posErr,
           true, true);
  writeSvg((out / "fig_1_10_normal.svg").string(), "Fig. 1.10: median normal error vs alpha = 0",
           "t", "degrees", nrmErr, true, true);
}

}  // namespace

static int run(int argc, char** argv) {
  scalespace::retainFreedMemory();  // as the CLI does (core/MemoryReuse.hpp)
  std::size_t n = 1000000, fig10Points = 100000;
  int scales = 50, threads = 0, mlsSteps = -1;
  std::string mode = "all", out = ".";
  double tMax = 0;
  bool robust = false;
  for (int a = 1; a + 1 < argc; a += 2) {
    const std::string k = argv[a], v = argv[a + 1];
    if (k == "--points")
      n = scalespace::bench::parseCount(k, v);
    else if (k == "--scales")
      scales = scalespace::bench::parseInteger(k, v);
    else if (k == "--out")
      out = v;
    else if (k == "--mode")
      mode = v;
    else if (k == "--threads")
      threads = scalespace::bench::parseInteger(k, v);
    else if (k == "--mls-steps")
      mlsSteps = scalespace::bench::parseInteger(k, v);
    else if (k == "--fig10-points")
      fig10Points = scalespace::bench::parseCount(k, v);
    else if (k == "--tmax")
      tMax = scalespace::bench::parseNumber(k, v);
    else if (k == "--robust")
      robust = v == "1";
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      return 2;
    }
  }
  fs::create_directories(out);
  ThreadLimit limit(threads);
  ScaleSpaceOptions options;
  options.series.count = scales;
  options.series.tMax = tMax;
  options.fit.robust = robust;
  if (mlsSteps > 0) options.fit.mlsMaxSteps = mlsSteps;
  if (mode == "all" || mode == "sampler" || mode == "timing") {
    const PointCloud cloud = scanLikeCloud(n, 1);
    if (mode != "timing") {
      auto idx = makeSpatialIndex(cloud.positions());
      samplerBench(cloud, medianKnnRadius(cloud.positions(), *idx, 10));
    }
    if (mode != "sampler") timingBench(cloud, options, out);
  }
  if (mode == "all" || mode == "fig10")
    fig10Bench(scanLikeCloud(fig10Points, 2), options, out, fig10Points / 100);
  return 0;
}

int main(int argc, char** argv) {
  return scalespace::bench::guardedMain("fig_1_10", [&] { return run(argc, argv); });
}
