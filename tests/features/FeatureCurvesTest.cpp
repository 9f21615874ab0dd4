// Feature curves by multi-scale voting (Sec. 3.4.1): the 12 edges of a cube are one convex curve;
// a box standing on a ground plane adds its footprint as a separate concave curve; flat faces stay
// unlabelled; the mesh-vertex protocol labels vertices; options are checked.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "features/CubeMesh.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/core/NormalEstimation.hpp"
#include "scalespace/features/FeatureCurves.hpp"

using namespace scalespace;

namespace {

/// Points drawn uniformly on axis-aligned rectangles (exact normals), `density` per unit area.
struct RectangleSampler {
  std::mt19937_64 random{5};
  std::vector<Vec3> positions, normals;
  // The rectangle origin + u a + v b (a, b in [0, 1]), normal n.
  void add(const Vec3& origin, const Vec3& a, const Vec3& b, const Vec3& n, double density,
           const std::function<bool(const Vec3&)>& keep = {}) {
    std::uniform_real_distribution<double> uniform(0, 1);
    const auto count = std::size_t(density * a.cross(b).norm());
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3 p = origin + uniform(random) * a + uniform(random) * b;
      if (keep && !keep(p)) continue;
      positions.push_back(p);
      normals.push_back(n);
    }
  }
  PointCloud cloud() const {
    PointCloud c;
    c.setRelativePositions(positions, Vec3::Zero());
    c.setNormals(normals);
    return c;
  }
};

/// The faces of the box [0,1]^3 (without its bottom when `bottom` is false).
void addBox(RectangleSampler& s, double density, bool bottom) {
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  s.add(Vec3(0, 0, 1), x, y, z, density);
  if (bottom) s.add(Vec3(0, 0, 0), x, y, -z, density);
  s.add(Vec3(0, 0, 0), x, z, -y, density);
  s.add(Vec3(0, 1, 0), x, z, y, density);
  s.add(Vec3(0, 0, 0), y, z, -x, density);
  s.add(Vec3(1, 0, 0), y, z, x, density);
}

/// The box without its bottom standing on the ground [-1, 2]^2 at z = 0 (without the footprint).
void addBoxOnGround(RectangleSampler& s) {
  addBox(s, 8000, false);
  s.add(Vec3(-1, -1, 0), Vec3(3, 0, 0), Vec3(0, 3, 0), Vec3::UnitZ(), 8000,
        [](const Vec3& p) { return !(p.x() > 0 && p.x() < 1 && p.y() > 0 && p.y() < 1); });
}

/// Distance from p to the segment [a, b].
double segmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

struct Edge {
  Vec3 a, b;
};

std::vector<Edge> cubeEdges() {
  std::vector<Edge> edges;
  for (int axis = 0; axis < 3; ++axis)
    for (int u = 0; u < 2; ++u)
      for (int v = 0; v < 2; ++v) {
        Vec3 a = Vec3::Zero();
        a[(axis + 1) % 3] = u;
        a[(axis + 2) % 3] = v;
        Vec3 b = a;
        b[axis] = 1;
        edges.push_back({a, b});
      }
  return edges;
}

/// Of the points within `band` of the middle 80% of an edge, the fraction labelled with `sign`,
/// and the curve ids they carry.
struct EdgeLabels {
  double fraction = 0;
  std::set<int> curves;
};
EdgeLabels labelsAlong(const std::vector<Vec3>& points, const FeatureCurveResult& r, const Edge& e,
                       double band, int sign) {
  const Vec3 a = e.a + 0.1 * (e.b - e.a), b = e.a + 0.9 * (e.b - e.a);
  std::size_t near = 0, labelled = 0;
  EdgeLabels out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (segmentDistance(points[i], a, b) > band) continue;
    ++near;
    if (r.convexity[i] == sign && r.curveId[i] >= 0) {
      ++labelled;
      out.curves.insert(r.curveId[i]);
    }
  }
  out.fraction = near ? double(labelled) / double(near) : 0;
  return out;
}

/// The edge id most of the labelled points near the middle of `edge` carry (away from its
/// corners), and the share of them carrying it.
std::pair<int, double> edgeIdAlong(const std::vector<Vec3>& points, const FeatureCurveResult& r,
                                   const Edge& edge, double band) {
  std::map<int, std::size_t> count;
  std::size_t total = 0;
  const Vec3 d = edge.b - edge.a;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double along = (points[i] - edge.a).dot(d) / d.squaredNorm();
    if (along < 0.2 || along > 0.8 || segmentDistance(points[i], edge.a, edge.b) > band ||
        r.edgeId[i] < 0)
      continue;
    ++count[r.edgeId[i]];
    ++total;
  }
  std::pair<int, double> best{-1, 0.0};
  for (const auto& [id, c] : count)
    if (double(c) / double(total) > best.second) best = {id, double(c) / double(total)};
  return best;
}

}  // namespace

