#include "scalespace/features/TubeFit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"

namespace scalespace {

namespace {

Vec3 anyPerpendicular(const Vec3& d) {
  return (std::abs(d.x()) < 0.9 ? d.cross(Vec3::UnitX()) : d.cross(Vec3::UnitY())).normalized();
}

// Gauss-Newton on sum (|p - c| - r - slope s)^2 from the given centre, p the points' coordinates
// across the axis and s along it (centred): a circle (slope 0 and no s) or a cone. A cone seen
// from one side is not concentric arcs of one circle: fitting one circle to it would move the
// centre towards the points.
void fitCircle(const std::vector<Eigen::Vector2d>& flat, const std::vector<double>& along,
               Eigen::Vector2d& centre, double& r, double& slope) {
  const bool cone = !along.empty();
  r = 0;
  slope = 0;
  for (const auto& p : flat) r += (p - centre).norm();
  r /= double(flat.size());
  for (int iteration = 0; iteration < 12; ++iteration) {
    Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
    Eigen::Vector4d jtr = Eigen::Vector4d::Zero();
    for (std::size_t k = 0; k < flat.size(); ++k) {
      const Eigen::Vector2d d = flat[k] - centre;
      const double len = d.norm(), s = cone ? along[k] : 0.0;
      if (len == 0) continue;
      const Eigen::Vector4d j(-d.x() / len, -d.y() / len, -1, -s);
      jtj += j * j.transpose();
      jtr += j * (len - r - slope * s);
    }
    if (!cone) jtj(3, 3) = 1;  // slope stays 0
    const Eigen::Vector4d step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) break;
    centre += step.head<2>();
    r += step[2];
    slope += step[3];
    if (step.norm() < 1e-9 * (1 + std::abs(r))) break;
  }
}

// The straight axis: direction, centre and radius. False when the normals do not turn around
// any axis (all parallel: a plane).
bool fitStraightAxis(const std::vector<Vec3>& positions, const std::vector<Vec3>& scaleNormals,
                     const std::vector<Index>& points, const Vec3* direction, TubeFit& fit) {
  const double n = double(points.size());
  Mat3 spread = Mat3::Zero();
  Vec3 centroid = Vec3::Zero();
  for (const Index i : points) {
    spread += scaleNormals[i] * scaleNormals[i].transpose();
    centroid += positions[i];
  }
  centroid /= n;
  const Vec3 a =
      direction
          ? direction->normalized()
          : Vec3(Eigen::SelfAdjointEigenSolver<Mat3>(spread).eigenvectors().col(0).normalized());
  // The centre nearest to every normal line x_i + s n_i, in the plane normal to a: with u_i the
  // in-plane direction across the normal, minimise sum ((c - x_i) . u_i)^2, the component of c
  // along a pinned to the centroid's.
  Mat3 lhs = n * a * a.transpose();
  Vec3 rhs = n * a * a.dot(centroid);
  for (const Index i : points) {
    const Vec3 m = scaleNormals[i] - scaleNormals[i].dot(a) * a;
    if (m.squaredNorm() < 1e-12) continue;
    const Vec3 u = a.cross(m).normalized();
    lhs += u * u.transpose();
    rhs += u * u.dot(positions[i]);
  }
  // Parallel normals leave the in-plane part of lhs with rank <= 1.
  const Eigen::SelfAdjointEigenSolver<Mat3> check(lhs - n * a * a.transpose());
  if (!(check.eigenvalues()[1] > 1e-3 * n)) return false;
  Vec3 c = lhs.ldlt().solve(rhs);
  // Geometric circle fit in the plane normal to a, from there.
  const Vec3 e1 = anyPerpendicular(a), e2 = a.cross(e1);
  Eigen::Vector2d centre(e1.dot(c), e2.dot(c));
  std::vector<Eigen::Vector2d> flat;
  std::vector<double> along;
  flat.reserve(points.size());
  along.reserve(points.size());
  for (const Index i : points) {
    flat.emplace_back(e1.dot(positions[i]), e2.dot(positions[i]));
    along.push_back(a.dot(positions[i] - centroid));
  }
  double r = 0, slope = 0;
  fitCircle(flat, along, centre, r, slope);
  fit.direction = a;
  fit.centre = centre.x() * e1 + centre.y() * e2 + a.dot(centroid) * a;
  fit.straightRadius = std::abs(r);
  return std::isfinite(fit.straightRadius);
}

// The curved axis: axis points x - n / kappa1 averaged in cells of size h, chained along the
// longest path of their minimum spanning tree. The cells are anchored at the proposals' lower
// corner, not at the coordinates' zero: a grid fixed in space would cut a translated region
// differently (other nodes, another axis, the tube accepted or not as the cloud moves).
std::vector<Vec3> curvedAxis(const std::vector<Vec3>& positions,
                             const std::vector<Vec3>& scaleNormals,
                             const std::vector<float>& kappa1, const std::vector<Index>& points,
                             double h) {
  std::vector<Vec3> proposals;
  proposals.reserve(points.size());
  for (const Index i : points)
    if (kappa1[i] != 0) proposals.push_back(positions[i] - scaleNormals[i] / double(kappa1[i]));
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (const Vec3& p : proposals) lo = lo.cwiseMin(p);
  std::vector<Vec3> nodes;
  for (;; h *= 2) {
    std::vector<std::pair<std::int64_t, std::size_t>> keyed;
    keyed.reserve(proposals.size());
    for (std::size_t k = 0; k < proposals.size(); ++k) {
      const Vec3 p = proposals[k] - lo;
      const auto cell = [&](double v) { return std::int64_t(std::floor(v / h)) & 0x1fffff; };
      keyed.emplace_back((cell(p.x()) << 42) | (cell(p.y()) << 21) | cell(p.z()), k);
    }
    std::sort(keyed.begin(), keyed.end());
    nodes.clear();
    for (std::size_t b = 0; b < keyed.size();) {
      std::size_t e = b;
      Vec3 sum = Vec3::Zero();
      while (e < keyed.size() && keyed[e].first == keyed[b].first)
        sum += proposals[keyed[e++].second];
      if (e - b >= 2) nodes.push_back(sum / double(e - b));
      b = e;
    }
    if (nodes.size() <= 1500) break;
  }
  const std::size_t m = nodes.size();
  if (m < 2) return nodes;
  // Prim on the complete graph, then the tree's longest path (two farthest-node searches).
  std::vector<double> best(m, std::numeric_limits<double>::infinity());
  std::vector<std::size_t> parent(m, 0);
  std::vector<std::uint8_t> inTree(m, 0);
  std::vector<std::vector<std::size_t>> tree(m);
  std::size_t current = 0;
  inTree[0] = 1;
  for (std::size_t added = 1; added < m; ++added) {
    std::size_t next = m;
    for (std::size_t j = 0; j < m; ++j) {
      if (inTree[j]) continue;
      const double d = (nodes[j] - nodes[current]).squaredNorm();
      if (d < best[j]) {
        best[j] = d;
        parent[j] = current;
      }
      if (next == m || best[j] < best[next]) next = j;
    }
    inTree[next] = 1;
    tree[next].push_back(parent[next]);
    tree[parent[next]].push_back(next);
    current = next;
  }
  auto farthest = [&](std::size_t from, std::vector<std::size_t>& via) {
    std::vector<double> dist(m, -1);
    via.assign(m, m);
    std::vector<std::size_t> stack{from};
    dist[from] = 0;
    std::size_t far = from;
    while (!stack.empty()) {
      const std::size_t v = stack.back();
      stack.pop_back();
      if (dist[v] > dist[far]) far = v;
      for (const std::size_t w : tree[v])
        if (dist[w] < 0) {
          dist[w] = dist[v] + (nodes[w] - nodes[v]).norm();
          via[w] = v;
          stack.push_back(w);
        }
    }
    return far;
  };
  std::vector<std::size_t> via;
  const std::size_t a = farthest(0, via);
  const std::size_t b = farthest(a, via);
  std::vector<Vec3> path;
  for (std::size_t v = b; v != m; v = via[v]) path.push_back(nodes[v]);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Vec3> smooth = path;
    for (std::size_t k = 1; k + 1 < path.size(); ++k)
      smooth[k] = 0.25 * (path[k - 1] + 2 * path[k] + path[k + 1]);
    path.swap(smooth);
  }
  return path;
}

