#pragma once
// The pure encode/decode functions of the compact stack encoding (docs/STACK_FORMAT.md,
// "Compact encoding": float16 and the octahedral frame since format version 2, the shared-exponent
// offsets and the 8-bit logarithmic codes of version 3). They are kept apart from the file handling
// so that they can be tested exhaustively, and so that scripts/read_stack.py can mirror them line
// by line.
//
// Everything here is deterministic and uses only integer arithmetic wherever a decision is taken
// (octahedral fold, sign of the tangent basis), so that a decoder written in another language
// (NumPy) takes the same branches as ours.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "scalespace/core/Types.hpp"

namespace scalespace::quant {

// ------------------------------------------------------------------------------------ float16

/// IEEE 754 binary16 maximum finite value.
constexpr float kHalfMax = 65504.0f;

/// float32 -> binary16 bits, round to nearest, ties to even (as numpy.float16 does), without
/// relying on _Float16 (not portable to every compiler we build with). Values whose rounding
/// would overflow to infinity are clamped to +-65504 and `clamped` is set; NaN is written as 0
/// and `clamped` is set too (the stack never holds inf or NaN). Subnormals are kept.
std::uint16_t floatToHalf(float value, bool& clamped);
/// binary16 bits -> float32 (exact).
float halfToFloat(std::uint16_t bits);

// -------------------------------------------------------------------------------- octahedral

/// Octahedral unit-vector encoding (Cigolle et al. 2014) with two signed-normalised 11-bit
/// components: q = round(u * 1023) in [-1023, 1023], stored in excess-1023 (0..2046). Chosen over
/// spherical angles because its error is nearly uniform over the sphere and the decoding is a
/// few adds. The encoder tries the 4 neighbouring grid points and keeps the closest one
/// ("precise" variant), which halves the worst error of plain rounding.
constexpr int kOctBits = 11;
constexpr int kOctMax = (1 << (kOctBits - 1)) - 1;  // 1023
/// Worst angle (radians) between a unit vector and its decoded octahedral code. A rounding error of
/// at most h/2 per coordinate (h = 1/1023 in the octahedral square) moves the point of the
/// octahedron |x|+|y|+|z| = 1 by at most sqrt((h/2)^2 + (h/2)^2 + h^2) = 1.2247 h, and the
/// octahedron is at distance >= 1/sqrt(3) from the centre, so the direction turns by at most
/// 1.2247 * sqrt(3) h = 2.1213 h = 2.07e-3 rad = 0.119 degrees.
constexpr double kOctMaxAngle = 2.1214 / kOctMax;

/// 22-bit octahedral code of `n` (any length > 0; a zero or non-finite vector encodes +z):
/// bits 0..10 = qx + 1023, bits 11..21 = qy + 1023.
std::uint32_t encodeOctahedral(const Vec3& n);
/// Decodes the 22 low bits of `code` to a unit vector.
Vec3 decodeOctahedral(std::uint32_t code);

// --------------------------------------------------------------------- frame (normal, dir_max)

/// Bits of the dir_max angle: theta = q * pi / 1024, q in [0, 1023] (a direction is an axis, so
/// [0, pi) covers every line of the tangent plane).
constexpr int kAngleBits = 10;
constexpr int kAngleSteps = 1 << kAngleBits;
/// Worst angle between a tangent axis and its decoded angle, given an exact normal.
constexpr double kAngleMaxError = kPi / (2 * kAngleSteps);

/// The deterministic tangent basis (b1, b2) of a decoded normal n (Duff et al. 2017, "Building an
/// orthonormal basis, revisited"): s = +1 if zSign >= 0 else -1, a = -1 / (s + n.z),
/// b = n.x n.y a, b1 = (1 + s n.x^2 a, s b, -s n.x), b2 = (b, s + n.y^2 a, -n.y). zSign is the
/// integer z of the octahedral code (exact, so that every decoder takes the same branch).
void tangentBasis(const Vec3& n, int zSign, Vec3& b1, Vec3& b2);

/// The angle in [0, pi] of the axis through (c, s) (atan2(s, c), plus pi when negative), within
/// 1e-11 rad, without a library call.
double fastAxisAngle(double c, double s);
/// q = round(theta K / pi) mod K for that axis angle theta (K = kAngleSteps), exactly as with
/// std::atan2 and std::lround (values near a rounding tie are recomputed with them); 0 for a
/// zero or non-finite (c, s).
std::uint32_t quantizeAxisAngle(double c, double s);

/// Packs a unit normal and a principal direction into 32 bits: bits 0..21 the octahedral normal,
/// bits 22..31 the angle q of dir_max in the tangent basis of the *decoded* normal:
/// dir_max = cos(theta) b1 + sin(theta) b2, theta = q pi / 1024.
std::uint32_t encodeFrame(const Vec3& normal, const Vec3& dirMax);
/// Decodes a frame; dirMin = normal x dirMax, so (dirMax, dirMin, normal) is right-handed. Our
/// fits return either handedness (the shape operator's dirMax = n x dirMin is computed before the
/// normal is oriented like the input normals; tangentBasis gives the other one): principal
/// directions are axes, so only the line of dirMin is meaningful, in both encodings.
void decodeFrame(std::uint32_t code, Vec3& normal, Vec3& dirMax, Vec3& dirMin);

/// Angle (radians, in [0, pi/2]) between the lines spanned by a and b.
double axisAngle(const Vec3& a, const Vec3& b);

// ------------------------------------------------------- shared-exponent offsets (version 3)

/// The projection offset o = (projection - input) / t in 32 bits: one 5-bit exponent e shared by
/// three 9-bit sign-magnitude components (the idea of OpenGL's RGB9_E5 and of block floating
/// point; EXT_texture_shared_exponent, 2008), component c = (-1)^s_c m_c 2^(e - bias):
///
///   bits 0..8: x (bit 8 sign, bits 0..7 magnitude m), 9..17: y, 18..26: z, 27..31: e.
///
/// The three components of one offset have similar magnitudes where it matters (the error is
/// bounded by the largest one, which sets the length of the offset), so one exponent serves all
/// three and leaves 8 bits of magnitude each, 12 bits less than three float16.
/// The encoder takes the smallest e whose rounding keeps every |m_c| <= 255, so the largest
/// component uses the full magnitude range (128..255) unless e = 0; rounding is to nearest, ties
/// away from zero; a component that rounds to 0 (in particular an exact 0) is stored as +0.
constexpr int kOffsetBias = 27;
constexpr int kOffsetExponentMax = 31;
constexpr int kOffsetMagnitudeMax = 255;
/// Offsets whose largest component reaches 255.5 * 2^(31 - 27) = 4088 (in units of t) do not fit
/// (m would round to 256 at the largest exponent): every component is clamped to 255 * 16, with
/// its sign, and the offset is counted as clamped. Measured offsets stay below 1.5 t.
constexpr double kOffsetMaxMagnitude = 255.5 * (1 << (kOffsetExponentMax - kOffsetBias));
/// Worst error per component, |decoded_c - o_c| <= max(kOffsetRelativeError * max_c |o_c|,
/// kOffsetAbsoluteFloor). Derivation: rounding m_c errs by at most half a step 2^(e - bias - 1).
/// If e > 0, e - 1 was rejected, i.e. max |o_c| 2^(bias - e + 1) >= 255.5, so half a step is at
/// most max |o_c| / 255.5 (3.91e-3, between 2^-9 and 2^-8); if e = 0, half a step is 2^-(bias + 1)
/// = 2^-28 = 3.7e-9. Offsets from 2^-20 (where m reaches 128 at e = 0) to 4088 keep the full
/// relative precision.
constexpr double kOffsetRelativeError = 1.0 / 255.5;
constexpr double kOffsetAbsoluteFloor = 1.0 / double(1u << (kOffsetBias + 1));

/// Encodes an offset (units of t). NaN components are written as 0 and set `clamped`; offsets
/// beyond kOffsetMaxMagnitude (inf included) are clamped as above and set `clamped`.
std::uint32_t encodeSharedExponent(const Vec3& offset, bool& clamped);
/// Decodes a code written with exponent bias `bias` (exact: an integer times a power of two).
Vec3 decodeSharedExponent(std::uint32_t code, int bias = kOffsetBias);

// ---------------------------------------------------- 8-bit logarithmic codes (version 3)

/// Quantities spanning many decades (anisotropy, geometric variation) in one byte.
/// Unsigned ("log8", for nu >= 0): code 0 is exactly 0; codes k = 1..C (C = 255) split [lo, hi]
/// into C bins of equal ratio r = (hi / lo)^(1/C), bin k = [lo r^(k-1), lo r^k], decoded to its
/// geometric centre lo r^(k - 1/2) = lo * (hi / lo)^((k - 0.5) / C).
/// Signed ("slog8", for the anisotropy 1 - |u_l|, negative for a few percent of the fits): bit 7
/// is the sign and bits 0..6 the code of the magnitude with C = 127 (0 and 128 decode to 0; the
/// encoder writes 0).
/// The encoder picks the code whose centre is nearest in log, so for lo <= |v| <= hi the relative
/// error is at most half a step: |decoded / v - 1| <= sqrt(r) - 1. Below lo the nearest of 0 and
/// the first centre c1 is taken (absolute error <= c1 / 2 = lo sqrt(r) / 2). Hence, for
/// |v| <= hi, |decoded - v| <= (sqrt(r) - 1) |v| + lo sqrt(r) / 2.
/// Clamping (counted through `clamped`): |v| > hi (inf included) -> the largest code of its sign;
/// NaN -> 0; unsigned only: v < 0 -> 0, counted only when v < -kLogNegativeTolerance (a negative
/// float rounding of 0 is not a clamp).
class Log8Code {
 public:
  /// Requires 0 < lo < hi, both finite (Error otherwise: callers validate what they read).
  Log8Code(double lo, double hi, bool isSigned = false);
  std::uint8_t encode(double value, bool& clamped) const;
  double decode(std::uint8_t code) const { return centre_[code]; }
  double lo() const { return lo_; }
  double hi() const { return hi_; }
  bool isSigned() const { return signed_; }
  /// Codes per sign: C = 255 unsigned, 127 signed.
  int magnitudeCodes() const { return signed_ ? 127 : 255; }
  /// r = (hi / lo)^(1/C).
  double stepRatio() const { return ratio_; }
  /// sqrt(r) - 1: the relative error bound within [lo, hi].
  double maxRelativeError() const { return std::sqrt(ratio_) - 1; }
  /// lo sqrt(r) / 2: the absolute error bound below lo.
  double absoluteFloor() const { return 0.5 * centre_[1]; }

