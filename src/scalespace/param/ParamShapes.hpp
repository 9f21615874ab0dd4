#pragma once
// The shapes with known answers of the parametrization benchmark (Chapter 4): surfaces of disk
// topology (a map onto a plane exists), of sphere topology (a map onto the sphere exists), an
// annulus and a torus (genus 1: neither exists without a cut, the map must be flagged).
//
// Each shape is a triangle mesh built on a grid of its parameter domain (what a mesh
// parametrizer, the peer of the benchmark, runs on) with exact vertex normals from the
// parametric map; the point cloud is drawn uniformly by area on that mesh (io/MeshSampling), so
// the cloud and the peer's mesh describe the same surface.
#include <cstdint>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/io/MeshFormat.hpp"

namespace scalespace {

enum class ParamShape {
  BumpyDisk,      // unit disk, height field of bumps 0.1 high            (disk)
  Hemisphere,     // unit half sphere                                      (disk)
  Relief,         // square 2 x 2 carrying a bump, a ridge and a valley    (disk)
  HoledSheet,     // wavy square 2 x 2 with two round holes                (disk, 3 boundaries)
  PartialSphere,  // 75% of a unit sphere seen by a scanner, one occlusion hole (disk, 2 bdries)
  Triaxial,       // ellipsoid of semi-axes 1 : 1.5 : 2                    (sphere)
  Blob,           // star-shaped bumpy blob                                (sphere)
  RoundedCube,    // superquadric |x|^8 + |y|^8 + |z|^8 = 1                (sphere)
  Tube,           // cylinder radius 0.5, height 2, open at both ends       (annulus)
  Torus           // major radius 1, minor 0.35                             (genus 1)
};

/// "bumpy-disk", "hemisphere", "relief", "holed-sheet", "partial-sphere", "triaxial", "blob",
/// "rounded-cube", "tube", "ring"; parse throws OptionError naming the accepted values. (The
/// torus is "ring": `generate torus` is the analytic torus of Chapter 1.)
const char* paramShapeName(ParamShape shape);
ParamShape parseParamShape(const std::string& name);
/// Whether `name` is one of the names above.
bool isParamShapeName(const std::string& name);
std::vector<ParamShape> allParamShapes();

enum class ParamTopology { Disk, Sphere, Annulus, Torus };
ParamTopology paramShapeTopology(ParamShape shape);
const char* paramTopologyName(ParamTopology topology);

/// The shape's mesh on a grid of `resolution` cells along each parameter (per cube face for the
/// closed shapes), with exact unit vertex normals (outward for closed shapes, +z side for the
/// open ones). Throws OptionError unless 4 <= resolution <= 4096.
TriangleMesh paramShapeMesh(ParamShape shape, int resolution);

struct ParamShapeOptions {
  std::size_t pointCount = 100000;
  /// Standard deviation of the Gaussian position noise as a fraction of the bounding-box
  /// diagonal (the noisy variant: 1e-3). Normals stay exact.
  double noise = 0;
  std::uint64_t seed = 1;
  /// Grid cells per parameter of the generating mesh; 0 picks one fine enough that the mesh's
  /// facets are far below the point spacing (at most 1024).
  int resolution = 0;
};

/// Points drawn uniformly by area on paramShapeMesh, normals interpolated from the exact vertex
/// normals. Throws OptionError for a zero count, negative or non-finite noise.
PointCloud generateParamShape(ParamShape shape, const ParamShapeOptions& options = {});

}  // namespace scalespace
