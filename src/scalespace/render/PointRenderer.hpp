#pragma once
// Software point renderer: orthographic projection, round splats and a z-buffer, no GPU and no
// window. Used by `scalespace render` and for figures of the plane components.
#include <string>
#include <vector>

#include "scalespace/core/PointCloud.hpp"
#include "scalespace/render/Image.hpp"

namespace scalespace {

constexpr int kMaxPointRadius = 32;

struct RenderOptions {
  int width = 1024;
  int height = 768;
  /// "front" (looking along +y), "top" (along -z), "iso" (along (-1,1,-1)) or "X,Y,Z": the
  /// direction the camera looks along, for the default up axis +z. Up is `up` (or the axis
  /// "front" looks along, when looking along `up`).
  std::string view = "iso";
  /// The cloud's up axis: "z" (default), "y" (many scanners and mesh formats), "x", or one of
  /// them negated ("-y"). The named views turn with it: "top" looks down it, "front" along the
  /// next axis after it (y for z, x for y, z for x; negated with a negated up axis).
  std::string up = "z";
  /// Colour source, first match wins: `colors` (one per point), `labelAttribute` (distinct hues,
  /// -1 grey), `colorAttribute` (viridis over the 2nd-98th percentile; x, y, z = coordinates), the
  /// cloud's red/green/blue columns, else light grey.
  std::vector<Rgb> colors;
  std::string labelAttribute;
  std::string colorAttribute;
  /// Splat radius in pixels; negative = automatic from the point density on screen. Larger than
  /// kMaxPointRadius draws with kMaxPointRadius.
  int pointRadius = -1;
  /// Headlight shading |n . view| when the cloud has normals.
  bool shading = true;
  Rgb background{255, 255, 255};
  double margin = 0.05;  // fraction of the image left free around the framed bounding box
};

/// The right-handed frame of an up axis name: up, and the two horizontal axes (side, ahead) with
/// side x ahead = up ("z": x, y, z). Throws OptionError for a name other than [-]x, [-]y, [-]z.
struct UpFrame {
  Vec3 side, ahead, up;
};
UpFrame upFrame(const std::string& up);

/// Unit viewing direction for a view name (in the frame of `up`) or "X,Y,Z" (as given); throws
/// OptionError for anything else.
Vec3 viewDirection(const std::string& view, const std::string& up = "z");

/// Renders the cloud framed on its bounding box. Throws OptionError for a bad size, view or
/// attribute name.
Image renderPoints(const PointCloud& cloud, const RenderOptions& options);

/// The per-point colours renderPoints would use (before shading).
std::vector<Rgb> pointColors(const PointCloud& cloud, const RenderOptions& options);

}  // namespace scalespace
