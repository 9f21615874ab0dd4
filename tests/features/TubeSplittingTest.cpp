// Splitting a region by the axes its points propose (features/TubeSplitting): three strands side by
// side, whose points near a contact propose axes anywhere between them, come apart, one per
// strand; one tube, straight or bent, does not.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "scalespace/core/Error.hpp"
#include "scalespace/features/TubeSplitting.hpp"

using namespace scalespace;

namespace {

struct Scene {
  std::vector<Vec3> positions, normals;
  std::vector<float> kappa1;
  std::vector<int> strand;
};

/// Three strands of radius r along x, axes on a circle of radius 1.2 r about the x axis (they
/// touch, as a cable's do). A point within `contact` of another strand gets what a fit spanning
/// both reads: a curvature radius between r and 3 r and its normal turned by up to 30 degrees,
/// so that it proposes an axis point anywhere between the strands.
Scene cable(double r, double contact, std::size_t perStrand, std::mt19937_64& rng,
            double blurHalfLength = 0) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> axes;
  for (int k = 0; k < 3; ++k) {
    const double phi = 2 * kPi * k / 3;
    axes.emplace_back(0, 1.2 * r * std::cos(phi), 1.2 * r * std::sin(phi));
  }
  Scene s;
  for (int k = 0; k < 3; ++k)
    for (std::size_t n = 0; n < perStrand;) {
      const double a = 2 * kPi * u(rng), x = -1 + 2 * u(rng);
      const Vec3 normal(0, std::cos(a), std::sin(a));
      const Vec3 p = axes[std::size_t(k)] + Vec3(x, 0, 0) + r * normal;
      double gap = 1e9;
      for (int j = 0; j < 3; ++j)
        if (j != k) gap = std::min(gap, (p - axes[std::size_t(j)] - Vec3(x, 0, 0)).norm() - r);
      if (gap < 0) continue;  // inside another strand: hidden
      ++n;
      Vec3 readNormal = normal;
      double radius = r;
      // Strand 0 may also read its curvature as badly as a contact over |x| < blurHalfLength.
      if (gap < contact || (k == 0 && std::abs(x) < blurHalfLength)) {
        const double turn = (2 * u(rng) - 1) * kPi / 6;
        readNormal = Eigen::AngleAxisd(turn, Vec3::UnitX()) * normal;
        radius = r * (1 + 2 * u(rng));
      }
      s.positions.push_back(p);
      s.normals.push_back(readNormal);
      s.kappa1.push_back(float(1 / radius));
      s.strand.push_back(k);
    }
  return s;
}

std::vector<Index> all(const Scene& s) {
  std::vector<Index> points(s.positions.size());
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = Index(i);
  return points;
}

/// splitIntoThinnerTubes on the whole cloud fitted as one tube at scale t, the input normals
/// taken as the scale's.
std::vector<ThinTube> splitCable(const Scene& s, double t, const TubeSplitOptions& options) {
  const TubeFit whole = fitTube(s.positions, s.normals, s.normals, s.kappa1, all(s), t);
  return splitIntoThinnerTubes(s.positions, s.normals, s.normals, s.kappa1, all(s), whole, t, {},
                               options);
}

}  // namespace

TEST(TubeSplitting, ACablesStrandsComeApartOnePartEach) {
  std::mt19937_64 rng(1);
  const double r = 0.05, t = 0.04;
  const Scene s = cable(r, 0.6 * r, 6000, rng);
  const auto parts = splitByProposedAxes(s.positions, s.normals, s.kappa1, all(s), t, 0.02, 30);
  ASSERT_EQ(parts.size(), 3u);
  std::set<int> strands;
  std::size_t held = 0;
  for (const std::vector<Index>& part : parts) {
    EXPECT_TRUE(std::is_sorted(part.begin(), part.end()));
    std::size_t count[3] = {0, 0, 0};
    for (const Index i : part) ++count[s.strand[i]];
    const int major = int(std::max_element(count, count + 3) - count);
    strands.insert(major);
    // Every point of a part is of one strand: the contacts' proposals lie in sparse cells.
    EXPECT_GE(double(count[major]), 0.99 * double(part.size()));
    held += part.size();
  }
  EXPECT_EQ(strands.size(), 3u);
  EXPECT_GE(double(held), 0.5 * double(s.positions.size()));

  // Without the contacts' scatter the three axes are three lines of proposals.
  std::mt19937_64 rng2(2);
  const Scene clean = cable(r, 0, 4000, rng2);
  EXPECT_EQ(
      splitByProposedAxes(clean.positions, clean.normals, clean.kappa1, all(clean), t, 0.02, 30)
          .size(),
      3u);

  TubeSplitOptions off;
  off.enabled = false;
  EXPECT_TRUE(
      splitByProposedAxes(s.positions, s.normals, s.kappa1, all(s), t, 0.02, 30, off).empty());
}

