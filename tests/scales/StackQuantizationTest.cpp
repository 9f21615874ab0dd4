#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/scales/StackQuantization.hpp"

namespace scalespace::quant {
namespace {

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const Vec3 v(g(rng), g(rng), g(rng));
    if (v.norm() > 1e-6) return v.normalized();
  }
}

std::uint16_t half(float v) {
  bool clamped = false;
  return floatToHalf(v, clamped);
}

TEST(StackQuantization, HalfKnownValues) {
  EXPECT_EQ(half(0.0f), 0x0000);
  EXPECT_EQ(half(-0.0f), 0x8000);
  EXPECT_EQ(half(1.0f), 0x3c00);
  EXPECT_EQ(half(-2.0f), 0xc000);
  EXPECT_EQ(half(0.5f), 0x3800);
  EXPECT_EQ(half(65504.0f), 0x7bff);
  EXPECT_EQ(half(std::ldexp(1.0f, -14)), 0x0400);  // smallest normal
  EXPECT_EQ(half(std::ldexp(1.0f, -24)), 0x0001);  // smallest subnormal
  EXPECT_EQ(half(std::ldexp(1023.0f, -24)), 0x03ff);
  EXPECT_EQ(halfToFloat(0x0001), std::ldexp(1.0f, -24));
  EXPECT_EQ(halfToFloat(0x7bff), 65504.0f);
  EXPECT_EQ(halfToFloat(0xc000), -2.0f);
  EXPECT_EQ(halfToFloat(0x3555), 0.333251953125f);
  // Ties go to the even neighbour, in normals and subnormals.
  EXPECT_EQ(half(1.0f + std::ldexp(1.0f, -11)), 0x3c00);      // 1 + half an ulp -> 1
  EXPECT_EQ(half(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02);  // 1 + 1.5 ulp -> 1 + 2 ulp
  EXPECT_EQ(half(1.0f + std::ldexp(1.1f, -11)), 0x3c01);      // above the tie -> up
  EXPECT_EQ(half(std::ldexp(1.0f, -25)), 0x0000);             // half the smallest subnormal -> 0
  EXPECT_EQ(half(std::ldexp(3.0f, -25)), 0x0002);             // 1.5 subnormal steps -> 2
  EXPECT_EQ(half(std::ldexp(1.0f, -26)), 0x0000);
  EXPECT_EQ(half(2047.0f * std::ldexp(1.0f, -25)), 0x0400);  // rounds up into the normals
  EXPECT_EQ(half(65519.0f), 0x7bff);                         // rounds down, not clamped
  // Clamping: never inf or NaN.
  for (const float v : {65520.0f, 1e6f, std::numeric_limits<float>::infinity()}) {
    bool clamped = false;
    EXPECT_EQ(floatToHalf(v, clamped), 0x7bff) << v;
    EXPECT_TRUE(clamped) << v;
    clamped = false;
    EXPECT_EQ(floatToHalf(-v, clamped), 0xfbff) << v;
    EXPECT_TRUE(clamped) << v;
  }
  bool clamped = false;
  EXPECT_EQ(floatToHalf(std::numeric_limits<float>::quiet_NaN(), clamped), 0x0000);
  EXPECT_TRUE(clamped);
  clamped = false;
  floatToHalf(65519.0f, clamped);
  EXPECT_FALSE(clamped);
}

TEST(StackQuantization, HalfRoundTripOfEveryFiniteHalf) {
  // decode(encode(x)) == x for all 63488 finite halves, and the encoder rounds to the nearest.
  for (std::uint32_t b = 0; b < 0x10000u; ++b) {
    if (((b >> 10) & 0x1fu) == 0x1fu) continue;  // inf / NaN
    const float f = halfToFloat(std::uint16_t(b));
    const std::uint16_t back = half(f);
    if (f == 0.0f) {
      EXPECT_EQ(back & 0x7fffu, 0u);
    } else {
      ASSERT_EQ(back, b) << b;
    }
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(-70000.0f, 70000.0f);
  for (int k = 0; k < 20000; ++k) {
    const float v = u(rng) * std::ldexp(1.0f, -int(rng() % 30));
    const float back = halfToFloat(half(v));
    if (std::abs(v) < 65504.0f) {
      ASSERT_LE(std::abs(back - v),
                std::max(std::abs(v) * std::ldexp(1.0f, -11), std::ldexp(1.0f, -25)))
          << v;
    }
  }
}

TEST(StackQuantization, OctahedralErrorIsBoundedByTheBitCount) {
  std::mt19937_64 rng(7);
  double worst = 0;
  std::vector<Vec3> dirs;
  for (int k = 0; k < 200000; ++k) dirs.push_back(randomUnit(rng));
  // The axes, the octahedron's edges and the equator (fold) are the corner cases.
  for (int a = 0; a < 3; ++a)
    for (const double s : {1.0, -1.0}) dirs.push_back(s * Vec3::Unit(a));
  for (int k = 0; k < 2000; ++k) {
    const double phi = 2 * kPi * k / 2000;
    dirs.push_back(Vec3(std::cos(phi), std::sin(phi), 0));
    dirs.push_back(Vec3(std::cos(phi), std::sin(phi), 1e-9).normalized());
    dirs.push_back(Vec3(std::cos(phi), std::sin(phi), -1e-9).normalized());
  }
  for (const Vec3& d : dirs) {
    const std::uint32_t code = encodeOctahedral(d);
    ASSERT_LT(code, 1u << 22);
    const Vec3 back = decodeOctahedral(code);
    ASSERT_NEAR(back.norm(), 1.0, 1e-12);
    worst = std::max(worst, std::atan2(d.cross(back).norm(), d.dot(back)));
  }
  EXPECT_LE(worst, kOctMaxAngle);
  EXPECT_GT(worst, 0.2 * kOctMaxAngle);  // the bound is not absurdly loose
  std::printf("octahedral 2 x 11 bits: max angle error %.3g rad (bound %.3g)\n", worst,
              kOctMaxAngle);
  // Degenerate input encodes +z, does not crash.
  EXPECT_NEAR(decodeOctahedral(encodeOctahedral(Vec3::Zero())).z(), 1.0, 1e-12);
}

TEST(StackQuantization, FrameRoundTripAsAxes) {
  std::mt19937_64 rng(11);
  double worstNormal = 0, worstMax = 0, worstMin = 0;
  for (int k = 0; k < 100000; ++k) {
    const Vec3 n = randomUnit(rng);
    const Vec3 t = (randomUnit(rng).cross(n)).normalized();
    const Vec3 dmin = n.cross(t);  // the compact encoding's handedness: dirMin = n x dirMax
    const std::uint32_t code = encodeFrame(n, t);
    Vec3 n2, max2, min2;
    decodeFrame(code, n2, max2, min2);
    ASSERT_NEAR(max2.norm(), 1.0, 1e-12);
    ASSERT_NEAR(max2.dot(n2), 0.0, 1e-12);
    ASSERT_NEAR(min2.dot(n2), 0.0, 1e-12);
    ASSERT_NEAR(min2.dot(max2), 0.0, 1e-12);
    worstNormal = std::max(worstNormal, axisAngle(n, n2));
    worstMax = std::max(worstMax, axisAngle(t, max2));
    worstMin = std::max(worstMin, axisAngle(dmin, min2));
    // The frame keeps its handedness: dir_min has the sign of n x dirMax up to dir_max's.
    if (t.dot(max2) > 0) {
      ASSERT_GT(dmin.dot(min2), 0.99);
    }
  }
  EXPECT_LE(worstNormal, kOctMaxAngle);
  EXPECT_LE(worstMax, kAngleMaxError + kOctMaxAngle);
  EXPECT_LE(worstMin, kAngleMaxError + 2 * kOctMaxAngle);
  std::printf("frame: max error normal %.3g, dir_max %.3g, dir_min %.3g rad\n", worstNormal,
              worstMax, worstMin);
  // The angle is an axis: t and -t give the same code.
  const Vec3 n = Vec3(0.3, -0.2, 0.9).normalized();
  const Vec3 t = n.cross(Vec3::UnitX()).normalized();
  EXPECT_EQ(encodeFrame(n, t), encodeFrame(n, -t));
}

TEST(StackQuantization, BitPackingRoundTrip) {
  for (const std::size_t n : {0, 1, 7, 8, 9, 63, 64, 1001}) {
    std::vector<std::uint8_t> flags(n);
    for (std::size_t i = 0; i < n; ++i) flags[i] = std::uint8_t((i * 7919 + n) % 3 == 0 ? 2 : 0);
    std::vector<std::uint8_t> packed(packedBytes(n), 0xff);
    packBits(flags.data(), n, packed.data());
    ASSERT_EQ(packed.size(), (n + 7) / 8);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(unpackBit(packed.data(), i), flags[i] ? 1 : 0);
    if (n % 8) {
      EXPECT_EQ(packed.back() >> (n % 8), 0);  // padding bits are zero
    }
  }
  // numpy.packbits(bitorder='little') of [1, 0, 0, 0, 0, 0, 0, 1, 1] is [0x81, 0x01].
  const std::uint8_t f[9] = {1, 0, 0, 0, 0, 0, 0, 1, 1};
  std::uint8_t p[2];
  packBits(f, 9, p);
  EXPECT_EQ(p[0], 0x81);
  EXPECT_EQ(p[1], 0x01);
}

// ------------------------------------------------------------ shared-exponent offsets (v3)

std::uint32_t offsetCode(const Vec3& o, bool* clampedOut = nullptr) {
  bool clamped = false;
  const std::uint32_t code = encodeSharedExponent(o, clamped);
  if (clampedOut) *clampedOut = clamped;
  return code;
}

TEST(StackQuantization, SharedExponentKnownValues) {
  EXPECT_EQ(offsetCode(Vec3::Zero()), 0u);
  EXPECT_EQ(offsetCode(Vec3(-0.0, 0.0, -0.0)), 0u);  // no negative zero
  // 1 = 128 2^-7: e = 27 - 7 = 20, x magnitude 128, y = -0.5 = -64 2^-7 (sign bit 8 of y).
  const std::uint32_t one = offsetCode(Vec3(1, -0.5, 0));
  EXPECT_EQ(one, (20u << 27) | 128u | ((0x100u | 64u) << 9));
  EXPECT_EQ(decodeSharedExponent(one), Vec3(1, -0.5, 0));
  // 255.4 2^-7 stays at e = 20 (m = 255), 255.5 2^-7 rounds to 256: one exponent more.
  EXPECT_EQ(offsetCode(Vec3(0, 0, 255.4 / 128)) >> 27, 20u);
  EXPECT_EQ((offsetCode(Vec3(0, 0, 255.4 / 128)) >> 18) & 0x1ffu, 255u);
  EXPECT_EQ(offsetCode(Vec3(0, 0, 255.5 / 128)) >> 27, 21u);
  EXPECT_EQ((offsetCode(Vec3(0, 0, 255.5 / 128)) >> 18) & 0x1ffu, 128u);
  // The smallest exponent: steps of 2^-27, ties away from zero, below half a step -> 0.
  EXPECT_EQ(offsetCode(Vec3(std::ldexp(1.0, -27), 0, 0)), 1u);
  EXPECT_EQ(offsetCode(Vec3(std::ldexp(1.0, -28), 0, 0)), 1u);
  EXPECT_EQ(offsetCode(Vec3(std::ldexp(0.99, -28), 0, 0)), 0u);
  EXPECT_EQ(offsetCode(Vec3(1e-300, -1e-300, 0)), 0u);
  EXPECT_EQ(decodeSharedExponent(1u), Vec3(std::ldexp(1.0, -27), 0, 0));
  // 2^-20 is the first offset with a full 8-bit magnitude at e = 0.
  EXPECT_EQ(offsetCode(Vec3(std::ldexp(1.0, -20), 0, 0)), 128u);
  // The decoding uses the bias it is given (the manifest's).
  EXPECT_EQ(decodeSharedExponent(one, 20), Vec3(128, -64, 0));
}

TEST(StackQuantization, SharedExponentClampsAndNeverReturnsNaN) {
  const double maxDecoded = 255.0 * 16;  // 255 2^(31 - 27)
  bool clamped = true;
  const std::uint32_t below = offsetCode(Vec3(4087.9, -1, 0), &clamped);
  EXPECT_FALSE(clamped);
  EXPECT_EQ(decodeSharedExponent(below).x(), maxDecoded);
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Vec3& o : {Vec3(4088, 0, 0), Vec3(0, -1e300, 3), Vec3(inf, 0, 0), Vec3(1, -inf, inf),
                        Vec3(-inf, -inf, -inf)}) {
    const Vec3 d = decodeSharedExponent(offsetCode(o, &clamped));
    EXPECT_TRUE(clamped) << o.transpose();
    ASSERT_TRUE(d.allFinite()) << o.transpose();
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(std::abs(d[c]), maxDecoded);
      if (std::abs(o[c]) >= 4088) {
        EXPECT_EQ(d[c], std::copysign(maxDecoded, o[c]));
      }
      EXPECT_FALSE(std::signbit(d[c]) != std::signbit(o[c]) && d[c] != 0) << o.transpose();
    }
  }
  // NaN components are zeroed (and counted); the others are kept.
  const Vec3 d = decodeSharedExponent(offsetCode(Vec3(nan, 0.25, -0.5), &clamped));
  EXPECT_TRUE(clamped);
  EXPECT_EQ(d, Vec3(0, 0.25, -0.5));
  EXPECT_EQ(offsetCode(Vec3(nan, nan, nan), &clamped), 0u);
  EXPECT_TRUE(clamped);
}