using Projection = AxisLocator::Projection;

Projection projectOnSegment(const std::vector<Vec3>& axis, std::size_t s, const Vec3& p) {
  const Vec3 d = axis[s + 1] - axis[s];
  const double len2 = d.squaredNorm();
  const double u = len2 > 0 ? std::clamp((p - axis[s]).dot(d) / len2, 0.0, 1.0) : 0.0;
  return {s, u, (p - (axis[s] + u * d)).norm()};
}

}  // namespace

// The nearest point of the axis: among the segments at the few axis vertices nearest to p (a
// kd-tree over the vertices) when the axis is long, else among all of them. A point of a tube
// is within about a radius of its axis, and the vertices are at least that far apart, so its
// segment ends at one of its nearest vertices.
AxisLocator::AxisLocator(const std::vector<Vec3>& axis) : axis_(axis) {
  if (axis.size() > kBruteForceVertices) index_ = makeSpatialIndex(axis_);
}

AxisLocator::~AxisLocator() = default;

AxisLocator::Projection AxisLocator::project(const Vec3& p) const {
  Projection best{0, 0, std::numeric_limits<double>::infinity()};
  auto consider = [&](std::size_t s) {
    const Projection q = projectOnSegment(axis_, s, p);
    if (q.distance < best.distance || (q.distance == best.distance && s < best.segment)) best = q;
  };
  if (!index_) {
    for (std::size_t s = 0; s + 1 < axis_.size(); ++s) consider(s);
    return best;
  }
  thread_local std::vector<Neighbor> near;
  index_->knnSearch(p, 4, near);
  for (const Neighbor& v : near) {
    if (v.index > 0) consider(v.index - 1);
    if (v.index + 1 < axis_.size()) consider(v.index);
  }
  return best;
}

