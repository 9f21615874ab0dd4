#pragma once
// exp(-x) for x >= 0, for the robust re-weighting factors (fit/LocalFit.cpp): they are evaluated
// for every neighbour at every re-weighting pass, and libm's exp was a large share of the robust
// multi-scale projection's time (bench/fig_1_10 --mode timing --robust 1). Relative error below
// 1e-8 (tested against std::exp), which is far below what a weight needs; deterministic (no
// table, no rounding-mode dependence), so results stay identical for any thread count.
#include <cmath>
#include <cstdint>
#include <cstring>

namespace scalespace {

// The constants of expNegative, shared with its 4-lane version (fit/RobustReweighting.cpp).
namespace fastexp {
constexpr double kMaxArgument = 708.0;  // exp(-708) ~ 3e-308: beyond it, 0
// exp(-x) = 2^-n * exp(-x + n ln 2) with n = round(x / ln 2), so the reduced argument
// y = n ln 2 - x lies in [-ln2/2, ln2/2]; ln 2 is split in two parts (Cody-Waite) so that
// n ln 2 is exact to double precision.
constexpr double kInvLn2 = 1.4426950408889634;
constexpr double kLn2Hi = 6.93147180369123816490e-01;
constexpr double kLn2Lo = 1.90821492927058770002e-10;
// 1/k! for the Taylor series of e^y to degree 7 (|y| <= 0.347: truncation error < 6e-9
// relative).
constexpr double kC2 = 1.0 / 2, kC3 = 1.0 / 6, kC4 = 1.0 / 24, kC5 = 1.0 / 120, kC6 = 1.0 / 720,
                 kC7 = 1.0 / 5040;
}  // namespace fastexp

/// exp(-x) for x >= 0 (x > 708 and NaN give 0; x <= 0 is clamped to exp(0) = 1).
inline double expNegative(double x) {
  using namespace fastexp;
  if (!(x < kMaxArgument)) return 0.0;  // also catches NaN: a weight of 0, never NaN
  if (x <= 0) return 1.0;
  const double n = std::floor(x * kInvLn2 + 0.5);
  const double y = (n * kLn2Hi - x) + n * kLn2Lo;
  // Estrin's form, so that the terms do not wait on each other as in Horner's chain.
  const double y2 = y * y;
  const double p =
      ((1 + y) + y2 * (kC2 + y * kC3)) + (y2 * y2) * ((kC4 + y * kC5) + y2 * (kC6 + y * kC7));
  // Scale by 2^-n through the exponent bits (n <= 1022 here, so the result stays normal except
  // for the last few units: those go through ldexp, which handles subnormals).
  const std::int64_t k = std::int64_t(n);
  if (k > 1000) return std::ldexp(p, -int(k));
  std::uint64_t bits = std::uint64_t(1023 - k) << 52;
  double scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

}  // namespace scalespace
