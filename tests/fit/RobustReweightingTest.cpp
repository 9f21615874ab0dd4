// The fused RIMLS re-weighting and the first (kernel-weighted) sums: every implementation
// (portable, AVX2, AVX-512) against a direct evaluation of the formula with std::exp, for every
// tail length of the 4- and 8-wide loops.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "scalespace/fit/OrientedSphereFit.hpp"
#include "scalespace/fit/RobustLanes.hpp"
#include "scalespace/fit/RobustReweighting.hpp"

using namespace scalespace;

namespace {

struct Reference {
  std::vector<double> rho;
  double sums[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  double change = 0;
  int used = 0;
};

Reference direct(const AlgebraicSphere& s, double invSr2, double invSn2, const NeighborColumns& c,
                 const std::vector<double>& previous) {
  Reference r;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const Vec3 q(c.qx[k], c.qy[k], c.qz[k]), n(c.nx[k], c.ny[k], c.nz[k]);
    const Vec3 g = s.gradient(q);
    double rho = 0;
    if (g.norm() > 0) {
      const double dist = s.value(q) / g.norm();
      rho = std::exp(-(dist * dist * invSr2 + (n - g.normalized()).squaredNorm() * invSn2));
    }
    r.rho.push_back(rho);
    r.change = std::max(r.change, std::abs(rho - previous[k]));
    const double w = c.weight[k] * rho;
    const double item[9] = {1, q.x(), q.y(), q.z(), n.x(), n.y(), n.z(), q.dot(n), q.squaredNorm()};
    for (int i = 0; i < 9; ++i) r.sums[i] += w * item[i];
    r.used += w > 0;
  }
  return r;
}

NeighborColumns randomNeighbors(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  NeighborColumns c;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 q(u(rng), u(rng), 0.2 * u(rng));
    const Vec3 normal = Vec3(0.3 * u(rng), 0.3 * u(rng), 1).normalized();
    const double r = q.squaredNorm();  // t = 1
    c.push(q, normal, r < 1 ? (r - 1) * (r - 1) : 0.0);
  }
  return c;
}

/// A sphere through the neighbourhood of randomNeighbors (nearly the plane z = 0).
AlgebraicSphere randomSphere(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  AlgebraicSphere s;
  s.uc = 0.05 * u(rng);
  s.ul = Vec3(0.1 * u(rng), 0.1 * u(rng), 1);
  s.uq = 0.3 * u(rng);
  return s;
}

void checkAgainstDirect(SimdKernel kernel) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  const double invSr2 = 1 / (0.2 * 0.2), invSn2 = 1 / (0.5 * 0.5);
  for (std::size_t n = 0; n <= 37; ++n) {
    const NeighborColumns c = randomNeighbors(n, rng);
    const AlgebraicSphere s = randomSphere(rng);
    std::vector<double> previous(n), rho;
    for (double& p : previous) p = 0.5 + 0.5 * u(rng);
    SphereSums sums;
    const double change = reweight(s, invSr2, invSn2, c, previous, rho, sums, kernel);
    const Reference ref = direct(s, invSr2, invSn2, c, previous);
    ASSERT_EQ(rho.size(), n);
    for (std::size_t k = 0; k < n; ++k) EXPECT_NEAR(rho[k], ref.rho[k], 1e-8 * ref.rho[k] + 1e-300);
    EXPECT_NEAR(change, ref.change, 1e-8);
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(sums.s[i], ref.sums[i], 1e-8 * (1 + std::abs(ref.sums[i])));
    EXPECT_EQ(sums.used, ref.used);
  }
}

}  // namespace

// The first fit's sums: a factor of 1 for every neighbour.
TEST(RobustReweighting, KernelWeightedSumsMatchTheFormula) {
  std::mt19937 rng(5);
  for (SimdKernel kernel : {SimdKernel::Portable, SimdKernel::Avx512, SimdKernel::Auto}) {
    for (std::size_t n = 0; n <= 37; ++n) {
      const NeighborColumns c = randomNeighbors(n, rng);
      double ref[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      int used = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const Vec3 q(c.qx[k], c.qy[k], c.qz[k]), nk(c.nx[k], c.ny[k], c.nz[k]);
        const double item[9] = {1,      q.x(),  q.y(),     q.z(),          nk.x(),
                                nk.y(), nk.z(), q.dot(nk), q.squaredNorm()};
        for (int i = 0; i < 9; ++i) ref[i] += c.weight[k] * item[i];
        used += c.weight[k] > 0;
      }
      SphereSums sums;
      sums.s[0] = 42;  // overwritten: the sums start from zero
      kernelWeightedSums(c, sums, kernel);
      for (int i = 0; i < 9; ++i) EXPECT_NEAR(sums.s[i], ref[i], 1e-12 * (1 + std::abs(ref[i])));
      EXPECT_EQ(sums.used, used);
    }
  }
}

TEST(RobustReweighting, PortableMatchesTheFormula) { checkAgainstDirect(SimdKernel::Portable); }

