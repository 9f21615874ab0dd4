#include "scalespace/core/PipeScene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <random>

#include "scalespace/core/Error.hpp"

namespace scalespace {
namespace {

// Layout (metres). Pipes run along x between x = -2 and 2 unless said otherwise.
constexpr double kThinRadius = 0.03, kMediumRadius = 0.1, kThickRadius = 0.35;
constexpr double kBentRadius = 0.12, kElbowRadius = 0.4;  // tube radius, bend radius of the axis
constexpr double kTaperStart = 0.15, kTaperEnd = 0.05;
constexpr double kStrandRadius = 0.05, kHelixRadius = 0.06, kHelixPitch = 0.8;
const Vec3 kBentStart{-2.0, 0.8, 0.4};
constexpr double kBentFirstLength = 1.7, kBentSecondLength = 1.0;
const Vec3 kBoxLo{1.2, 1.1, 0.0}, kBoxHi{2.0, 1.7, 0.5};

// A parametric surface patch over (u, v) in [0, 1]^2: position and unit outward normal.
struct Patch {
  int pipe = -1, part = -1;
  bool floor = false;  // points under what stands on it are not sampled
  std::function<void(double, double, Vec3&, Vec3&)> eval;
  double area = 0, maxJacobian = 0;
};

double jacobian(const Patch& patch, double u, double v) {
  const double h = 1e-6;
  Vec3 p0, pu, pv, n;
  patch.eval(u, v, p0, n);
  patch.eval(u + h, v, pu, n);
  patch.eval(u, v + h, pv, n);
  return ((pu - p0) / h).cross((pv - p0) / h).norm();
}

// Area by the midpoint rule, and a bound on the area element for rejection sampling.
void measure(Patch& patch) {
  const int g = 96;
  double sum = 0, peak = 0;
  for (int i = 0; i < g; ++i)
    for (int j = 0; j < g; ++j) {
      const double jac = jacobian(patch, (i + 0.5) / g, (j + 0.5) / g);
      sum += jac;
      peak = std::max(peak, jac);
    }
  patch.area = sum / (g * g);
  patch.maxJacobian = 1.05 * peak;
}

// Two unit vectors completing d into an orthonormal frame.
void frame(const Vec3& d, Vec3& e1, Vec3& e2) {
  e1 = (std::abs(d.z()) < 0.9 ? d.cross(Vec3::UnitZ()) : d.cross(Vec3::UnitX())).normalized();
  e2 = d.cross(e1);
}

// Tube around the segment a + s d, s in [0, length], radius r0 at a to r1 at the far end.
Patch tube(int pipe, int part, const Vec3& a, const Vec3& d, double length, double r0, double r1) {
  Vec3 e1, e2;
  frame(d, e1, e2);
  Patch patch;
  patch.pipe = pipe;
  patch.part = part;
  const double slope = (r1 - r0) / length;
  patch.eval = [=](double u, double v, Vec3& p, Vec3& n) {
    const double s = u * length, theta = 2 * kPi * v;
    const Vec3 radial = std::cos(theta) * e1 + std::sin(theta) * e2;
    p = a + s * d + (r0 + slope * s) * radial;
    n = (radial - slope * d).normalized();
  };
  return patch;
}

// Axis-aligned rectangle: origin + u du + v dv, normal given.
Patch rectangle(const Vec3& origin, const Vec3& du, const Vec3& dv, const Vec3& normal) {
  Patch patch;
  patch.eval = [=](double u, double v, Vec3& p, Vec3& n) {
    p = origin + u * du + v * dv;
    n = normal;
  };
  return patch;
}

// Centre of strand k of the cable at abscissa s along the cable's axis (x from -2).
Vec3 strandCentre(const Vec3& start, int k, double s) {
  const double phi = 2 * kPi * s / kHelixPitch + 2 * kPi * k / 3;
  return start + Vec3(s, kHelixRadius * std::cos(phi), kHelixRadius * std::sin(phi));
}

Patch strand(int pipe, int k, const Vec3& start, double length) {
  Patch patch;
  patch.pipe = pipe;
  patch.part = k;
  patch.eval = [=](double u, double v, Vec3& p, Vec3& n) {
    const double s = u * length, theta = 2 * kPi * v;
    const double omega = 2 * kPi / kHelixPitch, phi = omega * s + 2 * kPi * k / 3;
    const Vec3 radial(0, std::cos(phi), std::sin(phi));
    const Vec3 tangent =
        Vec3(1, -kHelixRadius * omega * std::sin(phi), kHelixRadius * omega * std::cos(phi))
            .normalized();
    const Vec3 binormal = tangent.cross(radial);
    n = std::cos(theta) * radial + std::sin(theta) * binormal;
    p = strandCentre(start, k, s) + kStrandRadius * n;
  };
  return patch;
}

// Whether a point of strand k lies inside another strand (the strands touch; those points are
// hidden): the distance to the other strands' centre curves near the same abscissa.
bool insideOtherStrand(const Vec3& start, int k, const Vec3& p) {
  for (int j = 0; j < 3; ++j) {
    if (j == k) continue;
    for (int step = -10; step <= 10; ++step) {
      const double s = p.x() - start.x() + 0.005 * step;
      if ((p - strandCentre(start, j, s)).norm() < kStrandRadius) return true;
    }
  }
  return false;
}

// Whether the ray from a point of strand k along `direction` (unit) meets another strand.
bool occludedByOtherStrand(const Vec3& start, int k, const Vec3& p, const Vec3& direction) {
  constexpr double kStep = 0.004, kReach = 0.24;  // beyond the cable's diameter (0.22 m)
  for (double d = kStep; d <= kReach; d += kStep)
    if (insideOtherStrand(start, k, p + d * direction)) return true;
  return false;
}

// Whether the other strands hide a point of strand k (outward `normal`): from `scanner` when
// given (the line to it is blocked), else from every scanner around the cable (the lines along
// the normal and along eight directions 50 degrees from it, an incidence a scan still returns,
// all blocked). Without this the scene held points no scan has (a third of the cable's, facing
// into the channel 2 cm wide between the strands) whose normals no estimate could orient
// (bench/README.md, bench_cylinders --estimate-normals).
bool hiddenByOtherStrands(const Vec3& start, int k, const Vec3& p, const Vec3& normal,
                          const Vec3* scanner) {
  if (scanner) return occludedByOtherStrand(start, k, p, (*scanner - p).normalized());
  if (!occludedByOtherStrand(start, k, p, normal)) return false;
  const Vec3 u = normal.unitOrthogonal(), v = normal.cross(u);
  const double c = std::cos(50 * kPi / 180), s = std::sin(50 * kPi / 180);
  for (int a = 0; a < 8; ++a) {
    const double psi = a * kPi / 4;
    const Vec3 d = c * normal + s * (std::cos(psi) * u + std::sin(psi) * v);
    if (!occludedByOtherStrand(start, k, p, d)) return false;
  }
  return true;
}

const Vec3 kCableStart{-2.0, -0.9, 0.6};

// The five faces of a box standing on the floor (lo.z() = 0: its bottom is not seen).
void addStandingBox(std::vector<Patch>& patches, const Vec3& lo, const Vec3& hi) {
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ(), size = hi - lo;
  patches.push_back(rectangle({lo.x(), lo.y(), hi.z()}, size.x() * x, size.y() * y, z));
  patches.push_back(rectangle(lo, size.x() * x, size.z() * z, -y));
  patches.push_back(rectangle({lo.x(), hi.y(), 0}, size.x() * x, size.z() * z, y));
  patches.push_back(rectangle(lo, size.y() * y, size.z() * z, -x));
  patches.push_back(rectangle({hi.x(), lo.y(), 0}, size.y() * y, size.z() * z, x));
}

std::vector<Patch> rackPatches() {
  std::vector<Patch> patches;
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  // Not cylinders: floor, wall, box (its bottom lies on the floor).
  patches.push_back(rectangle({-2.5, -2.2, 0}, 5 * x, 4.2 * y, z));
  patches.back().floor = true;
  patches.push_back(rectangle({-2.5, 2.0, 0}, 5 * x, 1.8 * z, -y));
  addStandingBox(patches, kBoxLo, kBoxHi);
  // Straight pipes.
  patches.push_back(tube(0, -1, {-2, -1.75, 0.4}, x, 4, kThinRadius, kThinRadius));
  patches.push_back(tube(1, -1, {-2, -1.3, 0.5}, x, 4, kMediumRadius, kMediumRadius));
  patches.push_back(tube(2, -1, {-2, -0.2, 0.8}, x, 4, kThickRadius, kThickRadius));
  // Bent pipe: along +x, a quarter torus turning up, then along +z.
  patches.push_back(tube(3, 0, kBentStart, x, kBentFirstLength, kBentRadius, kBentRadius));
  const Vec3 bendCentre = kBentStart + kBentFirstLength * x + kElbowRadius * z;
  Patch elbow;
  elbow.pipe = 3;
  elbow.part = 1;
  elbow.eval = [=](double u, double v, Vec3& p, Vec3& n) {
    const double phi = u * kPi / 2, theta = 2 * kPi * v;
    const Vec3 out(std::sin(phi), 0, -std::cos(phi));  // from the bend centre to the axis
    n = std::cos(theta) * out + std::sin(theta) * y;
    p = bendCentre + kElbowRadius * out + kBentRadius * n;
  };
  patches.push_back(elbow);
  patches.push_back(
      tube(3, 2, bendCentre + kElbowRadius * x, z, kBentSecondLength, kBentRadius, kBentRadius));
  // Tapering pipe.
  patches.push_back(tube(4, -1, {0.6, 0.8, 0.45}, x, 1.7, kTaperStart, kTaperEnd));
  // Cable.
  for (int k = 0; k < 3; ++k) patches.push_back(strand(5, k, kCableStart, 4));
  return patches;
}

// The poles layout: vertical poles of radius 0.05-0.5 m standing on a floor beside a box, whose
// edges a coarse scale rounds into tubes. Azimuths are measured from +x towards +y.
struct Pole {
  Vec3 foot;
  double radius, height;
  double seenFrom, seenArc;  // the azimuths a scan has: seenArc radians from seenFrom
};
// The half pole is seen over the 4 rad centred on the south (-y), where the one-sided scan's
// tripod stands.
constexpr double kHalfArc = 4.0, kHalfFrom = 1.5 * kPi - kHalfArc / 2;
const Pole kPoles[] = {{{-2.0, -2.0, 0}, 0.05, 2.0, 0, 2 * kPi},
                       {{0.0, 1.5, 0}, 0.2, 3.0, 0, 2 * kPi},
                       {{2.0, -1.0, 0}, 0.5, 2.5, kHalfFrom, kHalfArc},
                       {{-2.5, 2.5, 0}, 0.12, 1.5, 0, 2 * kPi}};
const Vec3 kRackScanner{1.3, -2.2, 4.8}, kPoleScanner{0, -5, 1.6};
const Vec3 kPoleBoxLo{1.0, 2.2, 0.0}, kPoleBoxHi{2.0, 2.8, 0.8};
constexpr double kPoleFloorHalf = 4.0;
// The band every pole lacks (a scanner's shadow): heights and azimuths.
constexpr double kBandLow = 0.8, kBandHigh = 1.0, kBandArc = 2.0;

double azimuthAbout(const Vec3& p, const Vec3& foot) {
  const double a = std::atan2(p.y() - foot.y(), p.x() - foot.x());
  return a < 0 ? a + 2 * kPi : a;
}

std::vector<Patch> polePatches() {
  std::vector<Patch> patches;
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  patches.push_back(rectangle({-kPoleFloorHalf, -kPoleFloorHalf, 0}, 2 * kPoleFloorHalf * x,
                              2 * kPoleFloorHalf * y, z));
  patches.back().floor = true;
  addStandingBox(patches, kPoleBoxLo, kPoleBoxHi);
  for (int i = 0; i < int(std::size(kPoles)); ++i) {
    const Pole& pole = kPoles[i];
    patches.push_back(tube(i, -1, pole.foot, z, pole.height, pole.radius, pole.radius));
  }
  return patches;
}

// What a scan of the layout does not have, at a point of `patch` (outward `normal`): the floor
// under the box (and, for the poles, inside them), the cable's points that its other strands
// hide, the poles' band and unseen side.
bool missing(PipeLayout layout, const Patch& patch, const Vec3& p, const Vec3& normal,
             const Vec3* scanner) {
  auto inBox = [&](const Vec3& lo, const Vec3& hi) {
    return p.x() > lo.x() && p.x() < hi.x() && p.y() > lo.y() && p.y() < hi.y();
  };
  if (layout == PipeLayout::Rack) {
    if (patch.floor) return inBox(kBoxLo, kBoxHi);
    return patch.pipe == 5 && (insideOtherStrand(kCableStart, patch.part, p) ||
                               hiddenByOtherStrands(kCableStart, patch.part, p, normal, scanner));
  }
  if (patch.floor) {
    if (inBox(kPoleBoxLo, kPoleBoxHi)) return true;
    for (const Pole& pole : kPoles)
      if (std::hypot(p.x() - pole.foot.x(), p.y() - pole.foot.y()) < pole.radius) return true;
    return false;
  }
  if (patch.pipe < 0) return false;
  const Pole& pole = kPoles[patch.pipe];
  const double azimuth = azimuthAbout(p, pole.foot);
  double fromSeen = azimuth - pole.seenFrom;
  if (fromSeen < 0) fromSeen += 2 * kPi;
  return fromSeen > pole.seenArc || (p.z() > kBandLow && p.z() < kBandHigh && azimuth < kBandArc);
}

std::vector<Patch> scenePatches(PipeLayout layout) {
  std::vector<Patch> patches = layout == PipeLayout::Rack ? rackPatches() : polePatches();
  for (Patch& patch : patches) measure(patch);
  return patches;
}

}  // namespace

std::vector<PipeTruth> pipeSceneTruth(PipeLayout layout) {
  if (layout == PipeLayout::Poles) {
    std::vector<PipeTruth> truth;
    for (int i = 0; i < int(std::size(kPoles)); ++i) {
      const Pole& pole = kPoles[i];
      PipeTruth t;
      t.id = i;
      char name[32];
      std::snprintf(name, sizeof name, "%spole r %.2g", pole.seenArc < 2 * kPi ? "half " : "",
                    pole.radius);
      t.name = name;
      t.radius = t.radiusEnd = pole.radius;
      t.axisPoint = pole.foot;
      t.axisDirection = Vec3::UnitZ();
      t.length = pole.height;
      truth.push_back(t);
    }
    return truth;
  }
  std::vector<PipeTruth> truth(6);
  auto straight = [](int id, const char* name, double r, const Vec3& a) {
    PipeTruth t;
    t.id = id;
    t.name = name;
    t.radius = t.radiusEnd = r;
    t.axisPoint = a;
    t.length = 4;
    return t;
  };
  truth[0] = straight(0, "thin", kThinRadius, {-2, -1.75, 0.4});
  truth[1] = straight(1, "medium", kMediumRadius, {-2, -1.3, 0.5});
  truth[2] = straight(2, "thick", kThickRadius, {-2, -0.2, 0.8});
  truth[3].id = 3;
  truth[3].name = "bent";
  truth[3].kind = PipeKind::Bent;
  truth[3].radius = truth[3].radiusEnd = kBentRadius;
  truth[3].axisPoint = kBentStart;
  truth[3].length = kBentFirstLength + kPi / 2 * kElbowRadius + kBentSecondLength;
  truth[4].id = 4;
  truth[4].name = "tapering";
  truth[4].kind = PipeKind::Tapering;
  truth[4].radius = kTaperStart;
  truth[4].radiusEnd = kTaperEnd;
  truth[4].axisPoint = {0.6, 0.8, 0.45};
  truth[4].length = 1.7;
  truth[5] = straight(5, "cable", kHelixRadius + kStrandRadius, kCableStart);
  truth[5].kind = PipeKind::Cable;
  truth[5].strandRadius = kStrandRadius;
  return truth;
}

PointCloud generatePipeScene(const PipeSceneOptions& options) {
  if (options.pointCount == 0) throw OptionError("pointCount must be >= 1");
  if (!(options.noise >= 0) || !std::isfinite(options.noise))
    throw OptionError("noise must be finite and >= 0");
  const std::vector<Patch> patches = scenePatches(options.layout);
  const Vec3 scanner = options.oneSidedScanner.value_or(
      options.layout == PipeLayout::Rack ? kRackScanner : kPoleScanner);
  std::vector<double> cumulative;
  double total = 0;
  for (const Patch& patch : patches) cumulative.push_back(total += patch.area);

  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const std::size_t n = options.pointCount;
  std::vector<Vec3> positions(n), normals(n);
  std::vector<double> pipe(n), part(n);
  for (std::size_t i = 0; i < n;) {
    const std::size_t k = std::min<std::size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), uniform(rng) * total) -
            cumulative.begin(),
        patches.size() - 1);
    const Patch& patch = patches[k];
    const double u = uniform(rng), v = uniform(rng);
    if (uniform(rng) * patch.maxJacobian > jacobian(patch, u, v)) continue;
    Vec3 p, normal;
    patch.eval(u, v, p, normal);
    if (options.oneSided && normal.dot(scanner - p) <= 0) continue;
    if (missing(options.layout, patch, p, normal, options.oneSided ? &scanner : nullptr)) continue;
    positions[i] = p;
    normals[i] = normal;
    pipe[i] = patch.pipe;
    part[i] = patch.part;
    ++i;
  }
  if (options.noise > 0) {
    Vec3 lo = positions[0], hi = positions[0];
    for (const Vec3& p : positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    std::normal_distribution<double> gauss(0.0, options.noise * (hi - lo).norm());
    for (Vec3& p : positions) p += Vec3(gauss(rng), gauss(rng), gauss(rng));
  }
  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  cloud.setNormals(std::move(normals));
  cloud.addAttribute("gt_pipe", ScalarType::Int32).values = std::move(pipe);
  cloud.addAttribute("gt_part", ScalarType::Int32).values = std::move(part);
  if (options.oneSided) cloud.setViewpoint(scanner);
  return cloud;
}

}  // namespace scalespace
