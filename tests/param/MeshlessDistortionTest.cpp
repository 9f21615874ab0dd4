// The meshless distortion of Sec. 4.4 and the fold / overlap checks on maps with known answers:
// an isometry (no distortion), a stretch (eps_conf = the stretch, areas uniform), a fold, an
// overlap.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <random>
#include <set>

#include "scalespace/core/Error.hpp"
#include "scalespace/param/MapDefects.hpp"
#include "scalespace/param/MeshlessDistortion.hpp"
#include "scalespace/param/ParamShapes.hpp"

using namespace scalespace;

namespace {

/// A jittered grid of the unit square in the plane z = 0 (normals +z).
std::vector<Vec3> square(int side) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<Vec3> points;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i)
      points.emplace_back((i + jitter(rng)) / side, (j + jitter(rng)) / side, 0);
  return points;
}

DomainMap planeMap(const std::vector<Vec3>& points, const std::function<Vec2(const Vec3&)>& f) {
  std::vector<Vec2> uv;
  for (const Vec3& p : points) uv.push_back(f(p));
  return domainFromCoordinates(uv, {});
}

/// Median of the values of points away from the square's border (the neighbourhoods there are
/// one-sided, which the measure reads as anisotropy of both ellipses alike).
std::vector<float> interior(const std::vector<Vec3>& points, const std::vector<float>& values) {
  std::vector<float> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].x() > 0.2 && points[i].x() < 0.8 && points[i].y() > 0.2 && points[i].y() < 0.8)
      out.push_back(values[i]);
  return out;
}

}  // namespace

TEST(MeshlessDistortion, AnIsometryHasNone) {
  const std::vector<Vec3> points = square(60);
  const std::vector<Vec3> normals(points.size(), Vec3::UnitZ());
  // A rotation and a translation: every ellipse the same in 3D and in the domain.
  const DomainMap map = planeMap(points, [](const Vec3& p) {
    return Vec2(0.6 * p.x() - 0.8 * p.y() + 5, 0.8 * p.x() + 0.6 * p.y() - 2);
  });
  const DistortionResult d = measureDistortion(points, normals, map);
  ASSERT_EQ(d.sizes.size(), 3u);
  for (const DistortionAtSize& s : d.sizes) {
    SCOPED_TRACE(s.neighbors);
    EXPECT_NEAR(s.areaFactor, 1, 1e-9);
    EXPECT_NEAR(s.medianConformal, 1, 1e-6);
    EXPECT_NEAR(s.p90Authalic, 1, 1e-6);
    EXPECT_EQ(s.undetermined, 0u);
  }
  const MapDefects defects = findMapDefects(points, normals, map);
  EXPECT_EQ(defects.folds + defects.overlaps + defects.undetermined, 0u);
  EXPECT_NEAR(defects.localScale[100], 1, 1e-6);
  EXPECT_NEAR(defects.medianStretch, 1, 1e-6);
  EXPECT_NEAR(defects.p90Stretch, 1, 1e-6);
}

TEST(MeshlessDistortion, AStretchIsConformalDistortionOnly) {
  const std::vector<Vec3> points = square(60);
  const std::vector<Vec3> normals(points.size(), Vec3::UnitZ());
  // u = 2x: circles become ellipses twice as long (eps_conf = 2); areas double everywhere,
  // which the global area factor absorbs (eps_auth = 1).
  const DomainMap map = planeMap(points, [](const Vec3& p) { return Vec2(2 * p.x(), p.y()); });
  const DistortionResult d = measureDistortion(points, normals, map, DistortionOptions{{32}});
  const DistortionAtSize& s = d.sizes[0];
  EXPECT_NEAR(s.areaFactor, 0.5, 1e-6);
  const std::vector<float> conf = interior(points, s.conformal);
  const std::vector<float> auth = interior(points, s.authalic);
  // Eq. 4.3 compares anisotropies, not maps: where the 3D neighbourhood is itself slightly
  // anisotropic and not aligned with the stretch, it reads less than 2 (docs/THESIS_NOTES.md).
  EXPECT_NEAR(positiveQuantile(conf, 0.5), 2, 0.1);
  EXPECT_GT(positiveQuantile(conf, 0.1), 1.6);
  EXPECT_LT(positiveQuantile(conf, 0.9), 2.4);
  EXPECT_NEAR(positiveQuantile(auth, 0.9), 1, 1e-6);
  // The local maps' singular values read the stretch exactly, everywhere (borders included):
  // the least-squares linear map of a linear map is that map.
  const MapDefects stretched = findMapDefects(points, normals, map);
  EXPECT_EQ(stretched.undetermined, 0u);
  for (const float r : stretched.stretch) ASSERT_NEAR(r, 2, 1e-5);
  EXPECT_NEAR(stretched.medianStretch, 2, 1e-5);
  // A mirror is no fold: every local map flips alike.
  const DomainMap mirror = planeMap(points, [](const Vec3& p) { return Vec2(-p.x(), p.y()); });
  const MapDefects defects = findMapDefects(points, normals, mirror);
  EXPECT_EQ(defects.folds + defects.overlaps, 0u);
  EXPECT_EQ(defects.majoritySign, -1);
}

