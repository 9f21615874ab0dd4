// Clouds: files to and from NumPy, normals, curvature at one scale, rendering. Each function
// mirrors its command's defaults (cli/CloudCommands.cpp, cli/PlanesCommands.cpp `render`).
#include <pybind11/stl.h>

#include <chrono>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalOrientation.hpp"
#include "scalespace/fit/CurvatureEstimation.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"
#include "scalespace/render/LineRenderer.hpp"
#include "scalespace/render/PointRenderer.hpp"

namespace scalespace::python {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

py::dict readCloudPy(const std::string& path, bool dropInvalid, std::size_t sample,
                     std::uint64_t seed) {
  ReadOptions options;
  options.dropNonFinite = dropInvalid;
  options.meshSamples = sample;
  options.seed = seed;
  if (sample > 0) {
    const CloudFormat format = formatFromPath(path);
    if (!canHoldFaces(format))
      throw OptionError("sample applies to meshes (.off .obj .stl, .ply with faces); " + path +
                        " is a " + formatName(format) + " point cloud");
  }
  ReadReport report;
  PointCloud cloud;
  {
    py::gil_scoped_release release;
    cloud = readCloud(path, options, &report);
  }
  py::dict out;
  out["points"] = vectorsToArray(cloud.positions(), cloud.origin());
  out["normals"] = cloud.hasNormals() ? py::object(vectorsToArray(cloud.normals())) : py::none();
  py::dict attributes;
  std::vector<AttributeColumn> columns;
  for (const AttributeColumn& a : cloud.attributes()) columns.push_back(a);
  for (AttributeColumn& a : columns) {
    const std::string name = a.name;
    attributes[py::str(name)] = columnToArray(std::move(a), true);
  }
  out["attributes"] = attributes;
  out["format"] = report.format;
  out["dropped"] = report.droppedNonFinite;
  out["unusable_normals_dropped"] = report.unusableNormalsDropped;
  if (cloud.viewpoint()) {
    const Vec3& v = *cloud.viewpoint();
    out["viewpoint"] = py::make_tuple(v.x(), v.y(), v.z());
  } else {
    out["viewpoint"] = py::none();
  }
  return out;
}

void writeCloudPy(const std::string& path, const py::handle& points, const py::handle& normals,
                  const py::handle& attributes, bool ascii) {
  // An empty cloud is a valid file (the readers read it back), unlike an empty input to analyse.
  const bool empty = py::len(py::module_::import("numpy").attr("asarray")(points)) == 0;
  PooledCloud cloud;
  std::size_t n = 0;
  if (!empty) {
    cloud = makeCloud(asPoints(points), normals);
    n = cloud.size();
  }
  if (!attributes.is_none()) {
    std::vector<AttributeColumn> columns;
    for (const auto& [key, value] : py::cast<py::dict>(attributes)) {
      const std::string name = py::cast<std::string>(key);
      const py::array any = py::module_::import("numpy").attr("asarray")(value);
      AttributeColumn column{name, scalarTypeOf(any.dtype(), name), {}};
      const auto values = DoubleArray::ensure(any);
      if (values.ndim() != 1 || std::size_t(values.size()) != n)
        throwValue("attribute '" + name + "': expected " + std::to_string(n) +
                   " values (one per point), got shape " +
                   std::string(py::str(py::tuple(any.attr("shape")))));
      column.values.assign(values.data(), values.data() + values.size());
      columns.push_back(std::move(column));
    }
    cloud.setAttributes(std::move(columns));
  }
  py::gil_scoped_release release;
  writeCloud(cloud, path, WriteOptions{ascii});
}

py::tuple normalsPy(const py::handle& points, std::size_t k, const std::string& orient,
                    const py::handle& viewpoint, double acrossWeight, bool visibility, double sheet,
                    bool signFromPca, bool signByRays, bool reflect,
                    std::optional<std::size_t> maxK, std::optional<int> threads,
                    py::object progress) {
  if (signFromPca && signByRays) throw OptionError("give one of sign_from_pca and sign_by_rays");
  PooledCloud cloud = makeCloud(asPoints(points), py::none());
  const std::optional<Vec3> view = asOptionalVec3(viewpoint, "viewpoint");
  Call call(std::move(progress), threads);
  std::vector<std::uint8_t> reliable = call([&] {
    return estimateAndOrient(cloud, k, orient, view, call.progress(), acrossWeight, visibility,
                             sheet, maxK.value_or(std::max(k, NormalEstimationOptions{}.maxK)),
                             signByRays    ? SheetSign::ByRays
                             : signFromPca ? SheetSign::FromPlanes
                                           : SheetSign::OwnTree,
                             reflect);
  });
  py::array_t<bool> reliableArray(py::ssize_t(reliable.size()));
  for (std::size_t i = 0; i < reliable.size(); ++i) reliableArray.mutable_data()[i] = reliable[i];
  return py::make_tuple(vectorsToArray(cloud.normals()), reliableArray);
}

py::object curvaturePy(const py::handle& points, const py::handle& normals,
                       std::optional<double> scale, std::optional<int> scaleK,
                       const std::string& estimator, bool mls, bool robust, std::size_t k,
                       bool withSummary, std::optional<int> threads, py::object progress) {
  CurvatureOptions options;
  options.fit.estimator = parseEstimator(estimator);
  options.fit.mls = mls;
  options.fit.robust = robust;
  options.scale = scale.value_or(0);
  options.scaleK = scaleK.value_or(0);
  validateCurvatureOptions(options);
  // The cost of the binding itself is timed apart (summary's input/output_seconds): checking and
  // copying the arrays in, handing the columns out and giving the copies' buffers back.
  const auto inputStart = std::chrono::steady_clock::now();
  PooledCloud cloud = makeCloud(asPoints(points), normals);
  const double inputSeconds = secondsSince(inputStart);
  if (std::size_t(options.scaleK) >= cloud.size())
    throw OptionError("scale_k " + std::to_string(options.scaleK) +
                      " must be smaller than the number of points (" +
                      std::to_string(cloud.size()) + ")");
  Call call(std::move(progress), threads);
  const bool estimated = !cloud.hasNormals();
  double librarySeconds = 0;
  const CurvatureSummary summary = call([&] {
    if (estimated) estimateAndOrient(cloud, k, "mst", std::nullopt, call.progress());
    const auto start = std::chrono::steady_clock::now();
    CurvatureSummary s = computeCurvatureColumns(cloud, options, call.progress());
    librarySeconds = secondsSince(start);
    return s;
  });
  warn(summary.warnings);
  // The columns, moved out of the cloud (no copy; the integer ones narrowed in their own buffers),
  // under the names `scalespace curvature` writes.
  const auto outputStart = std::chrono::steady_clock::now();
  py::dict out;
  for (const std::string& name : curvatureColumnNames()) {
    AttributeColumn* column = cloud.findAttribute(name);
    if (column) out[py::str(name)] = resultColumnToArray(std::move(*column));
  }
  cloud.recycle();  // the input copies' buffers back to the pool, here to be timed
  const double outputSeconds = secondsSince(outputStart);
  if (!withSummary) return std::move(out);
  // What `scalespace curvature` writes in its JSON summary.
  py::dict s;
  s["points"] = summary.points;
  s["invalid_fits"] = summary.invalid;
  s["mean_neighbors"] = summary.meanNeighbors;
  s["median_scale"] = summary.medianScale;
  s["seconds"] = summary.seconds;
  s["library_seconds"] = librarySeconds;
  s["input_seconds"] = inputSeconds;
  s["output_seconds"] = outputSeconds;
  s["normals_estimated"] = estimated;
  s["warnings"] = summary.warnings;
  return py::make_tuple(out, s);
}

// The dict lines() returns as the library's polylines: vertices (absolute), offsets, closed, and
// its per-vertex arrays as columns (what line_color_by names).
PolylineSet polylinesFrom(const py::handle& object) {
  if (!py::isinstance<py::dict>(object))
    throwType("lines: expected the dict that scalespace.lines() returns");
  const py::dict d = py::reinterpret_borrow<py::dict>(object);
  for (const char* key : {"vertices", "offsets"})
    if (!d.contains(key)) throwValue(std::string("lines: no '") + key + "' entry");
  PolylineSet set;
  const py::array any = py::module_::import("numpy").attr("asarray")(d["vertices"]);
  if (any.size() == 0) return set;
  const Points vertices = asPoints(any, "lines['vertices']");
  set.vertices.setAbsolutePositions(vertices.data, vertices.size);
  const auto offsets = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(
      py::module_::import("numpy").attr("asarray")(d["offsets"]));
  if (!offsets || offsets.ndim() != 1) throwValue("lines['offsets']: expected a 1-D array");
  set.offsets.clear();
  for (py::ssize_t i = 0; i < offsets.size(); ++i) {
    if (offsets.data()[i] < 0) throwValue("lines['offsets']: negative offset");
    set.offsets.push_back(std::size_t(offsets.data()[i]));
  }
  if (d.contains("closed")) {
    const auto closed =
        py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(
            py::module_::import("numpy").attr("asarray")(d["closed"]));
    if (closed) set.closed.assign(closed.data(), closed.data() + closed.size());
  }
  for (const auto& [key, value] : d) {
    const std::string name = py::cast<std::string>(key);
    const py::array a = py::module_::import("numpy").attr("asarray")(value);
    if (a.ndim() != 1 || std::size_t(a.size()) != vertices.size || name == "offsets") continue;
    const auto values = DoubleArray::ensure(a);
    set.vertices.addAttribute(name, ScalarType::Float64)
        .values.assign(values.data(), values.data() + values.size());
  }
  validatePolylineSet(set, "lines");
  return set;
}

py::array_t<std::uint8_t> renderPy(const py::handle& points, const py::handle& normals,
                                   const py::handle& colors, const py::handle& labels,
                                   const py::handle& values, const std::string& view,
                                   const std::string& up, int width, int height, int pointRadius,
                                   bool shading, const py::handle& lines,
                                   const std::string& lineColorBy) {
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.view = view;
  options.up = up;
  viewDirection(options.view, options.up);  // validate before the conversions
  options.pointRadius = pointRadius;
  options.shading = shading;
  PooledCloud cloud = makeCloud(asPoints(points), normals);
  const std::size_t n = cloud.size();
  const int given = int(!colors.is_none()) + int(!labels.is_none()) + int(!values.is_none());
  if (given > 1) throw OptionError("give at most one of colors, labels and values");
  auto column = [&](const py::handle& object, const char* name) {
    const DoubleArray a = DoubleArray::ensure(py::module_::import("numpy").attr("asarray")(object));
    if (!a || a.ndim() != 1 || std::size_t(a.size()) != n)
      throwValue(std::string(name) + ": expected " + std::to_string(n) + " values (one per point)");
    AttributeColumn& c = cloud.addAttribute(name, ScalarType::Float64);
    c.values.assign(a.data(), a.data() + n);
  };
  if (!labels.is_none()) {
    column(labels, "labels");
    options.labelAttribute = "labels";
  } else if (!values.is_none()) {
    column(values, "values");
    options.colorAttribute = "values";
  } else if (!colors.is_none()) {
    const auto rgb = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(
        py::module_::import("numpy").attr("asarray")(colors));
    if (!rgb || rgb.ndim() != 2 || rgb.shape(1) != 3 || std::size_t(rgb.shape(0)) != n)
      throwValue("colors: expected a uint8 array of shape (" + std::to_string(n) + ", 3)");
    options.colors.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      options.colors[i] = Rgb{rgb.data()[3 * i], rgb.data()[3 * i + 1], rgb.data()[3 * i + 2]};
  }
  // The lines first, as `render --lines` reads them: a bad colour attribute fails before drawing.
  PolylineSet polylines;
  LineRenderOptions lineOptions;
  lineOptions.colorAttribute = lineColorBy;
  if (!lines.is_none()) {
    polylines = polylinesFrom(lines);
    polylineColors(polylines, lineOptions);
  } else if (!lineColorBy.empty()) {
    throw OptionError("line_color_by goes with lines");
  }
  Image image;
  {
    py::gil_scoped_release release;
    Rendering rendering = renderPointsWithDepth(cloud, options);
    if (!lines.is_none()) drawPolylines(rendering, polylines, lineOptions);
    image = std::move(rendering.image);
  }
  std::vector<std::uint8_t> pixels(3 * image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    pixels[3 * i] = image.pixels[i].r;
    pixels[3 * i + 1] = image.pixels[i].g;
    pixels[3 * i + 2] = image.pixels[i].b;
  }
  return toArray(std::move(pixels), {image.height, image.width, 3});
}

}  // namespace

