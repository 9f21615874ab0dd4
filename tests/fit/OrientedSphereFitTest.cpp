// Every derivative of the oriented sphere fit against central finite differences in a fixed
// frame: the scalar field f(y) = u_c(y) (the fit at y in its own centred frame evaluated at y),
// the parameters re-expressed in the frame of x, and the scale derivatives.
#include <gtest/gtest.h>

#include "FitTestClouds.hpp"
#include "scalespace/fit/OrientedSphereFit.hpp"
#include "scalespace/fit/WeightKernel.hpp"

using namespace scalespace;
using namespace scalespace::test;

namespace {

OrientedSphereFitResult fitRaw(const TestCloud& c, const Vec3& x, double t, FitDerivatives order,
                               bool scale = false) {
  OrientedSphereFit f;
  f.begin(x, t, order, scale);
  for (std::size_t i = 0; i < c.positions.size(); ++i) f.add(c.positions[i], c.normals[i]);
  return f.finish(6);
}

// A generic (non-umbilic, noisy) cloud so that no derivative vanishes by symmetry.
std::unique_ptr<TestCloud> genericCloud() {
  auto c = sampleCloud(SurfaceShape::Saddle, Vec3::Zero(), 1.2, 6000, 11);
  addPositionNoise(c->positions, 0.01, 12);
  addNormalRotationNoise(c->normals, 5, Vec3(1, 2, 3), 13);
  c->build();
  return c;
}

}  // namespace

TEST(WeightKernel, DerivativesMatchFiniteDifferences) {
  const WeightKernel k(0.7);
  const Vec3 q(0.2, -0.3, 0.1);
  const double h = 1e-6;
  auto w = [&](const Vec3& y) { return WeightKernel::value(k.ratio(y.squaredNorm())); };
  const double r = k.ratio(q.squaredNorm());
  EXPECT_NEAR(w(q), std::pow(q.squaredNorm() / 0.49 - 1, 2), 1e-15);
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = h * Vec3::Unit(a);
    EXPECT_NEAR(k.gradient(q, r)(a), (w(q + e) - w(q - e)) / (2 * h), 1e-7);
    const Vec3 fd = (k.gradient(q + e, k.ratio((q + e).squaredNorm())) -
                     k.gradient(q - e, k.ratio((q - e).squaredNorm()))) /
                    (2 * h);
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(k.hessian(q, r)(b, a), fd(b), 1e-6);
  }
  const WeightKernel kp(0.7 + h), km(0.7 - h);
  const double fdT = (WeightKernel::value(kp.ratio(q.squaredNorm())) -
                      WeightKernel::value(km.ratio(q.squaredNorm()))) /
                     (2 * h);
  EXPECT_NEAR(k.scaleDerivative(r), fdT, 1e-7);
  EXPECT_EQ(WeightKernel::value(k.ratio(0.7 * 0.7)), 0.0);
}

TEST(OrientedSphereFit, CompleteGradientAndHessianMatchFiniteDifferences) {
  const auto c = genericCloud();
  const Vec3 x(0.07, -0.05, 0.03);  // off the surface, off the symmetry axes
  const double t = 0.6, h = 1e-5;
  const auto r2 = fitRaw(*c, x, t, FitDerivatives::Second);
  const auto r1 = fitRaw(*c, x, t, FitDerivatives::First);
  const auto r0 = fitRaw(*c, x, t, FitDerivatives::None);
  ASSERT_TRUE(r2.valid && r1.valid && r0.valid);
  // Orders give the same parameters.
  EXPECT_NEAR(r0.sphere.uq, r2.sphere.uq, 1e-12);
  EXPECT_NEAR((r1.gradient - r2.gradient).norm(), 0, 1e-12);
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = h * Vec3::Unit(a);
    const auto p = fitRaw(*c, x + e, t, FitDerivatives::First);
    const auto m = fitRaw(*c, x - e, t, FitDerivatives::First);
    // Eq. 1.33: f(y) = u_c(y) in the frame centred at y.
    EXPECT_NEAR(r2.gradient(a), (p.sphere.uc - m.sphere.uc) / (2 * h), 1e-7) << a;
    // Eq. 1.36: derivative of the complete gradient.
    const Vec3 fdGrad = (p.gradient - m.gradient) / (2 * h);
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(r2.hessianW3(b, a), fdGrad(b), 2e-5) << a << b;
    // Parameters in the fixed frame of x: u_l(y) and u_c(y) re-expressed around x.
    const AlgebraicSphere sp = p.sphere.translated(x - (x + e));
    const AlgebraicSphere sm = m.sphere.translated(x - (x - e));
    EXPECT_NEAR(r1.gradUc(a), (sp.uc - sm.uc) / (2 * h), 1e-7);
    EXPECT_NEAR(r1.gradUq(a), (p.sphere.uq - m.sphere.uq) / (2 * h), 1e-6);
    const Vec3 fdUl = (sp.ul - sm.ul) / (2 * h);
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(r1.jacobianUl(b, a), fdUl(b), 1e-6);
  }
  // W3's Hessian is symmetric by construction (it is a true Hessian); W2's is not in general.
  EXPECT_NEAR((r2.hessianW3 - r2.hessianW3.transpose()).norm(), 0, 1e-9);
}

