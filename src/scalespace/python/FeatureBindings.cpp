// Curvature lines (Sec. 3.3) and feature curves (Sec. 3.4.1) from Python, with the options and
// defaults of `scalespace lines` and `scalespace features` (cli/FeatureCommands.cpp), on points.
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "scalespace/core/Error.hpp"
#include "scalespace/features/CurvatureLines.hpp"
#include "scalespace/features/FeatureCurves.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/MeshFormat.hpp"
#include "scalespace/python/Bindings.hpp"
#include "scalespace/python/Bridge.hpp"
#include "scalespace/scales/ScaleSeries.hpp"

namespace scalespace::python {
namespace {

// Every line of `sets` as arrays: vertices line after line, with the per-vertex quantities the
// CLI writes as PLY properties (line_id scale k1 k2 k_gap nu, the tangent and the normal) and
// offsets (line l is vertices[offsets[l]:offsets[l + 1]]).
py::dict linesToDict(const std::vector<CurvatureLineSet>& sets, const Vec3& origin) {
  std::vector<Vec3> positions, normals, tangents;
  std::vector<int> lineId;
  std::vector<double> scale, k1, k2, gap, nu;
  std::vector<std::uint64_t> offsets{0};
  std::vector<std::uint8_t> closed;
  std::vector<std::uint32_t> seeds;
  int id = 0;
  for (const CurvatureLineSet& set : sets)
    for (const CurvatureLine& line : set.lines) {
      for (const CurvatureLineVertex& v : line.vertices) {
        positions.push_back(v.position);
        normals.push_back(v.normal);
        tangents.push_back(v.tangent);
        lineId.push_back(id);
        scale.push_back(set.scale);
        k1.push_back(v.kappa1);
        k2.push_back(v.kappa2);
        gap.push_back(std::abs(v.kappa1) - std::abs(v.kappa2));
        nu.push_back(v.geometricVariation);
      }
      offsets.push_back(positions.size());
      closed.push_back(line.closed ? 1 : 0);
      seeds.push_back(line.seed);
      ++id;
    }
  py::dict d;
  d["vertices"] = vectorsToArray(positions, origin);
  d["normal"] = vectorsToArray(normals);
  d["tangent"] = vectorsToArray(tangents);
  d["line_id"] = toArray(std::move(lineId));
  d["scale"] = toArray(std::move(scale));
  d["k1"] = toArray(std::move(k1));
  d["k2"] = toArray(std::move(k2));
  d["k_gap"] = toArray(std::move(gap));
  d["nu"] = toArray(std::move(nu));
  d["offsets"] = toArray(std::move(offsets));
  d["closed"] = toArray(std::move(closed));
  d["seed"] = toArray(std::move(seeds));
  return d;
}

py::dict linesPy(const py::handle& points, const py::handle& normals, std::optional<double> scale,
                 std::optional<int> scales, double tmin, double tmax, double beta, double gamma,
                 double alpha, bool robust, int maxSteps, bool curvedSeedsFirst,
                 std::optional<int> threads, py::object progress) {
  if (scale.value_or(0) <= 0 && scales.value_or(0) <= 0)
    throw OptionError("give the scale: scale=T, or scales=M for M scales");
  if (scale && scales) throw OptionError("give scale or scales, not both");
  if (scales) validateScaleCount(*scales);
  CurvatureLineOptions options;
  options.beta = beta;
  options.gamma = gamma;
  options.alpha = alpha;
  options.maxSteps = maxSteps;
  options.curvedSeedsFirst = curvedSeedsFirst;
  options.fit.robust = robust;
  options.scale = scale.value_or(1);
  validateCurvatureLineOptions(options);
  PooledCloud cloud = makeCloud(asPoints(points), normals);
  Call call(std::move(progress), threads);
  std::vector<CurvatureLineSet> sets = call([&] {
    if (!cloud.hasNormals()) estimateAndOrient(cloud, 10, "mst", std::nullopt, call.progress());
    // The CLI's series for --scales: from the mean 16-NN distance to a tenth of the diagonal.
    std::vector<double> ts{scale.value_or(0)};
    if (scales) {
      const double lo = tmin > 0 ? tmin : meanKthNeighborDistance(cloud.positions(), 16);
      const double hi = tmax > 0 ? tmax : 0.1 * cloud.boundingBoxDiagonal();
      ts = scaleSeries(lo, std::max(hi, lo), *scales, ScaleSpacing::Log);
    }
    std::vector<CurvatureLineSet> out;
    for (std::size_t s = 0; s < ts.size(); ++s) {
      options.scale = ts[s];
      const ProgressCallback& progress = call.progress();
      const auto scaleProgress = [&](double f, std::string_view stage) {
        return progress((double(s) + f) / double(ts.size()), stage);
      };
      out.push_back(traceCurvatureLines(cloud, options, scaleProgress));
    }
    return out;
  });
  return linesToDict(sets, cloud.origin());
}

TriangleMesh meshFrom(const Points& vertices, const py::handle& triangles) {
  const py::array any = py::module_::import("numpy").attr("asarray")(triangles);
  const char kind = any.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throwType("triangles: expected integer vertex indices of shape (T, 3)");
  const auto t = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(any);
  if (t.ndim() != 2 || t.shape(1) != 3 || t.shape(0) == 0)
    throwValue("triangles: expected an array of shape (T, 3) with T >= 1");
  TriangleMesh mesh;
  mesh.vertices.assign(vertices.data, vertices.data + vertices.size);
  mesh.triangles.resize(std::size_t(t.shape(0)));
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      const long long v = t.data()[3 * f + std::size_t(c)];
      if (v < 0 || std::size_t(v) >= vertices.size)
        throwValue("triangles: row " + std::to_string(f) + " names vertex " + std::to_string(v) +
                   ", not one of the " + std::to_string(vertices.size) + " points");
      mesh.triangles[f][std::size_t(c)] = Index(v);
    }
  mesh.normals = areaWeightedVertexNormals(mesh);
  return mesh;
}

py::dict featuresPy(const py::handle& points, const py::handle& normals,
                    const py::handle& viewpoint, int scales, double spacing, double voteThreshold,
                    int minScales, double minCurvature, double noiseCurvature,
                    double salientThreshold, double salientCap, double minExtent,
                    double minPieceExtent, double joinGap, double centrelineReach,
                    double bandHalfWidth, double creaseReach, double creaseHalfWidth,
                    double creaseFlatness, double creaseSideMargin, bool creaseSidesByNormals,
                    bool rimLines, double edgeReach, double edgeRejoinAngle, bool allSalient,
                    bool salientPerScale, double beta, double gamma, bool curvedSeedsFirst,
                    bool withLines, const py::handle& triangles, std::size_t meshSamples,
                    double sheetNormals, const std::string& foldBorders, double foldReach,
                    double foldShare, std::optional<int> threads, py::object progress) {
  if (foldBorders != "auto" && foldBorders != "on" && foldBorders != "off")
    throw OptionError("fold_borders takes 'auto', 'on' or 'off', got '" + foldBorders + "'");
  FeatureCurveOptions options;
  options.foldBorders = foldBorders == "on";
  options.foldReach = foldReach;
  options.foldBorderShare = foldShare;
  options.scaleCount = scales;
  options.spacing = spacing;
  options.voteThreshold = voteThreshold;
  options.minVotingScales = minScales;
  options.minSalientCurvature = minCurvature;
  options.noiseSalientFactor = noiseCurvature;
  options.salientThreshold = salientThreshold;
  options.salientBoundCap = salientCap;
  options.minCurveExtent = minExtent;
  options.minPieceExtent = minPieceExtent;
  options.joinGap = joinGap;
  options.centrelineReach = centrelineReach;
  options.bandHalfWidth = bandHalfWidth;
  options.creaseReach = creaseReach;
  options.creaseHalfWidth = creaseHalfWidth;
  options.creaseFlatness = creaseFlatness;
  options.creaseSideMargin = creaseSideMargin;
  options.creaseSidesByPosition = !creaseSidesByNormals;
  options.rimLines = rimLines;
  options.edgeReach = edgeReach;
  options.edgeRejoinAngle = edgeRejoinAngle;
  options.ridgeOnly = !allSalient;
  options.salientBoundFromFinest = !salientPerScale;
  options.lines.beta = beta;
  options.lines.gamma = gamma;
  options.lines.curvedSeedsFirst = curvedSeedsFirst;
  validateFeatureCurveOptions(options);
  if (meshSamples < 1 || meshSamples > 10000)
    throw OptionError("mesh_samples must be in [1, 10000]");
  if (!(sheetNormals >= 0) || !std::isfinite(sheetNormals))
    throw OptionError("sheet_normals must be finite and >= 0 (0: PCA normals)");
  const std::optional<Vec3> view = asOptionalVec3(viewpoint, "viewpoint");
  PooledCloud cloud;
  std::optional<TriangleMesh> mesh;
  std::vector<std::string> warnings;
  if (triangles.is_none()) {
    cloud = makeCloud(asPoints(points), normals);
  } else {
    // A mesh is sampled by area (interpolated normals) and its vertices are labelled on its
    // edges, as `scalespace features` does with a mesh input.
    if (!normals.is_none())
      throw OptionError("normals go with a cloud; a mesh's come from its faces");
    mesh = meshFrom(asPoints(points), triangles);
  }
  Call call(std::move(progress), threads);
  std::optional<double> openShare;  // where the normals were estimated here
  FeatureCurveResult result = call([&] {
    if (!mesh) {
      if (!cloud.hasNormals()) {
        NormalOrientationResult orientation;
        estimateAndOrient(cloud, featureNormalOptions(sheetNormals), "mst", view, call.progress(),
                          &orientation);
        openShare = orientation.openShare;
        if (foldBorders == "auto") chooseFoldBorders(options, orientation);
        FeatureCurveResult found = detectFeatureCurves(cloud, options, call.progress());
        const std::string hint = foldBordersHint(orientation, found, "fold_borders='on'");
        if (foldBorders == "auto" && !hint.empty()) warnings.push_back(hint);
        return found;
      }
      return detectFeatureCurves(cloud, options, call.progress());
    }
    MeshFeatureCurves onMesh =
        detectMeshFeatureCurves(*mesh, options, meshSamples, call.progress());
    if (onMesh.coarse)
      warnings.push_back("the mesh is coarse (median edge " +
                         std::to_string(onMesh.curves.spacing) +
                         ", over 5% of its diagonal): the scales [e, 3e] are as large as its "
                         "faces; give a finer spacing, or remesh it");
    cloud = std::move(onMesh.samples);
    return std::move(onMesh.curves);
  });
  warn(warnings);
  py::dict d;
  d["feature_votes"] = toArray(std::move(result.votes));
  d["curve_id"] = toArray(std::move(result.curveId));
  d["convexity"] = toArray(std::move(result.convexity));
  d["spacing"] = result.spacing;
  d["max_vote"] = result.maxVote;
  d["noise_rms"] = result.noiseRms;
  d["salient_curvature_floor"] = result.salientCurvatureFloor;
  d["fold_borders"] = result.foldsApplied;
  d["fold_see_through"] = result.foldSeeThrough >= 0 ? py::object(py::float_(result.foldSeeThrough))
                                                     : py::object(py::none());
  d["fold_points"] = result.foldPoints;
  d["rays_open_share"] = openShare ? py::object(py::float_(*openShare)) : py::object(py::none());
  py::list curves;
  for (FeatureCurve& curve : result.curves) {
    py::dict c;
    std::vector<double> voted;
    for (std::size_t s = 0; s < result.scales.size(); ++s)
      if (curve.scaleMask >> s & 1) voted.push_back(result.scales[s].scale);
    c["points"] = toArray(std::move(curve.points));
    c["length"] = curve.length;
    c["convexity"] = curve.convexity > 0 ? "convex" : "concave";
    c["scales"] = toArray(std::move(voted));
    curves.append(c);
  }
  d["curves"] = curves;
  d["edge_id"] = toArray(std::move(result.edgeId));
  py::list edges;
  for (FeatureEdge& edge : result.edges) {
    py::dict e;
    e["points"] = toArray(std::move(edge.points));
    e["curve"] = edge.curve;
    e["length"] = edge.length;
    edges.append(e);
  }
  d["edges"] = edges;
  py::list perScale;
  for (const FeatureCurveScale& s : result.scales) {
    py::dict e;
    e["scale"] = s.scale;
    e["salient_bound"] = s.salientBound;
    e["vertex_bound"] = s.vertexBound;
    e["lines"] = s.lines;
    e["vertices"] = s.vertices;
    e["salient_vertices"] = s.salientVertices;
    perScale.append(e);
  }
  d["scales"] = perScale;
  if (withLines) d["lines"] = linesToDict(result.lineSets, cloud.origin());
  return d;
}

}  // namespace

