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
  /// Two attribute names (e.g. "u", "v" of a parametrization): the colours above are darkened
  /// on alternate cells of a grid over these two values, `checkerCells` cells across the larger
  /// of their 2nd-98th percentile ranges: a checkerboard shows how a map bends angles and areas.
  std::vector<std::string> checkerAttributes;
  int checkerCells = 12;
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

/// The orthographic camera renderPoints frames a cloud with: screen axes `right` and `up`,
/// `forward` the viewing direction, all in the cloud's frame (positions relative to `origin`).
struct ScreenFrame {
  Vec3 right = Vec3::UnitX(), up = Vec3::UnitZ(), forward = Vec3::UnitY();
  Vec3 origin = Vec3::Zero();  // the framed cloud's origin()
  double scale = 1.0;          // pixels per unit length
  double centreX = 0, centreY = 0;
  int width = 0, height = 0;
  double boxWidth = 0, boxHeight = 0;  // the framed bounding box on screen, in pixels
  /// Pixel coordinates (x right, y down; pixel (i, j) covers [i, i + 1) x [j, j + 1)) and depth
  /// (smaller = nearer) of a position relative to `origin`.
  Vec3 project(const Vec3& relative) const {
    return {0.5 * width + (relative.dot(right) - centreX) * scale,
            0.5 * height - (relative.dot(up) - centreY) * scale, relative.dot(forward)};
  }
};

/// The camera for `cloud`: its bounding box, projected, fills the image minus the margin. Throws
/// OptionError for a bad size, margin or view.
ScreenFrame frameCloud(const PointCloud& cloud, const RenderOptions& options);

/// An image with its depth buffer and camera, so that more can be drawn over the points (lines:
/// render/LineRenderer.hpp) with the depth test.
struct Rendering {
  Image image;
  std::vector<float> depth;  // per pixel, +infinity where nothing was drawn
  ScreenFrame frame;
  int pointRadius = 0;  // the splat radius drawn, in pixels
};

/// Renders the cloud framed on its bounding box. Throws OptionError for a bad size, view or
/// attribute name.
Rendering renderPointsWithDepth(const PointCloud& cloud, const RenderOptions& options);
inline Image renderPoints(const PointCloud& cloud, const RenderOptions& options) {
  return renderPointsWithDepth(cloud, options).image;
}

/// The per-point colours renderPoints would use (before shading).
std::vector<Rgb> pointColors(const PointCloud& cloud, const RenderOptions& options);

}  // namespace scalespace
