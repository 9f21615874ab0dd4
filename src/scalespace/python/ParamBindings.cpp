// The meshless parametrization of Chapter 4 from Python, with the options and defaults of
// `scalespace parametrize` and `distortion` (cli/ParamCommands.cpp), on points.
#include <pybind11/stl.h>

#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/param/MeshlessDistortion.hpp"
#include "scalespace/param/Parametrization.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"

namespace scalespace::python {
namespace {

py::array_t<double> vec3Array(const Vec3& v) {
  return toArray(std::vector<double>{v.x(), v.y(), v.z()});
}

py::array_t<double> uvArray(const std::vector<Vec2>& uv) {
  std::vector<double> flat;
  flat.reserve(2 * uv.size());
  for (const Vec2& p : uv) {
    flat.push_back(p.x());
    flat.push_back(p.y());
  }
  return toArray(std::move(flat), {py::ssize_t(uv.size()), 2});
}

/// The positions and normals the library reads: the cloud's (relative to its origin), with
/// normals estimated and oriented when none are given, as the CLI does.
PooledCloud cloudWithNormals(const Points& points, const py::handle& normals, Call& call) {
  PooledCloud cloud = makeCloud(points, normals);
  if (!cloud.hasNormals())
    call([&] { return estimateAndOrient(cloud, 10, "mst", std::nullopt, call.progress()); });
  return cloud;
}

py::dict parametrizePy(const py::handle& points, const py::handle& normals, int scales,
                       const std::string& domain, int k, double tmax, double alpha, int relax,
                       int relaxRounds, double rigidity, double sphereRigidity,
                       bool relaxLargeSpheres, std::optional<int> threads, py::object progress) {
  ParametrizationOptions options;
  options.flattening.scaleCount = scales;
  options.flattening.K = k;
  options.flattening.tMax = tmax;
  options.flattening.alpha = alpha;
  options.relaxation.iterations = relax;
  options.relaxation.rounds = relaxRounds;
  options.relaxation.rigidity = rigidity;
  options.relaxation.sphereRigidity = sphereRigidity;
  options.relaxation.largeSpheres = relaxLargeSpheres;
  options.domain.kind = parseDomainKind(domain);
  validateFlatteningOptions(options.flattening);
  validateRelaxationOptions(options.relaxation);
  Call call(std::move(progress), threads);
  const PooledCloud cloud = cloudWithNormals(asPoints(points), normals, call);
  const Parametrization p = call(
      [&] { return parametrize(cloud.positions(), cloud.normals(), options, call.progress()); });
  warn(p.warnings);
  const DomainMap& d = p.domain;
  py::dict out;
  out["domain"] = domainKindName(d.kind);
  const bool plane = d.kind == DomainKind::Plane;
  out["uv"] = plane ? py::object(uvArray(d.uv)) : py::object(py::none());
  out["direction"] = plane ? py::object(py::none()) : py::object(vectorsToArray(d.direction));
  out["longitude"] =
      plane ? py::object(py::none()) : py::object(toArray(std::vector<double>(d.longitude)));
  out["latitude"] =
      plane ? py::object(py::none()) : py::object(toArray(std::vector<double>(d.latitude)));
  out["valid"] = toArray(std::vector<std::uint8_t>(p.valid));
  out["fold"] = toArray(std::vector<std::uint8_t>(p.defects.fold));
  out["overlap"] = toArray(std::vector<std::uint8_t>(p.defects.overlap));
  out["local_scale"] = toArray(std::vector<float>(p.defects.localScale));
  out["flattened"] = vectorsToArray(p.flattening.positions, cloud.origin());
  out["global_fit_is_plane"] = d.globalFitIsPlane;
  out["centre"] = d.globalFitIsPlane ? py::object(py::none())
                                     : py::object(vec3Array(d.centre + cloud.origin()));
  out["radius"] = d.radius;
  out["cap_degrees"] = d.capDegrees;
  out["one_to_one"] = p.oneToOne;
  out["folds"] = p.defects.folds;
  out["overlaps"] = p.defects.overlaps;
  out["relaxed"] = p.relaxation.applied;
  out["relax_rounds_applied"] = p.relaxation.roundsApplied;
  out["warnings"] = p.warnings;
  out["seconds"] = p.flattening.seconds;
  return out;
}

py::dict distortionPy(const py::handle& points, const py::handle& normals, const py::handle& uv,
                      const py::handle& direction, const std::vector<int>& scalesK,
                      std::optional<int> threads, py::object progress) {
  DistortionOptions options;
  options.neighbors = scalesK;
  validateDistortionOptions(options);
  const Points p = asPoints(points);
  std::vector<Vec2> planeCoordinates;
  std::vector<Vec3> directions;
  if (!uv.is_none() == !direction.is_none())
    throw OptionError("give either uv (N, 2) or direction (N, 3)");
  if (!uv.is_none()) {
    const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(uv);
    if (!array || array.ndim() != 2 || array.shape(1) != 2 || std::size_t(array.shape(0)) != p.size)
      throw OptionError("uv must be an (N, 2) array with one row per point");
    const double* data = array.data();
    for (std::size_t i = 0; i < p.size; ++i)
      planeCoordinates.emplace_back(data[2 * i], data[2 * i + 1]);
  } else {
    const Points d = asVectors(direction, p.size, "direction");
    directions.assign(d.data, d.data + d.size);
  }
  const DomainMap domain = domainFromCoordinates(planeCoordinates, directions);
  Call call(std::move(progress), threads);
  const PooledCloud cloud = cloudWithNormals(p, normals, call);
  const DistortionResult result = call([&] {
    return measureDistortion(cloud.positions(), cloud.normals(), domain, options, call.progress());
  });
  const MapDefects defects =
      call([&] { return findMapDefects(cloud.positions(), cloud.normals(), domain); });
  py::list sizes;
  for (const DistortionAtSize& s : result.sizes) {
    py::dict d;
    d["neighbors"] = s.neighbors;
    d["conformal"] = toArray(std::vector<float>(s.conformal));
    d["authalic"] = toArray(std::vector<float>(s.authalic));
    d["median_conformal"] = s.medianConformal;
    d["p90_conformal"] = s.p90Conformal;
    d["median_authalic"] = s.medianAuthalic;
    d["p90_authalic"] = s.p90Authalic;
    d["area_factor"] = s.areaFactor;
    d["undetermined"] = s.undetermined;
    sizes.append(d);
  }
  py::dict out;
  out["sizes"] = sizes;
  out["fold"] = toArray(std::vector<std::uint8_t>(defects.fold));
  out["overlap"] = toArray(std::vector<std::uint8_t>(defects.overlap));
  out["stretch"] = toArray(std::vector<float>(defects.stretch));
  out["median_stretch"] = defects.medianStretch;
  out["p90_stretch"] = defects.p90Stretch;
  out["folds"] = defects.folds;
  out["overlaps"] = defects.overlaps;
  return out;
}

}  // namespace

void bindParametrization(py::module_& m) {
  using namespace pybind11::literals;
  m.def("parametrize", &parametrizePy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "scales"_a = 50, "domain"_a = "auto", "k"_a = 10, "tmax"_a = 0.0, "alpha"_a = 0.1,
        "relax"_a = RelaxationOptions{}.iterations, "relax_rounds"_a = RelaxationOptions{}.rounds,
        "rigidity"_a = RelaxationOptions{}.rigidity,
        "sphere_rigidity"_a = RelaxationOptions{}.sphereRigidity,
        "relax_large_spheres"_a = RelaxationOptions{}.largeSpheres, "threads"_a = py::none(),
        "progress"_a = py::none(),
        R"doc(Meshless parametrization (Sec. 4.3), as `scalespace parametrize`.

The points flow onto their APSS while the scale grows along `scales` linear per-point scales
(from each point's distance to its k-th neighbour to tmax, 0: the diagonal), then onto one
sphere or plane. domain: "auto" (a plane when the points fit in a cap of 80 degrees), "plane"
or "sphere". relax: local-global iterations per round of the relaxation of the domain (beyond
the thesis, on by default, a sphere up to 100k points unless relax_large_spheres; 0 gives the thesis' map; not applied when
it would add folds or overlaps); relax_rounds: its robust re-weighting rounds (1: plain least squares); rigidity:
how rigid the relaxation's local maps are on a plane domain (1: rotations, which keep lengths, so
areas too, where the surface allows; 0: similarities, angles only; between: a blend);
sphere_rigidity: the same on a sphere domain (mostly conformal by default). Without normals they are estimated and oriented,
as the CLI does. Returns a dict: domain, uv (N, 2) or None, direction (N, 3), longitude and
latitude (N,) in degrees or None, valid, fold, overlap (N,) uint8, local_scale (N,), flattened
(N, 3) absolute, global_fit_is_plane, centre, radius, cap_degrees, one_to_one, folds, overlaps,
relaxed, relax_rounds_applied, warnings, seconds.)doc");
  m.def("distortion", &distortionPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "uv"_a = py::none(), "direction"_a = py::none(),
        "scales_k"_a = std::vector<int>{16, 64, 256}, "threads"_a = py::none(),
        "progress"_a = py::none(),
        R"doc(Meshless distortion of a parametrization (Sec. 4.4), as `scalespace distortion`.

Give the map as uv (N, 2) plane coordinates or direction (N, 3) points of a sphere. Per
neighbourhood size (neighbour counts), eps_conf and eps_auth (Eq. 4.3-4.4; areas normalised by
the median ratio) per point and their median and 90th percentile; and the map's folds and
overlaps. Returns a dict: sizes (a list of dicts: neighbors, conformal, authalic (N,) float32,
median_conformal, p90_conformal, median_authalic, p90_authalic, area_factor, undetermined),
fold, overlap (N,) uint8, folds, overlaps.)doc");
}

}  // namespace scalespace::python
