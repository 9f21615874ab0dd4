#pragma once
// The pure encode/decode functions of the compact stack encoding (docs/STACK_FORMAT.md,
// "Compact encoding"). They are kept apart from the file handling so that they can be tested
// exhaustively, and so that scripts/read_stack.py can mirror them line by line.
//
// Everything here is deterministic and uses only integer arithmetic wherever a decision is taken
// (octahedral fold, sign of the tangent basis), so that a decoder written in another language
// (NumPy) takes the same branches as ours.
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
constexpr double kAngleMaxError = 3.14159265358979323846 / (2 * kAngleSteps);

/// The deterministic tangent basis (b1, b2) of a decoded normal n (Duff et al. 2017, "Building an
/// orthonormal basis, revisited"): s = +1 if zSign >= 0 else -1, a = -1 / (s + n.z),
/// b = n.x n.y a, b1 = (1 + s n.x^2 a, s b, -s n.x), b2 = (b, s + n.y^2 a, -n.y). zSign is the
/// integer z of the octahedral code (exact, so that every decoder takes the same branch).
void tangentBasis(const Vec3& n, int zSign, Vec3& b1, Vec3& b2);

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
