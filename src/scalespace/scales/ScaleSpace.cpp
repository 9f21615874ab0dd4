#include "scalespace/scales/ScaleSpace.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/Parallel.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/fit/FitPoints.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"

namespace scalespace {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void put3(std::vector<float>& v, std::size_t i, const Vec3& x) {
  v[3 * i] = float(x.x());
  v[3 * i + 1] = float(x.y());
  v[3 * i + 2] = float(x.z());
}

/// Sizes the arrays of the layer that `contents` holds, for n points; the others are left empty.
void sizeLayer(ScaleLayer& layer, std::size_t n, LayerContents contents) {
  if (contents == LayerContents::All) return layer.resize(n);
  layer = ScaleLayer{};
  layer.normal.assign(3 * n, 0.0f);
  for (auto* v : {&layer.meanCurvature, &layer.kMax, &layer.kMin}) v->assign(n, 0.0f);
  layer.valid.assign(n, 0);
  if (contents == LayerContents::NormalCurvaturesAndProjection)
    layer.projection.assign(3 * n, 0.0f);
}

/// Stores the fit of point i in the layer, with `projection` (the fit's, or the last valid one
/// when the fit is invalid); only what `contents` holds (planes read five of the fourteen
/// arrays: the other stores were 2.5 GB of memory traffic per 50 scales of 1M points).
void recordFit(const LocalFit& f, const Vec3& projection, std::size_t i, LayerContents contents,
               ScaleLayer& layer) {
  layer.valid[i] = f.valid ? 1 : 0;
  put3(layer.normal, i, f.normal);
  layer.meanCurvature[i] = float(f.meanCurvature);
  layer.kMax[i] = float(f.kMax);
  layer.kMin[i] = float(f.kMin);
  if (contents == LayerContents::NormalCurvaturesAndProjection)
    put3(layer.projection, i, projection);
  if (contents != LayerContents::All) return;
  layer.neighbors[i] = std::uint16_t(std::clamp(f.neighbors, 0, 65535));
  put3(layer.projection, i, projection);
  put3(layer.dirMax, i, f.dirMax);
  put3(layer.dirMin, i, f.dirMin);
  layer.tau[i] = float(f.tau);
  layer.kappa[i] = float(f.kappa);
  layer.fitness[i] = float(f.fitness);
  layer.anisotropy[i] = float(f.anisotropy);
  layer.geometricVariation[i] = float(f.geometricVariation);
}

/// out[i] = in[rank[i]] for every array of the layer, items of `width` values (3 for vectors).
template <typename T>
void gather(const std::vector<T>& in, const std::vector<Index>& rank, std::size_t width,
            std::vector<T>& out) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rank.size(), 4096), [&](const auto& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i)
      for (std::size_t c = 0; c < width; ++c) out[width * i + c] = in[width * rank[i] + c];
  });
}

/// The layer in input order from the layer in processing (Morton) order: point i of the cloud is
/// point rank[i] of the processing order. The fits are recorded in processing order and put in
/// input order here, one array at a time: storing each fit straight at its input index scatters
/// ~200 bytes per point over 14 arrays of the whole cloud, which is slower than this gather
/// (projection time of bench/fig_1_10 --mode timing).
void toInputOrder(const ScaleLayer& spatial, const std::vector<Index>& rank, LayerContents contents,
                  ScaleLayer& layer) {
  const bool all = contents == LayerContents::All;
  gather(spatial.normal, rank, 3, layer.normal);
  for (auto [in, out] : {std::pair{&spatial.meanCurvature, &layer.meanCurvature},
                         {&spatial.kMax, &layer.kMax},
                         {&spatial.kMin, &layer.kMin}})
    gather(*in, rank, 1, *out);
  gather(spatial.valid, rank, 1, layer.valid);
  if (contents == LayerContents::NormalCurvaturesAndProjection)
    gather(spatial.projection, rank, 3, layer.projection);
  if (!all) return;
  for (auto [in, out] : {std::pair{&spatial.projection, &layer.projection},
                         {&spatial.dirMax, &layer.dirMax},
                         {&spatial.dirMin, &layer.dirMin}})
    gather(*in, rank, 3, *out);
  for (auto [in, out] : {std::pair{&spatial.tau, &layer.tau},
                         {&spatial.kappa, &layer.kappa},
                         {&spatial.fitness, &layer.fitness},
                         {&spatial.anisotropy, &layer.anisotropy},
                         {&spatial.geometricVariation, &layer.geometricVariation}})
    gather(*in, rank, 1, *out);
  gather(spatial.neighbors, rank, 1, layer.neighbors);
}

/// The samples of one pyramid level and their index (Sec. 1.5.2).
struct PyramidLevel {
  std::vector<Index> members;  // indices into the (Morton-ordered) positions
  std::vector<Vec3> positions, normals;
  std::unique_ptr<SpatialIndex> index;
  double samplingSeconds = 0, indexSeconds = 0;
};