namespace {

using Projection = AxisLocator::Projection;

// An axis polyline judged against the points: radius profile (each point's distance to the axis
// shared between the two ends of its segment), RMS about that profile, and the arcs covered
// around the axis by the input normals and by the points themselves, in a frame carried along
// the axis without twist. Both arcs are needed: a box edge, rounded by the fits into a tube of
// radius ~t, has points around a quarter circle but normals in two directions only; an axis
// proposed far from a thin pipe (a fit much larger than the pipe) sees normals all around but
// the points under a narrow angle.
struct AxisEvaluation {
  std::vector<Vec3> axis;
  std::vector<double> radii;
  double rms = 0, meanDistance = 0, normalArc = 0, positionArc = 0;
  double normalDirections = 0, normalSectorFill = 0, evenSectorFill = 0, normalLean = 0;
  int faceSectors = 0;
};

// (Not in the thesis.) The share of the points' spread about the tube that a section shape
// fixed along the axis explains: the distances to the axis less the radius profile, fitted by
// least squares on the azimuth's harmonics 2 to 8 against the offset and first harmonic alone
// (a centre slightly off), each sum of squares over its degrees of freedom so that a small
// region's noise explains nothing; points beyond 3 robust sigmas of the first fit are left out.
// A prism's flat faces are such a shape; a tube's noise is not, nor is a twisted cable's relief,
// which turns along the axis. NaN azimuths (end caps) are skipped; 0 when too few points are
// left. Measured values: TubeFitOptions::maxSectionShapeShare.
double shapeShareOf(const std::vector<double>& azimuths, const std::vector<double>& spread) {
  // Columns: 1, then cos and sin of orders 1 to 8; the first kBase (the offset and order 1: a
  // centre slightly off) are the tube's own, the rest its shape. An oval's order 2 counts as
  // shape: without it more of a noisy box's false tubes stayed (its section is a rectangle).
  constexpr int kHarmonics = 8, kBase = 3, kColumns = 1 + 2 * kHarmonics;
  using Row = Eigen::Matrix<double, kColumns, 1>;
  std::vector<Row, Eigen::aligned_allocator<Row>> rows;
  std::vector<double> values;
  rows.reserve(azimuths.size());
  values.reserve(azimuths.size());
  for (std::size_t k = 0; k < azimuths.size(); ++k) {
    if (!std::isfinite(azimuths[k])) continue;
    // 1, cos, sin, then cos and sin of orders 2 to 8 by the angle-addition recurrence.
    const double c1 = std::cos(azimuths[k]), s1 = std::sin(azimuths[k]);
    Row r;
    r[0] = 1;
    r[1] = c1;
    r[2] = s1;
    double c = c1, sn = s1;
    for (int order = 2; order <= kHarmonics; ++order) {
      const double next = c * c1 - sn * s1;
      sn = sn * c1 + c * s1;
      c = next;
      r[2 * order - 1] = c;
      r[2 * order] = sn;
    }
    rows.push_back(r);
    values.push_back(spread[k]);
  }
  // Least squares on the first n columns over the points kept; the residuals are left in error.
  std::vector<char> kept(rows.size(), 1);
  std::vector<double> error(rows.size());
  auto fit = [&](int n, std::size_t& used) {
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    used = 0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      if (!kept[k]) continue;
      gram.selfadjointView<Eigen::Lower>().rankUpdate(rows[k].head(n));
      rhs += rows[k].head(n) * values[k];
      ++used;
    }
    gram = gram.selfadjointView<Eigen::Lower>();
    // A tiny ridge keeps the harmonics of a narrow arc, nearly dependent there, solvable.
    gram.diagonal().array() += 1e-9 * gram.diagonal().maxCoeff();
    const Eigen::VectorXd coef = gram.ldlt().solve(rhs);
    double squares = 0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      error[k] = values[k] - rows[k].head(n).dot(coef);
      if (kept[k]) squares += error[k] * error[k];
    }
    return squares;
  };
  std::size_t used = 0;
  if (rows.size() < std::size_t(10 * kColumns)) return 0;
  // Points far off the offset-and-centre fit (beyond 3 robust sigmas: a mug's handle, another
  // object grown into the region) are left out: a shape must hold along the whole axis, not at
  // one place. A prism's faces stay in (their spread is bounded).
  fit(kBase, used);
  std::vector<double> magnitudes(error.size());
  for (std::size_t k = 0; k < error.size(); ++k) magnitudes[k] = std::abs(error[k]);
  const auto middle = magnitudes.begin() + std::ptrdiff_t(magnitudes.size() / 2);
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  const double bound = 3 * 1.4826 * *middle;
  for (std::size_t k = 0; k < error.size(); ++k) kept[k] = std::abs(error[k]) <= bound;
  const double base = fit(kBase, used);
  if (used < std::size_t(10 * kColumns)) return 0;
  const double full = fit(kColumns, used);
  const double perBase = base / double(used - kBase), perFull = full / double(used - kColumns);
  return perBase > 0 ? std::max(0.0, 1 - perFull / perBase) : 0;
}

// The azimuths about a straight axis (one frame along it) and the distances less the radius
// profile; NaN where the offset runs along the axis (beyond its ends).
double sectionShapeShare(const std::vector<Vec3>& positions, const std::vector<Index>& points,
                         const std::vector<Vec3>& axis, const std::vector<double>& radii) {
  const Vec3 along = (axis.back() - axis.front()).normalized();
  const Vec3 u = anyPerpendicular(along), v = along.cross(u);
  const AxisLocator locator(axis);
  std::vector<double> azimuths(points.size()), spread(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    const AxisLocator::Projection p = locator.project(positions[points[k]]);
    const Vec3 offset = positions[points[k]] -
                        (axis[p.segment] + p.along * (axis[p.segment + 1] - axis[p.segment]));
    const Vec3 radial = offset - offset.dot(along) * along;
    azimuths[k] = radial.norm() < 0.5 * offset.norm() ? std::numeric_limits<double>::quiet_NaN()
                                                      : std::atan2(radial.dot(v), radial.dot(u));
    spread[k] = p.distance - ((1 - p.along) * radii[p.segment] + p.along * radii[p.segment + 1]);
  }
  return shapeShareOf(azimuths, spread);
}