 private:
  std::uint8_t encodeMagnitude(double magnitude, bool& clamped) const;  // magnitude > 0
  double lo_, hi_, ratio_;
  bool signed_;
  std::array<double, 256> centre_{};     // decoded values, centre_[0] = 0
  std::array<double, 256> edge_{};       // edge_[k] = lo r^k: the edges of bin k are k-1, k
  double log2Lo_ = 0, binsPerLog2_ = 0;  // a first guess of the bin from the exponent bits
};

/// Negative inputs of a log code down to -2^-23 (one float32 ulp at 1: what 1 - |u_l| rounds to
/// when |u_l| is 1 in exact arithmetic) are written as 0 without being counted as clamped.
constexpr double kLogNegativeTolerance = 1.0 / double(1u << 23);

/// The ranges of the version-3 stack (measured, docs/STACK_FORMAT.md): the anisotropy 1 - |u_l|
/// is at most 1 and typically 1e-6..1e-1 in magnitude; it is negative for 2.8 % of the fits of a
/// noisy 200k torus (24 % at the smallest scale, down to -0.415 at coarse ones), hence signed;
/// the fits give a few 1e-16 from rounding, coded 0. The geometric variation nu >= 0 ranged
/// 1.5e-17..7.8e3 on a torus, a stairs scene and a real scan (0.1 percentile >= 1e-10). Step
/// ratios: anisotropy 10^(7/127) = 1.1354 (relative error <= 6.56 %), nu 10^(16/255) = 1.1554
/// (<= 7.49 %).
constexpr double kAnisotropyLogMin = 1e-7;
constexpr double kAnisotropyLogMax = 1.0;
constexpr double kVariationLogMin = 1e-10;
constexpr double kVariationLogMax = 1e6;

// ------------------------------------------------------------------------------- bit packing

/// ceil(n / 8).
constexpr std::size_t packedBytes(std::size_t n) { return (n + 7) / 8; }
/// Packs n flags (non-zero = 1) little-endian bit order: flag i is bit (i % 8) of byte i / 8,
/// as numpy.packbits(..., bitorder='little'); padding bits are 0.
void packBits(const std::uint8_t* flags, std::size_t n, std::uint8_t* out);
/// Flag i of a packed array.
inline std::uint8_t unpackBit(const std::uint8_t* packed, std::size_t i) {
  return std::uint8_t((packed[i / 8] >> (i % 8)) & 1u);
}

}  // namespace scalespace::quant
