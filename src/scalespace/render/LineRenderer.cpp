#include "scalespace/render/LineRenderer.hpp"

#include <algorithm>
#include <cmath>

#include "scalespace/core/Error.hpp"

namespace scalespace {

namespace {

/// Liang-Barsky step: keeps the part of [t0, t1] where p t <= q.
bool clipAgainst(double p, double q, double& t0, double& t1) {
  if (p == 0) return q >= 0;
  const double t = q / p;
  if (p < 0)
    t0 = std::max(t0, t);
  else
    t1 = std::min(t1, t);
  return t0 <= t1;
}

Rgb mix(const Rgb& a, const Rgb& b, double t) {
  auto channel = [t](int x, int y) {
    return std::uint8_t(std::clamp(std::lround(x + t * (y - x)), 0L, 255L));
  };
  return {channel(a.r, b.r), channel(a.g, b.g), channel(a.b, b.b)};
}

}  // namespace

std::vector<Rgb> polylineColors(const PolylineSet& lines, const LineRenderOptions& options) {
  const PointCloud& vertices = lines.vertices;
  if (options.colorAttribute.empty()) return std::vector<Rgb>(vertices.size(), options.color);
  const std::string& name = options.colorAttribute;
  if (!vertices.findAttribute(name) && name != "x" && name != "y" && name != "z") {
    std::string known;
    for (const auto& a : vertices.attributes()) known += (known.empty() ? "" : ", ") + a.name;
    throw OptionError("LineRenderOptions::colorAttribute '" + name +
                      "' is not a vertex attribute of the lines (they have: " +
                      (known.empty() ? "none" : known) + "; x, y, z colour by a coordinate)");
  }
  // The points' colouring, so that a line and a cloud coloured by one quantity read alike.
  RenderOptions byAttribute;
  byAttribute.colorAttribute = name;
  return pointColors(vertices, byAttribute);
}

void drawSegments(Rendering& target, const std::vector<Segment>& segments,
                  const LineRenderOptions& options) {
  if (options.lineRadius < 0 || options.lineRadius > kMaxPointRadius)
    throw OptionError("LineRenderOptions::lineRadius must be in [0, " +
                      std::to_string(kMaxPointRadius) + "]");
  const ScreenFrame& frame = target.frame;
  Image& image = target.image;
  const int r = options.lineRadius;
  const double tolerancePixels =
      options.depthTolerance >= 0 ? options.depthTolerance : 2.0 * target.pointRadius + 2.0;
  const double tolerance = tolerancePixels / frame.scale;  // pixels -> depth units
  // Samples whose disc can touch the image.
  const double xMin = -r - 1.0, xMax = image.width + r + 1.0;
  const double yMin = -r - 1.0, yMax = image.height + r + 1.0;

  for (const Segment& s : segments) {
    const Vec3 a = frame.project(s.a - frame.origin), b = frame.project(s.b - frame.origin);
    if (!a.allFinite() || !b.allFinite()) continue;
    const Vec3 d = b - a;
    double t0 = 0, t1 = 1;
    if (!clipAgainst(-d.x(), a.x() - xMin, t0, t1) || !clipAgainst(d.x(), xMax - a.x(), t0, t1) ||
        !clipAgainst(-d.y(), a.y() - yMin, t0, t1) || !clipAgainst(d.y(), yMax - a.y(), t0, t1))
      continue;
    // One sample per pixel column (or row, for a steep segment) at its centre, between the
    // clipped ends: each column gets exactly one pixel, none is skipped by rounding, the line is
    // 8-connected, and the count is bounded by the image size whatever the segment's length.
    const Vec3 from = a + t0 * d, to = a + t1 * d, delta = to - from;
    const int axis = std::abs(delta.x()) >= std::abs(delta.y()) ? 0 : 1;
    const double lo = std::min(from[axis], to[axis]), hi = std::max(from[axis], to[axis]);
    for (long n = long(std::floor(lo)); n <= long(std::floor(hi)); ++n) {
      const double centre = std::clamp(double(n) + 0.5, lo, hi);
      const double f = delta[axis] != 0 ? (centre - from[axis]) / delta[axis] : 0.0;
      const Vec3 p = from + f * delta;
      const Rgb c = mix(s.colorA, s.colorB, t0 + f * (t1 - t0));
      const int px = axis == 0 ? int(n) : int(std::floor(p.x()));
      const int py = axis == 1 ? int(n) : int(std::floor(p.y()));
      const float z = float(p.z());
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          if (dx * dx + dy * dy > r * r) continue;
          const int x = px + dx, y = py + dy;
          if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
          float& zb = target.depth[std::size_t(y) * image.width + x];
          if (double(z) <= double(zb) + tolerance) {
            zb = std::min(zb, z);
            image.at(x, y) = c;
          }
        }
    }
  }
}

void drawPolylines(Rendering& target, const PolylineSet& lines, const LineRenderOptions& options) {
  validatePolylineSet(lines);
  const std::vector<Rgb> colors = polylineColors(lines, options);
  const PointCloud& v = lines.vertices;
  std::vector<Segment> segments;
  segments.reserve(v.size());
  for (std::size_t l = 0; l < lines.lineCount(); ++l) {
    const std::size_t first = lines.offsets[l], last = lines.offsets[l + 1] - 1;
    for (std::size_t i = first; i < last; ++i)
      segments.push_back(
          {v.absolutePosition(i), v.absolutePosition(i + 1), colors[i], colors[i + 1]});
    if (lines.isClosed(l))
      segments.push_back(
          {v.absolutePosition(last), v.absolutePosition(first), colors[last], colors[first]});
  }
  drawSegments(target, segments, options);
}

}  // namespace scalespace
