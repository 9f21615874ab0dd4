#pragma once
// Scale features for the plane tests, computed from the exact geometry of synthetic scenes
// instead of the APSS stack: near an edge (closer than the scale t) the normal bends towards the
// neighbouring face and the curvature grows like 1/t, as the rounded APSS surface does; far from
// edges normals are exact and curvatures zero. Enough to exercise the graph logic with known
// answers.
#include <algorithm>
#include <cmath>
#include <vector>

#include "scalespace/core/SceneGenerator.hpp"
#include "scalespace/planes/ScaleFeatures.hpp"

namespace scalespace::test {

inline std::vector<double> logScales(double lo, double hi, int count) {
  std::vector<double> t(static_cast<std::size_t>(count));
  for (int j = 0; j < count; ++j) t[std::size_t(j)] = lo * std::pow(hi / lo, j / double(count - 1));
  return t;
}

/// Axis-aligned box centred at the origin with edge lengths `size` (positions relative = absolute
/// because the box is centred).
inline std::vector<ScaleFeatures> boxFeatures(const PointCloud& cloud, const Vec3& size,
                                              const std::vector<double>& scales) {
  const Vec3 h = size / 2;
  std::vector<ScaleFeatures> out;
  for (double t : scales) {
    ScaleFeatures f;
    f.t = t;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec3 p = cloud.absolutePosition(i);
      const Vec3& own = cloud.normals()[i];
      Vec3 n = own;
      double bend = 0.0;
      for (int b = 0; b < 3; ++b) {
        if (std::abs(own[b]) > 0.5) continue;
        const double d = h[b] - std::abs(p[b]);  // distance to the edge with face (b, sign p_b)
        const double w = std::max(0.0, 1.0 - d / t);
        n[b] += w * (p[b] > 0 ? 1 : -1);
        bend = std::max(bend, w);
      }
      f.normals.push_back(n.normalized());
      f.projections.push_back(cloud.positions()[i]);  // the faces stay where they are
      f.kMax.push_back(float(bend / t));
      f.kMin.push_back(0.f);
      f.valid.push_back(1);
    }
    out.push_back(std::move(f));
  }
  return out;
}

/// Stairs of `steps` steps of size d = 1/steps (SceneKind::Stairs): treads (+z) and risers (-y)
/// turn towards the mean ramp normal (0,-1,1)/sqrt2 as t grows past half the step size, until at
/// t >= d the whole staircase is one plane; the projections move as far towards the mean ramp
/// z = y + d/2, as a plain APSS would smooth the steps.
inline std::vector<ScaleFeatures> stairsFeatures(const PointCloud& cloud, int steps,
                                                 const std::vector<double>& scales) {
  const double d = 1.0 / steps;
  const Vec3 ramp = Vec3(0, -1, 1).normalized();
  std::vector<ScaleFeatures> out;
  for (double t : scales) {
    ScaleFeatures f;
    f.t = t;
    const double s = std::clamp((t - 0.5 * d) / (0.5 * d), 0.0, 1.0);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      f.normals.push_back(((1 - s) * cloud.normals()[i] + s * ramp).normalized());
      const Vec3 p = cloud.absolutePosition(i);
      const Vec3 onRamp = p - (ramp.dot(p) - ramp.dot(Vec3(0, 0, 0.5 * d))) * ramp;
      f.projections.push_back(cloud.positions()[i] + s * (onRamp - p));
      f.kMax.push_back(float(s < 1 ? s / t : 0.0));
      f.kMin.push_back(0.f);
      f.valid.push_back(1);
    }
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace scalespace::test
