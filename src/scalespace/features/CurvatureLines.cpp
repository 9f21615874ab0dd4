#include "scalespace/features/CurvatureLines.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <string>
#include <unordered_map>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/SpatialIndex.hpp"
#include "scalespace/fit/FitPoints.hpp"
#include "scalespace/scales/PoissonDiskSampler.hpp"

namespace scalespace {

const char* lineStopName(LineStop stop) {
  switch (stop) {
    case LineStop::InvalidFit:
      return "invalid_fit";
    case LineStop::Umbilic:
      return "umbilic";
    case LineStop::Turn:
      return "turn";
    case LineStop::Stalled:
      return "stalled";
    case LineStop::Border:
      return "border";
    case LineStop::Collision:
      return "collision";
    case LineStop::Loop:
      return "loop";
    case LineStop::Jump:
      return "jump";
    case LineStop::SelfCollision:
      return "self_collision";
    case LineStop::MaxSteps:
      return "max_steps";
  }
  return "unknown";
}

double CurvatureLine::length() const {
  double sum = 0;
  for (std::size_t i = 1; i < vertices.size(); ++i)
    sum += (vertices[i].position - vertices[i - 1].position).norm();
  if (closed && vertices.size() > 2)
    sum += (vertices.front().position - vertices.back().position).norm();
  return sum;
}

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw OptionError(message);
}

bool hasPrincipalDirections(EstimatorKind kind) {
  return kind == EstimatorKind::W3 || kind == EstimatorKind::W2 || kind == EstimatorKind::Quadric ||
         kind == EstimatorKind::Jet;
}

/// The fit read as (kappa1, kappa2, v_min): kappa1 of larger magnitude (Sec. 3.3).
struct MinimalDirection {
  double kappa1 = 0, kappa2 = 0;
  Vec3 direction = Vec3::Zero();
};

MinimalDirection minimalDirection(const LocalFit& fit) {
  if (std::abs(fit.kMax) >= std::abs(fit.kMin)) return {fit.kMax, fit.kMin, fit.dirMin};
  return {fit.kMin, fit.kMax, fit.dirMax};
}

bool nearUmbilic(const MinimalDirection& m, double t, const CurvatureLineOptions& options) {
  const double a1 = std::abs(m.kappa1), a2 = std::abs(m.kappa2);
  return (a1 - a2) * t < options.minAnisotropy || a2 > (1 - options.minCurvatureGap) * a1;
}

CurvatureLineVertex makeVertex(const LocalFit& fit, const MinimalDirection& m,
                               const Vec3& tangent) {
  CurvatureLineVertex v;
  v.position = fit.projection;
  v.tangent = tangent;
  v.normal = fit.normal;
  v.kappa1 = m.kappa1;
  v.kappa2 = m.kappa2;
  v.geometricVariation = fit.geometricVariation;
  return v;
}

/// One way of one line: the vertices after the seed, in tracing order.
struct Way {
  std::size_t line = 0;
  int side = 0;  // 0 backward, 1 forward
  std::vector<CurvatureLineVertex> vertices;
  LineStop stop = LineStop::MaxSteps;
};

/// Where a committed vertex is: its line, way side and step (0 = the seed, shared by both ways).
struct VertexTag {
  std::size_t line;
  int side;
  int step;
  Vec3 position;
};

/// Uniform hash grid of cell side `cell` over the committed vertices: the collision queries
/// look at the 27 cells around a point.
class VertexGrid {
 public:
  explicit VertexGrid(double cell) : inverse_(1 / cell) {}
  void insert(const VertexTag& tag) { cells_[key(cellOf(tag.position))].push_back(tag); }
  template <class Visit>
  void forEachNear(const Vec3& p, Visit&& visit) const {
    const Eigen::Vector3i c = cellOf(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const VertexTag& tag : it->second) visit(tag);
        }
  }

 private:
  Eigen::Vector3i cellOf(const Vec3& p) const {
    return Eigen::Vector3i(int(std::floor(p.x() * inverse_)), int(std::floor(p.y() * inverse_)),
                           int(std::floor(p.z() * inverse_)));
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    auto part = [](int v) { return std::uint64_t(std::uint32_t(v) & 0x1FFFFF); };
    return part(c.x()) | (part(c.y()) << 21) | (part(c.z()) << 42);
  }
  double inverse_;
  std::unordered_map<std::uint64_t, std::vector<VertexTag>> cells_;
};