void bindFeatures(py::module_& m) {
  using namespace pybind11::literals;
  m.def("lines", &linesPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "scale"_a = py::none(), "scales"_a = py::none(), "tmin"_a = 0.0, "tmax"_a = 0.0,
        "beta"_a = 0.5, "gamma"_a = 0.5, "alpha"_a = 0.1, "robust"_a = false, "max_steps"_a = 2000,
        "curved_seeds_first"_a = CurvatureLineOptions{}.curvedSeedsFirst, "threads"_a = py::none(),
        "progress"_a = py::none(),
        R"doc(Minimal-curvature lines on the APSS (Sec. 3.3), as `scalespace lines`.

Give scale=T, or scales=M (log-spaced from tmin, default the mean 16-NN distance, to tmax,
default a tenth of the diagonal). beta: seeds' Poisson-disk radius / t; gamma: step / t;
alpha: pyramid radius / t. curved_seeds_first=False traces the seeds in the sampler's random
order (Sec. 3.3) instead of the most curved first. Returns a dict: vertices (V, 3) absolute,
normal, tangent (V, 3), line_id, scale, k1, k2, k_gap, nu (V,), offsets (L + 1,: line l is
vertices[offsets[l]:offsets[l + 1]]), closed (L,), seed (L,: the input point it started from).)doc");
  m.def("features", &featuresPy, "points"_a, "normals"_a = py::none(), py::kw_only(),
        "viewpoint"_a = py::none(), "scales"_a = 5, "spacing"_a = 0.0, "vote_threshold"_a = 0.05,
        "min_scales"_a = 3, "min_curvature"_a = 0.6, "noise_curvature"_a = 8.0,
        "salient_threshold"_a = 0.5, "salient_cap"_a = FeatureCurveOptions{}.salientBoundCap,
        "min_extent"_a = FeatureCurveOptions{}.minCurveExtent,
        "min_piece_extent"_a = FeatureCurveOptions{}.minPieceExtent, "join_gap"_a = 1.5,
        "centreline_reach"_a = FeatureCurveOptions{}.centrelineReach,
        "band_half_width"_a = FeatureCurveOptions{}.bandHalfWidth,
        "crease_reach"_a = FeatureCurveOptions{}.creaseReach,
        "crease_half_width"_a = FeatureCurveOptions{}.creaseHalfWidth,
        "crease_flatness"_a = FeatureCurveOptions{}.creaseFlatness,
        "crease_side_margin"_a = FeatureCurveOptions{}.creaseSideMargin,
        "crease_sides_by_normals"_a = !FeatureCurveOptions{}.creaseSidesByPosition,
        "rim_lines"_a = FeatureCurveOptions{}.rimLines,
        "edge_reach"_a = FeatureCurveOptions{}.edgeReach,
        "edge_rejoin_angle"_a = FeatureCurveOptions{}.edgeRejoinAngle, "all_salient"_a = false,
        "salient_per_scale"_a = false, "beta"_a = 0.5, "gamma"_a = 0.5,
        "curved_seeds_first"_a = CurvatureLineOptions{}.curvedSeedsFirst, "with_lines"_a = false,
        "triangles"_a = py::none(), "mesh_samples"_a = 100,
        "sheet_normals"_a = kFeatureSheetNormals, "fold_borders"_a = "auto",
        "fold_reach"_a = FeatureCurveOptions{}.foldReach,
        "fold_share"_a = FeatureCurveOptions{}.foldBorderShare, "threads"_a = py::none(),
        "progress"_a = py::none(),
        R"doc(Feature curves (Sec. 3.4.1), as `scalespace features` on a cloud.

Returns a dict: feature_votes (N,), curve_id (N,: -1 none), convexity (N,: +1, -1, 0), spacing
(e), max_vote, noise_rms (sigma read from the points), salient_curvature_floor (max(min_curvature,
noise_curvature * sigma / e): the |k1| t a salient vertex needs), curves (per curve: points, length, convexity, the scales that voted), edge_id (N,: -1 none)
and edges (per edge: points, curve, length; each curve split at its corners: where its points
within edge_reach x e do not lie along a line; adjacent pieces along one line, within
edge_rejoin_angle degrees, joined again where no third edge meets them; 0: no split / no
rejoining), scales (per
scale: scale, salient_bound (K), vertex_bound (the |k1| the salient vertices passed), lines,
vertices, salient_vertices), and with with_lines the lines traced (as lines() returns them).
salient_cap: a vertex with |k1| t >= salient_cap passes whatever K is (0: off). salient_per_scale=True takes K at each scale, not the finest
scale's K t over t. salient_cap=0, all_salient=True, min_scales=1, min_curvature=0, noise_curvature=0,
join_gap=0, salient_per_scale=True, centreline_reach=0, curved_seeds_first=False restore the
thesis' rules (with min_extent=0, min_piece_extent=0: every region kept; else regions spanning
under min_piece_extent x e are dropped before the joining, curves under min_extent x e after
it). centreline_reach, band_half_width: a curve keeps the points within
band_half_width x e of the centreline fitted to the salient vertices within centreline_reach x e;
where the points within crease_reach x e form two flat sides (RMS within crease_flatness x e or
twice the noise) the line where their planes meet replaces it, with crease_half_width (0: never);
the sides are the points beyond crease_side_margin x e, less 3 noise RMS, of the plane through
the centreline holding their mean normal (crease_sides_by_normals=True: by their normals);
where none is found and those points form one sheet stopping beside the curve (the rim of a part
thinner than crease_reach x e), the curve keeps the sheet within crease_half_width x e of its
outermost points (rim_lines=False: the centreline).
triangles (T, 3): points are a mesh's vertices (read_mesh), sampled with mesh_samples points per
vertex by area and labelled on the mesh edges (Sec. 3.4.1). sheet_normals: without normals, each
is estimated as the plane through the point and two neighbours that the most neighbours lie within
sheet_normals times the 10th neighbour's distance (or 8 noise RMS) of, where the PCA plane does not
hold them (one side's plane at a crease; 0: PCA normals), as estimate_normals(sheet=...,
sign_by_rays=True, reflect=True), and oriented (MST, the sign carried by the reflected agreement;
each part facing viewpoint=(x, y, z) when given: Cloud.viewpoint of a PCD, as the CLI does).
fold_borders: 'auto' (a cloud without normals whose estimated normals' rays find it closed, or
nearly closed, under 0.15, with at least half of the borders found seeing out on both sides: the
rim of a thin part, not the edges of an opening; off for meshes and clouds with normals), 'on'
or 'off': on a closed surface the points at a border
of the sheet their neighbours within fold_reach x e sample (the neighbours' centroid off the point
by fold_share x that radius or more, in their plane) are a fold thinner than the noise (a thin
part's rim) and join the convex curves; the dict's fold_borders says whether it applied and
fold_points how many points it added; fold_see_through the share of the borders found that see
out on both sides where auto measured it, else None; rays_open_share the share of the points whose
visibility rays see out on both sides where the normals were estimated here, else None: up to 0.05
is closed, and between that and 0.15 a warning says when the borders were left out as the edges
of an opening.)doc");
  m.def(
      "read_mesh",
      [](const std::string& path) {
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = readTriangleMesh(path);
        }
        std::vector<std::uint32_t> flat(3 * mesh.triangles.size());
        for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
          for (std::size_t c = 0; c < 3; ++c) flat[3 * f + c] = mesh.triangles[f][c];
        return py::make_tuple(vectorsToArray(mesh.vertices),
                              toArray(std::move(flat), {py::ssize_t(mesh.triangles.size()), 3}));
      },
      "path"_a,
      "The vertices (V, 3) float64 and triangles (T, 3) uint32 of an OFF, OBJ, STL (its "
      "repeated corners welded) or PLY mesh (polygons as fans).");
}

}  // namespace scalespace::python
