#include "scalespace/scales/StackQuantization.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "scalespace/core/Error.hpp"

namespace scalespace::quant {

namespace {}  // namespace

// ------------------------------------------------------------------------------------ float16

std::uint16_t floatToHalf(float value, bool& clamped) {
  // Integer-only, so the result does not depend on the FPU rounding mode or on _Float16 support.
  std::uint32_t x;
  std::memcpy(&x, &value, 4);
  const std::uint16_t sign = std::uint16_t((x >> 16) & 0x8000u);
  x &= 0x7fffffffu;
  if (x > 0x7f800000u) {  // NaN: never written; counted with the clamped values
    clamped = true;
    return 0;
  }
  if (x >= 0x38800000u) {  // |value| >= 2^-14: a normal half (or an overflow)
    // Rebias the exponent (127 -> 15) and round the 13 dropped mantissa bits to nearest even; a
    // carry out of the mantissa correctly bumps the exponent.
    std::uint32_t h = x - ((127u - 15u) << 23);
    const std::uint32_t odd = (h >> 13) & 1u;
    h += 0xfffu + odd;
    h >>= 13;
    if (h >= 0x7c00u) {  // would be inf: clamp to the largest finite half
      clamped = true;
      return std::uint16_t(sign | 0x7bffu);
    }
    return std::uint16_t(sign | h);
  }
  if (x < 0x33000000u) return sign;  // |value| <= 2^-25 (the tie rounds to the even 0)
  // Subnormal half: value = m * 2^(e - 150), in units of 2^-24 that is m >> (126 - e).
  const std::uint32_t e = x >> 23;
  const std::uint32_t m = (x & 0x7fffffu) | 0x800000u;
  const std::uint32_t shift = 126u - e;  // 14..24
  std::uint32_t h = m >> shift;
  const std::uint32_t rem = m & ((1u << shift) - 1u), half = 1u << (shift - 1u);
  if (rem > half || (rem == half && (h & 1u))) ++h;  // may carry into the smallest normal: right
  return std::uint16_t(sign | h);
}

float halfToFloat(std::uint16_t bits) {
  const std::uint32_t sign = std::uint32_t(bits & 0x8000u) << 16;
  const std::uint32_t exp = (bits >> 10) & 0x1fu, mant = bits & 0x3ffu;
  std::uint32_t x;
  if (exp == 0) {
    // Zero or subnormal: mant * 2^-24 is exact in float32.
    const float f = std::ldexp(float(mant), -24);
    std::memcpy(&x, &f, 4);
    x |= sign;
  } else if (exp == 31) {
    x = sign | 0x7f800000u | (mant << 13);
  } else {
    x = sign | ((exp + 127u - 15u) << 23) | (mant << 13);
  }
  float out;
  std::memcpy(&out, &x, 4);
  return out;
}

// -------------------------------------------------------------------------------- octahedral

namespace {

// Decodes an octahedral code; zInt is the integer z of the unfolded octahedron point, whose sign
// picks the tangent basis (exact, unlike the sign of a rounded float).
// The integer point of the unfolded octahedron for the code (qx, qy): |x| + |y| + |z| = kOctMax.
Vec3 octPoint(int qx, int qy) {
  int x = qx, y = qy;
  const int z = kOctMax - std::abs(qx) - std::abs(qy);
  if (z < 0) {  // lower hemisphere: unfold the triangles of the square's corners
    x = (kOctMax - std::abs(qy)) * (qx >= 0 ? 1 : -1);
    y = (kOctMax - std::abs(qx)) * (qy >= 0 ? 1 : -1);
  }
  return Vec3(x, y, z);
}

Vec3 decodeOct(std::uint32_t code, int& zInt) {
  const int qx = std::clamp(int(code & 0x7ffu) - kOctMax, -kOctMax, kOctMax);
  const int qy = std::clamp(int((code >> kOctBits) & 0x7ffu) - kOctMax, -kOctMax, kOctMax);
  const Vec3 d = octPoint(qx, qy);
  zInt = int(d.z());
  return d.normalized();  // |x| + |y| + |z| = 1023: never zero
}

std::uint32_t octCode(int qx, int qy) {
  return std::uint32_t(qx + kOctMax) | (std::uint32_t(qy + kOctMax) << kOctBits);
}

}  // namespace

std::uint32_t encodeOctahedral(const Vec3& nIn) {
  Vec3 n = nIn;
  double l1 = n.cwiseAbs().sum();
  if (!(l1 > 0) || !std::isfinite(l1)) {
    n = Vec3::UnitZ();
    l1 = 1;
  }
  double u = n.x() / l1, v = n.y() / l1;
  if (n.z() < 0) {
    const double fu = (1 - std::abs(v)) * (u >= 0 ? 1 : -1);
    const double fv = (1 - std::abs(u)) * (v >= 0 ? 1 : -1);
    u = fu, v = fv;
  }
  // Of the (up to) four codes around (u, v), the one whose direction d is nearest to n: the
  // largest d.n / |d|. The candidates are within a cell of n, so d.n > 0, and the comparison
  // (d.n)^2 |d'|^2 > (d'.n)^2 |d|^2 needs no square root or division. |u|, |v| <= 1: the integer
  // conversions cannot overflow.
  const double su = u * kOctMax, sv = v * kOctMax;
  const int fu = int(su) - (double(int(su)) > su ? 1 : 0);  // floor
  const int fv = int(sv) - (double(int(sv)) > sv ? 1 : 0);
  const int cuts[2][2] = {{fu, fu + (double(fu) < su ? 1 : 0)},
                          {fv, fv + (double(fv) < sv ? 1 : 0)}};
  std::uint32_t best = 0;
  double bestDot = 0, bestNorm2 = 1;  // any candidate with d.n > 0 beats this
  for (const int cu : cuts[0])
    for (const int cv : cuts[1]) {
      const int qx = std::clamp(cu, -kOctMax, kOctMax), qy = std::clamp(cv, -kOctMax, kOctMax);
      const Vec3 d = octPoint(qx, qy);
      const double dot = d.dot(n), norm2 = d.squaredNorm();
      if (dot > 0 && dot * dot * bestNorm2 > bestDot * bestDot * norm2) {
        best = octCode(qx, qy);
        bestDot = dot, bestNorm2 = norm2;
      }
    }
  return best;
}

Vec3 decodeOctahedral(std::uint32_t code) {
  int z;
  return decodeOct(code, z);
}

// --------------------------------------------------------------------- frame (normal, dir_max)

namespace {

// atan(x) for |x| <= tan(pi/8) as x P(x^2), P fitted by least squares on Chebyshev nodes; the
// error is below 1e-11 rad there (tested against std::atan in StackQuantizationTest).
double atanSmall(double x) {
  const double z = x * x;
  const double p = 0.9999999999913545 +
                   z * (-0.3333333242542884 +
                        z * (0.19999902374476486 +
                             z * (-0.1428200299972458 +
                                  z * (0.11044828804060822 +
                                       z * (-0.08477562355190124 + z * 0.04747293917837081)))));
  return x * p;
}

// The angle of (c, s) with s >= 0, in [0, pi], without calling atan2 (the encoder's costliest
// call: once per point and scale), with one division: atan(lo / hi) of the smaller over the
// larger of |c| and s, or pi/4 + atan((lo - hi) / (lo + hi)) beyond tan(pi/8).
double upperHalfAngle(double c, double s) {
  const double ac = std::abs(c);
  const bool steep = s > ac;
  const double lo = steep ? ac : s, hi = steep ? s : ac;
  constexpr double kTanPi8 = 0.41421356237309503;
  double theta =
      lo <= kTanPi8 * hi ? atanSmall(lo / hi) : 0.25 * kPi + atanSmall((lo - hi) / (lo + hi));
  if (steep) theta = 0.5 * kPi - theta;
  return c < 0 ? kPi - theta : theta;
}

}  // namespace

double fastAxisAngle(double c, double s) {
  if (s < 0) c = -c, s = -s;  // an axis: (c, s) and (-c, -s) are the same line
  return upperHalfAngle(c, s);
}

std::uint32_t quantizeAxisAngle(double c, double s) {
  if (!std::isfinite(c) || !std::isfinite(s) || (c == 0 && s == 0)) return 0;
  // The reference: q = round(theta K / pi) mod K with theta = atan2(s, c), plus pi when negative.
  // The fast angle is within 1e-11 rad of atan2 (3e-9 of a step): only values within 1e-6 of a
  // step of a rounding tie are recomputed with atan2, so the codes are exactly the reference's.
  const double steps = fastAxisAngle(c, s) * (kAngleSteps / kPi);  // [0, K]
  const int whole = int(steps);
  const double fraction = steps - whole;
  if (std::abs(fraction - 0.5) > 1e-6)
    return std::uint32_t(whole + (fraction > 0.5 ? 1 : 0)) % std::uint32_t(kAngleSteps);
  double theta = std::atan2(s, c);  // [-pi, pi]
  if (theta < 0) theta += kPi;
  return std::uint32_t(std::lround(theta * (kAngleSteps / kPi))) % std::uint32_t(kAngleSteps);
}

void tangentBasis(const Vec3& n, int zSign, Vec3& b1, Vec3& b2) {
  const double s = zSign >= 0 ? 1.0 : -1.0;
  const double a = -1.0 / (s + n.z());
  const double b = n.x() * n.y() * a;
  b1 = Vec3(1 + s * n.x() * n.x() * a, s * b, -s * n.x());
  b2 = Vec3(b, s + n.y() * n.y() * a, -n.y());
}

std::uint32_t encodeFrame(const Vec3& normal, const Vec3& dirMax) {
  const std::uint32_t oct = encodeOctahedral(normal);
  int z;
  const Vec3 n = decodeOct(oct, z);
  Vec3 b1, b2;
  tangentBasis(n, z, b1, b2);
  const std::uint32_t q = quantizeAxisAngle(dirMax.dot(b1), dirMax.dot(b2));
  return oct | (q << (2 * kOctBits));
}

void decodeFrame(std::uint32_t code, Vec3& normal, Vec3& dirMax, Vec3& dirMin) {
  int z;
  normal = decodeOct(code, z);
  Vec3 b1, b2;
  tangentBasis(normal, z, b1, b2);
  const double theta = double(code >> (2 * kOctBits)) * (kPi / kAngleSteps);
  dirMax = std::cos(theta) * b1 + std::sin(theta) * b2;
  dirMin = normal.cross(dirMax);
}

double axisAngle(const Vec3& a, const Vec3& b) {
  // atan2 of |a x b| and |a . b| is accurate for small angles, unlike acos.
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

// ------------------------------------------------------- shared-exponent offsets (version 3)

namespace {

// 2^k for |k| < 1000 (exact), built from its bits: ldexp is a library call.
double powerOfTwo(int k) {
  const std::uint64_t bits = std::uint64_t(k + 1023) << 52;
  double p;
  std::memcpy(&p, &bits, 8);
  return p;
}

// std::round for 0 <= x < 2^31 (half away from zero), without the library call.
std::uint32_t roundNonNegative(double x) {
  const std::uint32_t whole = std::uint32_t(x);
  return whole + (x - double(whole) >= 0.5 ? 1u : 0u);
}

}  // namespace

std::uint32_t encodeSharedExponent(const Vec3& offset, bool& clamped) {
  double v[3];
  double largest = 0;
  for (int c = 0; c < 3; ++c) {
    v[c] = offset[c];
    if (std::isnan(v[c])) {  // never expected: the fits report finite values
      v[c] = 0;
      clamped = true;
    }
    largest = std::max(largest, std::abs(v[c]));
  }
  if (!(largest > 0)) return 0;  // a zero offset is the code 0
  int e = kOffsetExponentMax;
  if (largest >= kOffsetMaxMagnitude) {  // inf included
    clamped = true;
  } else {
    // largest = f 2^k with f in [0.5, 1): largest 2^(8 - k) is in [128, 256), so e - bias = k - 8
    // puts the largest magnitude in the top half of 0..255, unless it rounds to 256 (then one
    // more). Exact: scaling by a power of two does not round. k is read off the exponent bits
    // (frexp's k for any normal double; the rare subnormal goes to frexp).
    int k;
    if (largest >= 0x1p-1000) {
      std::uint64_t bits;
      std::memcpy(&bits, &largest, 8);
      k = int(bits >> 52) - 1022;
    } else {
      std::frexp(largest, &k);
    }
    e = k - 8 + kOffsetBias;
    if (largest * powerOfTwo(kOffsetBias - e) >= kOffsetMagnitudeMax + 0.5) ++e;
    e = std::max(e, 0);  // tiny offsets: the absolute floor (kOffsetAbsoluteFloor)
  }
  std::uint32_t code = std::uint32_t(e) << 27;
  const double toMagnitude = powerOfTwo(kOffsetBias - e);
  for (int c = 0; c < 3; ++c) {
    const double scaled = std::abs(v[c]) * toMagnitude;  // exact, or inf when clamped
    const std::uint32_t m = scaled >= kOffsetMagnitudeMax - 0.5 ? std::uint32_t(kOffsetMagnitudeMax)
                                                                : roundNonNegative(scaled);
    const std::uint32_t sign = (m != 0 && v[c] < 0) ? 0x100u : 0u;  // no negative zero
    code |= (sign | m) << (9 * c);
  }
  return code;
}

Vec3 decodeSharedExponent(std::uint32_t code, int bias) {
  const int e = int(code >> 27) - bias;
  Vec3 o;
  for (int c = 0; c < 3; ++c) {
    const std::uint32_t field = (code >> (9 * c)) & 0x1ffu;
    const double m = double(field & 0xffu);
    o[c] = std::ldexp((field & 0x100u) ? -m : m, e);
  }
  return o;
}

// ---------------------------------------------------- 8-bit logarithmic codes (version 3)

Log8Code::Log8Code(double lo, double hi, bool isSigned) : lo_(lo), hi_(hi), signed_(isSigned) {
  if (!(lo > 0) || !(hi > lo) || !std::isfinite(hi))
    throw Error("Log8Code: the range must satisfy 0 < lo < hi < inf, not [" + std::to_string(lo) +
                ", " + std::to_string(hi) + "]");
  const int codes = magnitudeCodes();
  ratio_ = std::pow(hi / lo, 1.0 / codes);
  // The same expression as the NumPy decoder (docs/STACK_FORMAT.md), so both give the same doubles.
  edge_[0] = lo;
  for (int k = 1; k <= codes; ++k) {
    centre_[std::size_t(k)] = lo * std::pow(hi / lo, (k - 0.5) / codes);
    edge_[std::size_t(k)] = lo * std::pow(hi / lo, double(k) / codes);  // upper edge of bin k
    if (signed_) centre_[std::size_t(128 + k)] = -centre_[std::size_t(k)];
  }
  log2Lo_ = std::log2(lo);
  binsPerLog2_ = codes / std::log2(hi / lo);
}

std::uint8_t Log8Code::encode(double value, bool& clamped) const {
  if (std::isnan(value)) {
    clamped = true;
    return 0;
  }
  if (value == 0) return 0;
  if (value < 0) {
    if (!signed_) {
      if (value < -kLogNegativeTolerance) clamped = true;
      return 0;
    }
    const std::uint8_t m = encodeMagnitude(-value, clamped);
    return m == 0 ? 0 : std::uint8_t(0x80 | m);
  }
  return encodeMagnitude(value, clamped);
}

std::uint8_t Log8Code::encodeMagnitude(double value, bool& clamped) const {
  const int codes = magnitudeCodes();
  if (value > hi_) {  // inf included
    clamped = true;
    return std::uint8_t(codes);
  }
  if (value < lo_) return value >= 0.5 * centre_[1] ? 1 : 0;
  // The bin k with edge_[k - 1] <= value < edge_[k] (k = C when value >= edge_[C - 1]): the edges
  // are the geometric means of neighbouring centres, so it is the centre nearest in log. A guess
  // from a rough log2 (exponent bits and a quadratic in the mantissa, within 0.01 of log2: a
  // bin is >= 0.18 wide) is corrected against the edges, so the bin is exactly the edges' one;
  // no log call and no unpredictable bisection (the encoder runs twice per point and scale). The
  // edges are rounded doubles: a value within an ulp of an edge may go to either neighbour, still
  // within half a step (+ 1 ulp).
  std::uint64_t bits;
  std::memcpy(&bits, &value, 8);  // lo_ <= value <= hi_: a normal double
  const double m = 1.0 + double(bits & ((std::uint64_t(1) << 52) - 1)) * 0x1p-52;  // [1, 2)
  const double log2Value = double(int(bits >> 52) - 1023) + (m - 1) * (4.0 / 3 - (m - 1) / 3);
  int k = std::clamp(int((log2Value - log2Lo_) * binsPerLog2_) + 1, 1, codes);
  while (k < codes && edge_[std::size_t(k)] <= value) ++k;
  while (k > 1 && edge_[std::size_t(k - 1)] > value) --k;
  return std::uint8_t(k);
}

// ------------------------------------------------------------------------------- bit packing

void packBits(const std::uint8_t* flags, std::size_t n, std::uint8_t* out) {
  std::fill(out, out + packedBytes(n), std::uint8_t(0));
  for (std::size_t i = 0; i < n; ++i)
    if (flags[i]) out[i / 8] = std::uint8_t(out[i / 8] | (1u << (i % 8)));
}

}  // namespace scalespace::quant