TEST(OrientedSphereFit, ScaleDerivativesMatchFiniteDifferences) {
  const auto c = genericCloud();
  const Vec3 x(0.02, 0.04, -0.01);
  const double t = 0.5, h = 1e-6;
  const auto r = fitRaw(*c, x, t, FitDerivatives::None, true);
  const auto p = fitRaw(*c, x, t + h, FitDerivatives::None);
  const auto m = fitRaw(*c, x, t - h, FitDerivatives::None);
  EXPECT_NEAR(r.dUcDt, (p.sphere.uc - m.sphere.uc) / (2 * h), 1e-6);
  EXPECT_NEAR(r.dUqDt, (p.sphere.uq - m.sphere.uq) / (2 * h), 1e-5);
  EXPECT_NEAR((r.dUlDt - (p.sphere.ul - m.sphere.ul) / (2 * h)).norm(), 0, 1e-6);
}

TEST(OrientedSphereFit, FitsASphereExactly) {
  // Oriented samples of any sphere are reproduced exactly: centre and radius, Delta = |grad|^2.
  const auto c = sampleCloud(SurfaceShape::Sphere, Vec3::Zero(), 0.5, 500, 2);
  const auto r = fitRaw(*c, Vec3(0.01, 0.02, 0.03), 0.5, FitDerivatives::None);
  ASSERT_TRUE(r.valid);
  EXPECT_NEAR(r.sphere.radius(), 1, 1e-10);
  EXPECT_NEAR((r.sphere.center() - (Vec3(0, 0, -1) - Vec3(0.01, 0.02, 0.03))).norm(), 0, 1e-10);
  EXPECT_NEAR(r.sphere.kappa(), 1, 1e-10);  // positive with outward normals (docs/THESIS_NOTES.md)
  EXPECT_GT(r.sphere.uq, 0);
  // Projection (Eq. 1.10) lands on the sphere.
  const Vec3 proj = r.sphere.project(Vec3::Zero()) + Vec3(0.01, 0.02, 0.03);
  EXPECT_NEAR((proj - Vec3(0, 0, -1)).norm(), 1, 1e-10);
}

TEST(OrientedSphereFit, PlaneBranchOfTheProjection) {
  AlgebraicSphere s;
  s.uc = -0.3;
  s.ul = Vec3(0, 0, 2);
  s.uq = 0;  // the plane z = 0.15
  EXPECT_NEAR((s.project(Vec3(0.2, 0.1, 0.7)) - Vec3(0.2, 0.1, 0.15)).norm(), 0, 1e-15);
  s.uq = 1e-13;  // numerically a plane: no cancellation
  EXPECT_TRUE(s.isPlane(1));
  EXPECT_NEAR(s.project(Vec3(0.2, 0.1, 0.7)).z(), 0.15, 1e-9);
}

TEST(OrientedSphereFit, ColumnAccumulationEqualsOneByOne) {
  const auto c = genericCloud();
  std::vector<double> extra(c->positions.size());
  for (std::size_t i = 0; i < extra.size(); ++i) extra[i] = 0.25 + 0.5 * double(i % 3);
  extra[7] = 0;  // a zeroed sample is not counted
  const Vec3 x(0.05, -0.02, 0.01);
  for (FitDerivatives order :
       {FitDerivatives::None, FitDerivatives::First, FitDerivatives::Second}) {
    OrientedSphereFit one, batch;
    one.begin(x, 0.8, order, true);
    batch.begin(x, 0.8, order, true);
    for (std::size_t i = 0; i < c->positions.size(); ++i)
      one.add(c->positions[i], c->normals[i], extra[i]);
    NeighborColumns columns;
    for (std::size_t i = 0; i < c->positions.size(); ++i)
      columns.push(c->positions[i], c->normals[i], -1.0);  // d2 and weight are not read
    batch.addColumns(columns, extra.data());
    const OrientedSphereFitResult a = one.finish(6), b = batch.finish(6);
    ASSERT_TRUE(a.valid);
    EXPECT_EQ(a.neighbors, b.neighbors);
    // Same sums, possibly added in another order: equal to rounding.
    EXPECT_NEAR(a.sphere.uc, b.sphere.uc, 1e-12 * std::abs(a.sphere.uc));
    EXPECT_NEAR(a.sphere.uq, b.sphere.uq, 1e-12 * std::abs(a.sphere.uq));
    EXPECT_LT((a.sphere.ul - b.sphere.ul).norm(), 1e-12 * a.sphere.ul.norm());
    EXPECT_LT((a.hessianW3 - b.hessianW3).norm(), 1e-10 * (1 + a.hessianW3.norm()));
    EXPECT_LT((a.gradient - b.gradient).norm(), 1e-12 * a.gradient.norm());
    EXPECT_NEAR(a.dUqDt, b.dUqDt, 1e-10 * (1 + std::abs(a.dUqDt)));
  }
}