void bindClouds(py::module_& m) {
  using namespace pybind11::literals;
  m.def("_read", &readCloudPy, "path"_a, py::kw_only(), "drop_invalid"_a = false, "sample"_a = 0,
        "seed"_a = 1);
  m.def("_write", &writeCloudPy, "path"_a, "points"_a, "normals"_a = py::none(),
        "attributes"_a = py::none(), py::kw_only(), "ascii"_a = false);
  m.def("estimate_normals", &normalsPy, "points"_a, py::kw_only(), "k"_a = 10, "orient"_a = "mst",
        "viewpoint"_a = py::none(), "across_weight"_a = NormalOrientationOptions{}.acrossWeight,
        "visibility"_a = NormalOrientationOptions{}.visibility,
        "sheet"_a = NormalEstimationOptions{}.sheetTolerance, "sign_from_pca"_a = false,
        "sign_by_rays"_a = false, "reflect"_a = NormalOrientationOptions{}.reflectAcrossBisector,
        "max_k"_a = py::none(), "threads"_a = py::none(), "progress"_a = py::none(),
        R"doc(Estimates (PCA over k neighbours) and orients normals, as `scalespace normals`.

max_k: under noise comparable to the sampling, k doubles up to max_k (default 80) while the
normals of k and 2k neighbours differ by more than 12 degrees (median over a sample); max_k=k
keeps k as given.

orient: "mst" (Hoppe 1992 propagation, seeds towards +z; with viewpoint=(x, y, z), each
connected part instead faces it, as `scalespace` does with a PCD's VIEWPOINT: Cloud.viewpoint) or
"viewpoint" (each normal towards viewpoint, a scanner position in the points' coordinates). across_weight (mst): the
extra cost of an edge across a thin part, so that its two sides are oriented apart (0: Hoppe's
cost alone). visibility (mst): turn over the pieces of the tree that rays cast from the points
show facing the inside of a closed surface (the two sides of thin parts, creases). sheet: the
plane through the point and two neighbours that the most neighbours lie within sheet times the
k-th neighbour's distance (or 8 noise RMS) of, refitted to them, instead of the PCA plane: one
side's plane at a crease or on a part thinner than the sampling (0: PCA; features uses 0.05).
sign_from_pca (with sheet): orient the PCA normals and give each sheet normal its point's sign;
where two surfaces touch (the strands of a cable) the sheet normals' own tree can turn one inside
out (cylinders does this). sign_by_rays (with sheet): orient both ways (the sheet normals' own tree,
the PCA signs) and keep the one the visibility rays find facing inward less often (features does
this).
reflect (mst): the propagation compares each normal with its neighbour's reflected across the
plane bisecting their offset, not with the neighbour's itself: creases sharper than 90 degrees (a
narrow V-groove) and thin parts keep their sides apart (NormalOrientationOptions::
reflectAcrossBisector).
Returns (normals (N, 3) float64, reliable (N,) bool: False where the orientation is a guess).)doc");
  m.def("curvature", &curvaturePy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "scale"_a = py::none(), "scale_k"_a = py::none(), "estimator"_a = "w3", "mls"_a = false,
        "robust"_a = false, "k"_a = 10, "summary"_a = false, "threads"_a = py::none(),
        "progress"_a = py::none(),
        R"doc(Normals, mean and principal curvatures and directions at one scale (Ch. 1).

Give exactly one of scale (support radius t, in the points' units) and scale_k (per point,
t = distance to the K-th nearest neighbour). normals: oriented normals (N, 3); None estimates
and orients them (PCA over k neighbours, MST), as `scalespace curvature` does. estimator: w3 |
w2 | w1 | plane | mean | quadric | jet. mls: iterate the MLS projection; robust: RIMLS.
Returns a dict of (N,) arrays named as the columns `scalespace curvature` writes: nx ny nz
curv_mean curv_max curv_min dir_max_x .. dir_min_z gls_tau gls_kappa gls_fitness anisotropy
(float64), neighbors (int32), fit_valid (uint8; 0: invalid fit, zeros elsewhere).
Most fits invalid: a RuntimeWarning says why. summary=True returns (columns, summary): the
figures of the CLI's JSON summary (points, invalid_fits, mean_neighbors, median_scale, seconds:
the fits' time, library_seconds: the whole library call's, input_seconds and output_seconds: the
binding's own time to check and copy the arrays in and to hand the columns out, normals_estimated,
warnings).)doc");
  m.def("render", &renderPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "colors"_a = py::none(), "labels"_a = py::none(), "values"_a = py::none(), "view"_a = "iso",
        "up"_a = "z", "width"_a = 1024, "height"_a = 768, "point_radius"_a = -1, "shading"_a = true,
        "lines"_a = py::none(), "line_color_by"_a = "",
        R"doc(Renders the points (software, orthographic) to an (height, width, 3) uint8 image.

Colour by colors (N, 3) uint8, or labels (N,) integers (distinct hues, -1 grey), or values (N,)
(viridis over the 2nd-98th percentile); else light grey. view: front | top | iso | "X,Y,Z";
up: the cloud's up axis (z | y | x | -z | -y | -x). point_radius -1: automatic.
lines: the dict lines() returns, drawn over the points where the surface does not hide them
(solid red, or coloured by one of its per-vertex arrays: line_color_by="k_gap").)doc");
}

}  // namespace scalespace::python