TEST(StackQuantization, SharedExponentCanonicalCodesRoundTrip) {
  // Every exponent and every x field (sign, magnitude) with a range of y, z: a code the encoder can
  // produce (largest magnitude >= 128 unless e = 0, no negative zero) decodes and re-encodes to
  // itself, and every code decodes to finite values.
  std::size_t checked = 0;
  for (std::uint32_t e = 0; e <= 31; ++e)
    for (std::uint32_t x = 0; x < 512; ++x)
      for (std::uint32_t y = 0; y < 512; y += 37)
        for (const std::uint32_t z : {0u, 1u, 200u, 0x100u | 255u}) {
          const std::uint32_t code = (e << 27) | x | (y << 9) | (z << 18);
          const Vec3 o = decodeSharedExponent(code);
          ASSERT_TRUE(o.allFinite());
          const std::uint32_t fields[3] = {x, y, z};
          std::uint32_t largest = 0;
          bool negativeZero = false;
          for (const std::uint32_t f : fields) {
            largest = std::max(largest, f & 0xffu);
            negativeZero = negativeZero || f == 0x100u;
          }
          if (negativeZero || (e > 0 && largest < 128)) continue;
          ASSERT_EQ(offsetCode(o), code) << std::hex << code;
          ++checked;
        }
  EXPECT_GT(checked, 200000u);
}