TEST(MeshlessDistortion, AFoldAndAnOverlapAreFlagged) {
  const std::vector<Vec3> points = square(60);
  const std::vector<Vec3> normals(points.size(), Vec3::UnitZ());
  // u = x up to 0.7, then back: the strip x > 0.7 is mirrored (a fold) and lands on 0.4..0.7
  // (an overlap).
  const DomainMap folded = planeMap(
      points, [](const Vec3& p) { return Vec2(p.x() < 0.7 ? p.x() : 1.4 - p.x(), p.y()); });
  const MapDefects d = findMapDefects(points, normals, folded);
  std::size_t strip = 0, foldsInStrip = 0, foldsOutside = 0, overlapsFar = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].x();
    if (x > 0.75) {
      ++strip;
      foldsInStrip += d.fold[i];
    } else if (x < 0.65) {
      foldsOutside += d.fold[i];
    }
    if (x < 0.3) overlapsFar += d.overlap[i];  // nothing lands on x < 0.4
  }
  EXPECT_GT(foldsInStrip, strip * 9 / 10);
  EXPECT_EQ(foldsOutside, 0u);
  EXPECT_GT(d.overlaps, strip / 2);
  EXPECT_EQ(overlapsFar, 0u);
}

TEST(MeshlessDistortion, BadInputsAreRejected) {
  const std::vector<Vec3> points = square(10);
  const DomainMap map = planeMap(points, [](const Vec3& p) { return Vec2(p.x(), p.y()); });
  EXPECT_THROW(measureDistortion(points, {}, map, DistortionOptions{{}}), OptionError);
  EXPECT_THROW(measureDistortion(points, {}, map, DistortionOptions{{2}}), OptionError);
  EXPECT_THROW(measureDistortion(points, {}, map, DistortionOptions{{100000}}), OptionError);
  const std::vector<Vec3> fewer(points.begin(), points.begin() + 50);
  EXPECT_THROW(measureDistortion(fewer, {}, map), OptionError);
  EXPECT_THROW(findMapDefects(fewer, {}, map), OptionError);
  EXPECT_THROW(domainFromCoordinates({Vec2(0, NAN)}, {}), OptionError);
  EXPECT_THROW(domainFromCoordinates({}, {Vec3::Zero()}), OptionError);
  EXPECT_THROW(domainFromCoordinates({}, {}), OptionError);
  // Without normals the tangent planes come from the neighbours: same answer on a plane.
  const DistortionResult d = measureDistortion(points, {}, map, DistortionOptions{{8}});
  EXPECT_NEAR(d.sizes[0].medianConformal, 1, 1e-6);
  // Every point equal: no ellipse anywhere, no crash.
  const std::vector<Vec3> same(20, Vec3(1, 1, 1));
  const DomainMap sameMap = domainFromCoordinates(std::vector<Vec2>(20, Vec2(0, 0)), {});
  const DistortionResult none = measureDistortion(same, {}, sameMap, DistortionOptions{{8}});
  EXPECT_EQ(none.sizes[0].undetermined, 20u);
  EXPECT_EQ(findMapDefects(same, {}, sameMap).undetermined, 20u);
}

TEST(ParamShapes, MeshesHaveTheirTopology) {
  // Euler characteristic V - E + F: a disk 1, an annulus and a torus 0 (grid meshes share
  // their vertices; the closed star shapes are six separate faces and are not checked).
  auto euler = [](const TriangleMesh& m) {
    std::set<std::pair<Index, Index>> edges;
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k)
        edges.insert(std::minmax(t[std::size_t(k)], t[std::size_t((k + 1) % 3)]));
    return long(m.vertices.size()) - long(edges.size()) + long(m.triangles.size());
  };
  EXPECT_EQ(euler(paramShapeMesh(ParamShape::BumpyDisk, 40)), 1);
  EXPECT_EQ(euler(paramShapeMesh(ParamShape::Tube, 40)), 0);
  EXPECT_EQ(euler(paramShapeMesh(ParamShape::Torus, 40)), 0);
  EXPECT_EQ(euler(paramShapeMesh(ParamShape::HoledSheet, 80)), -1);  // two holes
  // A hemisphere of radius 1 has area 2 pi, less the rim the grid's jagged border leaves out.
  const TriangleMesh h = paramShapeMesh(ParamShape::Hemisphere, 200);
  double area = 0;
  for (const auto& t : h.triangles)
    area += 0.5 *
            (h.vertices[t[1]] - h.vertices[t[0]]).cross(h.vertices[t[2]] - h.vertices[t[0]]).norm();
  EXPECT_NEAR(area, 2 * 3.14159265358979, 0.08);
  EXPECT_THROW(paramShapeMesh(ParamShape::Blob, 2), OptionError);
  EXPECT_THROW(parseParamShape("donut"), OptionError);
  EXPECT_EQ(parseParamShape(paramShapeName(ParamShape::Torus)), ParamShape::Torus);
}
