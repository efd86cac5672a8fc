#include "tests/support/synthetic_trajectories.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "common/units.h"

namespace airtwin::testing {
namespace {

// Advances (r, v) along a ray by one 25 ms frame: RK4 at 0.25 ms on dr/dt = v,
// dv/dt = xi1 v + xi2 u(r) + xi3; a speed falling through zero stops the object.
void advance_frame(const FieldCoefficients& c, double xi1, double xi2, double xi3, double& r,
                   double& v) {
  const double h = 0.025 / 100;
  auto acc = [&](double rr, double vv) { return xi1 * vv + xi2 * c.speed(rr) + xi3; };
  for (int j = 0; j < 100; ++j) {
    const double k1 = acc(r, v), k2 = acc(r + 0.5 * h * v, v + 0.5 * h * k1);
    const double k3 = acc(r + 0.5 * h * (v + 0.5 * h * k1), v + 0.5 * h * k2);
    const double k4 = acc(r + h * (v + 0.5 * h * k2), v + h * k3);
    r += h * v + h * h / 6 * (k1 + k2 + k3);
    v += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    if (v < 0) v = 0;
  }
}

}  // namespace

TrajectorySet make_ray_trajectories(const AirFieldModel& model, double xi1, double xi2, double xi3,
                                    int n, std::uint64_t seed, const std::string& object) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> start(0.2, 0.58), angle(-kPi, kPi);
  TrajectorySet set;
  for (int i = 0; i < n; ++i) {
    const NozzleOrientation o{angle(rng), deg_to_rad(i % 2 ? 22.5 : 0.0)};
    const OrientedField f = model.at(o);
    const double a = angle(rng);
    const Eigen::Vector2d dir = Eigen::Rotation2Dd(a) * Eigen::Vector2d::UnitX();
    const FieldCoefficients c = f.coefficients(a - o.pan_rad);
    double r = start(rng), v = 0;
    Trajectory tr;
    tr.id = std::to_string(i);
    tr.object = object;
    for (int k = 0; k <= 80; ++k) {
      tr.samples.push_back({k * 0.025, f.stagnation_point() + r * dir, o});
      advance_frame(c, xi1, xi2, xi3, r, v);
    }
    set.trajectories.push_back(tr);
  }
  return set;
}

std::string make_speed_series_csv(const AirFieldModel& model, double xi1, double xi2, double xi3,
                                  int n, std::uint64_t seed, double noise) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> start(0.2, 0.58), angle(-kPi, kPi);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::string csv = "t,v,vair\n";
  int frame = 0;
  for (int i = 0; i < n; ++i) {
    const OrientedField f = model.at({angle(rng), deg_to_rad(i % 2 ? 22.5 : 0.0)});
    const FieldCoefficients c = f.coefficients(angle(rng));
    double r = start(rng), v = 0;
    for (int k = 0; k <= 80; ++k, ++frame) {
      const double measured = std::max(0.0, v * (1 + noise * gauss(rng)));
      csv += std::to_string(frame * 0.025) + "," + std::to_string(measured) + "," +
             std::to_string(c.speed(r)) + "\n";
      advance_frame(c, xi1, xi2, xi3, r, v);
    }
  }
  return csv;
}

}  // namespace airtwin::testing