TEST(FeatureCurves, TheTwelveEdgesOfACubeAreConvex) {
  RectangleSampler s;
  addBox(s, 8000, true);
  const PointCloud cloud = s.cloud();
  const FeatureCurveResult r = detectFeatureCurves(cloud, FeatureCurveOptions{});
  ASSERT_EQ(r.scales.size(), 5u);
  const double e = r.spacing;
  for (const Edge& edge : cubeEdges()) {
    const EdgeLabels l = labelsAlong(cloud.positions(), r, edge, 0.5 * e, +1);
    EXPECT_GT(l.fraction, 0.9) << edge.a.transpose() << " -> " << edge.b.transpose();
  }
  // Nothing concave; face centres (beyond 4 e of every edge) unlabelled.
  std::size_t concave = 0, flatLabelled = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    concave += r.convexity[i] < 0;
    double nearest = 1e9;
    for (const Edge& edge : cubeEdges())
      nearest = std::min(nearest, segmentDistance(cloud.positions()[i], edge.a, edge.b));
    if (nearest > 4 * e) flatLabelled += r.curveId[i] >= 0;
  }
  EXPECT_EQ(concave, 0u);
  EXPECT_EQ(flatLabelled, 0u);
  // The edges meet at the corners: one curve of 12 edges, length ~12.
  ASSERT_GE(r.curves.size(), 1u);
  const FeatureCurve& largest = *std::max_element(r.curves.begin(), r.curves.end(),
                                                  [](const FeatureCurve& a, const FeatureCurve& b) {
                                                    return a.points.size() < b.points.size();
                                                  });
  EXPECT_EQ(largest.convexity, 1);
  EXPECT_NEAR(largest.length, 12.0, 3.0);
  EXPECT_EQ(largest.scaleMask, 0x1Fu) << "every scale voted";
  // Split at the corners: 12 edges, each cube edge one of them, of length ~1.
  EXPECT_EQ(r.edges.size(), 12u);
  std::set<int> ids;
  for (const Edge& edge : cubeEdges()) {
    const auto [id, share] = edgeIdAlong(cloud.positions(), r, edge, 0.5 * e);
    EXPECT_GT(share, 0.99) << edge.a.transpose() << " -> " << edge.b.transpose();
    ids.insert(id);
    if (id >= 0) {
      EXPECT_NEAR(r.edges[std::size_t(id)].length, 1.0, 0.25);
    }
  }
  EXPECT_EQ(ids.size(), 12u);
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(r.edgeId[i] >= 0, r.curveId[i] >= 0);
  // edgeReach 0: one edge per curve.
  FeatureCurveOptions whole;
  whole.edgeReach = 0;
  const FeatureCurveResult unsplit = detectFeatureCurves(cloud, whole);
  EXPECT_EQ(unsplit.edgeId, unsplit.curveId);
  EXPECT_EQ(unsplit.edges.size(), unsplit.curves.size());
}

// The voting detail is returned only when asked for, changes no label, and agrees with the curves'
// scale masks and with the salient vertices' positions (each within e of a point it voted for).
TEST(FeatureCurves, TheVotingDetailIsKeptOnlyWhenAskedFor) {
  RectangleSampler s;
  addBox(s, 8000, true);
  const PointCloud cloud = s.cloud();
  const FeatureCurveResult plain = detectFeatureCurves(cloud, FeatureCurveOptions{});
  EXPECT_TRUE(plain.voterScales.empty());
  EXPECT_TRUE(plain.salientPositions.empty());
  FeatureCurveOptions detailed;
  detailed.keepVotingDetail = true;
  const FeatureCurveResult r = detectFeatureCurves(cloud, detailed);
  EXPECT_EQ(r.curveId, plain.curveId);
  ASSERT_EQ(r.voterScales.size(), cloud.size());
  ASSERT_FALSE(r.salientPositions.empty());
  ASSERT_EQ(r.salientScales.size(), r.salientPositions.size());
  ASSERT_EQ(r.salientSigns.size(), r.salientPositions.size());
  for (const FeatureCurve& curve : r.curves) {
    std::uint32_t mask = 0;
    for (const Index p : curve.points) mask |= r.voterScales[p];
    EXPECT_EQ(mask, curve.scaleMask);
  }
  // The convex vertices lie on the edges; the few concave ones are the fit's ringing beside them
  // (docs/THESIS_NOTES.md, "Salient filter"), which labels nothing.
  std::size_t concave = 0;
  std::vector<double> distances;
  for (std::size_t k = 0; k < r.salientPositions.size(); ++k) {
    EXPECT_LT(r.salientScales[k], r.scales.size());
    if (r.salientSigns[k] < 0) {
      ++concave;
      continue;
    }
    const Vec3& v = r.salientPositions[k];
    double nearest = 1e9;
    for (const Edge& edge : cubeEdges())
      nearest = std::min(nearest, segmentDistance(v, edge.a, edge.b));
    EXPECT_LT(nearest, 1.5 * r.spacing) << v.transpose();
    distances.push_back(nearest);
  }
  ASSERT_FALSE(distances.empty());
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  EXPECT_LT(distances[distances.size() / 2], 0.5 * r.spacing)
      << "the APSS rounds the edge a little";
  EXPECT_LT(concave, r.salientPositions.size() / 10) << r.salientPositions.size();
  for (const std::int8_t c : r.convexity) EXPECT_GE(c, 0);
}