// The bin of an azimuth in [-pi, pi] among `bins` equal ones round the circle.
std::size_t azimuthBin(double angle, int bins) {
  return std::size_t(std::min(bins - 1, int((angle + kPi) / (2 * kPi) * bins)));
}

// (Not in the thesis.) Each normal's lean from its point's radial direction (azimuths about the
// axis; NaN skipped), signed and taken as a line (an inner wall's normals face the axis),
// averaged per 10-degree sector of the points' azimuth over the whole axis. A tube's normals are
// radial: its sector means stay near 0, and a twisted cable's strands, turning along it, average
// out. A prism's face keeps one normal while the points go round: over the sectors it spans the
// mean lean falls as fast as the azimuth rises. Reads the RMS of the sector means (degrees) and
// the longest run of neighbouring sectors over which the normals turn less than half as far as
// the points (TubeFitOptions::maxFaceSectors, minFaceLeanDegrees).
void readFaces(const std::vector<double>& normalAngle, const std::vector<double>& positionAngle,
               double& lean, int& run) {
  constexpr int kSectors = 36;
  constexpr double kMinInSector = 10;
  std::array<double, kSectors> sum{}, count{};
  for (std::size_t k = 0; k < normalAngle.size(); ++k) {
    if (std::isnan(normalAngle[k]) || std::isnan(positionAngle[k])) continue;
    double d = std::remainder(normalAngle[k] - positionAngle[k], 2 * kPi);
    if (d > kPi / 2) d -= kPi;
    if (d < -kPi / 2) d += kPi;
    const std::size_t b = azimuthBin(positionAngle[k], kSectors);
    sum[b] += d;
    count[b] += 1;
  }
  double squares = 0, weight = 0;
  for (std::size_t b = 0; b < std::size_t(kSectors); ++b) {
    if (count[b] < kMinInSector) continue;
    squares += sum[b] * sum[b] / count[b];
    weight += count[b];
  }
  lean = weight > 0 ? std::sqrt(squares / weight) * 180 / kPi : 0;
  run = 0;
  for (int b = 0, current = 0; b < 2 * kSectors; ++b) {
    const std::size_t i = std::size_t(b % kSectors), j = std::size_t((b + 1) % kSectors);
    const bool stall = count[i] >= kMinInSector && count[j] >= kMinInSector &&
                       sum[j] / count[j] - sum[i] / count[i] < -kPi / kSectors;
    current = stall ? current + 1 : 0;
    run = std::max(run, std::min(current, kSectors));
  }
}