TEST(StackQuantization, SharedExponentMeetsTheDocumentedBound) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> logMag(-12, std::log10(4000.0)), u(-1, 1);
  double worstRelative = 0;
  for (int k = 0; k < 300000; ++k) {
    // Random directions and lengths over 15 decades; a third with a zero or tiny component.
    Vec3 o = std::pow(10.0, logMag(rng)) * Vec3(u(rng), u(rng), u(rng));
    if (k % 3 == 1) o[int(rng() % 3)] = 0;
    if (k % 3 == 2) o[int(rng() % 3)] *= 1e-6;
    bool clamped = false;
    const std::uint32_t code = encodeSharedExponent(o, clamped);
    ASSERT_FALSE(clamped);
    const Vec3 d = decodeSharedExponent(code);
    const double a = o.cwiseAbs().maxCoeff();
    const double bound = std::max(kOffsetRelativeError * a, kOffsetAbsoluteFloor);
    for (int c = 0; c < 3; ++c) {
      ASSERT_LE(std::abs(d[c] - o[c]), bound * (1 + 1e-12)) << o.transpose();
      if (o[c] == 0) {
        ASSERT_EQ(d[c], 0.0);
      }
    }
    // The largest component uses the top half of the magnitudes unless e = 0.
    if ((code >> 27) > 0) {
      std::uint32_t largest = 0;
      for (int c = 0; c < 3; ++c) largest = std::max(largest, (code >> (9 * c)) & 0xffu);
      ASSERT_GE(largest, 128u) << o.transpose();
    }
    if (a > 1e-6) worstRelative = std::max(worstRelative, (d - o).cwiseAbs().maxCoeff() / a);
  }
  EXPECT_GT(worstRelative, 0.9 * kOffsetRelativeError);  // the bound is tight
  std::printf("shared exponent: max error / max |o_i| %.4g (bound %.4g)\n", worstRelative,
              kOffsetRelativeError);
}

