#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "scalespace/scales/StackQuantization.hpp"

namespace scalespace::quant {
namespace {

const double kPi = std::acos(-1.0);

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

}  // namespace
}  // namespace scalespace::quant
