// The multi-scale stack (Sec. 1.5) from Python: computed in memory (small clouds) or streamed to
// a NAME.stack folder, and read back one scale or one point's series at a time, as `scalespace
// scales` and `scalespace export` do (cli/ScalesCommands.cpp).
#include <pybind11/stl.h>

#include <memory>
#include <variant>

#include "scalespace/core/Error.hpp"
#include "scalespace/fit/FitDiagnosis.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"
#include "scalespace/scales/ScaleStackCompute.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"

namespace scalespace::python {
namespace {

/// A stack held in memory (computeScaleStackInMemory) or read from disk (ScaleStackReader).
class Stack {
 public:
  Stack(ScaleStack stack, std::vector<Vec3> inputPositions, const Vec3& origin)
      : memory_(std::make_unique<ScaleStack>(std::move(stack))),
        input_(std::move(inputPositions)),
        origin_(origin) {}
  explicit Stack(const std::string& path)
      : reader_(std::make_unique<ScaleStackReader>(path)),
        input_(reader_->inputPositions()),
        origin_(reader_->info().origin),
        path_(path) {}

  std::size_t pointCount() const { return input_.size(); }
  const std::vector<double>& scales() const {
    return memory_ ? memory_->summary.series.scales : reader_->info().scales;
  }
  std::size_t scaleCount() const { return scales().size(); }
  const std::vector<ScaleStats>& stats() const {
    return memory_ ? memory_->summary.stats : reader_->info().stats;
  }

  py::dict scale(long long j) const {
    if (j < 0 || std::size_t(j) >= scaleCount())
      throw OptionError("scale " + std::to_string(j) + " is not in the stack (0.." +
                        std::to_string(scaleCount() - 1) + ")");
    ScaleLayer layer;
    {
      py::gil_scoped_release release;
      layer = memory_ ? memory_->layers[std::size_t(j)] : reader_->readScale(std::size_t(j));
    }
    return layerToDict(std::move(layer), pointCount());
  }

  py::dict point(long long i) const {
    if (i < 0 || std::size_t(i) >= pointCount())
      throw OptionError("point " + std::to_string(i) + " is not in the stack (0.." +
                        std::to_string(pointCount() - 1) + ")");
    ScaleLayer series;
    if (reader_) {
      py::gil_scoped_release release;
      series = reader_->readPointSeries(std::size_t(i));
    } else {
      // Entry j of each array is scale j, as readPointSeries gives it.
      series.resize(scaleCount());
      for (std::size_t j = 0; j < scaleCount(); ++j)
        copyEntry(memory_->layers[j], std::size_t(i), series, j);
    }
    return layerToDict(std::move(series), scaleCount());
  }

  py::array_t<double> inputPositions() const { return vectorsToArray(input_); }
  const std::string& path() const { return path_; }
  py::list statsList() const {
    py::list out;
    for (const ScaleStats& s : stats()) {
      py::dict d;
      d["t"] = s.t;
      d["samples"] = s.samples;
      d["mean_neighbors"] = s.meanNeighbors;
      d["mean_mls_steps"] = s.meanMlsSteps;
      d["valid_points"] = s.validPoints;
      d["sampling_seconds"] = s.samplingSeconds;
      d["projection_seconds"] = s.projectionSeconds;
      out.append(d);
    }
    return out;
  }

 private:
  static void copyEntry(const ScaleLayer& from, std::size_t i, ScaleLayer& to, std::size_t j) {
    for (int c = 0; c < 3; ++c) {
      const std::size_t a = 3 * i + std::size_t(c), b = 3 * j + std::size_t(c);
      to.projection[b] = from.projection[a];
      to.normal[b] = from.normal[a];
      to.dirMax[b] = from.dirMax[a];
      to.dirMin[b] = from.dirMin[a];
    }
    to.meanCurvature[j] = from.meanCurvature[i];
    to.kMax[j] = from.kMax[i];
    to.kMin[j] = from.kMin[i];
    to.tau[j] = from.tau[i];
    to.kappa[j] = from.kappa[i];
    to.fitness[j] = from.fitness[i];
    to.anisotropy[j] = from.anisotropy[i];
    to.geometricVariation[j] = from.geometricVariation[i];
    to.neighbors[j] = from.neighbors[i];
    to.valid[j] = from.valid[i];
  }

  // The names of `scalespace export`'s columns; vectors as (n, 3) arrays, the projection in
  // absolute coordinates (float32 relative to the origin, plus the origin, as the export writes).
  py::dict layerToDict(ScaleLayer&& L, std::size_t n) const {
    py::dict d;
    std::vector<double> projection(L.projection.size());
    for (std::size_t k = 0; k < projection.size(); ++k)
      projection[k] = double(L.projection[k]) + origin_[int(k % 3)];
    const py::ssize_t rows = py::ssize_t(n);
    d["projection"] = toArray(std::move(projection), {rows, 3});
    d["normal"] = toArray(std::move(L.normal), {rows, 3});
    d["dir_max"] = toArray(std::move(L.dirMax), {rows, 3});
    d["dir_min"] = toArray(std::move(L.dirMin), {rows, 3});
    d["curv_mean"] = toArray(std::move(L.meanCurvature));
    d["curv_max"] = toArray(std::move(L.kMax));
    d["curv_min"] = toArray(std::move(L.kMin));
    d["gls_tau"] = toArray(std::move(L.tau));
    d["gls_kappa"] = toArray(std::move(L.kappa));
    d["gls_fitness"] = toArray(std::move(L.fitness));
    d["anisotropy"] = toArray(std::move(L.anisotropy));
    d["geometric_variation"] = toArray(std::move(L.geometricVariation));
    d["neighbors"] = toArray(std::move(L.neighbors));
    d["fit_valid"] = toArray(std::move(L.valid));
    return d;
  }