// The vote balls of single salient vertices, each a little off the edge (and inside the cube: the
// APSS rounds it), label a band wider than the vote radius e; trimming the band to the centreline
// fitted to the vertices of all scales keeps it within e of the edges and the edges labelled.
TEST(FeatureCurves, TheBandIsTrimmedToTheCentrelineOfTheVotes) {
  RectangleSampler s;
  addBox(s, 8000, true);
  const PointCloud cloud = s.cloud();
  FeatureCurveOptions untrimmed;
  untrimmed.centrelineReach = 0;
  const FeatureCurveResult wide = detectFeatureCurves(cloud, untrimmed);
  FeatureCurveOptions centreline;  // the centreline everywhere, not the sides' planes
  centreline.creaseReach = 0;
  const FeatureCurveResult trimmed = detectFeatureCurves(cloud, centreline);
  FeatureCurveOptions tighter = centreline;
  tighter.bandHalfWidth = 0.8;
  const FeatureCurveResult tight = detectFeatureCurves(cloud, tighter);
  FeatureCurveOptions byPlanes;  // the default: the line where the sides' planes meet
  const FeatureCurveResult planes = detectFeatureCurves(cloud, byPlanes);
  const double e = trimmed.spacing;
  // The share of the labelled points beyond `reach` of every edge, away from the corners (where
  // the vertices of three edges do not lie along a line and the points keep their labels).
  auto beyond = [&](const FeatureCurveResult& r, double reach) {
    std::size_t count = 0, labelled = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (r.curveId[i] < 0) continue;
      const Vec3& p = cloud.positions()[i];
      double nearest = 1e9;
      for (const Edge& edge : cubeEdges())
        nearest = std::min(nearest, segmentDistance(p, edge.a, edge.b));
      const Vec3 corner = p.array().round().matrix();
      if ((p - corner).norm() < 3 * e) continue;
      ++labelled;
      count += nearest > reach;
    }
    return double(count) / double(std::max<std::size_t>(labelled, 1));
  };
  // The centreline lies a little inside the edge: a half-width h keeps points up to about
  // (h + 0.3) e from it.
  EXPECT_GT(beyond(wide, 1.1 * e), 0.02);
  EXPECT_LT(beyond(tight, 1.1 * e), 0.25 * beyond(wide, 1.1 * e)) << beyond(wide, 1.1 * e);
  EXPECT_LT(beyond(trimmed, 1.2 * e), 0.25 * beyond(wide, 1.2 * e)) << beyond(wide, 1.2 * e);
  EXPECT_LT(beyond(trimmed, 1.2 * e), beyond(tight, 1.1 * e)) << "a wider band keeps more";
  // The cube's faces are flat: the line where they meet is the edge itself, and the band is the
  // points within creaseHalfWidth (1) e of it. (The sides by position, split by a plane through
  // the salient vertices' centreline, take now and then a point of the other face next to the
  // edge, which moves the line by a hundredth of e.)
  EXPECT_EQ(beyond(planes, 1.02 * e), 0.0);
  EXPECT_LT(beyond(planes, 1.0 * e + 1e-12), 0.002);
  FeatureCurveOptions byNormals;
  byNormals.creaseSidesByPosition = false;
  EXPECT_EQ(beyond(detectFeatureCurves(cloud, byNormals), 1.0 * e + 1e-12), 0.0);
  EXPECT_GT(beyond(trimmed, 1.0 * e), 0.0) << "the centreline lies inside the edge";
  for (const Edge& edge : cubeEdges())
    EXPECT_GT(labelsAlong(cloud.positions(), planes, edge, 0.9 * e, +1).fraction, 0.95)
        << edge.a.transpose() << " -> " << edge.b.transpose();
  for (const Edge& edge : cubeEdges())
    EXPECT_GT(labelsAlong(cloud.positions(), trimmed, edge, 0.7 * e, +1).fraction, 0.95)
        << edge.a.transpose() << " -> " << edge.b.transpose();
  // Only points leave the band.
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (trimmed.curveId[i] >= 0) {
      ASSERT_GE(wide.curveId[i], 0);
    }
}

TEST(FeatureCurves, ABoxOnTheGroundAddsItsFootprintAsAConcaveCurve) {
  RectangleSampler s;
  addBoxOnGround(s);
  const PointCloud cloud = s.cloud();
  const FeatureCurveResult r = detectFeatureCurves(cloud, FeatureCurveOptions{});
  const double e = r.spacing;
  std::set<int> footprintCurves, convexCurves;
  for (const Edge& edge : cubeEdges()) {
    const bool footprint = edge.a.z() == 0 && edge.b.z() == 0;
    const EdgeLabels l = labelsAlong(cloud.positions(), r, edge, 0.5 * e, footprint ? -1 : +1);
    EXPECT_GT(l.fraction, 0.9) << (footprint ? "footprint " : "convex ") << edge.a.transpose()
                               << " -> " << edge.b.transpose();
    (footprint ? footprintCurves : convexCurves).insert(l.curves.begin(), l.curves.end());
  }
  EXPECT_EQ(footprintCurves.size(), 1u) << "the footprint is one closed concave curve";
  EXPECT_EQ(convexCurves.size(), 1u) << "the top and the vertical edges meet at the corners";
  for (const int c : footprintCurves) {
    EXPECT_EQ(r.curves[std::size_t(c)].convexity, -1);
    EXPECT_EQ(convexCurves.count(c), 0u);
    EXPECT_NEAR(r.curves[std::size_t(c)].length, 4.0, 1.0);
  }
  // Per edge: the 8 convex edges and the 4 of the footprint, each its own.
  std::set<int> ids;
  for (const Edge& edge : cubeEdges()) {
    const auto [id, share] = edgeIdAlong(cloud.positions(), r, edge, 0.5 * e);
    EXPECT_GT(share, 0.99);
    ids.insert(id);
  }
  EXPECT_EQ(ids.size(), 12u);
  EXPECT_EQ(ids.count(-1), 0u);
}

