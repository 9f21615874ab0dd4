#pragma once
// A pipe-rack scene in metres with ground truth, for the cylinders of Sec. 3.5: straight tubes of
// radii 0.03, 0.1 and 0.35 m (ratio > 10), a bent pipe (radius 0.12 m) (straight, a 90-degree elbow
// of torus, straight), a tapering pipe (cone), a cable of three strands twisted around a common
// axis (three thin tubes at a small scale, one thick tube at a large one), and what must not become
// a cylinder: a floor, a wall and a box standing on the floor. Sampled uniformly by area with exact
// outward normals. The cable's strands hide each other: a full scan has no point that every line
// of sight within 50 degrees of its normal leaves blocked by another strand (the channel between
// them, the bottoms of their grooves), a one-sided scan none whose line to its scanner is.
//
// Columns: "gt_pipe" (int32: PipeTruth::id, -1 on the floor, wall and box) and "gt_part" (int32:
// for the bent pipe 0 / 1 / 2 = first straight / elbow / second straight, for the cable the strand
// 0..2, else -1).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"

namespace scalespace {

/// Rack: the pipe rack above. Poles: four vertical poles standing on an 8 x 8 m floor (radius
/// 0.05, 0.2, 0.5 and 0.12 m, 1.5-3 m tall; the 0.5 m one seen over 4 rad of azimuth only, its
/// south side, a half pole; each lacking a band 0.8-1 m high over 2 rad, a scanner's shadow) and a
/// box 1 x 0.6 x 0.8 m, whose edges a coarse scale rounds into tubes that must not be taken for
/// cylinders.
enum class PipeLayout { Rack, Poles };

struct PipeSceneOptions {
  PipeLayout layout = PipeLayout::Rack;
  std::size_t pointCount = 200000;
  /// Standard deviation of the isotropic Gaussian positional noise as a fraction of the
  /// bounding-box diagonal (about 6.7 m for the rack, 12 m for the poles).
  double noise = 0.0;
  std::uint64_t seed = 1;
  /// Keep only what a scanner sees (normals facing oneSidedScanner, which the cloud's viewpoint()
  /// holds): every pipe is seen from one side, a half-pipe (the other pipes do not hide each
  /// other; the cable's strands do).
  bool oneSided = false;
  /// Unset: the layout's own, above and in front of the rack (1.3, -2.2, 4.8), or a tripod south
  /// of the poles' floor (0, -5, 1.6), facing the half pole's seen side.
  std::optional<Vec3> oneSidedScanner;
};

enum class PipeKind { Straight, Bent, Tapering, Cable };

/// A pipe of the scene, for scoring.
struct PipeTruth {
  int id = 0;
  std::string name;
  PipeKind kind = PipeKind::Straight;
  double radius = 0;        // Straight, Bent, Cable (envelope: strand radius + helix radius)
  double radiusEnd = 0;     // Tapering: radius at the far end (radius at axisPoint)
  double strandRadius = 0;  // Cable
  Vec3 axisPoint = Vec3::Zero(), axisDirection = Vec3::UnitX();  // Straight, Tapering, Cable
  double length = 0;                                             // along the axis
};

/// The pipes of the scene, by id.
std::vector<PipeTruth> pipeSceneTruth(PipeLayout layout = PipeLayout::Rack);

/// Throws OptionError for a zero point count or negative noise.
PointCloud generatePipeScene(const PipeSceneOptions& options = {});

}  // namespace scalespace