void evaluateAxis(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                  const std::vector<Index>& points, bool straight, AxisEvaluation& e) {
  const std::size_t m = e.axis.size();
  std::vector<Projection> proj(points.size());
  std::vector<double> sum(m, 0), weight(m, 0);
  e.meanDistance = 0;
  const AxisLocator locator(e.axis);
  for (std::size_t k = 0; k < points.size(); ++k) {
    proj[k] = locator.project(positions[points[k]]);
    sum[proj[k].segment] += (1 - proj[k].along) * proj[k].distance;
    weight[proj[k].segment] += 1 - proj[k].along;
    sum[proj[k].segment + 1] += proj[k].along * proj[k].distance;
    weight[proj[k].segment + 1] += proj[k].along;
    e.meanDistance += proj[k].distance;
  }
  e.meanDistance /= double(points.size());
  e.radii.resize(m);
  for (std::size_t k = 0; k < m; ++k) e.radii[k] = weight[k] > 1e-9 ? sum[k] / weight[k] : -1;
  for (std::size_t k = 0; k < m; ++k)  // vertices no point projects to take their neighbour's
    if (e.radii[k] < 0) e.radii[k] = k > 0 ? e.radii[k - 1] : e.meanDistance;
  double squares = 0;
  for (const Projection& p : proj) {
    const double r = (1 - p.along) * e.radii[p.segment] + p.along * e.radii[p.segment + 1];
    squares += (p.distance - r) * (p.distance - r);
  }
  e.rms = std::sqrt(squares / double(points.size()));

  constexpr int kBins = 24;
  std::vector<Vec3> tangent(m - 1), across(m - 1);
  for (std::size_t s = 0; s + 1 < m; ++s) {
    tangent[s] = (e.axis[s + 1] - e.axis[s]).normalized();
    Vec3 a = s == 0 ? anyPerpendicular(tangent[0]) : across[s - 1];
    a -= a.dot(tangent[s]) * tangent[s];
    across[s] = a.squaredNorm() > 1e-12 ? a.normalized() : anyPerpendicular(tangent[s]);
  }
  // A direction's azimuth around the axis at segment s, in the frame carried along it; NaN when
  // it runs along the axis (an end cap, not the side).
  auto azimuth = [&](std::size_t s, const Vec3& d) {
    const Vec3 radial = d - d.dot(tangent[s]) * tangent[s];
    if (radial.norm() < 0.5 * d.norm()) return std::numeric_limits<double>::quiet_NaN();
    return std::atan2(radial.dot(tangent[s].cross(across[s])), radial.dot(across[s]));
  };
  // Arcs are counted per axis segment, each in its own frame, and the median over the segments
  // holding enough points is kept: along a polyline that wanders (the axis of a box's rounded
  // footprint turning at its corners) one frame would smear two face normals over many angles.
  // Per segment, NaN where it holds too few points: the arc (degrees) of the bins holding at least
  // a quarter of the mean count, and its span, all but the longest run of bins under that count
  // round the circle (the gaps between a prism's faces included).
  struct SegmentArcs {
    std::vector<double> filled, span;
  };
  auto segmentArcs = [&](const std::vector<double>& angles) {
    std::vector<std::array<std::uint32_t, kBins>> bins(m - 1);
    for (auto& b : bins) b.fill(0);
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!std::isnan(angles[k])) ++bins[proj[k].segment][azimuthBin(angles[k], kBins)];
    SegmentArcs arcs{std::vector<double>(m - 1, std::numeric_limits<double>::quiet_NaN()),
                     std::vector<double>(m - 1, std::numeric_limits<double>::quiet_NaN())};
    for (std::size_t s = 0; s + 1 < m; ++s) {
      std::uint32_t counted = 0;
      for (const std::uint32_t c : bins[s]) counted += c;
      if (counted < 2 * kBins) continue;
      const double enough = std::max(2.0, 0.25 * counted / kBins);
      int filled = 0, longest = 0, run = 0;
      for (const std::uint32_t c : bins[s]) filled += double(c) >= enough;
      for (int k = 0; k < 2 * kBins; ++k) {
        run = double(bins[s][std::size_t(k % kBins)]) < enough ? run + 1 : 0;
        longest = std::max(longest, std::min(run, kBins));
      }
      arcs.filled[s] = 360.0 * filled / kBins;
      arcs.span[s] = 360.0 * (kBins - longest) / kBins;
    }
    return arcs;
  };
  // One count over the whole axis, for a short or sparse region, which only a straight axis (one
  // frame) can give; a sparse bent one is not trusted.
  auto wholeArc = [&](const std::vector<double>& angles) {
    if (!straight) return 0.0;
    std::array<std::uint32_t, kBins> all{};
    std::uint32_t counted = 0;
    for (const double angle : angles)
      if (!std::isnan(angle)) ++all[azimuthBin(angle, kBins)], ++counted;
    int filled = 0;
    for (const std::uint32_t c : all) filled += double(c) >= std::max(2.0, 0.25 * counted / kBins);
    return 360.0 * filled / kBins;
  };
  auto median = [](std::vector<double> values) {
    values.erase(
        std::remove_if(values.begin(), values.end(), [](double v) { return std::isnan(v); }),
        values.end());
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2),
                     values.end());
    return values[values.size() / 2];
  };
  std::vector<double> normalAngle(points.size());
  for (std::size_t k = 0; k < points.size(); ++k)
    normalAngle[k] = azimuth(proj[k].segment, normals[points[k]]);
  std::vector<double> positionAngle(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    const std::size_t s = proj[k].segment;
    const Vec3 foot = e.axis[s] + proj[k].along * (e.axis[s + 1] - e.axis[s]);
    positionAngle[k] = azimuth(s, Vec3(positions[points[k]] - foot));
  }
  readFaces(normalAngle, positionAngle, e.normalLean, e.faceSectors);
  const SegmentArcs normalArcs = segmentArcs(normalAngle),
                    positionArcs = segmentArcs(positionAngle);
  e.normalArc = median(normalArcs.filled);
  e.positionArc = median(positionArcs.filled);
  if (std::isnan(e.normalArc)) e.normalArc = wholeArc(normalAngle);
  if (std::isnan(e.positionArc)) e.positionArc = wholeArc(positionAngle);
  // The effective number of bins a set of azimuths takes (the exponential of their histogram's
  // entropy).
  const auto histogramBins = [](const std::vector<std::uint32_t>& histogram) {
    std::uint32_t counted = 0;
    for (const std::uint32_t c : histogram) counted += c;
    double entropy = 0;
    for (const std::uint32_t c : histogram)
      if (c > 0) entropy -= double(c) / counted * std::log(double(c) / counted);
    return std::exp(entropy);
  };
  const auto effectiveBins = [&](const std::vector<double>& angles, int bins) {
    std::vector<std::uint32_t> histogram(std::size_t(bins), 0);
    for (const double angle : angles)
      if (!std::isnan(angle)) ++histogram[azimuthBin(angle, bins)];
    return histogramBins(histogram);
  };
  // The 2-degree directions the normals take around the axis: a tube's turn continuously, a
  // prism's sit on its few faces.
  e.normalDirections = effectiveBins(normalAngle, 180);
  // How fully the normals take the 10-degree sectors of the arc: a tube's turn with its points
  // and fill it, tessellated or not (a 40-gon's facets are 9 degrees apart); a box edge's faces,
  // rounded into a tube at a scale above them, lie all round the arc with their normals in two
  // directions however far noise smears them. Two readings, the larger kept: the effective
  // number of sectors the normals take over the arc's sectors, and the same with each sector of
  // points weighted alike over the sectors they cover (a tube sampled unevenly around its axis,
  // as a locally refined mesh's vertices are, has its normals where its points are dense).
  // The arc of the first reading is counted twice and the lower fill kept: as the bins the
  // normals and the points fill, and, per axis segment (median), as the span round the axis they
  // take, gaps included. A noisy prism's face directions, each smeared over a few bins, fill
  // the bins they take evenly; the span holds the gaps between its faces as well (libcgal-demo's
  // octahedron under noise 1e-3 of the diagonal: 0.9-1.0 over the bins, 0.4-0.6 over the span).
  constexpr int kSectors = 36;
  std::vector<std::vector<std::uint32_t>> sectors(m - 1, std::vector<std::uint32_t>(kSectors, 0));
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!std::isnan(normalAngle[k]))
      ++sectors[proj[k].segment][azimuthBin(normalAngle[k], kSectors)];
  std::vector<double> spanFills(m - 1, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t s = 0; s + 1 < m; ++s) {
    if (std::isnan(normalArcs.span[s]) || std::isnan(positionArcs.span[s])) continue;
    const double span = std::min(normalArcs.span[s], positionArcs.span[s]);
    if (span > 0) spanFills[s] = histogramBins(sectors[s]) / (span / 10);
  }
  const double arc = std::min(e.normalArc, e.positionArc);
  const double binFill = arc > 0 ? effectiveBins(normalAngle, kSectors) / (arc / 10) : 0;
  const double spanFill = median(spanFills);
  e.normalSectorFill = std::isnan(spanFill) ? binFill : std::min(binFill, spanFill);
  {
    const auto sectorOf = [&](double angle) { return azimuthBin(angle, kSectors); };
    std::array<double, kSectors> pointsIn{}, normalsIn{};
    double counted = 0;
    for (const double angle : positionAngle)
      if (!std::isnan(angle)) pointsIn[sectorOf(angle)] += 1, counted += 1;
    const double enough = std::max(2.0, 0.25 * counted / kSectors);
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (std::isnan(positionAngle[k]) || std::isnan(normalAngle[k])) continue;
      const double inSector = pointsIn[sectorOf(positionAngle[k])];
      if (inSector >= enough) normalsIn[sectorOf(normalAngle[k])] += 1 / inSector;
    }
    double total = 0, entropy = 0;
    int covered = 0;
    for (const double c : pointsIn) covered += c >= enough;
    for (const double w : normalsIn) total += w;
    for (const double w : normalsIn)
      if (w > 0) entropy -= w / total * std::log(w / total);
    e.evenSectorFill = covered > 0 && total > 0 ? std::exp(entropy) / covered : 0;
  }
}

