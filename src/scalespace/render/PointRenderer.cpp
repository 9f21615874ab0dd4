#include "scalespace/render/PointRenderer.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "scalespace/core/Error.hpp"
#include "scalespace/render/ColorMap.hpp"

namespace scalespace {

UpFrame upFrame(const std::string& up) {
  const bool negated = !up.empty() && up[0] == '-';
  const std::string axis = negated ? up.substr(1) : up;
  if (axis.size() != 1 || axis[0] < 'x' || axis[0] > 'z')
    throw OptionError("RenderOptions::up '" + up + "' is not x, y, z, -x, -y or -z");
  // Cyclic order: up e_i, side e_(i+1), ahead +-e_(i+2), so side x ahead = up.
  const int i = axis[0] - 'x';
  const double sign = negated ? -1.0 : 1.0;
  UpFrame f;
  f.up = sign * Vec3::Unit(i);
  f.side = Vec3::Unit((i + 1) % 3);
  f.ahead = sign * Vec3::Unit((i + 2) % 3);
  return f;
}

Vec3 viewDirection(const std::string& view, const std::string& up) {
  const UpFrame f = upFrame(up);
  if (view == "front") return f.ahead;
  if (view == "top") return -f.up;
  if (view == "iso") return (-f.side + f.ahead - f.up).normalized();
  std::stringstream in(view);
  Vec3 d;
  char c1 = 0, c2 = 0;
  if (in >> d.x() >> c1 >> d.y() >> c2 >> d.z() && c1 == ',' && c2 == ',' &&
      (in >> std::ws).eof() && d.allFinite() && d.norm() > 0)
    return d.normalized();
  throw OptionError("RenderOptions::view '" + view +
                    "' is not front, top, iso or a direction X,Y,Z (e.g. 1,0,-1)");
}

namespace {
const AttributeColumn& requireAttribute(const PointCloud& cloud, const std::string& name) {
  const AttributeColumn* column = cloud.findAttribute(name);
  if (!column) {
    std::string known;
    for (const auto& a : cloud.attributes()) known += (known.empty() ? "" : ", ") + a.name;
    throw OptionError("the cloud has no attribute '" + name +
                      "' (it has: " + (known.empty() ? "none" : known) + ")");
  }
  return *column;
}
}  // namespace

namespace {

std::vector<Rgb> baseColors(const PointCloud& cloud, const RenderOptions& options);

/// Darkens the colours of the points in odd cells of the checker grid (RenderOptions).
void applyChecker(const PointCloud& cloud, const RenderOptions& options, std::vector<Rgb>& colors) {
  if (options.checkerAttributes.empty()) return;
  if (options.checkerAttributes.size() != 2)
    throw OptionError("RenderOptions::checkerAttributes needs two attribute names");
  if (options.checkerCells < 1 || options.checkerCells > 10000)
    throw OptionError("RenderOptions::checkerCells must be in [1, 10000]");
  const auto& a = requireAttribute(cloud, options.checkerAttributes[0]).values;
  const auto& b = requireAttribute(cloud, options.checkerAttributes[1]).values;
  const ScalarRange ra = robustRange(a), rb = robustRange(b);
  const double aLo = ra.lo, bLo = rb.lo;
  const double span = std::max(ra.hi - ra.lo, rb.hi - rb.lo);
  if (!(span > 0)) return;
  const double cell = span / options.checkerCells;
  for (std::size_t i = 0; i < colors.size(); ++i) {
    if (!std::isfinite(a[i]) || !std::isfinite(b[i])) continue;
    const double x = std::floor((a[i] - aLo) / cell), y = std::floor((b[i] - bLo) / cell);
    if (std::fmod(std::abs(x + y), 2.0) < 0.5) continue;
    Rgb& c = colors[i];
    c = Rgb{std::uint8_t(c.r * 0.55), std::uint8_t(c.g * 0.55), std::uint8_t(c.b * 0.55)};
  }
}

}  // namespace

std::vector<Rgb> pointColors(const PointCloud& cloud, const RenderOptions& options) {
  std::vector<Rgb> colors = baseColors(cloud, options);
  applyChecker(cloud, options, colors);
  return colors;
}

namespace {

std::vector<Rgb> baseColors(const PointCloud& cloud, const RenderOptions& options) {
  const std::size_t n = cloud.size();
  if (!options.colors.empty()) {
    if (options.colors.size() != n)
      throw OptionError("render colours: " + std::to_string(options.colors.size()) +
                        " colours for " + std::to_string(n) + " points");
    return options.colors;
  }
  if (!options.labelAttribute.empty())
    return colorizeLabels(requireAttribute(cloud, options.labelAttribute).values);
  if (!options.colorAttribute.empty()) {
    const std::string& name = options.colorAttribute;
    // "x", "y", "z" colour by a coordinate unless the cloud has a column of that name.
    if (!cloud.findAttribute(name) && (name == "x" || name == "y" || name == "z")) {
      std::vector<double> values(n);
      const int axis = name[0] - 'x';
      for (std::size_t i = 0; i < n; ++i) values[i] = cloud.absolutePosition(i)[axis];
      return colorizeScalars(values, robustRange(values));
    }
    const auto& values = requireAttribute(cloud, name).values;
    return colorizeScalars(values, robustRange(values));
  }
  const AttributeColumn* r = cloud.findAttribute("red");
  const AttributeColumn* g = cloud.findAttribute("green");
  const AttributeColumn* b = cloud.findAttribute("blue");
  if (r && g && b) {
    // 16-bit colour channels (LAS) are scaled down to 8 bits.
    double top = 0;
    for (const auto* c : {r, g, b})
      for (double v : c->values) top = std::max(top, v);
    const double scale = top > 255 ? 1.0 / 257.0 : 1.0;
    std::vector<Rgb> colors(n);
    auto byte = [&](double v) {
      return std::uint8_t(std::clamp(std::lround(v * scale), 0L, 255L));
    };
    for (std::size_t i = 0; i < n; ++i)
      colors[i] = {byte(r->values[i]), byte(g->values[i]), byte(b->values[i])};
    return colors;
  }
  return std::vector<Rgb>(n, Rgb{200, 200, 200});
}

}  // namespace

ScreenFrame frameCloud(const PointCloud& cloud, const RenderOptions& options) {
  if (options.width <= 0 || options.height <= 0 || options.width > 16384 || options.height > 16384)
    throw OptionError("RenderOptions::width and height must be between 1 and 16384");
  if (options.margin < 0 || options.margin >= 0.5)
    throw OptionError("render margin must be in [0, 0.5)");
  ScreenFrame f;
  f.forward = viewDirection(options.view, options.up);
  const UpFrame frame = upFrame(options.up);
  const Vec3 upHint = std::abs(f.forward.dot(frame.up)) > 0.99 ? frame.ahead : frame.up;
  f.right = f.forward.cross(upHint).normalized();
  f.up = f.right.cross(f.forward);
  f.origin = cloud.origin();
  f.width = options.width;
  f.height = options.height;
  if (cloud.empty()) return f;

  // Framing: the projected corners of the bounding box fill the image minus the margin.
  Vec3 lo, hi;
  cloud.bounds(lo, hi);
  double minX = 1e300, maxX = -1e300, minY = 1e300, maxY = -1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                      (c & 4) ? hi.z() : lo.z());
    minX = std::min(minX, corner.dot(f.right));
    maxX = std::max(maxX, corner.dot(f.right));
    minY = std::min(minY, corner.dot(f.up));
    maxY = std::max(maxY, corner.dot(f.up));
  }
  const double usable = 1.0 - 2.0 * options.margin;
  const double spanX = maxX - minX, spanY = maxY - minY;
  // A single point (zero span) keeps 1 pixel per unit.
  if (spanX > 0 || spanY > 0)
    f.scale = std::min(spanX > 0 ? usable * options.width / spanX : 1e300,
                       spanY > 0 ? usable * options.height / spanY : 1e300);
  f.centreX = 0.5 * (minX + maxX);
  f.centreY = 0.5 * (minY + maxY);
  f.boxWidth = spanX * f.scale;
  f.boxHeight = spanY * f.scale;
  return f;
}