/// Steps between two vertices of one line along it (the seed is step 0 of both ways).
int stepsApart(int sideA, int stepA, int sideB, int stepB) {
  return sideA == sideB ? std::abs(stepA - stepB) : stepA + stepB;
}

}  // namespace

void validateCurvatureLineOptions(const CurvatureLineOptions& o) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  require(positive(o.scale), "CurvatureLineOptions::scale must be finite and > 0 (got " +
                                 std::to_string(o.scale) + ")");
  require(positive(o.beta), "CurvatureLineOptions::beta must be finite and > 0");
  require(positive(o.gamma), "CurvatureLineOptions::gamma must be finite and > 0");
  require(std::isfinite(o.alpha) && o.alpha >= 0 && o.alpha < 0.5,
          "CurvatureLineOptions::alpha must be in [0, 0.5): the pyramid samples are 2 alpha t "
          "apart and a fit needs several within t");
  require(hasPrincipalDirections(o.fit.estimator),
          std::string("CurvatureLineOptions::fit.estimator must give principal directions (w3, "
                      "w2, quadric or jet), not ") +
              estimatorName(o.fit.estimator));
  require(o.fit.mls,
          "CurvatureLineOptions::fit.mls must be on: the vertices are MLS-projected "
          "onto the surface (Eq. 3.2)");
  validateFitOptions(o.fit);
  require(std::isfinite(o.minAnisotropy) && o.minAnisotropy >= 0,
          "CurvatureLineOptions::minAnisotropy must be finite and >= 0");
  require(std::isfinite(o.minCurvatureGap) && o.minCurvatureGap >= 0 && o.minCurvatureGap <= 1,
          "CurvatureLineOptions::minCurvatureGap must be in [0, 1]");
  require(std::isfinite(o.borderOffset) && o.borderOffset >= 0,
          "CurvatureLineOptions::borderOffset must be finite and >= 0");
  require(std::isfinite(o.maxTurnDegrees) && o.maxTurnDegrees > 0 && o.maxTurnDegrees <= 180,
          "CurvatureLineOptions::maxTurnDegrees must be in (0, 180]");
  require(std::isfinite(o.maxProjectionShift) && o.maxProjectionShift > 0,
          "CurvatureLineOptions::maxProjectionShift must be finite and > 0");
  require(std::isfinite(o.collisionFraction) && o.collisionFraction >= 0,
          "CurvatureLineOptions::collisionFraction must be finite and >= 0");
  require(o.maxSteps >= 1 && o.maxSteps <= 1000000,
          "CurvatureLineOptions::maxSteps must be in [1, 1000000]");
}

std::vector<Index> lineSamples(const std::vector<Vec3>& positions, double alpha, double t,
                               std::uint64_t seed) {
  std::vector<Index> all(positions.size());
  std::iota(all.begin(), all.end(), Index(0));
  return samplePyramidLevel(positions, all, alpha, t, seed, 0);  // alpha = 0 keeps every point
}