// Re-centres each vertex of a curved axis on its cross-section: the circle fitted to the points
// nearest to it, in the plane normal to the axis there. The proposals x - n / kappa1 place the
// axis only as well as kappa1 is known (poorly where a tube bends more tightly than twice its
// radius, as on a knot); the points themselves do not depend on it.
void recentreAxis(const std::vector<Vec3>& positions, const std::vector<Index>& points,
                  std::vector<Vec3>& axis) {
  const std::size_t m = axis.size();
  if (m < 2) return;
  std::vector<std::vector<Index>> near(m);
  const AxisLocator locator(axis);
  for (const Index i : points) {
    const Projection q = locator.project(positions[i]);
    near[q.along < 0.5 ? q.segment : q.segment + 1].push_back(i);
  }
  std::vector<Vec3> moved = axis;
  for (std::size_t k = 0; k < m; ++k) {
    if (near[k].size() < 10) continue;
    const Vec3 tangent = (axis[std::min(k + 1, m - 1)] - axis[k > 0 ? k - 1 : 0]).normalized();
    const Vec3 e1 = anyPerpendicular(tangent), e2 = tangent.cross(e1);
    std::vector<Eigen::Vector2d> flat;
    for (const Index i : near[k]) {
      const Vec3 d = positions[i] - axis[k];
      flat.emplace_back(e1.dot(d), e2.dot(d));
    }
    double spread = 0;  // the section's size about the current vertex
    for (const auto& p : flat) spread += p.norm();
    spread /= double(flat.size());
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    double r = 0, slope = 0;
    fitCircle(flat, {}, centre, r, slope);
    // A section seen under a narrow angle can send the circle anywhere: only moves that keep it
    // of the section's size are taken.
    if (centre.allFinite() && std::isfinite(r) && centre.norm() < 0.5 * spread && r < 2 * spread)
      moved[k] = axis[k] + centre.x() * e1 + centre.y() * e2;
  }
  axis.swap(moved);
}

}  // namespace

TubeSurface::TubeSurface(const TubeFit& tube) : tube_(tube), locator_(tube.axis) {}

double TubeSurface::residual(const Vec3& p, Vec3* radial) const {
  const Projection q = locator_.project(p);
  const std::size_t s = q.segment;
  if (radial) {
    const Vec3 foot = tube_.axis[s] + q.along * (tube_.axis[s + 1] - tube_.axis[s]);
    *radial = q.distance > 0 ? Vec3((p - foot) / q.distance) : Vec3::Zero();
  }
  return q.distance - ((1 - q.along) * tube_.radii[s] + q.along * tube_.radii[s + 1]);
}

