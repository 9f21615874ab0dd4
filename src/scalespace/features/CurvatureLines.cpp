#include "scalespace/features/CurvatureLines.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
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
  bool active = true;
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
  require(std::isfinite(o.collisionFraction) && o.collisionFraction >= 0,
          "CurvatureLineOptions::collisionFraction must be finite and >= 0");
  require(o.maxSteps >= 1 && o.maxSteps <= 1000000,
          "CurvatureLineOptions::maxSteps must be in [1, 1000000]");
}

std::vector<Index> lineSamples(const std::vector<Vec3>& positions, double alpha, double t,
                               std::uint64_t seed) {
  std::vector<Index> all(positions.size());
  std::iota(all.begin(), all.end(), Index(0));
  if (alpha <= 0) return all;
  return poissonDiskSample(positions, all, poissonDiskSeparation(alpha, t),
                           pyramidLevelSeed(seed, 0));
}

namespace {

/// Traces the lines of one scale. Sequential tracing (Kalogerakis 2009: each line runs until it
/// meets an earlier one) is what the result reproduces, but lines are traced in batches so that
/// each step of a batch is one call of the shared fit driver: a batch's lines advance together,
/// stop on the lines of earlier batches as they go, and are then cut, in line order, where they
/// meet an earlier line of their own batch. A line's path depends on its own fits only, so this
/// gives exactly the sequential result, for any thread count.
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
        cosTurn_(std::cos(options.maxTurnDegrees * M_PI / 180)),
        lines_(std::max(collision_, 1e-9 * t_)) {
    fitOptions_.fit = options.fit;
  }

  /// Traces the lines of `seeds` (input points, in tracing order) and appends them to the result.
  void traceBatch(const std::vector<Index>& seeds, const std::vector<Vec3>& seedPositions) {
    const std::vector<Start> starts = startLines(seeds, seedPositions);
    std::vector<Way> ways(2 * starts.size());
    for (std::size_t l = 0; l < starts.size(); ++l) {
      ways[2 * l] = Way{l, 0, {}, true, LineStop::MaxSteps};
      ways[2 * l + 1] = Way{l, 1, {}, true, LineStop::MaxSteps};
    }
    advance(starts, ways);
    keepUntilEarlierLines(starts, ways);
  }

 private:
  struct Start {
    Index seed;
    CurvatureLineVertex vertex;
  };

  std::vector<LocalFit> fit(const std::vector<Vec3>& queries) {
    result_.fits += queries.size();
    return fitPoints(samples_, FitQueries{queries, scales_}, fitOptions_);
  }

  /// The projected seeds with a minimal direction, away from the lines traced so far.
  std::vector<Start> startLines(const std::vector<Index>& seeds,
                                const std::vector<Vec3>& seedPositions) {
    const std::vector<LocalFit> fits = fit(seedPositions);
    std::vector<Start> starts;
    std::vector<Neighbor> found;
    for (std::size_t s = 0; s < seeds.size(); ++s) {
      const LocalFit& f = fits[s];
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
      if (nearEarlierLine(f.projection)) continue;
      starts.push_back({seeds[s], makeVertex(f, m, m.direction)});
    }
    return starts;
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
    return offset.norm() > options_.borderOffset * t_;
  }

  bool nearEarlierLine(const Vec3& p) const {
    bool near = false;
    lines_.forEachNear(p, [&](const VertexTag& tag) {
      near = near || (tag.position - p).squaredNorm() < collision_ * collision_;
    });
    return near;
  }