// Sensor noise of 0.13 e (1e-3 of the diagonal on bench_features' models) gives flat faces a
// |kappa1| t above the fixed floor of 0.6 in many places; the floor that grows with the noise read
// from the points keeps the ground away from the edges unlabelled and still finds the box's edges.
TEST(FeatureCurves, TheSalientFloorFollowsTheNoiseReadFromThePoints) {
  RectangleSampler s;
  addBoxOnGround(s);
  const PointCloud clean = s.cloud();
  const FeatureCurveResult cleanResult = detectFeatureCurves(clean, FeatureCurveOptions{});
  const double e = cleanResult.spacing, sigma = 0.13 * e;
  EXPECT_LT(cleanResult.noiseRms, 1e-9);
  EXPECT_EQ(cleanResult.salientCurvatureFloor, FeatureCurveOptions{}.minSalientCurvature);

  std::mt19937_64 random(11);
  std::normal_distribution<double> gauss(0, sigma);
  std::vector<Vec3> noisy = s.positions;
  for (Vec3& p : noisy) p += Vec3(gauss(random), gauss(random), gauss(random));
  // Normals estimated from the noisy points as for a scan (PCA over 10 neighbours), oriented
  // along the exact ones.
  NormalEstimationResult estimated = estimateNormals(noisy);
  for (std::size_t i = 0; i < noisy.size(); ++i)
    if (estimated.normals[i].dot(s.normals[i]) < 0) estimated.normals[i] *= -1;
  PointCloud cloud;
  cloud.setRelativePositions(noisy, Vec3::Zero());
  cloud.setNormals(estimated.normals);
  // The specks the floor prevents, counted before the extent filter (3 e) drops most of them.
  const auto run = [&](double factor, std::size_t& farLabelled, double minExtent = 1) {
    FeatureCurveOptions options;
    options.noiseSalientFactor = factor;
    options.minCurveExtent = minExtent;
    const FeatureCurveResult r = detectFeatureCurves(cloud, options);
    farLabelled = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      double nearest = 1e9;
      for (const Edge& edge : cubeEdges())
        nearest = std::min(nearest, segmentDistance(s.positions[i], edge.a, edge.b));
      if (nearest > 4 * e) farLabelled += r.curveId[i] >= 0;
    }
    return r;
  };
  std::size_t farWithFloor = 0, farWithout = 0;
  const FeatureCurveResult r = run(FeatureCurveOptions{}.noiseSalientFactor, farWithFloor);
  run(0.0, farWithout);
  EXPECT_NEAR(r.noiseRms, sigma, 0.2 * sigma);
  EXPECT_NEAR(r.salientCurvatureFloor, 8 * r.noiseRms / r.spacing, 1e-12);
  // Measured: 10 and 676 of 103,893 points beyond 4 e of every edge.
  EXPECT_LT(farWithFloor, 50u);
  EXPECT_GT(farWithout, 300u) << "the fixed floor alone labels the noisy ground";
  // Without the floor, the default extent (3 e, after the joining) drops most of those specks
  // (measured: 98) and keeps every edge.
  std::size_t farSpecksDropped = 0;
  const FeatureCurveResult dropped =
      run(0.0, farSpecksDropped, FeatureCurveOptions{}.minCurveExtent);
  EXPECT_LT(farSpecksDropped, farWithout / 4);
  for (const FeatureCurveResult* result : {&r, &dropped})
    for (const Edge& edge : cubeEdges()) {
      const bool footprint = edge.a.z() == 0 && edge.b.z() == 0;
      const EdgeLabels l = labelsAlong(s.positions, *result, edge, 0.5 * e, footprint ? -1 : +1);
      EXPECT_GT(l.fraction, 0.8) << (footprint ? "footprint " : "convex ") << edge.a.transpose();
    }
}

// Lines stop short of the corners where creases meet, so the region growing alone cuts the box's
// edges into pieces; joinGap joins the pieces of one sign, never a convex piece to a concave one.
TEST(FeatureCurves, PiecesOfOneSignMeetingAtCornersAreOneCurve) {
  RectangleSampler s;
  addBoxOnGround(s);
  const PointCloud cloud = s.cloud();
  FeatureCurveOptions pieces;
  pieces.joinGap = 0;
  const FeatureCurveResult apart = detectFeatureCurves(cloud, pieces);
  const FeatureCurveResult joined = detectFeatureCurves(cloud, FeatureCurveOptions{});
  EXPECT_GT(apart.curves.size(), joined.curves.size());  // measured: 4 pieces
  EXPECT_EQ(joined.curves.size(), 2u) << "one convex curve (top and verticals), one footprint";
  // The same points are labelled with the same signs; only the curve ids differ.
  EXPECT_EQ(apart.convexity, joined.convexity);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    EXPECT_EQ(apart.curveId[i] >= 0, joined.curveId[i] >= 0);
  for (const FeatureCurve& c : joined.curves)
    for (const Index p : c.points) ASSERT_EQ(joined.convexity[p], c.convexity);
}

TEST(FeatureCurves, SameResultForAnyThreadCount) {
  RectangleSampler s;
  addBox(s, 3000, true);
  const PointCloud cloud = s.cloud();
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    return detectFeatureCurves(cloud, FeatureCurveOptions{});
  };
  const FeatureCurveResult one = run(1), many = run(4);
  EXPECT_EQ(one.votes, many.votes);
  EXPECT_EQ(one.curveId, many.curveId);
  EXPECT_EQ(one.edgeId, many.edgeId);
}