bool radiiAgree(const TubeFit& a, const TubeFit& b, double tolerance) {
  return std::abs(a.radius - b.radius) <= tolerance * std::max(a.radius, b.radius);
}

double medianRelativeResidual(const std::vector<Vec3>& positions, const std::vector<Index>& points,
                              const TubeFit& tube) {
  if (points.empty()) return 0;
  if (tube.axis.size() < 2 || !(tube.radius > 0)) return std::numeric_limits<double>::infinity();
  const TubeSurface surface(tube);
  constexpr std::size_t kMaxPoints = 4096;
  const std::size_t stride = (points.size() + kMaxPoints - 1) / kMaxPoints;
  std::vector<double> residuals;
  residuals.reserve(points.size() / stride + 1);
  for (std::size_t k = 0; k < points.size(); k += stride)
    residuals.push_back(std::abs(surface.residual(positions[points[k]])));
  const auto middle = residuals.begin() + std::ptrdiff_t(residuals.size() / 2);
  std::nth_element(residuals.begin(), middle, residuals.end());
  return *middle / tube.radius;
}

const char* tubeRejectionName(TubeRejection rejection) {
  switch (rejection) {
    case TubeRejection::None:
      return "none";
    case TubeRejection::TooSmall:
      return "too_small";
    case TubeRejection::Flat:
      return "flat";
    case TubeRejection::NarrowArc:
      return "narrow_arc";
    case TubeRejection::Thin:
      return "thin";
    case TubeRejection::Rough:
      return "rough";
    case TubeRejection::Faceted:
      return "faceted";
    case TubeRejection::Merged:
      return "merged";
    case TubeRejection::Split:
      return "split";
  }
  return "?";
}

void validateTubeFitOptions(const TubeFitOptions& options) {
  auto check = [](bool ok, const char* message) {
    if (!ok) throw OptionError(message);
  };
  check(std::isfinite(options.minCurvatureFactor) && options.minCurvatureFactor >= 0,
        "TubeFitOptions::minCurvatureFactor must be finite and >= 0");
  check(options.minArcDegrees >= 0 && options.minArcDegrees <= 360,
        "TubeFitOptions::minArcDegrees must be in [0, 360]");
  check(std::isfinite(options.minRadiusFactor) && options.minRadiusFactor >= 0,
        "TubeFitOptions::minRadiusFactor must be finite and >= 0");
  check(std::isfinite(options.maxRelativeRms) && options.maxRelativeRms > 0,
        "TubeFitOptions::maxRelativeRms must be finite and > 0");
  check(options.maxSectionShapeShare >= 0 && options.maxSectionShapeShare <= 1,
        "TubeFitOptions::maxSectionShapeShare must be in [0, 1] (1: no test)");
  check(std::isfinite(options.maxSectionShapeRms) && options.maxSectionShapeRms >= 0,
        "TubeFitOptions::maxSectionShapeRms must be finite and >= 0");
  check(options.maxFaceSectors >= 0, "TubeFitOptions::maxFaceSectors must be >= 0 (36: no test)");
  check(std::isfinite(options.minFaceLeanDegrees) && options.minFaceLeanDegrees >= 0,
        "TubeFitOptions::minFaceLeanDegrees must be finite and >= 0");
  check(std::isfinite(options.minNormalDirections) && options.minNormalDirections >= 0,
        "TubeFitOptions::minNormalDirections must be finite and >= 0");
  check(options.minSectorFill >= 0 && options.minSectorFill <= 1,
        "TubeFitOptions::minSectorFill must be in [0, 1]");
  check(std::isfinite(options.straightRmsRatio) && options.straightRmsRatio >= 1,
        "TubeFitOptions::straightRmsRatio must be finite and >= 1");
  check(options.maxRadiusDisagreement >= 1,
        "TubeFitOptions::maxRadiusDisagreement must be >= 1 (infinity: off)");
}

