// The nozzle actuator: servo limits, the field delay, the jet ramp, command validation.

#include "sim/nozzle_actuator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// Time-optimal move of distance D under speed limit v and acceleration limit a, from rest to
// rest: a trapezoid (D > v^2 / a) or a triangle.
double optimal_move_time(double distance, double v, double a) {
  return distance > v * v / a ? distance / v + v / a : 2.0 * std::sqrt(distance / a);
}

TEST(ServoStep, NeverExceedsItsLimitsAndStopsOnTheTarget) {
  const double v_max = 7.0, a_max = 30.0, dt = 0.001;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> target_dist(-3.0, 3.0);
  double angle = 0.0, rate = 0.0;
  for (int move = 0; move < 30; ++move) {
    const double target = target_dist(rng);
    const double distance = std::abs(target - angle);
    const bool from_rest = rate == 0.0;
    int steps = 0;
    double previous_rate = rate;
    while (angle != target && steps < 100000) {
      servo_step(target, v_max, a_max, dt, &angle, &rate);
      EXPECT_LE(std::abs(rate), v_max + 1e-12);
      // Acceleration bound, including the final stop on the target.
      EXPECT_LE(std::abs(rate - previous_rate), a_max * dt + 1e-9);
      previous_rate = rate;
      ++steps;
    }
    ASSERT_EQ(angle, target) << "move " << move << " did not arrive";
    EXPECT_EQ(rate, 0.0);
    // Close to the time-optimal profile: within a few steps of discretisation.
    if (from_rest && distance > 0.01) {
      EXPECT_GE(steps * dt, optimal_move_time(distance, v_max, a_max) - 1e-9);
      EXPECT_NEAR(steps * dt, optimal_move_time(distance, v_max, a_max), 0.01)
          << "distance " << distance;
    }
  }
}

TEST(NozzleActuator, ReachesTheCommandAtTheServoRate) {
  NozzleActuatorParameters p;
  const double dt = 0.001;
  NozzleActuator nozzle(p, {0.0, 0.0}, dt);
  const NozzleOrientation target{-kPi / 2, deg_to_rad(50)};
  nozzle.command(target);
  double peak = 0.0, t = 0.0;
  while (
      (nozzle.actual().pan_rad != target.pan_rad || nozzle.actual().tilt_rad != target.tilt_rad) &&
      t < 5.0) {
    nozzle.step();
    t += dt;
    peak = std::max({peak, std::abs(nozzle.pan_rate_radps()), std::abs(nozzle.tilt_rate_radps())});
  }
  EXPECT_EQ(nozzle.actual().pan_rad, target.pan_rad);
  EXPECT_EQ(nozzle.actual().tilt_rad, target.tilt_rad);
  EXPECT_LE(peak, p.max_speed_radps);
  EXPECT_GT(peak, 0.9 * p.max_speed_radps);  // a 90 deg pan reaches full speed
  // 90 deg of pan: pi/2 / 7 + 7 / 30 = 0.458 s.
  const double optimal = optimal_move_time(kPi / 2, p.max_speed_radps, p.max_acceleration_radps2);
  EXPECT_GE(t, optimal - 1e-9);
  EXPECT_NEAR(t, optimal, 0.01);
}

TEST(NozzleActuator, FieldFollowsTheActualOrientationAfterTheDelay) {
  NozzleActuatorParameters p;
  p.field_delay_s = 0.2;
  const double dt = 0.002;
  NozzleActuator nozzle(p, {0.0, 0.1}, dt);
  nozzle.command({1.0, 0.5});
  std::vector<NozzleOrientation> actual;
  for (int k = 0; k < 600; ++k) {
    nozzle.step();
    actual.push_back(nozzle.actual());
    const int delayed = k - 100;  // 0.2 s / 2 ms
    const NozzleOrientation expected = delayed >= 0 ? actual[delayed] : NozzleOrientation{0.0, 0.1};
    ASSERT_EQ(nozzle.effective().pan_rad, expected.pan_rad) << "step " << k;
    ASSERT_EQ(nozzle.effective().tilt_rad, expected.tilt_rad) << "step " << k;
  }
  EXPECT_EQ(nozzle.effective().pan_rad, 1.0);
}

TEST(NozzleActuator, JetRampFollowsItsDefinition) {
  NozzleActuatorParameters p;
  const double dt = 0.001;
  NozzleActuator nozzle(p, {0.0, 0.0}, dt);
  EXPECT_EQ(nozzle.jet_level(), 0.0);
  nozzle.set_jet(true);
  // On: 1 - exp(-t / tau_on); the paper's steady state after ~8 s (Appendix B).
  for (int k = 1; k <= 8000; ++k) {
    nozzle.step();
    const double t = k * dt;
    ASSERT_NEAR(nozzle.jet_level(), 1.0 - std::exp(-t / p.jet_rise_time_constant_s), 1e-9);
  }
  EXPECT_NEAR(nozzle.jet_level(), 0.99, 1e-6);
  // Off: decays from where it was with tau_off.
  const double start = nozzle.jet_level();
  nozzle.set_jet(false);
  for (int k = 1; k <= 1000; ++k) {
    nozzle.step();
    ASSERT_NEAR(nozzle.jet_level(), start * std::exp(-k * dt / p.jet_fall_time_constant_s), 1e-9);
  }
  nozzle.set_jet(true);
  nozzle.settle_jet();
  EXPECT_EQ(nozzle.jet_level(), 1.0);
}

TEST(NozzleActuator, CalibrationOffsetBiasesTheServosNotTheCommand) {
  NozzleActuatorParameters p;
  p.pan_offset_rad = 0.05;
  p.tilt_offset_rad = -0.03;
  NozzleActuator nozzle(p, {0.2, 0.5}, 0.001);
  // Servos start on command + offset; the command is what was asked for.
  EXPECT_EQ(nozzle.commanded().pan_rad, 0.2);
  EXPECT_DOUBLE_EQ(nozzle.actual().pan_rad, 0.25);
  EXPECT_DOUBLE_EQ(nozzle.effective().tilt_rad, 0.47);
  // A command at the tilt floor: the biased target is clamped to the servo range.
  nozzle.command({-1.0, 0.0});
  for (int k = 0; k < 2000; ++k) nozzle.step();
  EXPECT_EQ(nozzle.commanded().tilt_rad, 0.0);
  EXPECT_DOUBLE_EQ(nozzle.actual().pan_rad, -0.95);
  EXPECT_EQ(nozzle.actual().tilt_rad, 0.0);
  NozzleActuatorParameters bad;
  bad.tilt_offset_rad = std::nan("");
  EXPECT_THROW(NozzleActuator(bad, {0.0, 0.1}, 0.001), InputError);
}

TEST(NozzleActuator, RejectsCommandsOutsideTheRanges) {
  NozzleActuator nozzle(NozzleActuatorParameters{}, {0.0, 0.0}, 0.001);
  EXPECT_THROW(nozzle.command({0.0, deg_to_rad(61)}), InputError);
  EXPECT_THROW(nozzle.command({0.0, -0.01}), InputError);
  EXPECT_THROW(nozzle.command({4.0, 0.1}), InputError);
  EXPECT_THROW(nozzle.command({std::nan(""), 0.1}), InputError);
  EXPECT_NO_THROW(nozzle.command({-kPi, deg_to_rad(60)}));
  NozzleActuatorParameters bad;
  bad.max_speed_radps = 0.0;
  EXPECT_THROW(NozzleActuator(bad, {0.0, 0.0}, 0.001), InputError);
}

}  // namespace
}  // namespace airtwin