TEST(FeatureCurves, MeshVerticesAreLabelledOnTheMeshEdges) {
  RectangleSampler s;
  addBox(s, 8000, true);
  const PointCloud cloud = s.cloud();
  std::vector<Vec3> vertices;
  std::vector<std::array<Index, 3>> triangles;
  test::cubeMesh(4, vertices, triangles);
  ASSERT_EQ(vertices.size(), 98u);
  const KnnGraph graph = buildMeshEdgeGraph(vertices.size(), triangles);
  EXPECT_EQ(graph.neighbors.size(), 2 * (3 * triangles.size() / 2));  // each edge in 2 triangles
  const FeatureCurveResult r = detectFeatureCurves(cloud, FeatureCurveOptions{}, vertices, graph);
  ASSERT_EQ(r.curveId.size(), vertices.size());
  std::size_t edge = 0, edgeConvex = 0, inside = 0, insideLabelled = 0;
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    int onBorder = 0;  // coordinates at 0 or 1: 3 at a corner, 2 on an edge, 1 inside a face
    for (int c = 0; c < 3; ++c)
      onBorder += std::abs(vertices[v][c]) < 1e-9 || std::abs(vertices[v][c] - 1) < 1e-9;
    if (onBorder == 2) {
      ++edge;
      edgeConvex += r.convexity[v] == 1 && r.curveId[v] >= 0;
    }
    if (onBorder == 1) {
      ++inside;
      insideLabelled += r.curveId[v] >= 0;
    }
  }
  EXPECT_EQ(edge, 36u);
  EXPECT_GE(edgeConvex, 33u) << "of the 36 vertices inside the cube's edges";
  EXPECT_EQ(inside, 54u);
  EXPECT_EQ(insideLabelled, 0u);
  EXPECT_THROW(buildMeshEdgeGraph(3, {{0, 1, 5}}), OptionError);
}

// On a nearly closed cloud `auto` keeps the borders as folds only when they see out on both
// sides: the rim of a part thinner than the noise does (a noisy sheet's border), the edge of an
// opening in a closed surface has the surface behind it (a box with a square hole in its top).
TEST(FeatureCurves, FoldsAreKeptWhereTheBordersSeeOutOnBothSides) {
  FeatureCurveOptions options;
  options.foldBorders = true;
  options.foldSeeThroughShare = kFoldSeeThroughShare;

  RectangleSampler sheet;
  sheet.add(Vec3(0, 0, 0), Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), 8000);
  std::normal_distribution<double> noise(0, 0.002);
  for (Vec3& p : sheet.positions) p.z() += noise(sheet.random);
  const FeatureCurveResult thin = detectFeatureCurves(sheet.cloud(), options);
  EXPECT_TRUE(thin.foldsApplied);
  EXPECT_GT(thin.foldSeeThrough, 0.9);
  EXPECT_GT(thin.foldPoints, 0u);

  RectangleSampler holed;
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  holed.add(Vec3(0, 0, 1), x, y, z, 6000, [](const Vec3& p) {
    return std::abs(p.x() - 0.5) > 0.4 || std::abs(p.y() - 0.5) > 0.4;
  });
  holed.add(Vec3(0, 0, 0), x, y, -z, 6000);
  holed.add(Vec3(0, 0, 0), x, z, -y, 6000);
  holed.add(Vec3(0, 1, 0), x, z, y, 6000);
  holed.add(Vec3(0, 0, 0), y, z, -x, 6000);
  holed.add(Vec3(1, 0, 0), y, z, x, 6000);
  const PointCloud box = holed.cloud();
  const FeatureCurveResult opening = detectFeatureCurves(box, options);
  EXPECT_FALSE(opening.foldsApplied);
  EXPECT_GE(opening.foldSeeThrough, 0.0);
  EXPECT_LT(opening.foldSeeThrough, 0.1);
  EXPECT_EQ(opening.foldPoints, 0u);
  // Without the test the hole's rim is taken as a fold: the test is what leaves it out.
  options.foldSeeThroughShare = 0;
  const FeatureCurveResult taken = detectFeatureCurves(box, options);
  EXPECT_TRUE(taken.foldsApplied);
  EXPECT_GT(taken.foldPoints, 100u);
  EXPECT_EQ(taken.foldSeeThrough, -1);

  // `auto`: closed, nearly closed (with the test) and open; the hint only where the test left
  // the borders out.
  NormalOrientationResult rays;
  rays.closedSurface = true;
  FeatureCurveOptions chosen;
  chooseFoldBorders(chosen, rays);
  EXPECT_TRUE(chosen.foldBorders);
  EXPECT_EQ(chosen.foldSeeThroughShare, 0);
  rays.closedSurface = false;
  rays.openShare = 0.1;
  chooseFoldBorders(chosen, rays);
  EXPECT_TRUE(chosen.foldBorders);
  EXPECT_EQ(chosen.foldSeeThroughShare, kFoldSeeThroughShare);
  EXPECT_EQ(foldBordersHint(rays, thin, "on"), "");
  const std::string hint = foldBordersHint(rays, opening, "on");
  EXPECT_NE(hint.find("open at 10.0%"), std::string::npos) << hint;
  EXPECT_NE(hint.find("on makes them convex curves"), std::string::npos) << hint;
  rays.openShare = 0.3;
  chooseFoldBorders(chosen, rays);
  EXPECT_FALSE(chosen.foldBorders);
  EXPECT_EQ(chosen.foldSeeThroughShare, 0);
  EXPECT_EQ(foldBordersHint(rays, opening, "on"), "");
  rays.openShare = 0.1;
  chooseFoldBorders(chosen, rays);
  rays.closedSurface = true;
  chooseFoldBorders(chosen, rays);
  EXPECT_TRUE(chosen.foldBorders);
  EXPECT_EQ(chosen.foldSeeThroughShare, 0);
  // Asked to test and finding no border: nothing taken (a closed box with no border at all).
  RectangleSampler closedBox;
  addBox(closedBox, 3000, true);
  options.foldSeeThroughShare = kFoldSeeThroughShare;
  const FeatureCurveResult none = detectFeatureCurves(closedBox.cloud(), options);
  EXPECT_EQ(none.foldSeeThrough, -1);
  EXPECT_FALSE(none.foldsApplied);
  EXPECT_EQ(none.foldPoints, 0u);
}