Rendering renderPointsWithDepth(const PointCloud& cloud, const RenderOptions& options) {
  Rendering out;
  out.frame = frameCloud(cloud, options);
  const ScreenFrame& frame = out.frame;
  Image& image = out.image;
  image = Image(options.width, options.height, options.background);
  out.depth.assign(image.pixels.size(), std::numeric_limits<float>::infinity());
  if (cloud.empty()) return out;
  const std::vector<Rgb> colors = pointColors(cloud, options);

  // Each point fills (2r + 1)^2 pixels: beyond kMaxPointRadius a typo would take minutes.
  int radius = std::min(options.pointRadius, kMaxPointRadius);
  if (radius < 0) {
    // Half the mean spacing of the points over the framed area, so a dense surface looks closed.
    const double area = std::max(1.0, frame.boxWidth) * std::max(1.0, frame.boxHeight);
    radius = int(std::clamp(std::lround(0.5 * std::sqrt(area / double(cloud.size()))), 0L, 8L));
  }
  out.pointRadius = radius;

  std::vector<float>& depth = out.depth;
  const auto& positions = cloud.positions();
  const bool shade = options.shading && cloud.hasNormals();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = positions[i];
    const Vec3 s = frame.project(p);
    const double sx = s.x(), sy = s.y();
    const float z = float(s.z());  // smaller = nearer to the camera
    if (!std::isfinite(sx) || !std::isfinite(sy)) continue;
    const int px = int(std::floor(sx)), py = int(std::floor(sy));
    Rgb c = colors[i];
    if (shade) {
      // Two-sided headlight: normals of unoriented clouds may point either way.
      const double light =
          0.35 + 0.65 * std::min(1.0, std::abs(cloud.normals()[i].dot(frame.forward)));
      c = {std::uint8_t(c.r * light), std::uint8_t(c.g * light), std::uint8_t(c.b * light)};
    }
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        if (dx * dx + dy * dy > radius * radius) continue;
        const int x = px + dx, y = py + dy;
        if (x < 0 || y < 0 || x >= options.width || y >= options.height) continue;
        float& zb = depth[std::size_t(y) * options.width + x];
        if (z < zb) {  // z-buffer: the nearest splat wins
          zb = z;
          image.at(x, y) = c;
        }
      }
  }
  return out;
}

}  // namespace scalespace
