#pragma once
// Synthetic piecewise-planar scenes of the thesis (Table 2.1: Tri, Stairs, Cubes) plus a plain box,
// and two building-like scenes in metres (House, Yard) with details a few centimetres deep on large
// planes and structures standing on the ground, sampled uniformly by area with exact outward
// normals, a ground-truth face label per point (integer attribute column "gt_face"), a ground-truth
// group label where the scene has coarse structures made of several faces ("gt_group") and
// optional Gaussian noise (Fig. 2.14).
#include <cstdint>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace {

enum class SceneKind {
  Tri,     // a ground square carrying a triangular prism ("roof"): ground, 2 slopes, 2 gables
  Stairs,  // a staircase: alternating treads and risers along a mean ramp of 45 degrees
  Cubes,   // nested cubes on cubes: four levels, each cube half the size of the one below
  Box,     // the six faces of an axis-aligned box (tests)
  /// Ground 14 x 10 m carrying a house 8 x 6 m, walls 3 m with 10 windows recessed 6 cm (pane and
  /// four reveals each), a gable roof (ridge 2 m above the eaves) whose -y side carries 6 x 4
  /// tiles 0.8 x 0.5 m raised 2.5 cm (top and four sides each), and a straight staircase of 10
  /// steps (0.3 m deep, 0.18 m high, 1.2 m wide) on the ground. Groups: 0 = the tiled roof side
  /// (roof plane, tile tops and tile sides), 1 = the staircase's treads and risers (its mean ramp).
  House,
  /// Ground 10 x 8 m carrying a ramp (3 m rising 0.6 m), a low wall (6 x 0.25 x 0.8 m), three boxes
  /// and a staircase of 4 steps (0.3 m deep, 0.2 m high, 1 m wide). Group 0 = the staircase's
  /// treads and risers.
  Yard
};

/// "tri" | "stairs" | "cubes" | "box" | "house" | "yard" -> kind; throws OptionError naming the
/// accepted values.
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
/// Faces hidden by the scene (a box's bottom on the ground, a tile's underside on the roof) are not
/// faces: the ground or roof face has a hole there instead.
struct SceneFace {
  int label = 0;
  int group = -1;  // coarse structure made of several faces (sceneGroupNames), -1 for none
  Vec3 normal = Vec3::UnitZ();
  std::vector<Vec3> triangles;  // 3 vertices per triangle
  double area() const;
};

/// The exact faces of a scene (what the samples are drawn from); the labels are 0..n-1.
std::vector<SceneFace> sceneFaces(SceneKind kind, const SceneOptions& options = {});

/// Names of the groups of a scene, by group id (empty for the Table 2.1 scenes and Box).
std::vector<std::string> sceneGroupNames(SceneKind kind);

/// Samples `options.pointCount` points uniformly by area over the faces: positions (noisy if
/// options.noise > 0), exact normals of the face each point was drawn from, "gt_face" (int32) and,
/// for scenes with groups, "gt_group" (int32, the face's group or -1). Deterministic for a given
/// seed; the Table 2.1 scenes and Box have no "gt_group" column, so their output is the same as
/// before the groups existed.
PointCloud generateScene(SceneKind kind, const SceneOptions& options = {});

}  // namespace scalespace