// ------------------------------------------------------------ 8-bit logarithmic codes (v3)

TEST(StackQuantization, Log8EveryCodeRoundTrips) {
  for (const auto& [lo, hi] :
       {std::pair{kAnisotropyLogMin, kAnisotropyLogMax},
        std::pair{kVariationLogMin, kVariationLogMax}, std::pair{0.5, 2.0}}) {
    const Log8Code code(lo, hi);
    EXPECT_EQ(code.decode(0), 0.0);
    EXPECT_NEAR(code.decode(1), lo * std::sqrt(code.stepRatio()), 1e-12 * lo);
    EXPECT_NEAR(code.decode(255), hi / std::sqrt(code.stepRatio()), 1e-12 * hi);
    for (int k = 0; k <= 255; ++k) {
      bool clamped = false;
      const double v = code.decode(std::uint8_t(k));
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_EQ(code.encode(v, clamped), k) << v;
      ASSERT_FALSE(clamped);
      if (k > 1) {
        ASSERT_NEAR(v / code.decode(std::uint8_t(k - 1)), code.stepRatio(), 1e-12);
      }
      // The bin edges go to a neighbouring code, within half a step either way.
      const double edge = lo * std::pow(code.stepRatio(), k);
      if (k >= 1) {
        const std::uint8_t e = code.encode(edge, clamped);
        ASSERT_TRUE(e == k || e == k + 1 || (k == 255 && e == 255)) << k << " " << int(e);
        ASSERT_LE(std::abs(code.decode(e) - edge), code.maxRelativeError() * edge * (1 + 1e-12));
      }
    }
  }
  EXPECT_THROW(Log8Code(0, 1), Error);
  EXPECT_THROW(Log8Code(1, 1), Error);
  EXPECT_THROW(Log8Code(1e-7, std::numeric_limits<double>::infinity()), Error);
  EXPECT_THROW(Log8Code(std::numeric_limits<double>::quiet_NaN(), 1), Error);
}

