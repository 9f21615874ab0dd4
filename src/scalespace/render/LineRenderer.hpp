#pragma once
// Lines drawn over a point rendering (curvature lines, feature curves): segments rasterised in
// the rendering's camera, depth-tested against the splats already drawn.
//
// Lines traced on a surface lie on it, among its splats, and a splat is a flat disc at its
// centre's depth: where the surface is seen at an angle, the disc in front of a line vertex is
// nearer than the vertex by up to its radius. A segment pixel is therefore drawn unless the depth
// buffer holds something nearer by more than a tolerance of a few splat radii (in pixels' worth
// of depth); a surface farther in front of the line still hides it.
#include <string>
#include <vector>

#include "scalespace/io/Polylines.hpp"
#include "scalespace/render/Image.hpp"
#include "scalespace/render/PointRenderer.hpp"

namespace scalespace {

/// One segment in absolute coordinates, with the colour at each end (interpolated between).
struct Segment {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  Rgb colorA, colorB;
};

struct LineRenderOptions {
  /// Solid colour of every line, unless colorAttribute is set.
  Rgb color{230, 25, 25};
  /// Colour by this vertex attribute: viridis over its 2nd-98th percentile, as the points'
  /// --color (x, y, z = the coordinates when there is no column of that name).
  std::string colorAttribute;
  /// Half-width in pixels: 0 draws 1-pixel lines. At most kMaxPointRadius.
  int lineRadius = 1;
  /// Depth tolerance in pixels (see the file comment); negative = 2 * pointRadius + 2 of the
  /// rendering drawn into.
  double depthTolerance = -1;
};

/// The colour of each vertex of `lines` under `options`. Throws OptionError naming
/// LineRenderOptions::colorAttribute when the vertices have no such column.
std::vector<Rgb> polylineColors(const PolylineSet& lines, const LineRenderOptions& options);

/// Draws `segments` into `target` (its image, depth buffer and camera), each pixel of a segment
/// at the segment's depth there; drawn pixels take the nearer depth. Parts outside the image are
/// clipped; segments with a non-finite end are skipped. Throws OptionError for a lineRadius
/// outside [0, kMaxPointRadius].
void drawSegments(Rendering& target, const std::vector<Segment>& segments,
                  const LineRenderOptions& options);

/// Draws every segment of `lines` (closing segments of closed lines included) with
/// polylineColors. Throws OptionError as polylineColors, drawSegments and validatePolylineSet.
void drawPolylines(Rendering& target, const PolylineSet& lines, const LineRenderOptions& options);

}  // namespace scalespace