namespace {

/// Traces the lines of one scale: a pool of at most `poolSize` lines advances in rounds, one step
/// of every active way per round and one call of the shared fit driver per round. When lines end,
/// the next seeds (in the seeded random order) start lines in their place, unless they lie on a
/// line already drawn. A way stops on any vertex placed in an earlier round by another line, or
/// in the same round by a line started before it. Everything is decided per round from the state
/// of the previous one, so the result depends on the pool size (a function of the seed count), not
/// on the thread count. A small pool approaches the sequential tracer (each line runs until it
/// meets an earlier one) that a pool of one would be.
class LineTracer {
 public:
  LineTracer(const CurvatureLineOptions& options, const SurfaceSamples& samples,
             CurvatureLineSet& result)
      : options_(options),
        samples_(samples),
        result_(result),
        t_(options.scale),
        delta_(options.gamma * options.scale),
        collision_(options.collisionFraction * delta_),
        closing_(delta_ + 2 * collision_),
        maxShift_(options.maxProjectionShift * delta_),
        cosTurn_(std::cos(options.maxTurnDegrees * M_PI / 180)),
        placed_(std::max(collision_, 1e-9 * options.scale)) {
    fitOptions_.fit = options.fit;
  }

  /// The fits at the seeds (counted in CurvatureLineSet::fits): all of them before tracing, so
  /// that the seeds can be ordered by their curvature (CurvatureLineOptions::curvedSeedsFirst).
  std::vector<LocalFit> fitSeeds(const std::vector<Vec3>& seedPositions) {
    return fit(seedPositions);
  }

  /// `seedFits`: the fit at each seed position (the seeds' order).
  void trace(const std::vector<Index>& seeds, const std::vector<LocalFit>& seedFits,
             std::size_t poolSize, const std::function<void(double)>& progress) {
    std::size_t next = 0;
    std::vector<std::size_t> active;  // ways, by increasing id
    while (next < seeds.size() || !active.empty()) {
      progress(double(next) / double(std::max<std::size_t>(1, seeds.size())));
      const std::size_t want = poolSize > active.size() / 2 ? poolSize - active.size() / 2 : 0;
      if (want > 0 && next < seeds.size()) {
        const std::size_t end = std::min(seeds.size(), next + want);
        startLines(seeds, seedFits, next, end, active);
        next = end;
      }
      if (!active.empty()) step(active);
    }
    // Lines in the order their seeds started them.
    for (Line& line : lines_) {
      CurvatureLine out = assemble(line);
      ++result_.stops[std::size_t(out.stopBackward)];
      ++result_.stops[std::size_t(out.stopForward)];
      if (out.vertices.size() >= 2) result_.lines.push_back(std::move(out));
    }
  }

 private:
  struct Line {
    Index seed;
    CurvatureLineVertex start;
    std::size_t ways[2];  // backward, forward
  };

  std::vector<LocalFit> fit(const std::vector<Vec3>& queries) {
    result_.fits += queries.size();
    return fitPoints(samples_, FitQueries{queries, scales_}, fitOptions_);
  }

  /// Starts a line at each projected seed of [first, end) with a minimal direction, inside the
  /// data and away from the lines drawn so far (those started just before it included).
  void startLines(const std::vector<Index>& seeds, const std::vector<LocalFit>& seedFits,
                  std::size_t first, std::size_t end, std::vector<std::size_t>& active) {
    std::vector<Neighbor> found;
    for (std::size_t s = 0; s < end - first; ++s) {
      const LocalFit& f = seedFits[first + s];
      if (!f.valid) {
        ++result_.stops[std::size_t(LineStop::InvalidFit)];
        continue;
      }
      const MinimalDirection m = minimalDirection(f);
      if (nearUmbilic(m, t_, options_)) {
        ++result_.stops[std::size_t(LineStop::Umbilic)];
        continue;
      }
      result_.seedKappa1.push_back(std::abs(m.kappa1));
      if (atBorder(f.projection, f.normal, found)) {
        ++result_.stops[std::size_t(LineStop::Border)];
        continue;
      }
      if (nearAnyLine(f.projection)) continue;
      const std::size_t id = lines_.size();
      lines_.push_back(
          {seeds[first + s], makeVertex(f, m, m.direction), {ways_.size(), ways_.size() + 1}});
      for (int side = 0; side < 2; ++side) {
        active.push_back(ways_.size());
        ways_.push_back(Way{id, side, {}, LineStop::MaxSteps});
      }
      placed_.insert({id, 0, 0, f.projection});
    }
  }

