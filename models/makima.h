#pragma once
// MATLAB's modified Akima interpolation ("makima"), used for the tilt direction of the field
// coefficients (paper, section III-A). Works from 2 nodes (linear) up; with 3 nodes it is close to,
// not equal to, the interpolating parabola.
//
// Node slopes: d_i = (w1 delta_{i-1} + w2 delta_i) / (w1 + w2) with
//   w1 = |delta_{i+1} - delta_i| + |delta_{i+1} + delta_i| / 2,
//   w2 = |delta_{i-1} - delta_{i-2}| + |delta_{i-1} + delta_{i-2}| / 2, d_i = 0 when w1 + w2 = 0;
// the missing interval slopes at each end come from quadratic extrapolation
// (delta_0 = 2 delta_1 - delta_2, delta_{-1} = 2 delta_0 - delta_1); then cubic Hermite per
// interval.

#include <span>
#include <vector>

namespace airtwin {

/// Node slopes of MATLAB's makima for strictly increasing `x` (n >= 2) and values `y`.
std::vector<double> makima_slopes(std::span<const double> x, std::span<const double> y);

/// Cubic Hermite basis on one interval, for a parameter t in [0, 1] and width h:
/// value = h00 y0 + h10 d0 + h01 y1 + h11 d1 (the slopes already multiplied by h in h10, h11).
struct HermiteWeights {
  double h00, h10, h01, h11;
};
HermiteWeights hermite_weights(double t, double h);

/// A makima interpolant through (x, y). Outside [x.front(), x.back()] it clamps to the end values
/// (extrapolation is unsafe for the field model, as the paper warns).
class Makima {
 public:
  Makima(std::vector<double> x, std::vector<double> y);
  double operator()(double xq) const;
  const std::vector<double>& slopes() const { return d_; }

 private:
  std::vector<double> x_, y_, d_;
};

/// Locates xq in the strictly increasing nodes: interval index k (x[k] <= xq <= x[k+1]) and the
/// parameter t in [0, 1]; xq is clamped to the node range first.
void locate_interval(std::span<const double> x, double xq, size_t* k, double* t);

}  // namespace airtwin