TEST(StackQuantization, SignedLog8RoundTripsBothSigns) {
  const Log8Code code(kAnisotropyLogMin, kAnisotropyLogMax, true);
  EXPECT_EQ(code.magnitudeCodes(), 127);
  for (int k = 0; k <= 255; ++k) {
    bool clamped = false;
    const double v = code.decode(std::uint8_t(k));
    ASSERT_TRUE(std::isfinite(v));
    const int m = k & 0x7F;
    ASSERT_EQ(v, k >= 128 ? -code.decode(std::uint8_t(m)) : v);
    ASSERT_EQ(code.encode(v, clamped), m == 0 ? 0 : k) << v;  // 128 (-0) is written as 0
    ASSERT_FALSE(clamped);
  }
  struct Case {
    double v;
    int expected;
    bool clamped;
  };
  const double inf = std::numeric_limits<double>::infinity();
  bool ignored = false;
  const int quarter = code.encode(0.25, ignored);
  for (const Case& c :
       {Case{-1e-16, 0, false}, Case{-0.25, 0x80 | quarter, false}, Case{-1.0, 0x80 | 127, false},
        Case{-1.5, 0x80 | 127, true}, Case{-inf, 0x80 | 127, true}, Case{1.5, 127, true},
        Case{std::numeric_limits<double>::quiet_NaN(), 0, true}}) {
    bool clamped = false;
    EXPECT_EQ(code.encode(c.v, clamped), c.expected) << c.v;
    EXPECT_EQ(clamped, c.clamped) << c.v;
  }
}

