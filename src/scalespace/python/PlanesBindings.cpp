// Planes by persistence (Ch. 2) from Python: run the pipeline (or read a result folder) and ask
// the queries of Sec. 2.4 as `scalespace planes` and `scalespace segment` do
// (cli/PlanesCommands.cpp). Plane offsets are kept absolute, as the result files hold them.
#include <pybind11/stl.h>

#include <filesystem>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/KnnGraph.hpp"
#include "scalespace/fit/FitDiagnosis.hpp"
#include "scalespace/planes/PlaneExport.hpp"
#include "scalespace/planes/PlaneQueries.hpp"
#include "scalespace/planes/StackPlanes.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"

namespace scalespace::python {
namespace {

class Planes {
 public:
  Planes(PlaneModel model, std::string input)
      : model_(std::move(model)), input_(std::move(input)) {}

  const PlaneModel& model() const { return model_; }
  const std::string& input() const { return input_; }
  std::size_t pointCount() const { return model_.membership.pointCount; }

  py::dict components() const {
    const std::size_t n = model_.components.size();
    std::vector<int> id(n), birthLevel(n), deathLevel(n), persistence(n), level(n);
    std::vector<double> birth(n), death(n), scale(n), offset(n), rms(n), area(n);
    std::vector<std::uint64_t> points(n);
    std::vector<double> normal(3 * n);
    std::vector<std::uint8_t> planar(n), noiseLimited(n);
    for (std::size_t c = 0; c < n; ++c) {
      const PlaneComponent& p = model_.components[c];
      id[c] = p.id;
      birthLevel[c] = p.birthLevel;
      deathLevel[c] = p.deathLevel;
      birth[c] = p.birthScale;
      death[c] = p.deathScale;
      persistence[c] = p.persistence;
      level[c] = p.representativeLevel;
      scale[c] = p.representativeScale;
      points[c] = p.pointCount;
      for (int k = 0; k < 3; ++k) normal[3 * c + std::size_t(k)] = p.plane.normal[k];
      offset[c] = p.plane.offset;
      rms[c] = p.plane.rms;
      area[c] = p.area;
      planar[c] = p.planar;
      noiseLimited[c] = p.noiseLimited;
    }
    // The fields of components.csv, with the plane n . x = offset in absolute coordinates.
    py::dict d;
    d["id"] = toArray(std::move(id));
    d["birth_level"] = toArray(std::move(birthLevel));
    d["birth_scale"] = toArray(std::move(birth));
    d["death_level"] = toArray(std::move(deathLevel));
    d["death_scale"] = toArray(std::move(death));
    d["persistence"] = toArray(std::move(persistence));
    d["representative_level"] = toArray(std::move(level));
    d["representative_scale"] = toArray(std::move(scale));
    d["point_count"] = toArray(std::move(points));
    d["normal"] = toArray(std::move(normal), {py::ssize_t(n), 3});
    d["offset"] = toArray(std::move(offset));
    d["rms"] = toArray(std::move(rms));
    d["area"] = toArray(std::move(area));
    d["planar"] = toArray(std::move(planar));
    d["noise_limited"] = toArray(std::move(noiseLimited));
    return d;
  }

  py::array_t<int> membership() const {
    std::vector<int> ids = model_.membership.ids;
    return toArray(std::move(ids),
                   {py::ssize_t(model_.membership.levelCount), py::ssize_t(pointCount())});
  }

  py::array_t<int> byPersistence(int minPersistence) const {
    return toArray(labelsByPersistence(model_, minPersistence));
  }

  py::array_t<int> atScale(double t, int minPersistence) const {
    if (model_.scales.empty()) throw OptionError("the planes hold no scales");
    return toArray(labelsAtScale(model_, t, minPersistence));
  }

  py::dict brush(const py::handle& indices) const {
    const auto matches = rankByBrush(model_, asIndices(indices, "brush", pointCount()));
    std::vector<int> component, persistence;
    std::vector<double> score, overlap;
    for (const BrushMatch& m : matches) {
      component.push_back(m.component);
      score.push_back(m.score);
      overlap.push_back(m.overlap);
      persistence.push_back(model_.components[std::size_t(m.component)].persistence);
    }
    py::dict d;
    d["component"] = toArray(std::move(component));
    d["score"] = toArray(std::move(score));
    d["overlap"] = toArray(std::move(overlap));
    d["persistence"] = toArray(std::move(persistence));
    return d;
  }

