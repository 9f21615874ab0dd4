#pragma once
// The multi-scale, multi-resolution representation of Sec. 1.5 (Fig. 1.9): for each scale t_j
// (increasing), every input point is projected with the robust APSS fit of scale t_j onto the
// surface defined by that scale's Poisson-disk sample (original positions and normals of the
// sampled points), starting from its projection at scale j-1 (the input position at j = 1).
// Per point and scale we record the projection, normal, curvatures, directions, GLS parameters,
// anisotropy, neighbour count and validity.
#include <cstdint>
#include <functional>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/core/Progress.hpp"
#include "scalespace/fit/FitDiagnosis.hpp"
#include "scalespace/fit/LocalFit.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace {

/// What the layers handed to a ScaleSink hold (ScaleLayer).
enum class LayerContents {
  All,                  // every array
  NormalAndCurvatures,  // normal, meanCurvature, kMax, kMin, valid; the other arrays are empty
  NormalCurvaturesAndProjection  // the same and the projection
};

/// In which order the layers handed to a ScaleSink list the points (ScaleLayer::inputIndex).
enum class LayerOrder {
  Input,      // entry i is input point i
  Processing  // the order the points were processed in (spatial): entry k is input point
              // inputIndex[k]; saves putting every array back in input order, for a consumer
              // that reorders something smaller (the stack writer: the encoded bytes)
};

/// The fit each point makes at each scale of the stack: W3, MLS projection from the previous
/// scale's projection, so few steps are needed (docs/THESIS_NOTES.md, robust APSS parameters:
/// the authors allow up to 10, stop below 0.01 t). Robust re-weighting (RIMLS, Sec. 2.3) is what
/// the planes of Chapter 2 use; it is off by default: Sec. 1.5 builds the representation with
/// the plain APSS, which is much cheaper (bench/fig_1_10 --mode timing --robust 0, then 1).
inline FitOptions stackFitOptions() {
  FitOptions fit;
  fit.mls = true;
  fit.mlsMaxSteps = 10;
  fit.mlsTolerance = 0.01;
  return fit;
}

struct ScaleSpaceOptions {
  ScaleSeriesOptions series;  // M = 50 log-spaced scales by default (Sec. 1.5.1)
  double alpha = 0.1;  // Poisson-disk radius r_j = alpha t_j (Sec. 1.5.2): samples >= 2 r_j apart
  /// The per-point fit; `fit.mls` must stay on (the stack is a projection, Fig. 1.9) and
  /// `fit.expectFirstStepConverged` is set point by point from the previous scale.
  FitOptions fit = stackFitOptions();
  std::uint64_t seed = 1;  // Poisson-disk visiting order
  int threads = 0;         // 0: all cores
  /// NormalAndCurvatures is what plane detection reads: putting only those arrays in input order
  /// saves reordering the others.
  LayerContents layerContents = LayerContents::All;
  LayerOrder layerOrder = LayerOrder::Input;
};

/// OptionError naming the field unless the options can run: the scale series' count, alpha, the
/// fit options (fit/FitPoints.hpp validateFitOptions) and fit.mls on. runScaleSpace checks them
/// first; a caller can check them before reading its input.
void validateScaleSpaceOptions(const ScaleSpaceOptions& options);

/// Statistics of one scale (what Fig. 1.11 plots).
struct ScaleStats {
  double t = 0;
  std::size_t samples = 0;   // size of the Poisson-disk sample of this scale
  double meanNeighbors = 0;  // mean neighbours per projection (last fit of each point)
  double meanMlsSteps = 0;   // mean MLS steps (fits) per point
  std::size_t validPoints = 0;
  double samplingSeconds = 0;    // this level's Poisson-disk sampling
  double indexSeconds = 0;       // building the kd-tree on the sample
  double projectionSeconds = 0;  // projecting every input point
};

/// Everything computed at one scale, one entry per input point, in input order unless inputIndex
/// is set (LayerOrder::Processing: entry k is input point inputIndex[k]) (with
/// LayerContents::NormalAndCurvatures, only normal, meanCurvature, kMax, kMin and valid). Positions
/// are relative to the cloud's origin() (PointCloud.hpp); vectors are packed x,y,z.
struct ScaleLayer {
  std::vector<float> projection, normal, dirMax, dirMin;                   // 3 N each
  std::vector<float> meanCurvature, kMax, kMin;                            // N each
  std::vector<float> tau, kappa, fitness, anisotropy, geometricVariation;  // N each
  std::vector<std::uint16_t> neighbors;                                    // N, saturated at 65535
  std::vector<std::uint8_t> valid;                                         // N, 1 = valid fit
  std::vector<Index> inputIndex;  // empty (input order) or N: the input point of each entry
  void resize(std::size_t n);
  std::size_t size() const { return valid.size(); }
  /// Every array holds size() entries (LayerContents::All).
  bool complete() const;
};

/// The layer in input order (a copy of an input-order layer as it is). Throws OptionError when
/// inputIndex is not a permutation of 0..N-1.
ScaleLayer inInputOrder(const ScaleLayer& layer);

/// Receives each scale as soon as it is computed (j = 0..M-1), e.g. to stream it to disk.
using ScaleSink = std::function<void(std::size_t j, const ScaleLayer& layer, const ScaleStats&)>;

struct ScaleSpaceSummary {
  ScaleSeriesResult series;
  std::vector<ScaleStats> stats;
  std::uint64_t inputChecksum = 0;
  double totalSeconds = 0;
};

/// Runs the multi-scale projection. The cloud must have normals (OptionError otherwise: estimate
/// and orient them first, core/NormalEstimation + NormalOrientation). Deterministic for any
/// thread count. Progress per scale; the callback may cancel (throws Cancelled).
ScaleSpaceSummary runScaleSpace(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                const ScaleSink& sink, const ProgressCallback& progress = {});

/// The whole stack in memory (small clouds, tests): layers[j] for scale j.
struct ScaleStack {
  ScaleSpaceSummary summary;
  std::vector<ScaleLayer> layers;
};
/// Computes the whole stack in memory (M layers of N points: small clouds and tests). Large clouds
/// stream it to disk instead, one scale at a time: computeScaleStackToDisk (ScaleStackCompute.hpp).
ScaleStack computeScaleStackInMemory(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                     const ProgressCallback& progress = {});

/// FNV-1a 64-bit over the absolute positions and the normals (as little-endian doubles): identifies
/// the input a stack was computed from.
std::uint64_t cloudChecksum(const PointCloud& cloud);

/// The fits of a whole stack (every point at every scale) as fit/FitDiagnosis counts them, for
/// invalidFitWarnings: a run whose fits are mostly invalid says so.
FitCounts stackFitCounts(const ScaleSpaceSummary& summary, std::size_t points,
                         const ScaleSpaceOptions& options);

}  // namespace scalespace
