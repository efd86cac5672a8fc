#include "models/makima.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"

namespace airtwin {

std::vector<double> makima_slopes(std::span<const double> x, std::span<const double> y) {
  const size_t n = x.size();
  AIRTWIN_DEMAND(n >= 2 && y.size() == n);
  // Two nodes: the straight line.
  if (n == 2) {
    const double s = (y[1] - y[0]) / (x[1] - x[0]);
    return {s, s};
  }
  // Interval slopes, padded with two quadratically extrapolated slopes at each end:
  // delta[j + 2] holds the slope of interval j (0-based), j in [-2, n].
  std::vector<double> delta(n + 3);
  for (size_t j = 0; j + 1 < n; ++j) delta[j + 2] = (y[j + 1] - y[j]) / (x[j + 1] - x[j]);
  delta[1] = 2.0 * delta[2] - delta[3];
  delta[0] = 2.0 * delta[1] - delta[2];
  delta[n + 1] = 2.0 * delta[n] - delta[n - 1];
  delta[n + 2] = 2.0 * delta[n + 1] - delta[n];

  // Node i sits between intervals i-1 and i, i.e. delta[i + 1] and delta[i + 2].
  std::vector<double> d(n);
  for (size_t i = 0; i < n; ++i) {
    const double dm2 = delta[i], dm1 = delta[i + 1], d0 = delta[i + 2], dp1 = delta[i + 3];
    const double w1 = std::abs(dp1 - d0) + std::abs(dp1 + d0) / 2.0;
    const double w2 = std::abs(dm1 - dm2) + std::abs(dm1 + dm2) / 2.0;
    d[i] = (w1 + w2 == 0.0) ? 0.0 : (w1 * dm1 + w2 * d0) / (w1 + w2);
  }
  return d;
}

HermiteWeights hermite_weights(double t, double h) {
  const double t2 = t * t, t3 = t2 * t;
  return {2 * t3 - 3 * t2 + 1, (t3 - 2 * t2 + t) * h, -2 * t3 + 3 * t2, (t3 - t2) * h};
}

void locate_interval(std::span<const double> x, double xq, size_t* k, double* t) {
  const size_t n = x.size();
  AIRTWIN_DEMAND(n >= 2);
  xq = std::clamp(xq, x.front(), x.back());
  size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), xq) - x.begin());
  i = std::clamp<size_t>(i, 1, n - 1) - 1;
  *k = i;
  *t = (xq - x[i]) / (x[i + 1] - x[i]);
}

Makima::Makima(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)), d_(makima_slopes(x_, y_)) {}

double Makima::operator()(double xq) const {
  size_t k;
  double t;
  locate_interval(x_, xq, &k, &t);
  const HermiteWeights w = hermite_weights(t, x_[k + 1] - x_[k]);
  return w.h00 * y_[k] + w.h10 * d_[k] + w.h01 * y_[k + 1] + w.h11 * d_[k + 1];
}

}  // namespace airtwin