  py::array_t<int> similar(int query, const py::handle& within, int birthTolerance,
                           int deathTolerance, double areaTolerance, double angle) const {
    SimilarityOptions o;
    o.birthTolerance = birthTolerance;
    o.deathTolerance = deathTolerance;
    o.maxAreaDifference = areaTolerance;
    o.maxAngleDegrees = angle;
    validate(o);
    return toArray(findSimilar(model_, query, asIndices(within, "within", pointCount()), o));
  }

  // `segment --brush` / `--similar` label the points of the chosen components at their
  // representative level (cli/PlanesCommands.cpp labelComponent).
  py::array_t<int> labelComponents(const py::handle& components) const {
    std::vector<int> labels(pointCount(), -1);
    for (std::uint32_t c : asIndices(components, "components", model_.components.size())) {
      const int level = model_.components[c].representativeLevel;
      for (std::size_t i = 0; i < labels.size(); ++i)
        if (labels[i] < 0 && model_.membership.at(level, i) == int(c)) labels[i] = int(c);
    }
    return toArray(std::move(labels));
  }

  py::array_t<int> extend(const py::handle& labels, const py::handle& points,
                          const py::handle& normals, double distance, double angle) const {
    CoverageOptions o;
    o.maxDistanceFraction = distance;
    o.maxAngleDegrees = angle;
    validate(o);
    PooledCloud cloud = makeCloud(asPoints(points), normals);
    if (cloud.size() != pointCount())
      throwValue("points: has " + std::to_string(cloud.size()) +
                 " points but the planes were computed on " + std::to_string(pointCount()));
    const auto given = py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(
        py::module_::import("numpy").attr("asarray")(labels));
    if (!given || given.ndim() != 1 || std::size_t(given.size()) != pointCount())
      throwValue("labels: expected " + std::to_string(pointCount()) + " labels (one per point)");
    std::vector<int> in(given.data(), given.data() + given.size());
    // The algorithms work on positions relative to the cloud's origin (as `segment` does).
    PlaneModel model = model_;
    for (auto& c : model.components) c.plane.offset -= c.plane.normal.dot(cloud.origin());
    std::vector<int> out;
    {
      py::gil_scoped_release release;
      if (!cloud.hasNormals()) estimateAndOrient(cloud);
      out = extendCoverage(model, in, cloud.positions(), cloud.normals(),
                           buildKnnGraph(cloud.positions()), o);
    }
    return toArray(std::move(out));
  }

  void save(const std::string& directory) const {
    py::gil_scoped_release release;
    writePlaneModel(model_, Vec3::Zero(), input_, directory);
  }

