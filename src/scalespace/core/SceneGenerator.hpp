#pragma once
// Synthetic piecewise-planar scenes of the thesis (Table 2.1: Tri, Stairs, Cubes) plus a plain box,
// sampled uniformly by area with exact outward normals, a ground-truth face label per point
// (integer attribute column "gt_face") and optional Gaussian noise (Fig. 2.14).
#include <cstdint>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace {

enum class SceneKind {
  Tri,     // a ground square carrying a triangular prism ("roof"): ground, 2 slopes, 2 gables
  Stairs,  // a staircase: alternating treads and risers along a mean ramp of 45 degrees
  Cubes,   // nested cubes on cubes: four levels, each cube half the size of the one below
  Box      // the six faces of an axis-aligned box (tests)
};

/// "tri" | "stairs" | "cubes" | "box" -> kind; throws OptionError naming the accepted values.
SceneKind sceneKindFromName(const std::string& name);
const char* sceneKindName(SceneKind kind);

struct SceneOptions {
  std::size_t pointCount = 100000;
  /// Standard deviation of the isotropic Gaussian positional noise as a fraction of the
  /// bounding-box diagonal (Fig. 2.14 uses 1, 5, 10 and 25 x 1e-5). 0 = exact samples.
  double noise = 0.0;
  std::uint64_t seed = 1;
  int stairSteps = 8;           // Stairs: number of steps
  int cubeLevels = 4;           // Cubes: nesting levels (Sec. 2.5.1: four)
  Vec3 boxSize{1.0, 1.0, 1.0};  // Box: edge lengths
};

/// One planar face of a scene: a set of triangles sharing the outward normal and the label.
struct SceneFace {
  int label = 0;
  Vec3 normal = Vec3::UnitZ();
  std::vector<Vec3> triangles;  // 3 vertices per triangle
  double area() const;
};

/// The exact faces of a scene (what the samples are drawn from); the labels are 0..n-1.
std::vector<SceneFace> sceneFaces(SceneKind kind, const SceneOptions& options = {});

/// Samples `options.pointCount` points uniformly by area over the faces: positions (noisy if
/// options.noise > 0), exact normals of the face each point was drawn from, and "gt_face" (int32).
/// Deterministic for a given seed.
PointCloud generateScene(SceneKind kind, const SceneOptions& options = {});

}  // namespace scalespace