  /// The border test of CurvatureLineOptions::borderOffset.
  bool atBorder(const Vec3& p, const Vec3& normal, std::vector<Neighbor>& found) const {
    if (options_.borderOffset <= 0) return false;
    samples_.index.radiusSearch(p, t_, found);
    if (found.empty()) return true;
    Vec3 centroid = Vec3::Zero();
    for (const Neighbor& nb : found) centroid += samples_.positions[nb.index];
    Vec3 offset = centroid / double(found.size()) - p;
    offset -= offset.dot(normal) * normal;
    // Inside the data the centroid of n samples spread over a disc of radius t wanders by about
    // sigma = t / (2 sqrt(n)) per axis: a bound below 4 sigma would stop lines at random (8% of
    // the steps with 32 samples at 0.2 t; 0.03% at 4 sigma).
    const double sigma = t_ / (2 * std::sqrt(double(found.size())));
    return offset.norm() > std::max(options_.borderOffset * t_, 4 * sigma);
  }

  bool nearAnyLine(const Vec3& p) const {
    bool near = false;
    placed_.forEachNear(p, [&](const VertexTag& tag) {
      near = near || (tag.position - p).squaredNorm() < collision_ * collision_;
    });
    return near;
  }

  const CurvatureLineVertex& last(const Way& w) const {
    return w.vertices.empty() ? lines_[w.line].start : w.vertices.back();
  }
  Vec3 heading(const Way& w) const {
    const Vec3 tangent = last(w).tangent;
    return (w.vertices.empty() && w.side == 0) ? Vec3(-tangent) : tangent;
  }