  /// Rounds: every active way takes one step (Eq. 3.2); one fitPoints call per round.
  void advance(const std::vector<Start>& starts, std::vector<Way>& ways) {
    auto last = [&](const Way& w) -> const CurvatureLineVertex& {
      return w.vertices.empty() ? starts[w.line].vertex : w.vertices.back();
    };
    auto heading = [&](const Way& w) -> Vec3 {
      const Vec3 tangent = last(w).tangent;
      return (w.vertices.empty() && w.side == 0) ? Vec3(-tangent) : tangent;
    };
    // The batch's own vertices, for loops (a line meeting itself).
    VertexGrid own(std::max(collision_, 1e-9 * t_));
    for (std::size_t l = 0; l < starts.size(); ++l)
      own.insert({l, 0, 0, starts[l].vertex.position});

    std::vector<std::size_t> active(ways.size());
    std::iota(active.begin(), active.end(), std::size_t(0));
    std::vector<CurvatureLineVertex> candidate(ways.size());
    std::vector<std::uint8_t> outcome(ways.size());  // 0 continue, else 1 + LineStop
    std::vector<Vec3> queries;
    const double d2 = collision_ * collision_;
    for (int step = 1; !active.empty(); ++step) {
      queries.resize(active.size());
      for (std::size_t a = 0; a < active.size(); ++a) {
        const Way& w = ways[active[a]];
        queries[a] = last(w).position + delta_ * heading(w);
      }
      const std::vector<LocalFit> fits = fit(queries);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active.size(), 64), [&](const auto& r) {
        std::vector<Neighbor> found;
        for (std::size_t a = r.begin(); a != r.end(); ++a) {
          const std::size_t id = active[a];
          const Way& w = ways[id];
          const LineStop stop =
              stepOutcome(fits[a], last(w).position, heading(w), candidate[id], found);
          outcome[id] = stop == LineStop::MaxSteps ? 0 : std::uint8_t(1 + int(stop));
          if (outcome[id] || collision_ <= 0) continue;
          const Vec3& p = candidate[id].position;
          lines_.forEachNear(p, [&](const VertexTag& tag) {
            if (!outcome[id] && (tag.position - p).squaredNorm() < d2)
              outcome[id] = 1 + int(LineStop::Collision);
          });
          own.forEachNear(p, [&](const VertexTag& tag) {
            if (!outcome[id] && tag.line == w.line && (tag.position - p).squaredNorm() < d2 &&
                stepsApart(w.side, step, tag.side, tag.step) > 3)
              outcome[id] = 1 + int(LineStop::Loop);
          });
        }
      });
      // The two ways of a line meeting in the same round close it.
      for (std::size_t a = 0; a + 1 < active.size(); ++a) {
        const std::size_t back = active[a], forward = active[a + 1];
        if (forward != back + 1 || back % 2 || outcome[back] || outcome[forward]) continue;
        if ((candidate[back].position - candidate[forward].position).squaredNorm() < d2 &&
            2 * step > 3)
          outcome[back] = outcome[forward] = 1 + int(LineStop::Loop);
      }
      std::vector<std::size_t> next;
      for (const std::size_t id : active) {
        Way& w = ways[id];
        if (outcome[id]) {
          w.stop = LineStop(outcome[id] - 1);
          continue;
        }
        w.vertices.push_back(candidate[id]);
        if (collision_ > 0) own.insert({w.line, w.side, step, candidate[id].position});
        if (step < options_.maxSteps) next.push_back(id);
      }
      active.swap(next);
    }
  }

  /// What one step gives: MaxSteps (meaning "go on") and the new vertex, or why the way stops.
  LineStop stepOutcome(const LocalFit& f, const Vec3& from, const Vec3& previous,
                       CurvatureLineVertex& vertex, std::vector<Neighbor>& found) const {
    if (!f.valid) return LineStop::InvalidFit;
    if ((f.projection - from).norm() < 0.1 * delta_) return LineStop::Stalled;
    if (atBorder(f.projection, f.normal, found)) return LineStop::Border;
    const MinimalDirection m = minimalDirection(f);
    if (nearUmbilic(m, t_, options_)) return LineStop::Umbilic;
    const Vec3 tangent = m.direction.dot(previous) >= 0 ? m.direction : Vec3(-m.direction);
    if (tangent.dot(previous) < cosTurn_) return LineStop::Turn;
    vertex = makeVertex(f, m, tangent);
    return LineStop::MaxSteps;
  }

  /// Cuts each line of the batch, in line order, at its first vertex (from the seed outwards)
  /// within the collision distance of an earlier line of the batch (as cut), drops lines whose
  /// seed is there, and adds the rest to the result and to the lines the next batches stop on.
  void keepUntilEarlierLines(const std::vector<Start>& starts, std::vector<Way>& ways) {
    VertexGrid kept(std::max(collision_, 1e-9 * t_));
    const double d2 = collision_ * collision_;
    auto blocked = [&](const Vec3& p) {
      bool near = false;
      kept.forEachNear(
          p, [&](const VertexTag& tag) { near = near || (tag.position - p).squaredNorm() < d2; });
      return near;
    };
    for (std::size_t l = 0; l < starts.size(); ++l) {
      Way &back = ways[2 * l], &forward = ways[2 * l + 1];
      if (collision_ > 0 && blocked(starts[l].vertex.position)) {
        ++result_.stops[std::size_t(LineStop::Collision)];
        continue;
      }
      for (Way* w : {&back, &forward}) {
        if (collision_ <= 0) break;
        for (std::size_t i = 0; i < w->vertices.size(); ++i)
          if (blocked(w->vertices[i].position)) {
            w->vertices.resize(i);
            w->stop = LineStop::Collision;
            break;
          }
      }
      ++result_.stops[std::size_t(back.stop)];
      ++result_.stops[std::size_t(forward.stop)];
      CurvatureLine line = assemble(starts[l], back, forward);
      if (line.vertices.size() < 2) continue;
      for (const CurvatureLineVertex& v : line.vertices) {
        kept.insert({l, 0, 0, v.position});
        lines_.insert({result_.lines.size(), 0, 0, v.position});
      }
      result_.lines.push_back(std::move(line));
    }
  }

  /// The backward way reversed (its tangents turned to the line's direction), the seed, the
  /// forward way.
  static CurvatureLine assemble(const Start& start, const Way& back, const Way& forward) {
    CurvatureLine line;
    line.seed = start.seed;
    line.stopBackward = back.stop;
    line.stopForward = forward.stop;
    line.closed = back.stop == LineStop::Loop || forward.stop == LineStop::Loop;
    line.vertices.reserve(back.vertices.size() + 1 + forward.vertices.size());
    for (auto it = back.vertices.rbegin(); it != back.vertices.rend(); ++it) {
      line.vertices.push_back(*it);
      line.vertices.back().tangent = -it->tangent;
    }
    line.vertices.push_back(start.vertex);
    line.vertices.insert(line.vertices.end(), forward.vertices.begin(), forward.vertices.end());
    return line;
  }

  const CurvatureLineOptions& options_;
  const SurfaceSamples& samples_;
  CurvatureLineSet& result_;
  const double t_, delta_, collision_, cosTurn_;
  FitPointsOptions fitOptions_;
  const std::vector<double> scales_{options_.scale};
  VertexGrid lines_;  // vertices of the lines kept so far
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
  // Batches of a size that depends on the seed count only (never on the threads).
  const std::size_t batch = std::max<std::size_t>(256, seeds.size() / 32);
  LineTracer tracer(options, samples, result);
  for (std::size_t first = 0; first < seeds.size(); first += batch) {
    check(double(first) / double(seeds.size()), "tracing curvature lines");
    const std::vector<Index> part(
        seeds.begin() + std::ptrdiff_t(first),
        seeds.begin() + std::ptrdiff_t(std::min(seeds.size(), first + batch)));
    std::vector<Vec3> seedPositions(part.size());
    for (std::size_t s = 0; s < part.size(); ++s) seedPositions[s] = cloud.positions()[part[s]];
    tracer.traceBatch(part, seedPositions);
  }
  check(1, "tracing curvature lines");
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scalespace