TubeFit fitTube(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                const std::vector<Vec3>& scaleNormals, const std::vector<float>& kappa1,
                const std::vector<Index>& points, double t, const TubeFitOptions& options) {
  TubeFit fit;
  fit.pointCount = points.size();
  if (points.size() < std::max<std::size_t>(options.minPoints, 3)) return fit;
  double meanKappa = 0;
  std::vector<double> radii;
  for (const Index i : points) {
    meanKappa += kappa1[i];
    if (std::abs(kappa1[i]) * t >= options.minCurvatureFactor)
      radii.push_back(1 / std::abs(kappa1[i]));
  }
  meanKappa /= double(points.size());
  fit.rejection = TubeRejection::Flat;
  if (std::abs(meanKappa) * t < options.minCurvatureFactor || radii.size() < 3) return fit;
  if (!fitStraightAxis(positions, scaleNormals, points, nullptr, fit)) return fit;

  std::nth_element(radii.begin(), radii.begin() + std::ptrdiff_t(radii.size() / 2), radii.end());
  const double cell = std::max(t, radii[radii.size() / 2]);
  auto straightAxis = [&](const TubeFit& f) {
    AxisEvaluation e;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Index i : points) {
      const double s = (positions[i] - f.centre).dot(f.direction);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    const int pieces = std::max(1, int(std::lround((hi - lo) / cell)));
    for (int k = 0; k <= pieces; ++k)
      e.axis.push_back(f.centre + (lo + (hi - lo) * k / pieces) * f.direction);
    evaluateAxis(positions, normals, points, true, e);
    return e;
  };
  AxisEvaluation straight = straightAxis(fit);
  AxisEvaluation curved;
  curved.axis = curvedAxis(positions, scaleNormals, kappa1, points, cell);
  for (int pass = 0; pass < 2; ++pass) recentreAxis(positions, points, curved.axis);
  fit.straight = true;
  if (curved.axis.size() >= 2) {
    evaluateAxis(positions, normals, points, false, curved);
    // The normals' least-spread direction leans where they do not turn all around the axis (a
    // cone seen from one side); the chord of the re-centred curved axis does not. Keep the
    // straight axis that fits better.
    const Vec3 chord = curved.axis.back() - curved.axis.front();
    TubeFit alongChord = fit;
    if (chord.norm() > 0 && fitStraightAxis(positions, scaleNormals, points, &chord, alongChord)) {
      AxisEvaluation other = straightAxis(alongChord);
      if (other.rms < straight.rms) {
        straight = std::move(other);
        fit.direction = alongChord.direction;
        fit.centre = alongChord.centre;
        fit.straightRadius = alongChord.straightRadius;
      }
    }
    // The straight axis unless the curved one describes the points clearly better (a bent pipe),
    // or unless only the curved one has the radius the scale's curvature reads: a run of a
    // twisted strand seen from one side also lies on the cable's envelope, a straight tube of
    // twice its radius over a narrow arc, and fits it about as well.
    const auto offBy = [](double a, double b) { return std::max(a / b, b / a); };
    const double curvatureRadius = radii[radii.size() / 2];
    const double straightOff = offBy(fit.straightRadius, curvatureRadius);
    const bool straightReadsTheCurvature =
        !(straightOff > options.maxRadiusDisagreement &&
          offBy(curved.meanDistance, curvatureRadius) < straightOff);
    fit.straight = straightReadsTheCurvature &&
                   straight.rms <= std::max(options.straightRmsRatio * curved.rms,
                                            curved.rms + 0.02 * curved.meanDistance);
  }
  AxisEvaluation& chosen = fit.straight ? straight : curved;
  fit.axis = std::move(chosen.axis);
  fit.radii = std::move(chosen.radii);
  fit.rms = chosen.rms;
  fit.radius = fit.straight ? fit.straightRadius : chosen.meanDistance;
  fit.arcDegrees = std::min(chosen.normalArc, chosen.positionArc);
  fit.normalDirections = chosen.normalDirections;
  fit.sectorFill = std::max(chosen.normalSectorFill, chosen.evenSectorFill);
  // Read about a straight axis only: in the frame carried along a curved one, a twisted strand's
  // run read 0.34 (the noisy one-sided pipe rack, t = 0.0435).
  if (fit.straight)
    fit.sectionShapeShare = sectionShapeShare(positions, points, fit.axis, fit.radii);
  for (std::size_t k = 0; k + 1 < fit.axis.size(); ++k)
    fit.length += (fit.axis[k + 1] - fit.axis[k]).norm();
  fit.faceSectors = chosen.faceSectors;
  fit.normalLean = chosen.normalLean;

  fit.rejection = judgeTube(fit, t, options);
  return fit;
}

TubeRejection judgeTube(const TubeFit& fit, double t, const TubeFitOptions& options) {
  if (fit.length < fit.radius)  // a ring shorter than its radius: too little to call a tube
    return TubeRejection::TooSmall;
  if (fit.arcDegrees < options.minArcDegrees) return TubeRejection::NarrowArc;
  if (!(fit.radius >= options.minRadiusFactor * t)) return TubeRejection::Thin;
  if (!(fit.rms <= options.maxRelativeRms * std::max(fit.radius, t))) return TubeRejection::Rough;
  if (fit.normalDirections < std::min(options.minNormalDirections, 0.5 * double(fit.pointCount)) ||
      fit.sectorFill < options.minSectorFill)
    return TubeRejection::Faceted;
  if (fit.faceSectors > options.maxFaceSectors && fit.normalLean >= options.minFaceLeanDegrees)
    return TubeRejection::Faceted;
  // Both the share and the shape's own RMS (TubeFitOptions::maxSectionShapeRms).
  if (fit.sectionShapeShare > options.maxSectionShapeShare &&
      std::sqrt(fit.sectionShapeShare) * fit.rms > options.maxSectionShapeRms * fit.radius)
    return TubeRejection::Faceted;
  return TubeRejection::None;
}

double shareBeside(const TubeFit& a, const TubeFit& b) {
  if (a.axis.size() < 2 || b.axis.empty()) return 0;
  const AxisLocator locator(a.axis);
  const double reach = 3 * std::max(a.radius, b.radius);
  std::size_t beside = 0;
  for (const Vec3& v : b.axis) {
    const AxisLocator::Projection q = locator.project(v);
    const bool end =
        (q.segment == 0 && q.along <= 0) || (q.segment + 2 == a.axis.size() && q.along >= 1);
    beside += !end && q.distance <= reach;
  }
  return double(beside) / double(b.axis.size());
}

}  // namespace scalespace