// The AVX-512 second-order (W3) solve equals the portable Jet2 one (fused multiply-adds round
// once, so to a few ulps) on fits of several shapes, scales and frames, and degenerate sums are
// refused by both.
TEST(OrientedSphereFit, Avx512SecondOrderSolveEqualsPortable) {
  const auto generic = genericCloud();
  const auto sphere = sampleCloud(SurfaceShape::Sphere, Vec3(0.3, -0.2, 0.1), 0.8, 3000, 5);
  const auto torus = sampleCloud(SurfaceShape::Torus, Vec3(1.5, 0, 0), 1.2, 4000, 6);
  int compared = 0;
  for (const TestCloud* c : {generic.get(), sphere.get(), torus.get()}) {
    for (const Vec3& x : {Vec3(0.05, 0.02, -0.01), Vec3(0.3, -0.1, 0.2), Vec3(-0.4, 0.3, 0.0)}) {
      for (double t : {0.2, 0.5}) {
        OrientedSphereFit f;
        f.begin(x, t, FitDerivatives::Second, true);
        for (std::size_t i = 0; i < c->positions.size(); ++i) f.add(c->positions[i], c->normals[i]);
        const OrientedSphereFitResult a = f.finish(6, SimdKernel::Portable);
        const OrientedSphereFitResult b = f.finish(6, SimdKernel::Avx512);
        ASSERT_EQ(a.valid, b.valid);
        if (!a.valid) continue;
        ++compared;
        // Relative to each quantity's natural size at scale t (u_l and the gradients are unit
        // sized; u_q, the Jacobian and the Hessians are 1 / t): near-zero entries (u_q's
        // gradient on a sphere) carry only rounding noise.
        auto near = [](double u, double v, double size) { EXPECT_NEAR(u, v, 1e-11 * size); };
        const double perT = 1 / t + std::abs(a.sphere.uq) + a.hessianW3.norm();
        near(a.sphere.uc, b.sphere.uc, t);
        near(a.sphere.uq, b.sphere.uq, perT);
        for (int i = 0; i < 3; ++i) {
          near(a.sphere.ul[i], b.sphere.ul[i], 1);
          near(a.gradient[i], b.gradient[i], 1);
          near(a.gradUc[i], b.gradUc[i], 1);
          near(a.gradUq[i], b.gradUq[i], perT / t);
          for (int j = 0; j < 3; ++j) {
            near(a.hessianW3(i, j), b.hessianW3(i, j), perT);
            near(a.hessianW2(i, j), b.hessianW2(i, j), perT);
            near(a.jacobianUl(i, j), b.jacobianUl(i, j), perT);
          }
        }
      }
    }
  }
  EXPECT_GE(compared, 10);
  // All samples at one point: den = 0, refused by both.
  OrientedSphereFit f;
  f.begin(Vec3::Zero(), 1.0, FitDerivatives::Second);
  for (int i = 0; i < 10; ++i) f.add(Vec3(0.1, 0.1, 0.1), Vec3::UnitZ());
  EXPECT_FALSE(f.finish(6, SimdKernel::Portable).valid);
  EXPECT_FALSE(f.finish(6, SimdKernel::Avx512).valid);
  if (!avx512Available()) GTEST_SKIP() << "no AVX-512 on this CPU: the portable solve ran twice";
}

TEST(OrientedSphereFit, NeighboursOnALineAreADegenerateFit) {
  // Points on a line leave the sphere free to turn about it: the fit must say invalid, not report
  // curvatures made of rounding noise. A strip 1/20 as wide as it is long is still a surface.
  for (double width : {0.0, 1e-5, 0.05}) {
    TestCloud c;
    for (int i = 0; i < 200; ++i)
      for (int side : {-1, 1}) {
        c.positions.push_back(Vec3(-1 + 0.01 * i, 0.5 * side * width * (i % 3), 0.3));
        c.normals.push_back(Vec3(0, 0.2, 1).normalized());
      }
    for (FitDerivatives order : {FitDerivatives::First, FitDerivatives::Second}) {
      const auto r = fitRaw(c, Vec3(0, 0, 0.3), 1.0, order);
      EXPECT_EQ(r.valid, width > 0.01) << "width " << width;
    }
  }
}