TEST(StackQuantization, Log8MeetsTheDocumentedBound) {
  // Documented figures (docs/STACK_FORMAT.md).
  const Log8Code aniso(kAnisotropyLogMin, kAnisotropyLogMax, true);
  const Log8Code nu(kVariationLogMin, kVariationLogMax);
  EXPECT_NEAR(aniso.stepRatio(), 1.13532, 1e-5);
  EXPECT_NEAR(aniso.maxRelativeError(), 0.06551, 1e-5);
  EXPECT_NEAR(aniso.absoluteFloor(), 5.3276e-8, 1e-11);
  EXPECT_NEAR(nu.stepRatio(), 1.15543, 1e-5);
  EXPECT_NEAR(nu.maxRelativeError(), 0.07491, 1e-5);
  EXPECT_NEAR(nu.absoluteFloor(), 5.375e-11, 1e-14);
  std::mt19937_64 rng(17);
  for (const Log8Code* code : {&aniso, &nu}) {
    std::uniform_real_distribution<double> logV(std::log(code->lo()) - 3, std::log(code->hi()));
    double worst = 0;
    for (int k = 0; k < 200000; ++k) {
      const double v = std::exp(logV(rng));
      if (code->isSigned()) {  // the negative half mirrors the positive one
        bool c = false;
        ASSERT_EQ(code->decode(code->encode(-v, c)), -code->decode(code->encode(v, c))) << v;
      }
      bool clamped = false;
      const double d = code->decode(code->encode(v, clamped));
      ASSERT_FALSE(clamped) << v;
      ASSERT_LE(std::abs(d - v), code->maxRelativeError() * v * (1 + 1e-12) + code->absoluteFloor())
          << v;
      if (v >= code->lo()) {
        ASSERT_LE(std::abs(d - v), code->maxRelativeError() * v * (1 + 1e-12)) << v;
        worst = std::max(worst, std::abs(d - v) / v);
      } else {
        ASSERT_LE(std::abs(d - v), code->absoluteFloor() * (1 + 1e-12)) << v;
      }
    }
    EXPECT_GT(worst, 0.95 * code->maxRelativeError());
  }
}

TEST(StackQuantization, Log8ClampsAndNeverReturnsNaN) {
  const Log8Code code(1e-7, 1.0);  // unsigned
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    double v;
    int expected;
    bool clamped;
  };
  for (const Case& c :
       {Case{0.0, 0, false}, Case{-0.0, 0, false}, Case{-kLogNegativeTolerance, 0, false},
        Case{-1e-16, 0, false}, Case{-2.4e-7, 0, true}, Case{-0.15, 0, true}, Case{-inf, 0, true},
        Case{std::numeric_limits<double>::quiet_NaN(), 0, true}, Case{1e-300, 0, false},
        Case{1.0, 255, false}, Case{1.0 + 1e-15, 255, true}, Case{1e30, 255, true},
        Case{inf, 255, true}}) {
    bool clamped = false;
    const std::uint8_t k = code.encode(c.v, clamped);
    EXPECT_EQ(k, c.expected) << c.v;
    EXPECT_EQ(clamped, c.clamped) << c.v;
    EXPECT_TRUE(std::isfinite(code.decode(k)));
  }
  // Below lo: the nearest of 0 and the first centre.
  bool clamped = false;
  EXPECT_EQ(code.encode(0.49 * code.decode(1), clamped), 0);
  EXPECT_EQ(code.encode(0.51 * code.decode(1), clamped), 1);
  EXPECT_FALSE(clamped);
}