TEST(RobustReweighting, DefaultPathMatchesTheFormula) { checkAgainstDirect(SimdKernel::Auto); }

TEST(RobustReweighting, Avx2PathMatchesTheFormula) {
  checkAgainstDirect(SimdKernel::Avx2Fma);
  if (!avx2FmaAvailable()) GTEST_SKIP() << "no AVX2 + FMA on this CPU: portable kernel ran";
}

TEST(RobustReweighting, Avx512PathMatchesTheFormula) {
  checkAgainstDirect(SimdKernel::Avx512);
  if (!avx512Available()) GTEST_SKIP() << "no AVX-512 on this CPU: another kernel ran";
}

// A vanishing gradient gives rho = 0 (never NaN); far samples get an exactly zero factor.
TEST(RobustReweighting, DegenerateSphereAndFarSamplesGiveZeroFactors) {
  for (SimdKernel kernel :
       {SimdKernel::Portable, SimdKernel::Avx2Fma, SimdKernel::Avx512, SimdKernel::Auto}) {
    NeighborColumns c;
    for (int k = 0; k < 9; ++k) c.push(Vec3(0.1 * k, 0, 0), Vec3(0, 0, 1), 0.5);
    AlgebraicSphere flat;  // all zero: gradient 0 everywhere
    std::vector<double> previous(9, 1.0), rho;
    SphereSums sums;
    EXPECT_EQ(reweight(flat, 25, 4, c, previous, rho, sums, kernel), 1.0);
    for (double r : rho) EXPECT_EQ(r, 0.0);
    EXPECT_EQ(sums.used, 0);
    EXPECT_EQ(sums.s[0], 0.0);
    AlgebraicSphere far;  // plane z = 1e3: r / sigma_r huge
    far.uc = -1e3;
    far.ul = Vec3(0, 0, 1);
    reweight(far, 25, 4, c, previous, rho, sums, kernel);
    for (double r : rho) EXPECT_EQ(r, 0.0);
    for (double v : sums.s) EXPECT_TRUE(std::isfinite(v));
  }
}

// No previous factors (an empty vector) means all 1: the first re-weighting after the
// kernel-only fit. Same factors, sums and change, to the bit, as with a vector of ones, on every
// path and count.
TEST(RobustReweighting, EmptyPreviousFactorsAreOnes) {
  std::mt19937 rng(29);
  for (SimdKernel kernel :
       {SimdKernel::Portable, SimdKernel::Avx2Fma, SimdKernel::Avx512, SimdKernel::Auto}) {
    for (std::size_t n = 0; n <= 19; ++n) {
      const NeighborColumns c = randomNeighbors(n, rng);
      const AlgebraicSphere s = randomSphere(rng);
      std::vector<double> rhoOnes, rhoEmpty;
      SphereSums a, b;
      const double changeOnes =
          reweight(s, 25, 4, c, std::vector<double>(n, 1.0), rhoOnes, a, kernel);
      const double changeEmpty = reweight(s, 25, 4, c, {}, rhoEmpty, b, kernel);
      EXPECT_EQ(changeOnes, changeEmpty) << n;
      EXPECT_EQ(rhoOnes, rhoEmpty);
      for (int i = 0; i < 9; ++i) EXPECT_EQ(a.s[i], b.s[i]);
      EXPECT_EQ(a.used, b.used);
    }
  }
}

// Asking for less (ReweightOutput) changes nothing that is computed: the same factors on every
// path, the same sums without their count, and no change measured.
TEST(RobustReweighting, PartialOutputsEqualTheFullPass) {
  std::mt19937 rng(31);
  const double inf = std::numeric_limits<double>::infinity();
  for (SimdKernel kernel :
       {SimdKernel::Portable, SimdKernel::Avx2Fma, SimdKernel::Avx512, SimdKernel::Auto}) {
    for (std::size_t n = 0; n <= 19; ++n) {
      const NeighborColumns c = randomNeighbors(n, rng);
      const AlgebraicSphere s = randomSphere(rng);
      std::vector<double> previous(n, 0.5), rhoAll, rhoSums, rhoFactors;
      SphereSums all, sums, factors;
      reweight(s, 25, 4, c, previous, rhoAll, all, kernel, ReweightOutput::All);
      EXPECT_EQ(reweight(s, 25, 4, c, previous, rhoSums, sums, kernel, ReweightOutput::Sums), inf);
      EXPECT_EQ(
          reweight(s, 25, 4, c, previous, rhoFactors, factors, kernel, ReweightOutput::FactorsOnly),
          inf);
      EXPECT_EQ(rhoAll, rhoSums);
      EXPECT_EQ(rhoAll, rhoFactors);
      for (int i = 0; i < 9; ++i) {
        EXPECT_EQ(sums.s[i], all.s[i]);
        EXPECT_EQ(factors.s[i], 0.0);
      }
      EXPECT_EQ(sums.used, 0);
      EXPECT_EQ(factors.used, 0);
    }
  }
}