TEST(TubeSplitting, OneTubeStraightOrBentDoesNotSplit) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  Scene straight, bent;
  const double r = 0.1, bend = 0.6;
  for (int n = 0; n < 20000; ++n) {
    const double a = 2 * kPi * u(rng), x = -1 + 2 * u(rng);
    const Vec3 normal(0, std::cos(a), std::sin(a));
    straight.positions.push_back(Vec3(x, 0, 0) + r * normal);
    straight.normals.push_back(normal);
    // A curvature read up to 20% off, the error varying along the tube as a fit's does (the fits
    // of neighbours share most of their points).
    straight.kappa1.push_back(float(1 / (r * (1 + 0.2 * std::sin(5 * x + a)))));
    // A torus section (a 90-degree elbow), curvature radius bend about the z axis.
    const double b = 0.5 * kPi * u(rng);
    const Vec3 radial(std::cos(b), std::sin(b), 0);
    const Vec3 tn = std::cos(a) * radial + std::sin(a) * Vec3::UnitZ();
    bent.positions.push_back(bend * radial + r * tn);
    bent.normals.push_back(tn);
    bent.kappa1.push_back(float(1 / (r * (1 + 0.2 * std::sin(8 * b + a)))));
  }
  // The bent one's proposals are one part at every density level.
  EXPECT_TRUE(
      splitByProposedAxes(bent.positions, bent.normals, bent.kappa1, all(bent), 0.05, 0.02, 30)
          .empty());
  // The straight one's fall apart along its length at a high level (where the error spreads
  // them most the density dips), but its points read their own tube's radius: never split.
  for (const Scene* s : {&straight, &bent}) {
    const TubeFit whole = fitTube(s->positions, s->normals, s->normals, s->kappa1, all(*s), 0.05);
    ASSERT_TRUE(whole.isTube()) << tubeRejectionName(whole.rejection);
    EXPECT_TRUE(splitIntoThinnerTubes(s->positions, s->normals, s->normals, s->kappa1, all(*s),
                                      whole, 0.05, {})
                    .empty());
  }
}

TEST(TubeSplitting, ACableFittedAsOneTubeSplitsIntoItsStrands) {
  std::mt19937_64 rng(4);
  const double r = 0.05, t = 0.04;
  const Scene s = cable(r, 0.6 * r, 6000, rng);
  const TubeFit whole = fitTube(s.positions, s.normals, s.normals, s.kappa1, all(s), t);
  // Fitted as one tube, these straight strands read 1.42 r (the pipe rack's twisted cable, 1.8 r:
  // bench_cylinders); the strands' curvature radius, r, is under 0.75 of it.
  EXPECT_GT(whole.radius, 1.4 * r);
  TubeSplitOptions options;
  options.maxRadiusRatio = 0.75;
  const std::vector<ThinTube> strands = splitCable(s, t, options);
  ASSERT_EQ(strands.size(), 3u);
  for (const ThinTube& strand : strands) {
    EXPECT_TRUE(strand.tube.isTube());
    EXPECT_NEAR(strand.tube.radius, r, 0.05 * r);
    EXPECT_TRUE(strand.tube.straight);
  }
  // At the default 0.6 the tube is not thick enough to hold thinner ones.
  EXPECT_TRUE(splitCable(s, t, {}).empty());
  options.enabled = false;
  EXPECT_TRUE(splitCable(s, t, options).empty());
}

