// Cylinders across scales (Sec. 3.5) from Python, with the options and defaults of
// `scalespace cylinders` (cli/CylinderCommands.cpp), on points. The tubes' axes and centres are
// returned absolute, as the result files hold them.
#include <pybind11/stl.h>

#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/features/CylinderDetection.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"

namespace scalespace::python {
namespace {

// A (3,) float64 array.
py::array_t<double> vec3Array(const Vec3& v) {
  return toArray(std::vector<double>{v.x(), v.y(), v.z()});
}

void checkMinPersistence(int minPersistence) {
  if (minPersistence < 0) throw OptionError("min_persistence must be >= 0");
}

class Cylinders {
 public:
  Cylinders(CylinderDetection detection, const Vec3& origin)
      : detection_(std::move(detection)), origin_(origin) {}

  std::size_t pointCount() const { return detection_.graph.pointCount; }
  int levelCount() const { return detection_.scaleCount(); }
  std::size_t componentCount() const { return detection_.components.size(); }
  double seconds() const { return detection_.seconds; }

  py::array_t<double> scales() const {
    std::vector<double> out;
    for (const CylinderLevel& l : detection_.levels) out.push_back(l.scale);
    return toArray(std::move(out));
  }

  // The fields of components.json's "levels", with the rejections by TubeRejection name.
  py::list levels() const {
    py::list out;
    for (const CylinderLevel& l : detection_.levels) {
      py::dict rejected;
      for (std::size_t k = 1; k < l.rejections.size(); ++k)
        rejected[tubeRejectionName(TubeRejection(k))] = l.rejections[k];
      py::dict d;
      d["scale"] = l.scale;
      d["lines"] = l.lines;
      d["regular_lines"] = l.regularLines;
      d["regions"] = l.regions;
      d["tubes"] = l.tubes.size();
      d["rejected"] = rejected;
      d["seconds"] = l.seconds;
      out.append(d);
    }
    return out;
  }

  // The fields of components.json's "components", with direction and centre None for a bent
  // tube (the JSON leaves them out) and the representative scale of components.csv.
  py::list components() const {
    py::list out;
    for (const CylinderComponent& c : detection_.components) {
      const TubeFit& t = c.tube;
      py::dict d;
      d["id"] = c.id;
      d["birth_level"] = c.birthLevel;
      d["birth_scale"] = c.birthScale;
      d["death_level"] = c.deathLevel;
      d["death_scale"] = c.deathScale;
      d["gap_levels"] = c.gapLevels;
      d["persistence"] = c.persistence;
      d["representative_level"] = c.representativeLevel;
      d["representative_scale"] = detection_.levels[std::size_t(c.representativeLevel)].scale;
      d["point_count"] = t.pointCount;
      d["straight"] = t.straight;
      d["radius"] = t.radius;
      d["rms"] = t.rms;
      d["length"] = t.length;
      d["arc_degrees"] = t.arcDegrees;
      d["sector_fill"] = t.sectorFill;
      d["section_shape"] = t.sectionShapeShare;
      d["normal_lean"] = t.normalLean;
      d["face_sectors"] = t.faceSectors;
      d["direction"] = t.straight ? py::object(vec3Array(t.direction)) : py::object(py::none());
      d["centre"] = t.straight ? py::object(vec3Array(t.centre + origin_)) : py::object(py::none());
      d["axis"] = vectorsToArray(t.axis, origin_);
      d["radii"] = toArray(std::vector<double>(t.radii));
      out.append(d);
    }
    return out;
  }

  py::array_t<float> anisotropy(int level) const {
    checkLevel(level);
    return toArray(std::vector<float>(detection_.levels[std::size_t(level)].anisotropy));
  }

  int nearestLevel(double t) const { return nearestCylinderLevel(detection_, t); }

  py::array_t<int> atLevel(int level, int minPersistence) const {
    checkMinPersistence(minPersistence);
    return toArray(cylinderLabelsAtLevel(detection_, level, minPersistence));
  }

  py::array_t<int> atScale(double t, int minPersistence) const {
    checkMinPersistence(minPersistence);
    return toArray(
        cylinderLabelsAtLevel(detection_, nearestCylinderLevel(detection_, t), minPersistence));
  }

  py::array_t<int> byPersistence(int minPersistence) const {
    checkMinPersistence(minPersistence);
    return toArray(cylinderLabelsByPersistence(detection_, minPersistence));
  }