TEST(FeatureCurves, InvalidOptionsAreRefused) {
  RectangleSampler s;
  addBox(s, 500, true);
  const PointCloud cloud = s.cloud();
  auto refused = [&](auto change, const char* field) {
    FeatureCurveOptions options;
    change(options);
    try {
      detectFeatureCurves(cloud, options);
      ADD_FAILURE() << field << " accepted";
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  refused([](auto& o) { o.spacing = -1; }, "FeatureCurveOptions::spacing");
  refused([](auto& o) { o.scaleCount = 0; }, "FeatureCurveOptions::scaleCount");
  refused([](auto& o) { o.scaleCount = 40; }, "FeatureCurveOptions::scaleCount");
  refused([](auto& o) { o.maxScaleFactor = 0.5; }, "FeatureCurveOptions::minScaleFactor");
  refused([](auto& o) { o.salientPercentile = 2; }, "FeatureCurveOptions::salientPercentile");
  refused([](auto& o) { o.voteThreshold = 1; }, "FeatureCurveOptions::voteThreshold");
  refused([](auto& o) { o.graphNeighbors = 0; }, "FeatureCurveOptions::graphNeighbors");
  refused([](auto& o) { o.centrelineReach = -1; }, "FeatureCurveOptions::centrelineReach");
  refused([](auto& o) { o.bandHalfWidth = 0; }, "FeatureCurveOptions::bandHalfWidth");
  refused([](auto& o) { o.centrelineLinearity = 2; }, "FeatureCurveOptions::centrelineLinearity");
  refused([](auto& o) { o.creaseReach = -1; }, "FeatureCurveOptions::creaseReach");
  refused([](auto& o) { o.creaseHalfWidth = 0; }, "FeatureCurveOptions::creaseHalfWidth");
  refused([](auto& o) { o.creaseFlatness = std::nan(""); }, "FeatureCurveOptions::creaseFlatness");
  refused([](auto& o) { o.creaseSideMargin = -1; }, "FeatureCurveOptions::creaseSideMargin");
  refused([](auto& o) { o.creaseSideNoise = std::nan(""); },
          "FeatureCurveOptions::creaseSideNoise");
  refused([](auto& o) { o.edgeRejoinAngle = 95; }, "FeatureCurveOptions::edgeRejoinAngle");
  // One scale cannot give the default 3 voting scales: the message names both fields and values.
  refused([](auto& o) { o.scaleCount = 1; },
          "FeatureCurveOptions::minVotingScales must be in [1, FeatureCurveOptions::scaleCount = "
          "1], got 3");
  refused([](auto& o) { o.lines.gamma = 0; }, "CurvatureLineOptions::gamma");
  // All points at one place: a clear error, not a division by zero.
  PointCloud same;
  same.setRelativePositions(std::vector<Vec3>(10, Vec3(1, 2, 3)), Vec3::Zero());
  same.setNormals(std::vector<Vec3>(10, Vec3::UnitZ()));
  EXPECT_THROW(detectFeatureCurves(same, FeatureCurveOptions{}), OptionError);
  // Three positions, each written 20 times: not "one position", and the way out named.
  std::vector<Vec3> repeated;
  for (int copy = 0; copy < 20; ++copy)
    for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}) repeated.push_back(p);
  PointCloud few;
  few.setRelativePositions(repeated, Vec3::Zero());
  few.setNormals(std::vector<Vec3>(repeated.size(), Vec3::UnitZ()));
  try {
    detectFeatureCurves(few, FeatureCurveOptions{});
    FAIL() << "a cloud of three repeated positions was analysed";
  } catch (const OptionError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("16 or more duplicates"), std::string::npos) << message;
    EXPECT_NE(message.find("FeatureCurveOptions::spacing"), std::string::npos) << message;
  }
}

namespace {

/// A house-shaped prism: the box [0,1]^3 without its bottom whose top is a gable roof, its ridge
/// along x at y = 0.5, the roof planes turning by `ridgeDegrees` at it.
PointCloud gableHouse(double ridgeDegrees, double density) {
  const double h = 0.5 * std::tan(0.5 * ridgeDegrees * kPi / 180);
  const auto roof = [h](double y) { return 1 + h * (1 - std::abs(2 * y - 1)); };
  RectangleSampler s;
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  s.add(Vec3(0, 0, 0), x, z, -y, density);
  s.add(Vec3(0, 1, 0), x, z, y, density);
  for (const double gable : {0.0, 1.0})
    s.add(Vec3(gable, 0, 0), y, (1 + h) * z, gable == 0 ? -x : x, density,
          [&](const Vec3& p) { return p.z() <= roof(p.y()); });
  s.add(Vec3(0, 0, 1), x, Vec3(0, 0.5, h), Vec3(0, -h, 0.5).normalized(), density);
  s.add(Vec3(0, 0.5, 1 + h), x, Vec3(0, 0.5, -h), Vec3(0, h, 0.5).normalized(), density);
  return s.cloud();
}

}  // namespace