/// Level j drawn from the level before it (`previous`) with disk radius r_j = alpha t_j (nested
/// pyramid, samplePyramidLevel), with its samples' positions, normals and index.
void makePyramidLevel(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                      const std::vector<Index>& previous, double alpha, double t,
                      std::uint64_t seed, std::size_t j, PyramidLevel& level) {
  auto t0 = std::chrono::steady_clock::now();
  level.members = samplePyramidLevel(positions, previous, alpha, t, seed, j);
  level.samplingSeconds = secondsSince(t0);
  t0 = std::chrono::steady_clock::now();
  level.positions.resize(level.members.size());
  level.normals.resize(level.members.size());
  for (std::size_t s = 0; s < level.members.size(); ++s) {
    level.positions[s] = positions[level.members[s]];
    level.normals[s] = normals[level.members[s]];
  }
  level.index = makeSpatialIndex(level.positions);
  level.indexSeconds = secondsSince(t0);
}

}  // namespace

void ScaleLayer::resize(std::size_t n) {
  for (auto* v : {&projection, &normal, &dirMax, &dirMin}) v->assign(3 * n, 0.0f);
  for (auto* v :
       {&meanCurvature, &kMax, &kMin, &tau, &kappa, &fitness, &anisotropy, &geometricVariation})
    v->assign(n, 0.0f);
  neighbors.assign(n, 0);
  valid.assign(n, 0);
}

bool ScaleLayer::complete() const {
  const std::size_t n = size();
  if (!inputIndex.empty() && inputIndex.size() != n) return false;
  for (const auto* v : {&projection, &normal, &dirMax, &dirMin})
    if (v->size() != 3 * n) return false;
  for (const auto* v :
       {&meanCurvature, &kMax, &kMin, &tau, &kappa, &fitness, &anisotropy, &geometricVariation})
    if (v->size() != n) return false;
  return neighbors.size() == n;
}

ScaleLayer inInputOrder(const ScaleLayer& layer) {
  if (layer.inputIndex.empty()) return layer;
  ScaleLayer out;
  out.resize(layer.size());
  toInputOrder(layer, invertPermutation(layer.inputIndex), LayerContents::All, out);
  return out;
}

std::uint64_t cloudChecksum(const PointCloud& cloud) {
  std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a offset basis
  auto mix = [&h](double d) {
    unsigned char b[8];
    std::memcpy(b, &d, 8);  // little-endian hosts only (x86-64, arm64)
    for (unsigned char c : b) {
      h ^= c;
      h *= 0x100000001b3ULL;  // FNV prime
    }
  };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.absolutePosition(i);
    mix(p.x()), mix(p.y()), mix(p.z());
  }
  for (const Vec3& n : cloud.normals()) mix(n.x()), mix(n.y()), mix(n.z());
  return h;
}

void validateScaleSpaceOptions(const ScaleSpaceOptions& options) {
  validateScaleCount(options.series.count);
  validatePyramidAlpha(options.alpha);
  validateFitOptions(options.fit);
  if (!options.fit.mls)
    throw OptionError(
        "ScaleSpaceOptions::fit.mls must be true: the stack projects every point (Fig. 1.9)");
}