// ------------------------------------------------------------------------------------------
// The encoders avoid library calls (atan2, log, frexp, ldexp, round) and unpredictable branches;
// these tests hold them to the straightforward formulas, code for code.

std::uint32_t referenceAxisAngle(double c, double s) {
  if (!std::isfinite(c) || !std::isfinite(s) || (c == 0 && s == 0)) return 0;
  double theta = std::atan2(s, c);
  if (theta < 0) theta += kPi;
  return std::uint32_t(std::lround(theta * (kAngleSteps / kPi))) % std::uint32_t(kAngleSteps);
}

TEST(StackQuantization, FastAxisAngleEqualsAtan2) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g;
  double worst = 0;
  for (int k = 0; k < 400000; ++k) {
    const double c = g(rng), s = g(rng);
    double theta = std::atan2(s, c);
    if (theta < 0) theta += kPi;
    worst = std::max(worst, std::abs(fastAxisAngle(c, s) - theta));
  }
  EXPECT_LT(worst, 1e-11);
  EXPECT_NEAR(fastAxisAngle(1, 0), 0, 1e-15);
  EXPECT_NEAR(fastAxisAngle(0, 1), kPi / 2, 1e-15);
  EXPECT_NEAR(fastAxisAngle(-1, 1e-300), kPi, 1e-15);
  EXPECT_NEAR(fastAxisAngle(1, -1), 3 * kPi / 4, 1e-15);
}

TEST(StackQuantization, QuantizedAxisAngleIsTheAtan2Code) {
  std::mt19937_64 rng(22);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> jitter(-1e-9, 1e-9);
  for (int k = 0; k < 400000; ++k) {
    const double c = g(rng), s = g(rng);
    ASSERT_EQ(quantizeAxisAngle(c, s), referenceAxisAngle(c, s)) << c << " " << s;
  }
  // Directions on and next to every rounding tie, both half-planes, and the axes.
  const double step = kPi / kAngleSteps;
  for (int q = 0; q <= kAngleSteps; ++q)
    for (const double sign : {1.0, -1.0}) {
      const double theta = (q + 0.5) * step + jitter(rng);
      const double c = sign * std::cos(theta), s = sign * std::sin(theta);
      ASSERT_EQ(quantizeAxisAngle(c, s), referenceAxisAngle(c, s)) << q;
      ASSERT_EQ(quantizeAxisAngle(sign * std::cos(q * step), sign * std::sin(q * step)),
                referenceAxisAngle(sign * std::cos(q * step), sign * std::sin(q * step)));
    }
  for (const double c : {0.0, -0.0, 1.0, -1.0})
    for (const double s : {0.0, -0.0, 1.0, -1.0})
      EXPECT_EQ(quantizeAxisAngle(c, s), referenceAxisAngle(c, s)) << c << " " << s;
  EXPECT_EQ(quantizeAxisAngle(std::nan(""), 1), 0u);
}

std::uint32_t referenceSharedExponent(const Vec3& offset) {
  double largest = offset.cwiseAbs().maxCoeff();
  if (!(largest > 0)) return 0;
  int e = kOffsetExponentMax;
  if (largest < kOffsetMaxMagnitude) {
    int k;
    std::frexp(largest, &k);
    e = k - 8 + kOffsetBias;
    if (std::ldexp(largest, kOffsetBias - e) >= kOffsetMagnitudeMax + 0.5) ++e;
    e = std::max(e, 0);
  }
  std::uint32_t code = std::uint32_t(e) << 27;
  for (int c = 0; c < 3; ++c) {
    const double scaled = std::round(std::ldexp(std::abs(offset[c]), kOffsetBias - e));
    const std::uint32_t m =
        scaled >= kOffsetMagnitudeMax ? std::uint32_t(kOffsetMagnitudeMax) : std::uint32_t(scaled);
    code |= ((m != 0 && offset[c] < 0 ? 0x100u : 0u) | m) << (9 * c);
  }
  return code;
}

