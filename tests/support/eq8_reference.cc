#include "tests/support/eq8_reference.h"

#include <algorithm>
#include <cmath>

namespace airtwin::testing {

std::vector<double> eq8_ray_reference(const OrientedField& field, const ObjectDynamics& xi,
                                      const Eigen::Vector2d& p0_W, double duration_s,
                                      double sample_dt_s, const Eq8RayTerms& terms) {
  const Eigen::Vector2d s = field.stagnation_point();
  const Eigen::Vector2d u = (p0_W - s).normalized();
  auto air = [&](double r) { return terms.air_scale * field.speed(s + r * u); };
  const double c = -xi.xi1, intercept = terms.intercept_share * -xi.xi3;
  const double w0 = 2.0 * intercept / c;
  auto friction = [&](double r, double v) {
    const double rel = air(r) - v;
    return -std::max(0.0, -xi.xi3 - intercept) * std::max(0.0, 1.0 - terms.lift_s2pm2 * rel * rel);
  };
  auto drag = [&](double r, double v) {
    if (w0 == 0.0) return xi.xi1 * v + xi.xi2 * air(r);
    const double w = xi.xi2 / c * air(r) - v;
    const double n = std::abs(w);
    return n >= w0 ? std::copysign(c * n - intercept, w) : 0.5 * c / w0 * n * w;
  };
  auto accel = [&](double r, double v) { return drag(r, v) + friction(r, v); };
  auto drive = [&](double r) { return accel(r, 0.0); };
  const double h = 1e-4;
  const int per_sample = static_cast<int>(std::lround(sample_dt_s / h));
  double r = (p0_W - s).norm(), v = 0.0;
  bool moving = drive(r) > 0;
  std::vector<double> samples{r};
  const int n = static_cast<int>(std::lround(duration_s / sample_dt_s));
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < per_sample && moving; ++k) {
      const double k1r = v, k1v = accel(r, v);
      const double k2r = v + 0.5 * h * k1v, k2v = accel(r + 0.5 * h * k1r, v + 0.5 * h * k1v);
      const double k3r = v + 0.5 * h * k2v, k3v = accel(r + 0.5 * h * k2r, v + 0.5 * h * k2v);
      const double k4r = v + h * k3v, k4v = accel(r + h * k3r, v + h * k3v);
      r += h / 6 * (k1r + 2 * k2r + 2 * k3r + k4r);
      v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      if (v <= 0 && drive(r) <= 0) moving = false;
    }
    samples.push_back(r);
  }
  return samples;
}

}  // namespace airtwin::testing