// Fits side by side (InterleavedColumns): entry k of fit l at [8 k + l], zeros past its count.
TEST(RobustReweighting, InterleavedColumnsHoldEachFitInItsLane) {
  std::mt19937 rng(41);
  for (int count = 1; count <= InterleavedColumns::kLanes; ++count) {
    std::vector<NeighborColumns> fits;
    for (int l = 0; l < count; ++l)
      fits.push_back(randomNeighbors(std::size_t(7 * l + 3 * count) % 38, rng));
    const NeighborColumns* pointers[InterleavedColumns::kLanes];
    for (int l = 0; l < count; ++l) pointers[l] = &fits[std::size_t(l)];
    InterleavedColumns c;
    c.assign(pointers, count);
    ASSERT_EQ(c.fits, count);
    std::size_t longest = 0;
    for (const auto& f : fits) longest = std::max(longest, f.size());
    ASSERT_EQ(c.length, longest);
    for (int l = 0; l < InterleavedColumns::kLanes; ++l) {
      const std::size_t n = l < count ? fits[std::size_t(l)].size() : 0;
      EXPECT_EQ(std::size_t(c.count[l]), n);
      for (std::size_t k = 0; k < c.length; ++k) {
        const std::size_t o = 8 * k + std::size_t(l);
        const bool in = k < n;
        const NeighborColumns* f = in ? &fits[std::size_t(l)] : nullptr;
        EXPECT_EQ(c.qx[o], in ? f->qx[k] : 0.0);
        EXPECT_EQ(c.qz[o], in ? f->qz[k] : 0.0);
        EXPECT_EQ(c.ny[o], in ? f->ny[k] : 0.0);
        EXPECT_EQ(c.d2[o], in ? f->d2[k] : 0.0);
        EXPECT_EQ(c.weight[o], in ? f->weight[k] : 0.0);
      }
    }
  }
}

// The lanes make, fit by fit, what the single-fit passes make (kernel sums, then re-weightings
// each followed by a solve), up to the order of the sums: valid and invalid fits (too few
// neighbours, none, all at one position), with their factors.
TEST(RobustReweighting, FitsInLanesEqualTheSingleFitPasses) {
  std::mt19937 rng(43);
  const double t = 1, invSr2 = 1 / (0.2 * 0.2), invSn2 = 1 / (0.5 * 0.5);
  for (int count = 1; count <= InterleavedColumns::kLanes; ++count) {
    std::vector<NeighborColumns> fits;
    for (int l = 0; l < count; ++l)
      fits.push_back(randomNeighbors(std::size_t(5 * l + 2 * count) % 41, rng));
    if (count >= 3) {  // every neighbour at one position: degenerate
      NeighborColumns same;
      for (int k = 0; k < 12; ++k) same.push(Vec3(0.1, 0.2, 0), Vec3::UnitZ(), 0.9);
      fits[2] = same;
    }
    const NeighborColumns* pointers[InterleavedColumns::kLanes];
    for (int l = 0; l < count; ++l) pointers[l] = &fits[std::size_t(l)];
    InterleavedColumns c;
    c.assign(pointers, count);
    for (int passes : {0, 1, 5}) {
      for (SimdKernel kernel : {SimdKernel::Portable, SimdKernel::Auto}) {
        LaneSphere out[InterleavedColumns::kLanes];
        std::vector<double> factors[InterleavedColumns::kLanes];
        robustSpheresInLanes(c, t, passes, 6, invSr2, invSn2, out, factors, kernel);
        for (int l = 0; l < count; ++l) {
          SCOPED_TRACE(testing::Message() << count << " fits, fit " << l << ", passes " << passes
                                          << ", kernel " << int(kernel));
          const NeighborColumns& f = fits[std::size_t(l)];
          SphereSums sums;
          kernelWeightedSums(f, sums, SimdKernel::Portable);
          AlgebraicSphere sphere;
          const bool valid = sphereFromSums(sums.s, sums.used, t, 6, sphere);
          std::vector<double> rho, trial;
          for (int it = 0; it < passes && valid; ++it) {
            reweight(sphere, invSr2, invSn2, f, rho, trial, sums, SimdKernel::Portable);
            AlgebraicSphere next;
            if (!sphereFromSums(sums.s, sums.s[0] > 0 ? 1 : 0, t, 1, next)) break;
            sphere = next;
            std::swap(rho, trial);
          }
          ASSERT_EQ(out[l].valid, valid);
          EXPECT_EQ(out[l].neighbors, sums.used);
          if (!valid) continue;
          EXPECT_NEAR(out[l].sphere.uc, sphere.uc, 1e-9);
          EXPECT_NEAR(out[l].sphere.uq, sphere.uq, 1e-9 * (1 + std::abs(sphere.uq)));
          EXPECT_LT((out[l].sphere.ul - sphere.ul).norm(), 1e-9);
          ASSERT_EQ(factors[l].size(), rho.size());
          for (std::size_t k = 0; k < rho.size(); ++k) EXPECT_NEAR(factors[l][k], rho[k], 1e-8);
        }
      }
    }
  }
}
