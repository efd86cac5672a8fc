// The time turbulent air keeps its memory at an observer it sweeps past (models/turbulence_time.h),
// against its definition and its two limits, and the simulated anemometer's Eulerian time as the
// same law with Pope's Lagrangian time.

#include "models/turbulence_time.h"

#include <gtest/gtest.h>

#include <cmath>

#include "models/hotwire.h"

namespace airtwin {
namespace {

TEST(TurbulenceTime, TheIntegralLengthIsPopesHighReynoldsNumberOne) {
  // k = 0.5 m^2/s^2, epsilon = 2 m^2/s^3: k^1.5 / epsilon = 0.17678 m.
  EXPECT_NEAR(integral_length_m(0.5, 2.0), 0.43 * 0.35355339059327373 / 2.0, 1e-15);
}

TEST(TurbulenceTime, TheEddiesLifeAndTheirSweepCombineAsRates) {
  const double k = 0.5, epsilon = 2.0, t_l = 0.0375;  // T_L = 0.15 k / epsilon
  const double l11 = 0.43 * std::pow(k, 1.5) / epsilon;
  // At rest relative to the air the eddies' life alone; fast, their passage time L11 / U.
  EXPECT_DOUBLE_EQ(swept_integral_time_s(t_l, 0.0, k, epsilon), t_l);
  EXPECT_NEAR(swept_integral_time_s(t_l, 1e5, k, epsilon) * 1e5 / l11, 1.0, 1e-4);
  // Where the two are equal the time is half of either: U = L11 / T_L.
  EXPECT_NEAR(swept_integral_time_s(t_l, l11 / t_l, k, epsilon), 0.5 * t_l, 1e-15);
  // A tracer held at its 5.6 mm centre 0.4 m from s at tilt 0, in the shipped CFD's air (2.96 m/s,
  // k 0.611 m^2/s^2, epsilon 29.4 m^2/s^3): 1 / (1 / 3.12 ms + 2.96 / 6.99 mm) = 1.34 ms, less
  // than half of T_L.
  const double k_floor = 0.611, epsilon_floor = 29.4, t_l_floor = 0.15 * k_floor / epsilon_floor;
  const double t = swept_integral_time_s(t_l_floor, 2.96, k_floor, epsilon_floor);
  EXPECT_NEAR(t, 1.0 / (1.0 / t_l_floor + 2.96 / (0.43 * std::pow(k_floor, 1.5) / epsilon_floor)),
              1e-15);
  EXPECT_NEAR(t, 1.34e-3, 0.01e-3);
  EXPECT_LT(t, 0.5 * t_l_floor);
}

TEST(TurbulenceTime, TheAnemometersEulerianTimeIsTheSweptTimeWithPopesLagrangianTime) {
  for (double u : {0.0, 0.3, 2.5}) {
    const double k = 0.2, epsilon = 1.5;
    const double t_l = 4.0 * k / (3.0 * 2.1 * epsilon);  // C0 = 2.1
    EXPECT_DOUBLE_EQ(eulerian_integral_time_s(u, k, epsilon),
                     swept_integral_time_s(t_l, u, k, epsilon))
        << "U " << u;
  }
}

}  // namespace
}  // namespace airtwin