  std::unique_ptr<ScaleStack> memory_;
  std::unique_ptr<ScaleStackReader> reader_;
  std::vector<Vec3> input_;
  Vec3 origin_ = Vec3::Zero();
  std::string path_;
};

std::unique_ptr<Stack> computeStackPy(const py::handle& points, const py::handle& normals,
                                      int scales, const std::string& spacing, double tmin,
                                      double tmax, double alpha, bool robust, int mlsSteps,
                                      const std::string& estimator, std::uint64_t seed,
                                      const std::optional<std::string>& path,
                                      const std::string& encoding, std::optional<int> threads,
                                      py::object progress) {
  // `scalespace scales`' options and checks, before any work.
  ScaleSpaceOptions options;
  options.series.count = scales;
  options.series.spacing = parseScaleSpacing(spacing);
  options.series.tMin = tmin;
  options.series.tMax = tmax;
  options.alpha = alpha;
  options.fit.robust = robust;
  options.fit.mlsMaxSteps = mlsSteps;
  options.fit.estimator = parseEstimator(estimator);
  options.seed = seed;
  validateScaleSpaceOptions(options);
  StackWriteOptions write;
  write.encoding = parseStackEncoding(encoding);
  PooledCloud cloud = makeCloud(asPoints(points), normals);
  Call call(std::move(progress), threads);
  std::vector<std::string> warnings;
  std::optional<ScaleStack> memory;
  call([&] {
    if (!cloud.hasNormals()) estimateAndOrient(cloud, 10, "mst", std::nullopt, call.progress());
    ScaleSpaceSummary summary;
    if (path) {
      summary = computeScaleStackToDisk(cloud, options, *path, call.progress(), write);
    } else {
      memory = computeScaleStackInMemory(cloud, options, call.progress());
      summary = memory->summary;
    }
    warnings = invalidFitWarnings(cloud, stackFitCounts(summary, cloud.size(), options));
    return 0;
  });
  warn(warnings);
  if (path) return std::make_unique<Stack>(*path);
  std::vector<Vec3> input(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) input[i] = cloud.absolutePosition(i);
  return std::make_unique<Stack>(std::move(*memory), std::move(input), cloud.origin());
}

}  // namespace

void bindStacks(py::module_& m) {
  using namespace pybind11::literals;
  py::class_<Stack>(m, "Stack", R"doc(A multi-scale stack (Sec. 1.5): every point at M scales.

From compute_stack (in memory, or on disk with path=) or open_stack(path). scale(j) and
point(i) return dicts of arrays named as `scalespace export` names its columns: projection
(absolute, float64), normal, dir_max, dir_min ((n, 3) float32), curv_mean curv_max curv_min
gls_tau gls_kappa gls_fitness anisotropy geometric_variation (float32), neighbors (uint16),
fit_valid (uint8). A compact stack decodes invalid fits as zeros.)doc")
      .def_property_readonly("point_count", &Stack::pointCount)
      .def_property_readonly("scale_count", &Stack::scaleCount)
      .def_property_readonly(
          "scales", [](const Stack& s) { return toArray(std::vector<double>(s.scales())); },
          "the scales t_j, increasing")
      .def_property_readonly("stats", &Stack::statsList, "per scale: t, samples, timings, ...")
      .def_property_readonly("path", &Stack::path, "the folder ('' for a stack in memory)")
      .def("scale", &Stack::scale, "j"_a, "Scale j of every point (input order).")
      .def("point", &Stack::point, "i"_a, "Point i at every scale (entry j: scale j).")
      .def("input_positions", &Stack::inputPositions,
           "The input positions (absolute), (N, 3) float64.")
      .def("__len__", &Stack::scaleCount)
      .def("__repr__", [](const Stack& s) {
        return "<scalespace.Stack " + std::to_string(s.pointCount()) + " points x " +
               std::to_string(s.scaleCount()) + " scales" +
               (s.path().empty() ? std::string(" in memory") : " at " + s.path()) + ">";
      });
  m.def(
      "open_stack", [](const std::string& path) { return std::make_unique<Stack>(path); }, "path"_a,
      "Opens a stack folder written by compute_stack(path=...) or `scalespace scales`.");
  m.def("compute_stack", &computeStackPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "scales"_a = 50, "spacing"_a = "log", "tmin"_a = 0.0, "tmax"_a = 0.0, "alpha"_a = 0.1,
        "robust"_a = false, "mls_steps"_a = 10, "estimator"_a = "w3", "seed"_a = 1,
        "path"_a = py::none(), "encoding"_a = "compact", "threads"_a = py::none(),
        "progress"_a = py::none(),
        R"doc(Computes the multi-scale stack, as `scalespace scales`.

scales: M; spacing: log | linear; tmin/tmax 0: median 10-NN distance / bounding-box diagonal;
alpha: Poisson-disk radius / scale; robust: RIMLS (what planes uses). normals None: estimated
and oriented (PCA, 10 neighbours, MST). path: write NAME.stack there (encoding compact |
float32) and return it opened; None: keep it in memory (M x N values: small clouds).)doc");
}

}  // namespace scalespace::python