  /// One round: every active way takes one step (Eq. 3.2).
  void step(std::vector<std::size_t>& active) {
    std::vector<Vec3> queries(active.size());
    for (std::size_t a = 0; a < active.size(); ++a) {
      const Way& w = ways_[active[a]];
      queries[a] = last(w).position + delta_ * heading(w);
    }
    const std::vector<LocalFit> fits = fit(queries);
    std::vector<CurvatureLineVertex> candidate(active.size());
    std::vector<std::uint8_t> outcome(active.size());  // 0 go on, else 1 + LineStop
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active.size(), 64), [&](const auto& r) {
      std::vector<Neighbor> found;
      for (std::size_t a = r.begin(); a != r.end(); ++a) {
        const Way& w = ways_[active[a]];
        const int stepIndex = int(w.vertices.size()) + 1;
        const LineStop stop =
            stepOutcome(fits[a], last(w).position, heading(w), queries[a], candidate[a], found);
        outcome[a] = stop == LineStop::MaxSteps ? 0 : std::uint8_t(1 + int(stop));
        if (outcome[a] || collision_ <= 0) continue;
        const Vec3& p = candidate[a].position;
        outcome[a] = meeting(placed_, w, stepIndex, p);
      }
    });
    // Vertices of this round, in way order (lines started earlier first): one that comes within
    // the collision distance of a vertex kept before it in this round stops its way.
    if (collision_ > 0) {
      VertexGrid round(collision_);
      for (std::size_t a = 0; a < active.size(); ++a) {
        if (outcome[a]) continue;
        const Way& w = ways_[active[a]];
        const int stepIndex = int(w.vertices.size()) + 1;
        const Vec3& p = candidate[a].position;
        outcome[a] = meeting(round, w, stepIndex, p);
        if (!outcome[a]) round.insert({w.line, w.side, stepIndex, p});
      }
    }
    std::vector<std::size_t> next;
    next.reserve(active.size());
    for (std::size_t a = 0; a < active.size(); ++a) {
      Way& w = ways_[active[a]];
      if (outcome[a]) {
        w.stop = LineStop(outcome[a] - 1);
        continue;
      }
      w.vertices.push_back(candidate[a]);
      if (collision_ > 0)
        placed_.insert({w.line, w.side, int(w.vertices.size()), candidate[a].position});
      if (int(w.vertices.size()) < options_.maxSteps)
        next.push_back(active[a]);
      else
        w.stop = LineStop::MaxSteps;
    }
    active.swap(next);
  }

  /// 0 when the vertex `p` of way `w` at step `stepIndex` meets no vertex of `grid` within the
  /// collision distance, else 1 + Collision (another line's) or 1 + Loop (its own line's, more
  /// than 3 steps away along it: nearer ones are its neighbours).
  std::uint8_t meeting(const VertexGrid& grid, const Way& w, int stepIndex, const Vec3& p) const {
    std::uint8_t out = 0;
    grid.forEachNear(p, [&](const VertexTag& tag) {
      if (out || (tag.position - p).squaredNorm() >= collision_ * collision_) return;
      if (tag.line != w.line)
        out = 1 + int(LineStop::Collision);
      else if (stepsApart(w.side, stepIndex, tag.side, tag.step) > 3)
        out = 1 + int(LineStop::Loop);
    });
    return out;
  }

  /// What one step gives: MaxSteps (meaning "go on") and the new vertex, or why the way stops.
  /// `predicted` is q_n + delta v, the point the fit projected.
  LineStop stepOutcome(const LocalFit& f, const Vec3& from, const Vec3& previous,
                       const Vec3& predicted, CurvatureLineVertex& vertex,
                       std::vector<Neighbor>& found) const {
    if (!f.valid) return LineStop::InvalidFit;
    if ((f.projection - from).norm() < 0.1 * delta_) return LineStop::Stalled;
    // Projected off the sheet of q_n (across a crease, or onto another sheet within t): the
    // vertex would be far from the line, and the edge to it would cut across the shape.
    if ((f.projection - predicted).norm() > maxShift_) return LineStop::Jump;
    if (atBorder(f.projection, f.normal, found)) return LineStop::Border;
    const MinimalDirection m = minimalDirection(f);
    if (nearUmbilic(m, t_, options_)) return LineStop::Umbilic;
    const Vec3 tangent = m.direction.dot(previous) >= 0 ? m.direction : Vec3(-m.direction);
    if (tangent.dot(previous) < cosTurn_) return LineStop::Turn;
    vertex = makeVertex(f, m, tangent);
    return LineStop::MaxSteps;
  }

  /// The backward way reversed (its tangents turned to the line's direction), the seed, the
  /// forward way. A way that met its own line closes it only when the line's two ends meet
  /// (within closing_); one that met it elsewhere (a spiral meeting its previous turn, a way
  /// curling onto itself) stopped on a self collision and leaves the line open: closing it would
  /// join two far-apart vertices with one long edge across the shape.
  CurvatureLine assemble(const Line& l) const {
    const Way &back = ways_[l.ways[0]], &forward = ways_[l.ways[1]];
    CurvatureLine line;
    line.seed = l.seed;
    line.stopBackward = back.stop;
    line.stopForward = forward.stop;
    line.vertices.reserve(back.vertices.size() + 1 + forward.vertices.size());
    for (auto it = back.vertices.rbegin(); it != back.vertices.rend(); ++it) {
      line.vertices.push_back(*it);
      line.vertices.back().tangent = -it->tangent;
    }
    line.vertices.push_back(l.start);
    line.vertices.insert(line.vertices.end(), forward.vertices.begin(), forward.vertices.end());
    const bool loop = back.stop == LineStop::Loop || forward.stop == LineStop::Loop;
    line.closed =
        loop && line.vertices.size() > 2 &&
        (line.vertices.front().position - line.vertices.back().position).norm() <= closing_;
    if (loop && !line.closed) {
      if (line.stopBackward == LineStop::Loop) line.stopBackward = LineStop::SelfCollision;
      if (line.stopForward == LineStop::Loop) line.stopForward = LineStop::SelfCollision;
    }
    return line;
  }

  const CurvatureLineOptions& options_;
  const SurfaceSamples& samples_;
  CurvatureLineSet& result_;
  const double t_, delta_, collision_, closing_, maxShift_, cosTurn_;
  FitPointsOptions fitOptions_;
  const std::vector<double> scales_{options_.scale};
  std::vector<Line> lines_;
  std::vector<Way> ways_;
  VertexGrid placed_;  // every vertex placed so far
};

}  // namespace