  // The graph's region of the component at `level`: its tube's points there.
  py::array_t<std::uint32_t> points(int component, int level) const {
    if (component < 0 || std::size_t(component) >= detection_.components.size())
      throw OptionError("component " + std::to_string(component) + " does not exist (0.." +
                        std::to_string(detection_.components.size()) + ")");
    checkLevel(level);
    const GraphComponent& c = detection_.graph.components[std::size_t(component)];
    std::vector<std::uint32_t> out;
    const int region = level >= c.birthLevel && level <= c.deathLevel
                           ? c.regionAt[std::size_t(level - c.birthLevel)]
                           : -1;
    if (region >= 0) {  // -1: not at this level, or in a bridged gap
      const auto& indices =
          detection_.graph.levels[std::size_t(level)].regions[std::size_t(region)];
      out.assign(indices.begin(), indices.end());
    }
    return toArray(std::move(out));
  }

 private:
  void checkLevel(int level) const {
    if (level < 0 || level >= levelCount())
      throw OptionError("level " + std::to_string(level) + " is outside [0, " +
                        std::to_string(levelCount()) + ")");
  }

  CylinderDetection detection_;  // relative to origin_
  Vec3 origin_;
};

std::unique_ptr<Cylinders> cylindersPy(
    const py::handle& points, const py::handle& normals, const py::handle& viewpoint,
    const std::optional<std::vector<double>>& scales, int scaleCount, double tmin, double tmax,
    double minLineLength, double maxLineCurvature, double maxLineVariation, double epsilon,
    double minAnisotropy, double minArc, double minSectorFill, double maxSectionShape,
    double maxSectionShapeRms, int maxFaceSectors, double minFaceLean, double maxRms,
    bool oneCurvatureSign, bool splitByAxes, bool trimJunctions, bool narrowTubes, int maxGap,
    double bridgeRadiusTolerance, double nestedLinkTolerance, double trimKeepFraction,
    double trimMinRadius, double trimAgainstShare, double narrowMinArc, int narrowMinPersistence,
    double narrowRadiusSpread, std::optional<int> threads, py::object progress) {
  // `scalespace cylinders`' options and checks, before any work.
  CylinderOptions options;
  if (scales) options.scales = *scales;
  options.scaleCount = scaleCount;
  options.tMin = tmin;
  options.tMax = tmax;
  options.filter.minLengthFactor = minLineLength;
  options.filter.maxCurvatureFactor = maxLineCurvature;
  options.filter.maxMeanVariation = maxLineVariation;
  options.epsilon = epsilon;
  options.minAnisotropy = minAnisotropy;
  options.tube.minArcDegrees = minArc;
  options.tube.minSectorFill = minSectorFill;
  options.tube.maxSectionShapeShare = maxSectionShape;
  options.tube.maxSectionShapeRms = maxSectionShapeRms;
  options.tube.maxFaceSectors = maxFaceSectors;
  options.tube.minFaceLeanDegrees = minFaceLean;
  options.tube.maxRelativeRms = maxRms;
  options.oneCurvatureSign = oneCurvatureSign;
  options.split.enabled = splitByAxes;
  options.trim.enabled = trimJunctions;
  options.narrow.enabled = narrowTubes;
  options.maxGapLevels = maxGap;
  options.bridgeRadiusTolerance = bridgeRadiusTolerance;
  options.nestedLinkTolerance = nestedLinkTolerance;
  options.trim.keepFraction = trimKeepFraction;
  options.trim.minRadiusScales = trimMinRadius;
  options.trim.tubeMinAgainstShare = trimAgainstShare;
  options.narrow.minArcDegrees = narrowMinArc;
  options.narrow.minPersistence = narrowMinPersistence;
  options.narrow.maxRadiusSpread = narrowRadiusSpread;
  validateCylinderOptions(options);
  const std::optional<Vec3> view = asOptionalVec3(viewpoint, "viewpoint");
  PooledCloud cloud = makeCloud(asPoints(points), normals);
  Call call(std::move(progress), threads);
  CylinderDetection detection = call([&] {
    if (!cloud.hasNormals())
      estimateAndOrient(cloud, cylinderNormalOptions(), "mst", view, call.progress());
    return detectCylinders(cloud, options, call.progress());
  });
  return std::make_unique<Cylinders>(std::move(detection), cloud.origin());
}

}  // namespace

void bindCylinders(py::module_& m) {
  using namespace pybind11::literals;
  py::class_<Cylinders>(m, "Cylinders",
                        R"doc(Cylinders across scales (Sec. 3.5): what cylinders() returns.

Labels are (N,) int32 component ids, -1 for none. Coordinates are absolute.)doc")
      .def_property_readonly("scales", &Cylinders::scales, "(levels,) float64: the scales")
      .def_property_readonly("point_count", &Cylinders::pointCount)
      .def_property_readonly("seconds", &Cylinders::seconds, "time of the whole detection")
      .def_property_readonly(
          "levels", &Cylinders::levels,
          "per level a dict: scale, lines, regular_lines, regions, tubes, rejected (regions "
          "turned down by each test of the tube fit: too_small, flat, narrow_arc, thin, rough, "
          "faceted, merged), "
          "seconds")
      .def_property_readonly(
          "components", &Cylinders::components,
          "per component a dict: id, birth_level, birth_scale, death_level, death_scale, "
          "gap_levels (levels between them where it was not found), persistence (death_level - "
          "birth_level - gap_levels), representative_level and _scale (where it holds the most "
          "points: its "
          "tube is reported), point_count, straight, radius, rms, length, arc_degrees, "
          "sector_fill, section_shape (max_section_shape's measure; 0 for a bent tube), direction "
          "(3,) and centre (3,) of the straight axis (None for a bent tube), axis (K, 3), radii "
          "(K,: the radius at each axis vertex)")
      .def("anisotropy", &Cylinders::anisotropy, "level"_a,
           "(N,) float32: the line anisotropy sigma of each point at this level (Eq. 3.8-3.9), "
           "NaN where no regular line passes.")
      .def("nearest_level", &Cylinders::nearestLevel, "t"_a,
           "The level whose scale is nearest to t (log scale).")
      .def("labels_at_level", &Cylinders::atLevel, "level"_a, "min_persistence"_a = 0,
           "Per point the component holding it at this level if its persistence is >= "
           "min_persistence, else -1.")
      .def("labels_at_scale", &Cylinders::atScale, "t"_a, "min_persistence"_a = 0,
           "`cylinders --scale T`: labels_at_level at the level nearest to t.")
      .def("labels_by_persistence", &Cylinders::byPersistence, "min_persistence"_a = 0,
           "`cylinders` without --scale: per point the most persistent component (lower id on "
           "ties) with persistence >= min_persistence holding it at any level, else -1.")
      .def("points", &Cylinders::points, "component"_a, "level"_a,
           "(P,) uint32: the points of the component at this level (its tube's points there; "
           "empty at a level outside its life or in one of its gaps).")
      .def("__len__", &Cylinders::componentCount)
      .def("__repr__", [](const Cylinders& c) {
        return "<scalespace.Cylinders " + std::to_string(c.componentCount()) + " components, " +
               std::to_string(c.levelCount()) + " scales, " + std::to_string(c.pointCount()) +
               " points>";
      });
  m.def(
      "cylinders", &cylindersPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
      "viewpoint"_a = py::none(), "scales"_a = py::none(),
      "scale_count"_a = CylinderOptions{}.scaleCount, "tmin"_a = CylinderOptions{}.tMin,
      "tmax"_a = CylinderOptions{}.tMax, "min_line_length"_a = LineFilterOptions{}.minLengthFactor,
      "max_line_curvature"_a = LineFilterOptions{}.maxCurvatureFactor,
      "max_line_variation"_a = LineFilterOptions{}.maxMeanVariation,
      "epsilon"_a = CylinderOptions{}.epsilon, "min_anisotropy"_a = CylinderOptions{}.minAnisotropy,
      "min_arc"_a = TubeFitOptions{}.minArcDegrees,
      "min_sector_fill"_a = TubeFitOptions{}.minSectorFill,
      "max_section_shape"_a = TubeFitOptions{}.maxSectionShapeShare,
      "max_section_shape_rms"_a = TubeFitOptions{}.maxSectionShapeRms,
      "max_face_sectors"_a = TubeFitOptions{}.maxFaceSectors,
      "min_face_lean"_a = TubeFitOptions{}.minFaceLeanDegrees,
      "max_rms"_a = TubeFitOptions{}.maxRelativeRms,
      "one_curvature_sign"_a = CylinderOptions{}.oneCurvatureSign,
      "split_by_axes"_a = TubeSplitOptions{}.enabled,
      "trim_junctions"_a = TubeTrimOptions{}.enabled,
      "narrow_tubes"_a = NarrowTubeOptions{}.enabled, "max_gap"_a = CylinderOptions{}.maxGapLevels,
      "bridge_radius_tolerance"_a = CylinderOptions{}.bridgeRadiusTolerance,
      "nested_link_tolerance"_a = CylinderOptions{}.nestedLinkTolerance,
      "trim_keep_fraction"_a = TubeTrimOptions{}.keepFraction,
      "trim_min_radius"_a = TubeTrimOptions{}.minRadiusScales,
      "trim_against_share"_a = TubeTrimOptions{}.tubeMinAgainstShare,
      "narrow_min_arc"_a = NarrowTubeOptions{}.minArcDegrees,
      "narrow_min_persistence"_a = NarrowTubeOptions{}.minPersistence,
      "narrow_radius_spread"_a = NarrowTubeOptions{}.maxRadiusSpread, "threads"_a = py::none(),
      "progress"_a = py::none(),
      R"doc(Cylinders across scales (Sec. 3.5), as `scalespace cylinders`.

Regular minimal-curvature lines, their anisotropy, regions grown on it, a tube fitted to each
(curved axis, radius profile), linked across scales into persistent components. scales: the
scales themselves (increasing), else scale_count log-spaced ones in [tmin, tmax] (0: twice the
median distance to the 10th neighbour, a tenth of the diagonal). The regular lines (Eq.
3.5-3.7): at least min_line_length t long, total curvature at most max_line_curvature x length / t
radians, total geometric variation at most max_line_variation x their vertex count (the mean
tanh(nu)). epsilon: the region growing
tolerance of Eq. 3.10; min_anisotropy: the least sigma of a region's points; min_arc: degrees
the points' normals must turn around the axis; min_sector_fill: the share of the 10-degree
sectors of that arc the normals must fill (a box edge rounded into a tube fills about half);
max_section_shape: below 1, a straight tube is turned down when more than this share of its
points' spread about it is a section shape fixed along its axis (the azimuth's harmonics 2-8) of
RMS above 0.05 x its radius: a noisy box's faces read 0.23 and more, but so did the real table
legs of python3-pcl's table scan (0.25-0.68); 1 (default): off; max_section_shape_rms: that RMS
bound, over the radius; max_face_sectors: a tube is turned down when its normals turn less
than half as far as its points over more than this many neighbouring 10-degree sectors round its
axis (a prism's face keeps one normal while its points go round; 36: off) and the RMS of the
sectors' mean lean of the normals from the radial is at least min_face_lean degrees (a noisy
box's faces: 14 and more; pipes and a cable's strands: under 9);
max_rms: a tube's RMS distance to its surface over its radius. one_curvature_sign: a region
only grows over points curving the way its seed does, which stops it at the groove between a
noisy cable's strands (needs consistently oriented normals; off: Eq. 3.10 alone).
split_by_axes: a region whose points' curvature reads tubes thinner than its own is split by the
axes they propose (x - n / kappa1) into those tubes: the strands of a noisy cable grown into one
region across their contacts. trim_junctions: a region turned down as no tube, or a tube partly
curving against itself, is trimmed to its points curving one way and fitted again (a cylinder
standing on a plane, grown out onto the plane over the junction): the points curving the way
most do by at least trim_keep_fraction of their median |kappa1| t, kept as a tube of radius at
least trim_min_radius t; a tube is trimmed when trim_against_share of its points curve against
it. narrow_tubes: a region turned down for its arc alone (narrow_min_arc degrees or more) is kept
where it is found at scales narrow_min_persistence steps or more apart with radii within
narrow_radius_spread of one another (a cylinder seen from one side). max_gap: a component bridges up to this many
levels where its tube was not found (0: consecutive levels only, as the thesis), where the tubes
on both sides of the gap agree in radius within bridge_radius_tolerance of the larger.
nested_link_tolerance: tubes of two levels that fail the Jaccard rule, one holding over half of
the other's points, the smaller at least a quarter the size, are one component when the smaller
one's points lie on the larger one's tube within this share of its radius (median; 0: off); a
component of narrow tubes alone whose points lie on its best tube within it is kept whatever the
spread of its radii. Without normals they are estimated (sheet
planes, 10 neighbours) and oriented (MST of the PCA normals), as the CLI does. Returns a
Cylinders.)doc");
}

}  // namespace scalespace::python