TEST(StackQuantization, SharedExponentIsTheFrexpCode) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-40, 12);
  for (int k = 0; k < 300000; ++k) {
    Vec3 v;
    for (int c = 0; c < 3; ++c) v[c] = std::ldexp(mantissa(rng), exponent(rng));
    if (k % 7 == 0) v[k % 3] = std::round(v[k % 3] * 512) / 512;  // exact halves of a step
    bool clamped = false;
    ASSERT_EQ(encodeSharedExponent(v, clamped), referenceSharedExponent(v)) << v.transpose();
  }
  for (const double tiny : {4.9e-324, 1e-310, 0x1p-1000, 0x1p-1001}) {
    bool clamped = false;
    const Vec3 v(tiny, -tiny / 2, 0);
    EXPECT_EQ(encodeSharedExponent(v, clamped), referenceSharedExponent(v));
  }
}

TEST(StackQuantization, Log8IsTheBisectionCode) {
  for (const auto& code : {Log8Code(kAnisotropyLogMin, kAnisotropyLogMax, true),
                           Log8Code(kVariationLogMin, kVariationLogMax)}) {
    // The bin by bisection on the edges lo r^k (what the decoder's centres are the middles of).
    const int codes = code.magnitudeCodes();
    std::vector<double> edges(std::size_t(codes) + 1);
    for (int k = 0; k <= codes; ++k)
      edges[std::size_t(k)] = code.lo() * std::pow(code.hi() / code.lo(), double(k) / codes);
    auto reference = [&](double v) {
      return int(std::upper_bound(edges.begin(), edges.begin() + codes, v) - edges.begin());
    };
    std::vector<double> values;
    std::mt19937_64 rng(24);
    std::uniform_real_distribution<double> u(std::log(code.lo()), std::log(code.hi()));
    for (int k = 0; k < 200000; ++k) values.push_back(std::exp(u(rng)));
    for (const double e : edges)
      for (const double v : {e, std::nextafter(e, 0.0), std::nextafter(e, 2 * e)})
        values.push_back(v);
    for (const double v : values) {
      if (v < code.lo() || v > code.hi()) continue;
      bool clamped = false;
      ASSERT_EQ(int(code.encode(v, clamped)), reference(v)) << v;
      ASSERT_FALSE(clamped);
    }
  }
}

TEST(StackQuantization, OctahedralPicksTheNearestOfTheFourCodes) {
  std::mt19937_64 rng(25);
  const int m = kOctMax;
  for (int k = 0; k < 200000; ++k) {
    const Vec3 n = randomUnit(rng);
    const Vec3 chosen = decodeOctahedral(encodeOctahedral(n));
    // No code of the 5 x 5 block around the chosen one decodes nearer to n.
    const std::uint32_t code = encodeOctahedral(n);
    const int qx = int(code & 0x7ffu) - m, qy = int((code >> kOctBits) & 0x7ffu) - m;
    for (int dx = -2; dx <= 2; ++dx)
      for (int dy = -2; dy <= 2; ++dy) {
        const int x = std::clamp(qx + dx, -m, m), y = std::clamp(qy + dy, -m, m);
        const Vec3 other =
            decodeOctahedral(std::uint32_t(x + m) | (std::uint32_t(y + m) << kOctBits));
        ASSERT_LE(other.dot(n), chosen.dot(n) + 1e-15) << n.transpose();
      }
  }
}

}  // namespace
}  // namespace scalespace::quant