// A 50-degree ridge beside 90-degree edges, which set K: the thesis' K per scale grows with t
// (K t 2.37 at t = e, 2.75 at 3 e) and leaves the ridge salient at the finest scales only, 73% of
// it labelled; with K from the finest scale (the default) the whole ridge is one convex curve.
TEST(FeatureCurves, AWeakRidgeBesideStrongEdgesIsFoundWithTheFinestScalesK) {
  const double degrees = 50, h = 0.5 * std::tan(0.5 * degrees * kPi / 180);
  const PointCloud cloud = gableHouse(degrees, 8000);
  const Edge ridge{Vec3(0, 0.5, 1 + h), Vec3(1, 0.5, 1 + h)};
  FeatureCurveOptions thesis;
  thesis.salientBoundFromFinest = false;
  thesis.salientBoundCap = 0;
  const FeatureCurveResult perScale = detectFeatureCurves(cloud, thesis);
  const FeatureCurveResult finest = detectFeatureCurves(cloud, FeatureCurveOptions{});
  ASSERT_TRUE(FeatureCurveOptions{}.salientBoundFromFinest);
  for (std::size_t s = 1; s < finest.scales.size(); ++s)
    EXPECT_NEAR(finest.scales[s].salientBound * finest.scales[s].scale,
                finest.scales[0].salientBound * finest.scales[0].scale, 1e-12);
  const EdgeLabels before =
      labelsAlong(cloud.positions(), perScale, ridge, 0.5 * perScale.spacing, 1);
  const EdgeLabels after = labelsAlong(cloud.positions(), finest, ridge, 0.5 * finest.spacing, 1);
  EXPECT_LT(before.fraction, 0.85);  // measured 0.73
  EXPECT_GT(after.fraction, 0.95);   // measured 1.00
  EXPECT_EQ(after.curves.size(), 1u);
  // The box's 90-degree eaves stay labelled convex.
  for (const double y : {0.0, 1.0}) {
    const Edge eave{Vec3(0, y, 1), Vec3(1, y, 1)};
    EXPECT_GT(labelsAlong(cloud.positions(), finest, eave, 0.5 * finest.spacing, 1).fraction, 0.95);
  }
}

// A 30-degree ridge beside 90-degree eaves: K t (1.23 at every scale), set by the eaves, keeps the
// ridge's |kappa1| t under the relative bound and none of it is labelled; salientBoundCap 0.7
// bounds it at what a 30-degree crease gives (measured: 1.00 of the ridge; 0.95 at 0.75, 0.62
// at 0.8). The box on the ground (above) keeps its 12 edges and no other curve with the cap: the
// concave flanks of its convex edges, |kappa1| t up to 1.7, are not across-line maxima.
TEST(FeatureCurves, ACappedSalientBoundFindsAWeakRidgeBesideStrongEdges) {
  const double degrees = 30, h = 0.5 * std::tan(0.5 * degrees * kPi / 180);
  const PointCloud cloud = gableHouse(degrees, 8000);
  const Edge ridge{Vec3(0, 0.5, 1 + h), Vec3(1, 0.5, 1 + h)};
  ASSERT_EQ(FeatureCurveOptions{}.salientBoundCap, 0.7);
  FeatureCurveOptions uncapped;
  uncapped.salientBoundCap = 0;
  const FeatureCurveResult relative = detectFeatureCurves(cloud, uncapped);
  const FeatureCurveResult withCap = detectFeatureCurves(cloud, FeatureCurveOptions{});
  for (std::size_t s = 0; s < withCap.scales.size(); ++s) {
    const FeatureCurveScale& scale = withCap.scales[s];
    EXPECT_GT(0.5 * scale.salientBound * scale.scale, 1.0);
    EXPECT_NEAR(scale.vertexBound * scale.scale, 0.7, 1e-12);
    EXPECT_NEAR(relative.scales[s].vertexBound, 0.5 * relative.scales[s].salientBound, 1e-12);
  }
  EXPECT_LT(labelsAlong(cloud.positions(), relative, ridge, 0.5 * relative.spacing, 1).fraction,
            0.1);
  const EdgeLabels found = labelsAlong(cloud.positions(), withCap, ridge, 0.5 * withCap.spacing, 1);
  EXPECT_GT(found.fraction, 0.95);
  EXPECT_EQ(found.curves.size(), 1u);
  for (const double y : {0.0, 1.0}) {
    const Edge eave{Vec3(0, y, 1), Vec3(1, y, 1)};
    EXPECT_GT(labelsAlong(cloud.positions(), withCap, eave, 0.5 * withCap.spacing, 1).fraction,
              0.95);
  }
  FeatureCurveOptions negative;
  negative.salientBoundCap = -1;
  EXPECT_THROW(detectFeatureCurves(cloud, negative), OptionError);
}

// A part thinner than its noise reads as one sheet: its rim has no crease for the lines, only
// a border. With foldBorders (a closed surface) the border is a convex curve; without (an open
// scan) it is where the sampling stops and nothing is labelled.
TEST(FeatureCurves, TheBordersOfASheetAreFoldsOnlyWhenAsked) {
  RectangleSampler s;
  s.add(Vec3(0, 0, 0), Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), 8000);
  std::normal_distribution<double> noise(0, 0.002);
  for (Vec3& p : s.positions) p.z() += noise(s.random);
  const PointCloud cloud = s.cloud();
  const FeatureCurveResult off = detectFeatureCurves(cloud, FeatureCurveOptions{});
  EXPECT_EQ(off.foldPoints, 0u);
  EXPECT_TRUE(off.curves.empty());
  FeatureCurveOptions folds;
  folds.foldBorders = true;
  const FeatureCurveResult on = detectFeatureCurves(cloud, folds);
  const double e = on.spacing;
  EXPECT_GT(on.foldPoints, 0u);
  std::size_t rim = 0, rimConvex = 0, inside = 0, insideLabelled = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.positions()[i];
    const double toBorder = std::min({p.x(), 1 - p.x(), p.y(), 1 - p.y()});
    if (toBorder < 0.5 * e) {
      ++rim;
      rimConvex += on.curveId[i] >= 0 && on.convexity[i] == 1;
    } else if (toBorder > 2.5 * e) {
      ++inside;
      insideLabelled += on.curveId[i] >= 0;
    }
  }
  EXPECT_GT(double(rimConvex), 0.9 * double(rim));
  EXPECT_EQ(insideLabelled, 0u);
  // The four sides meet at the corners: one curve around the sheet, about 4 long.
  ASSERT_EQ(on.curves.size(), 1u);
  EXPECT_EQ(on.curves[0].convexity, 1);
  EXPECT_NEAR(on.curves[0].length, 4.0, 0.6);
  // The same labels for any thread count.
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(detectFeatureCurves(cloud, folds).curveId, on.curveId);
  }
  folds.foldReach = 0;
  EXPECT_THROW(detectFeatureCurves(cloud, folds), OptionError);
  folds.foldReach = 3;
  folds.foldBorderShare = 1.5;
  EXPECT_THROW(detectFeatureCurves(cloud, folds), OptionError);
  folds.foldBorderShare = 0.25;
  folds.foldSeeThroughShare = 1.5;
  EXPECT_THROW(detectFeatureCurves(cloud, folds), OptionError);
  folds.foldSeeThroughShare = 0.5;
  folds.foldRayCell = 0;
  EXPECT_THROW(detectFeatureCurves(cloud, folds), OptionError);
}