ScaleSpaceSummary runScaleSpace(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                const ScaleSink& sink, const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (cloud.empty()) throw OptionError("the cloud has no points: nothing to analyse");
  if (!cloud.hasNormals())
    throw OptionError(
        "the multi-scale projection needs oriented normals: estimate and orient them first "
        "(core/NormalEstimation + NormalOrientation; the CLI does it when they are missing)");
  validateScaleSpaceOptions(options);
  ThreadLimit limit(options.threads);

  ScaleSpaceSummary summary;
  summary.inputChecksum = cloudChecksum(cloud);
  const std::size_t n = cloud.size();

  // Process points along a Morton curve: consecutive points share neighbours (cache reuse).
  const std::vector<Index> order = spatialOrder(cloud.positions());
  const std::vector<Vec3> positions = applyPermutation(cloud.positions(), order);
  const std::vector<Vec3> normals = applyPermutation(cloud.normals(), order);
  // Builds an index only when t_min is automatic and not known already.
  summary.series = makeScaleSeries(positions, options.series);
  const std::vector<double>& scales = summary.series.scales;
  const std::size_t m = scales.size();

  std::vector<Vec3> current = positions;  // projection at the previous scale (Fig. 1.9)
  // Level 0 draws from every point.
  std::vector<Index> everyPoint(n);
  for (std::size_t k = 0; k < n; ++k) everyPoint[k] = Index(k);
  const bool inputOrder = options.layerOrder == LayerOrder::Input;
  const std::vector<Index> rank = inputOrder ? invertPermutation(order) : std::vector<Index>{};
  ScaleLayer spatial, layer;  // this scale in processing order, and in input order
  sizeLayer(spatial, n, options.layerContents);
  if (inputOrder) sizeLayer(layer, n, options.layerContents);
  if (!inputOrder) spatial.inputIndex = order;
  // Each scale starts from the projections of the previous one (`current`) and writes this
  // scale's into `next`; a point converged at its first MLS step at the previous scale likely
  // does again (FitQueries::convergedAtFirstStep).
  std::vector<Vec3> next(n);
  std::vector<std::uint8_t> convergedBefore(n, 0), convergedNow(n, 0);
  std::vector<double> scaleOfAll(1);
  FitPointsOptions walk;
  walk.fit = options.fit;
  walk.walk = QueryWalk::AsGiven;  // the points are in Morton order already
  // Level j + 1 of the pyramid depends on level j only, not on the projection: it is drawn and
  // indexed in a task while scale j projects (the index build is sequential and would leave the
  // other cores idle; bench/fig_1_10 --mode timing prints both times per scale).
  PyramidLevel thisLevel, nextLevel;
  tbb::task_group prepare;
  auto prepareLevel = [&](std::size_t j, const std::vector<Index>& previous, PyramidLevel& out) {
    makePyramidLevel(positions, normals, previous, options.alpha, scales[j], options.seed, j, out);
  };
  prepareLevel(0, everyPoint, thisLevel);
  everyPoint = {};

  try {
    for (std::size_t j = 0; j < m; ++j) {
      ScaleStats stats;
      stats.t = scales[j];
      stats.samplingSeconds = thisLevel.samplingSeconds;
      stats.samples = thisLevel.members.size();
      stats.indexSeconds = thisLevel.indexSeconds;
      if (j + 1 < m) prepare.run([&, j] { prepareLevel(j + 1, thisLevel.members, nextLevel); });

      auto t0 = std::chrono::steady_clock::now();
      const SurfaceSamples samples{thisLevel.positions, thisLevel.normals, *thisLevel.index};
      const double t = scales[j];
      // ProgressTracker keeps a reference to its callback: it must outlive the tracker.
      const ProgressCallback scaleProgress =
          progress ? ProgressCallback([&](double f, std::string_view) {
            return progress((double(j) + f) / double(m),
                            "scale " + std::to_string(j + 1) + "/" + std::to_string(m));
          })
                   : ProgressCallback();
      auto record = [&](std::size_t k, std::size_t, const LocalFit& f) {
        convergedNow[k] = f.mlsSteps == 1;
        next[k] = f.valid ? f.projection : current[k];  // an invalid fit keeps the last one
        recordFit(f, next[k], k, options.layerContents, spatial);
      };
      scaleOfAll[0] = t;
      const FitPointsSummary fits =
          fitPoints(samples, FitQueries{current, scaleOfAll, j > 0 ? &convergedBefore : nullptr},
                    walk, record, scaleProgress);
      std::swap(current, next);
      std::swap(convergedBefore, convergedNow);
      if (inputOrder) toInputOrder(spatial, rank, options.layerContents, layer);
      const ScaleLayer& result = inputOrder ? layer : spatial;
      stats.projectionSeconds = secondsSince(t0);
      stats.meanNeighbors = fits.neighbors / double(n);
      stats.meanMlsSteps = fits.mlsSteps / double(n);
      for (std::uint8_t v : result.valid) stats.validPoints += v;
      summary.stats.push_back(stats);
      if (sink) sink(j, result, stats);
      prepare.wait();
      std::swap(thisLevel, nextLevel);
    }
  } catch (...) {
    // The level task reads this frame: it must end before the frame unwinds (a cancelled
    // projection, a failing sink).
    prepare.cancel();
    prepare.wait();
    throw;
  }
  summary.totalSeconds = secondsSince(start);
  return summary;
}

ScaleStack computeScaleStackInMemory(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                     const ProgressCallback& progress) {
  ScaleStack stack;
  stack.summary = runScaleSpace(
      cloud, options,
      [&](std::size_t, const ScaleLayer& layer, const ScaleStats&) {
        stack.layers.push_back(layer);
      },
      progress);
  return stack;
}

FitCounts stackFitCounts(const ScaleSpaceSummary& summary, std::size_t points,
                         const ScaleSpaceOptions& options) {
  FitCounts counts;
  counts.largestScale = summary.series.tMax;
  counts.minNeighbors = options.fit.minNeighbors;
  for (const ScaleStats& stats : summary.stats) {
    counts.total += points;
    counts.invalid += points - stats.validPoints;
    counts.meanNeighbors += stats.meanNeighbors / double(summary.stats.size());
  }
  return counts;
}

}  // namespace scalespace