CurvatureLineSet traceCurvatureLines(const PointCloud& cloud, const CurvatureLineOptions& options,
                                     const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  validateCurvatureLineOptions(options);
  CurvatureLineSet result;
  result.scale = options.scale;
  result.stops.assign(std::size_t(LineStop::MaxSteps) + 1, 0);
  if (cloud.empty()) return result;
  require(cloud.hasNormals(),
          "traceCurvatureLines: the cloud has no normals (the APSS fits need oriented normals)");
  const double t = options.scale;
  auto check = [&](double fraction, const char* stage) {
    if (progress && !progress(fraction, stage)) throw Cancelled();
  };

  // The surface at scale t: the pyramid level's samples (Sec. 1.5.2).
  const std::vector<Index> sampleIds =
      lineSamples(cloud.positions(), options.alpha, t, options.seed);
  std::vector<Vec3> positions(sampleIds.size()), normals(sampleIds.size());
  for (std::size_t s = 0; s < sampleIds.size(); ++s) {
    positions[s] = cloud.positions()[sampleIds[s]];
    normals[s] = cloud.normals()[sampleIds[s]];
  }
  result.samples = positions.size();
  const auto index = makeSpatialIndex(positions);
  const SurfaceSamples samples{positions, normals, *index};
  check(0, "seeds");

  // Seeds: Poisson disk of radius beta t among the samples (separation 2 beta t), traced in a
  // seeded random order (spread over the shape, as a sequential tracer would pick them).
  std::vector<Index> seeds =
      poissonDiskSample(cloud.positions(), sampleIds, 2 * options.beta * t, options.seed + 1);
  result.seeds = seeds.size();
  std::sort(seeds.begin(), seeds.end(), [&](Index a, Index b) {
    const auto ka = sampleOrderKey(options.seed + 2, a), kb = sampleOrderKey(options.seed + 2, b);
    return ka != kb ? ka < kb : a < b;
  });
  // The pool's size depends on the seed count only (never on the threads): large enough for
  // each round's fits to fill the cores, small enough that concurrent lines rarely share a line's
  // path (they would cut it into pieces).
  const std::size_t pool = std::max<std::size_t>(32, seeds.size() / 128);
  std::vector<Vec3> seedPositions(seeds.size());
  for (std::size_t s = 0; s < seeds.size(); ++s) seedPositions[s] = cloud.positions()[seeds[s]];
  LineTracer tracer(options, samples, result);
  std::vector<LocalFit> seedFits = tracer.fitSeeds(seedPositions);
  if (options.curvedSeedsFirst) {
    // The most curved seeds first (|kappa1| t, decreasing; seeds without a minimal direction
    // last), in the random order among equals: lines on creases and ridges are traced before
    // the lines beside them can block their seeds or cut them (docs/THESIS_NOTES.md).
    std::vector<double> key(seeds.size(), -1);
    for (std::size_t s = 0; s < seeds.size(); ++s) {
      const LocalFit& f = seedFits[s];
      if (!f.valid) continue;
      const MinimalDirection m = minimalDirection(f);
      if (!nearUmbilic(m, t, options)) key[s] = std::abs(m.kappa1) * t;
    }
    std::vector<std::size_t> order(seeds.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return key[a] > key[b]; });
    std::vector<Index> sortedSeeds(seeds.size());
    std::vector<LocalFit> sortedFits(seeds.size());
    for (std::size_t s = 0; s < order.size(); ++s) {
      sortedSeeds[s] = seeds[order[s]];
      sortedFits[s] = std::move(seedFits[order[s]]);
    }
    seeds.swap(sortedSeeds);
    seedFits.swap(sortedFits);
  }
  tracer.trace(seeds, seedFits, pool,
               [&](double fraction) { check(fraction, "tracing curvature lines"); });
  check(1, "tracing curvature lines");
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scalespace