// A plate thicker than the spacing inside but thinner at its rim, its faces sloping by 10 degrees
// towards it (libcgal-demo's blade): the planes of the faces near the rim meet beyond it, so no
// crease line is found there, and the band is trimmed to the sheet within creaseHalfWidth e of
// its outermost points instead of to the salient vertices' centreline, which the APSS rounding
// the rim puts inside it.
TEST(FeatureCurves, TheBandOfAThinRimEndsAtItsOutermostPoints) {
  const double rimHalf = 0.002, slope = std::tan(10 * M_PI / 180);
  std::mt19937_64 random(29);
  std::uniform_real_distribution<double> uniform(0, 1), across(-1, 1);
  std::vector<Vec3> positions, normals;
  for (int i = 0; i < 16000; ++i) {
    const double px = uniform(random), py = uniform(random), side = i % 2 ? 1.0 : -1.0;
    const double toX = std::min(px, 1 - px), toY = std::min(py, 1 - py);
    // The face slopes down towards the nearer side of the square.
    const Vec3 out = toX < toY ? Vec3(px < 0.5 ? -1 : 1, 0, 0) : Vec3(0, py < 0.5 ? -1 : 1, 0);
    positions.emplace_back(px, py, side * (rimHalf + slope * std::min(toX, toY)));
    normals.push_back((Vec3(0, 0, side) + slope * out).normalized());
  }
  for (int i = 0; i < 400; ++i) {  // the rim itself, a strip 2 rimHalf wide
    const double t = uniform(random), zz = rimHalf * across(random);
    const int k = i % 4;
    const Vec3 p = k == 0   ? Vec3(t, 0, zz)
                   : k == 1 ? Vec3(t, 1, zz)
                   : k == 2 ? Vec3(0, t, zz)
                            : Vec3(1, t, zz);
    positions.push_back(p);
    normals.push_back(k == 0   ? Vec3(0, -1, 0)
                      : k == 1 ? Vec3(0, 1, 0)
                      : k == 2 ? Vec3(-1, 0, 0)
                               : Vec3(1, 0, 0));
  }
  PointCloud cloud;
  cloud.setRelativePositions(positions, Vec3::Zero());
  cloud.setNormals(normals);
  const FeatureCurveResult rim = detectFeatureCurves(cloud, FeatureCurveOptions{});
  FeatureCurveOptions centreline;
  centreline.rimLines = false;
  const FeatureCurveResult trimmed = detectFeatureCurves(cloud, centreline);
  const double e = rim.spacing;
  ASSERT_GT(e, 4 * rimHalf) << "the rim is thinner than the spacing";
  // Of the points labelled away from the corners, the share farther than `reach` from the border;
  // of the points within 0.9 e of it, the share labelled convex.
  auto toBorder = [](const Vec3& p) { return std::min({p.x(), 1 - p.x(), p.y(), 1 - p.y()}); };
  auto nearCorner = [&](const Vec3& p) {
    return std::min(p.x(), 1 - p.x()) + std::min(p.y(), 1 - p.y()) < 4 * e;
  };
  auto beyond = [&](const FeatureCurveResult& r, double reach) {
    std::size_t count = 0, labelled = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec3& p = cloud.positions()[i];
      if (r.curveId[i] < 0 || nearCorner(p)) continue;
      ++labelled;
      count += toBorder(p) > reach;
    }
    return double(count) / double(std::max<std::size_t>(labelled, 1));
  };
  auto recall = [&](const FeatureCurveResult& r) {
    std::size_t near = 0, convex = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec3& p = cloud.positions()[i];
      if (toBorder(p) > 0.9 * e || nearCorner(p)) continue;
      ++near;
      convex += r.curveId[i] >= 0 && r.convexity[i] == 1;
    }
    return double(convex) / double(std::max<std::size_t>(near, 1));
  };
  EXPECT_GT(recall(rim), 0.95);
  EXPECT_GT(recall(trimmed), 0.95);
  // The centreline keeps 8% of the band beyond e of the border; the rim line (measured: 0.1%)
  // keeps a point or two where the outermost sample lies a little inside the border.
  EXPECT_GT(beyond(trimmed, e), 0.04) << "the centreline lies inside the rim";
  EXPECT_LT(beyond(rim, e), 0.005) << beyond(trimmed, e);
}