TEST(TubeSplitting, AStrandCutAcrossByTheDensityLevelsIsJoinedAgain) {
  // Strand 0 reads its curvature as badly as a contact over a stretch of 2 r: its proposals thin
  // out there, and the density levels cut it in two pieces end to end, which are joined again.
  std::mt19937_64 rng(6);
  const double r = 0.05, t = 0.04;
  const Scene s = cable(r, 0.6 * r, 6000, rng, r);
  EXPECT_EQ(splitByProposedAxes(s.positions, s.normals, s.kappa1, all(s), t, 0.02, 30).size(), 4u);
  TubeSplitOptions options;
  options.maxRadiusRatio = 0.75;
  const std::vector<ThinTube> strands = splitCable(s, t, options);
  ASSERT_EQ(strands.size(), 3u);
  for (const ThinTube& strand : strands) {
    EXPECT_NEAR(strand.tube.radius, r, 0.05 * r);
    EXPECT_GT(strand.tube.length, 1.8);  // the whole strand, x in [-1, 1]
  }
}

TEST(TubeSplitting, AnAxisContinuesAnotherOnlyEndToEndOnItsLine) {
  const auto tubeAlong = [](std::vector<Vec3> axis) {
    TubeFit fit;
    fit.axis = std::move(axis);
    return fit;
  };
  const double r = 0.05;
  const TubeFit a = tubeAlong({Vec3(-1, 0, 0), Vec3(-0.5, 0, 0), Vec3(0, 0, 0)});
  // The next piece of the same strand, 2 r on, its axis bent by 5 degrees.
  const Vec3 bent(std::cos(5 * kPi / 180), std::sin(5 * kPi / 180), 0);
  const TubeFit b = tubeAlong({Vec3(2 * r, 0, 0), Vec3(2 * r, 0, 0) + 0.5 * bent});
  EXPECT_TRUE(continuesAxis(a, b, 3 * r, r));
  EXPECT_TRUE(continuesAxis(b, a, 3 * r, r));
  // Either order of the vertices: an axis has no direction.
  TubeFit reversed = b;
  std::reverse(reversed.axis.begin(), reversed.axis.end());
  EXPECT_TRUE(continuesAxis(a, reversed, 3 * r, r));
  // Too far on.
  EXPECT_FALSE(continuesAxis(a, tubeAlong({Vec3(4 * r, 0, 0), Vec3(1, 0, 0)}), 3 * r, r));
  // The run of the next strand of a cable scanned from one side: it begins where a ends, beside
  // it (two radii aside); a curved axis through both would bridge the two strands.
  EXPECT_FALSE(continuesAxis(a, tubeAlong({Vec3(r, 2 * r, 0), Vec3(1, 2 * r, 0)}), 3 * r, r));
  // A tube across a's end: b's end lies near a's line, a's end is off b's.
  EXPECT_FALSE(continuesAxis(a, tubeAlong({Vec3(2 * r, -0.5, 0), Vec3(2 * r, -r, 0)}), 3 * r, r));
  // The last segment of a noisy axis may point anywhere: a's tip 0.5 r aside of its line. The
  // direction over its last 2 r still leads to b, 3 r on; the last segment alone does not.
  std::vector<Vec3> noisy;
  for (int k = 0; k <= 50; ++k) noisy.emplace_back(-1 + 0.02 * k, 0, 0);
  noisy.back().y() = 0.5 * r;
  const TubeFit c = tubeAlong(noisy), d = tubeAlong({Vec3(3 * r, 0, 0), Vec3(1, 0, 0)});
  EXPECT_FALSE(continuesAxis(c, d, 4 * r, r));
  EXPECT_TRUE(continuesAxis(c, d, 4 * r, r, 2 * r));
  EXPECT_FALSE(continuesAxis(a, tubeAlong({Vec3(0, 0, 0)}), 3 * r, r));
}

TEST(TubeSplitting, OptionsAreChecked) {
  TubeSplitOptions o;
  EXPECT_NO_THROW(validateTubeSplitOptions(o));
  o.cellFactor = 0;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.minDensity = -1;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.maxRadiusRatio = 1.5;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.densitySteps = 0;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.linkRadius = 0.5;
  o.cellFactor = 0.01;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.minShare = 0.6;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.maxJoinGap = -1;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.maxJoinOffset = std::nan("");
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o = {};
  o.partRadiusDisagreement = 0.9;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
  o.partRadiusDisagreement = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(validateTubeSplitOptions(o));
  o = {};
  o.partMinArcDegrees = 400;
  EXPECT_THROW(validateTubeSplitOptions(o), OptionError);
}