 private:
  PlaneModel model_;  // offsets absolute
  std::string input_;
};

std::unique_ptr<Planes> planesPy(const py::handle& points, const py::handle& normals,
                                 const py::handle& viewpoint, int scales, double alpha,
                                 double angle, double maxStep, double maxRms, double mergeRms,
                                 double mergeDeviation, double mergeParallel, double refineDistance,
                                 bool refineUnlabelled, double fillMaxAngle, bool robust,
                                 const std::optional<std::string>& stack,
                                 const std::optional<std::string>& output, const std::string& input,
                                 std::optional<int> threads, py::object progress) {
  // `scalespace planes`' options and checks, before any work.
  if (scales < 2) throw OptionError("scales must be >= 2 (persistence needs levels)");
  ScaleSpaceOptions stackOptions;
  stackOptions.fit.robust = robust;
  stackOptions.series.count = scales;
  stackOptions.alpha = alpha;
  PlaneDetectionOptions options;
  options.growing.maxStep = maxStep;
  options.planarity.maxRelativeRms = maxRms;
  options.merging.maxRelativeRms = mergeRms;
  options.merging.maxRelativeDeviation = mergeDeviation;
  options.merging.parallelDegrees = mergeParallel;
  options.refinement.maxRelativeDistance = refineDistance;
  options.refinement.takeUnlabelled = refineUnlabelled;
  options.refinement.fillMaxAngleDegrees = fillMaxAngle;
  options.growing.maxAngleDegrees = angle;
  validateScaleSpaceOptions(stackOptions);
  validatePlaneDetectionOptions(options);
  if (output) checkPlaneResultDestination(*output);
  const std::optional<Vec3> view = asOptionalVec3(viewpoint, "viewpoint");
  PooledCloud cloud = makeCloud(asPoints(points), normals);
  Call call(std::move(progress), threads);
  std::vector<std::string> warnings;
  PlaneModel model = call([&] {
    PlaneDetection detection;
    if (stack) {
      const ScaleStackReader reader(*stack);
      detection = detectPlanesFromStack(cloud, reader, options, call.progress());
    } else {
      if (!cloud.hasNormals()) estimateAndOrient(cloud, 10, "mst", view, call.progress());
      StackPlaneDetection result =
          detectPlanesInCloud(cloud, stackOptions, options, call.progress());
      warnings =
          invalidFitWarnings(cloud, stackFitCounts(result.stack, cloud.size(), stackOptions));
      detection = std::move(result.detection);
    }
    PlaneModel m = makePlaneModel(detection);
    if (output) writePlaneModel(m, cloud.origin(), input, *output);
    return m;
  });
  warn(warnings);
  for (auto& c : model.components) c.plane.offset += c.plane.normal.dot(cloud.origin());
  for (auto& c : model.components)
    for (auto& loop : c.outlines)
      for (Vec3& v : loop) v += cloud.origin();
  return std::make_unique<Planes>(std::move(model), input);
}

}  // namespace

void bindPlanes(py::module_& m) {
  using namespace pybind11::literals;
  py::class_<Planes>(m, "Planes", R"doc(Planes by persistence (Ch. 2) and the queries of Sec. 2.4.

From planes(points) or read_planes(folder). Labels are (N,) int32 component ids, -1 for none.)doc")
      .def_property_readonly(
          "scales", [](const Planes& p) { return toArray(std::vector<double>(p.model().scales)); })
      .def_property_readonly("point_count", &Planes::pointCount)
      .def_property_readonly("input", &Planes::input, "the cloud file recorded with the result")
      .def_property_readonly(
          "components", &Planes::components,
          "dict of (C,) arrays: id, birth/death level and scale, persistence, "
          "representative level and scale, point_count, normal (C, 3), offset "
          "(plane normal . x = offset, absolute), rms, area, planar, noise_limited")
      .def_property_readonly("membership", &Planes::membership,
                             "(levels, N) int32: the component holding each point at each level")
      .def(
          "outlines",
          [](const Planes& p, int c) {
            if (c < 0 || std::size_t(c) >= p.model().components.size())
              throw OptionError("component " + std::to_string(c) + " does not exist");
            py::list loops;
            for (const auto& loop : p.model().components[std::size_t(c)].outlines)
              loops.append(vectorsToArray(loop));
            return loops;
          },
          "c"_a, "Outline loops of component c ((k, 3) arrays; empty for a result read back).")
      .def(
          "nearest_level", [](const Planes& p, double t) { return nearestLevel(p.model(), t); },
          "t"_a, "The level whose scale is nearest to t (log scale).")
      .def("labels_by_persistence", &Planes::byPersistence, "min_persistence"_a,
           "`segment --min-persistence P`: per point the most persistent component with "
           "persistence >= P (a planar one before a flagged one when the chains were split "
           "by planarity).")
      .def("labels_at_scale", &Planes::atScale, "t"_a, "min_persistence"_a = 0,
           "`segment --scale T`: the components at the computed scale nearest to t.")
      .def("rank_by_brush", &Planes::brush, "indices"_a,
           "`segment --brush`: components holding the brushed points ranked by Eq. 2.2: dict of "
           "arrays component, score, overlap, persistence (best first).")
      .def("find_similar", &Planes::similar, "component"_a, "within"_a, py::kw_only(),
           "birth_tolerance"_a = 5, "death_tolerance"_a = 5, "area_tolerance"_a = 1.0,
           "angle"_a = 90.0,
           "`segment --similar C --within IDS`: ids of the components like C among those holding "
           "a point of `within`.")
      .def("label_components", &Planes::labelComponents, "components"_a,
           "Labels the points of these components at their representative level (what segment "
           "writes for --brush, the best match, and --similar).")
      .def("extend_coverage", &Planes::extend, "labels"_a, "points"_a, "normals"_a = py::none(),
           py::kw_only(), "coverage_distance"_a = 0.2, "coverage_angle"_a = 45.0,
           "`segment --extend-coverage` (Sec. 2.5.1): labels spread to nearby points close to "
           "their plane.")
      .def("save", &Planes::save, "directory"_a,
           "Writes the result folder (components.json/.csv, outlines.obj, persistence.svg, "
           "membership.bin) into a new or empty folder or an earlier result.")
      .def("__repr__", [](const Planes& p) {
        return "<scalespace.Planes " + std::to_string(p.model().components.size()) +
               " components, " + std::to_string(p.model().scales.size()) + " scales, " +
               std::to_string(p.pointCount()) + " points>";
      });
  m.def("planes", &planesPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "viewpoint"_a = py::none(), "scales"_a = 50, "alpha"_a = 0.1, "angle"_a = 5.0,
        "max_step"_a = PlaneDetectionOptions{}.growing.maxStep,
        "max_rms"_a = PlaneDetectionOptions{}.planarity.maxRelativeRms,
        "merge_rms"_a = PlaneDetectionOptions{}.merging.maxRelativeRms,
        "merge_deviation"_a = PlaneDetectionOptions{}.merging.maxRelativeDeviation,
        "merge_parallel"_a = PlaneDetectionOptions{}.merging.parallelDegrees,
        "refine_distance"_a = PlaneDetectionOptions{}.refinement.maxRelativeDistance,
        "refine_unlabelled"_a = PlaneDetectionOptions{}.refinement.takeUnlabelled,
        "fill_max_angle"_a = PlaneDetectionOptions{}.refinement.fillMaxAngleDegrees,
        "robust"_a = true, "stack"_a = py::none(), "output"_a = py::none(), "input"_a = "",
        "threads"_a = py::none(), "progress"_a = py::none(),
        R"doc(Multi-scale planes by persistence (Chapter 2), as `scalespace planes`.

Without normals they are estimated and oriented (MST; each part facing viewpoint=(x, y, z) when
given, e.g. Cloud.viewpoint of a PCD, as the CLI does). scales: M log-spaced scales; alpha: the stack's Poisson-disk factor; angle: region growing theta
(degrees); max_step: the largest step (fraction of t) a region crosses along its seed's normal
(0.05; 0: the angle alone, Sec. 2.3.1); max_rms: regions whose plane RMS exceeds this fraction of
t and twice the noise are not planar, never linked to planar ones and their components flagged
(0.05; 0: the graph of Sec. 2.3.2); merge_rms, merge_deviation: adjacent regions each smaller
than the scale are merged before the filter where their union's plane RMS is at most merge_rms t
and no point is farther than merge_deviation t (0.1, 0.3: a staircase becomes its mean ramp;
merge_rms 0: as grown, Sec. 2.3.1); merge_parallel: a union within this angle (degrees) of a
large region next to it and within merge_deviation t of its plane, which that region does not
take, is undone (5; 0: kept); refine_distance: a merged region takes the neighbouring
points nearer its plane than their own region's, its plane within refine_distance t (0.3; 0: its
edges as grown); refine_unlabelled: it also takes the points of no region next to it that its
plane describes as well as its own (True; False: they stay unlabelled), except where their own
surface turns more than fill_max_angle degrees from its plane (75; 90: by distance alone); robust: the robust APSS of Sec. 2.3. stack: a stack folder
computed from these points instead of computing one. output: also write the result folder
(input: the cloud file to record in it).)doc");
  m.def(
      "read_planes",
      [](const std::string& directory) {
        std::string input;
        PlaneModel model = readPlaneModel(directory, &input);
        return std::make_unique<Planes>(std::move(model), input);
      },
      "directory"_a, "Reads a result folder of planes(output=...) or `scalespace planes`.");
}

}  // namespace scalespace::python
