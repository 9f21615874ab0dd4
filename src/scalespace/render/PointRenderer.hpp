#pragma once
// Software point renderer: orthographic projection, round splats and a z-buffer, no GPU and no
// window. Used by `scalespace render` and for figures of the plane components.
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/render/Image.hpp"

namespace scalespace {

struct RenderOptions {
  int width = 1024;
  int height = 768;
  /// "front" (looking along +y), "top" (along -z), "iso" (along (-1,1,-1)) or "X,Y,Z": the
  /// direction the camera looks along. Up is +z (or +y when looking along z).
  std::string view = "iso";
  /// Colour source, first match wins: `colors` (one per point), `labelAttribute` (distinct hues,
  /// -1 grey), `colorAttribute` (viridis over the 2nd-98th percentile; x, y, z = coordinates), the
  /// cloud's red/green/blue columns, else light grey.
  std::vector<Rgb> colors;
  std::string labelAttribute;
  std::string colorAttribute;
  /// Splat radius in pixels; negative = automatic from the point density on screen.
  int pointRadius = -1;
  /// Headlight shading |n . view| when the cloud has normals.
  bool shading = true;
  Rgb background{255, 255, 255};
  double margin = 0.05;  // fraction of the image left free around the framed bounding box
};

/// Unit viewing direction for a view name or "X,Y,Z"; throws OptionError for anything else.
Vec3 viewDirection(const std::string& view);

/// Renders the cloud framed on its bounding box. Throws OptionError for a bad size, view or
/// attribute name.
Image renderPoints(const PointCloud& cloud, const RenderOptions& options);

/// The per-point colours renderPoints would use (before shading).
std::vector<Rgb> pointColors(const PointCloud& cloud, const RenderOptions& options);

}  // namespace scalespace
