#pragma once
// Branch-free elementary functions for the air-field kernel, written so that a loop over them
// vectorises (compile with -fno-trapping-math, as models/ does). glibc's atan2 (~27 ns) and exp
// (~5.5 ns) dominated the field evaluation; these two keep full double accuracy:
//
// fast_atan2: fold (x, y) into the first octant (t = min/max in [0, 1]); for t > tan(pi/8) use
//   atan(t) = pi/4 + atan((t - 1) / (t + 1)), so |u| <= tan(pi/8); then atan(u) = u P(u^2), P a
//   degree-9 Chebyshev interpolant of atan(u)/u in s = (u^2 - c) / h, coefficients from
//   scripts/fit_atan_poly.py. Max error 7.8e-16 rad on the reduced range.
// fast_exp: x = k ln2 + f with |f| <= ln2 / 2 (Cody-Waite split of ln2), e^f by its Taylor
//   polynomial to degree 12 (truncation < 2e-17), times 2^k assembled in the exponent bits.
//   Input clamped to [-700, 700]: no overflow, no subnormals. A few ulp from libm's exp.

#include <bit>
#include <cmath>
#include <cstdint>

namespace airtwin {

namespace fast_math_detail {
constexpr double kZCenter = 0.08578643762690495;
constexpr double kZHalfWidth = 0.08578643762690495;
constexpr double kPoly[] = {
    0.9727918173603561,    -0.02590019545981393,    0.0012335918789502908,  -6.980070659579063e-05,
    4.296550143045863e-06, -2.7806799058893715e-07, 1.8604730911420124e-08, -1.2751439015801226e-09,
    9.007834478325095e-11, -6.194511570356554e-12};
constexpr double kTanPi8 = 0.41421356237309503;
constexpr double kPiValue = 3.141592653589793;
constexpr double kLog2e = 1.4426950408889634;
constexpr double kLn2Hi = 0.693147180369123816490;  // ln2 split: k * Hi is exact for |k| < 2^20
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kRoundMagic = 6755399441055744.0;  // 1.5 * 2^52
constexpr std::uint64_t kRoundMagicBits = 0x4338000000000000u;
}  // namespace fast_math_detail

/// atan2(y, x) in [-pi, pi]; 0 for (0, 0). Same sign conventions as std::atan2 for finite input.
/// Written with value selects only (no data-dependent branches), so random directions cost no
/// branch mispredictions and a loop over it vectorises.
inline double fast_atan2(double y, double x) {
  using namespace fast_math_detail;
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double hi = steep ? ay : ax, lo = steep ? ax : ay;
  const double t = lo / (hi > 1e-300 ? hi : 1e-300);  // in [0, 1]
  const bool upper = t > kTanPi8;
  const double u = (upper ? t - 1.0 : t) / (upper ? t + 1.0 : 1.0);
  const double s = (u * u - kZCenter) * (1.0 / kZHalfWidth);
  double p = kPoly[9];
  for (int i = 8; i >= 0; --i) p = p * s + kPoly[i];
  const double octant = (upper ? 0.25 * kPiValue : 0.0) + u * p;     // atan(t)
  const double quadrant = steep ? 0.5 * kPiValue - octant : octant;  // first quadrant
  const double half = x < 0.0 ? kPiValue - quadrant : quadrant;      // upper half-plane
  return std::copysign(half, y);
}

namespace fast_math_detail {
// The range reduction shared by the exponentials: x = k ln2 + f, |f| <= ln2 / 2. k = round(x / ln2)
// through the 1.5 * 2^52 trick: the low mantissa bits of `shifted` then hold k.
struct ExpReduced {
  double f;
  double shifted;
};
inline ExpReduced exp_reduce(double x) {
  x = x < -700.0 ? -700.0 : (x > 700.0 ? 700.0 : x);
  const double shifted = x * kLog2e + kRoundMagic;
  const double k = shifted - kRoundMagic;
  return {(x - k * kLn2Hi) - k * kLn2Lo, shifted};
}
// 2^k: biased exponent k + 1023 in bits 52..62.
inline double exp_scale(double shifted) {
  const std::uint64_t k_bits = std::bit_cast<std::uint64_t>(shifted) - kRoundMagicBits;
  return std::bit_cast<double>((k_bits + 1023u) << 52);
}
}  // namespace fast_math_detail

/// e^x for x in [-700, 700] (clamped outside), relative error a few 1e-16. The degree-12 Taylor
/// polynomial of e^f by Horner's scheme.
inline double fast_exp(double x) {
  using namespace fast_math_detail;
  const ExpReduced r = exp_reduce(x);
  const double f = r.f;
  double p = 1.0 / 479001600.0;  // 1/12!
  p = p * f + 1.0 / 39916800.0;
  p = p * f + 1.0 / 3628800.0;
  p = p * f + 1.0 / 362880.0;
  p = p * f + 1.0 / 40320.0;
  p = p * f + 1.0 / 5040.0;
  p = p * f + 1.0 / 720.0;
  p = p * f + 1.0 / 120.0;
  p = p * f + 1.0 / 24.0;
  p = p * f + 1.0 / 6.0;
  p = p * f + 0.5;
  p = p * f + 1.0;
  p = p * f + 1.0;
  return p * exp_scale(r.shifted);
}

/// The same e^x with the polynomial evaluated by Estrin's scheme: a shorter dependency chain
/// (~25% faster where exponentials are latency-bound, as in the fast predictor's RK4), same
/// accuracy, not bit-identical to fast_exp.
inline double fast_exp_estrin(double x) {
  using namespace fast_math_detail;
  const ExpReduced r = exp_reduce(x);
  const double f = r.f, f2 = f * f, f4 = f2 * f2, f8 = f4 * f4;
  const double p01 = 1.0 + f, p23 = 0.5 + f * (1.0 / 6), p45 = 1.0 / 24 + f * (1.0 / 120);
  const double p67 = 1.0 / 720 + f * (1.0 / 5040), p89 = 1.0 / 40320 + f * (1.0 / 362880);
  const double pab = 1.0 / 3628800 + f * (1.0 / 39916800), pc = 1.0 / 479001600;
  const double q0 = p01 + f2 * p23, q1 = p45 + f2 * p67, q2 = p89 + f2 * pab;
  return (q0 + f4 * q1 + f8 * (q2 + f4 * pc)) * exp_scale(r.shifted);
}

}  // namespace airtwin
