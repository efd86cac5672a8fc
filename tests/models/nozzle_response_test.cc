#include "models/nozzle_response.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/errors.h"

namespace airtwin {
namespace {

// Time for a trapezoidal move of d rad from rest to rest (speed v, acceleration a): the
// closed form, an independent truth for the stepped servo.
double trapezoid_time(double d, double v, double a) {
  if (d >= v * v / a) return d / v + v / a;  // reaches full speed
  return 2.0 * std::sqrt(d / a);             // triangular profile
}

// When the timeline first reaches `target` on the pan axis.
double arrival(const NozzleTimeline& tl, double target, double t_end) {
  for (double t = 0.0; t <= t_end; t += 1e-4) {
    if (std::abs(tl.actual(t).pan_rad - target) < 1e-9) return t;
  }
  return INFINITY;
}

TEST(NozzleResponse, ServoMovesLikeTheTrapezoidalProfile) {
  const NozzleResponseParameters p;  // 7 rad/s, 30 rad/s^2
  for (double d : {0.2, 1.0, 3.0}) {
    SCOPED_TRACE(d);
    const NozzleTimeline tl(p, {{0.0, {0.0, 0.3}}, {0.1, {d, 0.3}}}, 3.0, 1e-4);
    const double expected = 0.1 + trapezoid_time(d, p.max_speed_radps, p.max_acceleration_radps2);
    // One step of the discrete profile per phase change: well below a camera frame (25 ms).
    EXPECT_NEAR(arrival(tl, d, 3.0), expected, 0.01);
    EXPECT_DOUBLE_EQ(tl.actual(0.05).pan_rad, 0.0);  // before the command: at rest
    EXPECT_DOUBLE_EQ(tl.actual(0.3).tilt_rad, 0.3);  // the other axis does not move
    // Speed never exceeds the limit.
    for (double t = 0.0; t < 3.0; t += 0.01) {
      EXPECT_LE(std::abs(tl.actual(t + 0.01).pan_rad - tl.actual(t).pan_rad),
                p.max_speed_radps * 0.01 + 1e-9);
    }
  }
}

TEST(NozzleResponse, ServoMoveIsTheSteppedServoInTheLimit) {
  // The closed form against servo_axis_step at a 10 us step, its h -> 0 limit: short moves
  // (triangular), long ones (cruising), both directions, and no move at all.
  const NozzleResponseParameters p;
  for (double d : {0.0, 0.05, 1.0, -1.5, 4.1}) {
    SCOPED_TRACE(d);
    const double from = 0.3, to = from + d;
    const ServoMove move(from, to, p.max_speed_radps, p.max_acceleration_radps2);
    EXPECT_NEAR(move.duration_s(),
                trapezoid_time(std::abs(d), p.max_speed_radps, p.max_acceleration_radps2), 1e-12);
    double angle = from, rate = 0.0, worst = 0.0;
    const double h = 1e-5;
    for (int k = 1; k * h <= move.duration_s() + 0.05; ++k) {
      servo_axis_step(to, p.max_speed_radps, p.max_acceleration_radps2, h, &angle, &rate);
      worst = std::max(worst, std::abs(move.angle(k * h) - angle));
    }
    // The stepped servo lags by about a step's travel at full speed: 7e-5 rad.
    EXPECT_LT(worst, 2e-4);
    EXPECT_EQ(move.angle(-1.0), from);
    EXPECT_EQ(move.angle(move.duration_s()), to);
  }
}

TEST(NozzleResponse, FieldFollowsAfterTheTransitAndExtraDelay) {
  const NozzleResponseParameters p;
  const NozzleTimeline tl(p, {{0.0, {0.0, 0.0}}, {0.5, {1.0, 0.2}}}, 3.0);
  for (double t : {0.4, 0.7, 1.0, 2.0}) {
    EXPECT_DOUBLE_EQ(tl.effective(t).pan_rad, tl.actual(t - 0.2).pan_rad);
    EXPECT_DOUBLE_EQ(tl.effective(t, 0.3).tilt_rad, tl.actual(t - 0.5).tilt_rad);
  }
  EXPECT_TRUE(tl.at_rest_between(0.0, 0.5));
  EXPECT_FALSE(tl.at_rest_between(0.0, 0.6));
  EXPECT_TRUE(tl.at_rest_between(2.0, 3.0));
}

TEST(NozzleResponse, SettlesWhenTheLastMoveEnds) {
  // The pan's 1 rad move is the longer (the tilt's 0.2 rad ends first): settled when the pan
  // arrives (found by a scan, to a 1 ms step), about the trapezoid's time after the command (the
  // stepped profile's tolerance above).
  const NozzleResponseParameters p;
  const NozzleTimeline tl(p, {{0.0, {0.0, 0.0}}, {0.5, {1.0, 0.2}}}, 3.0);
  const double t = tl.settled_from_s();
  EXPECT_NEAR(t, arrival(tl, 1.0, 3.0), 1e-3);
  EXPECT_NEAR(t, 0.5 + trapezoid_time(1.0, p.max_speed_radps, p.max_acceleration_radps2), 0.02);
  EXPECT_TRUE(tl.at_rest_between(t, 3.0));
  EXPECT_FALSE(tl.at_rest_between(t - 2e-3, 3.0));
  // A nozzle that never moves is settled from the start.
  EXPECT_EQ(NozzleTimeline(p, {{0.25, {0.3, 0.1}}}, 2.0).settled_from_s(), 0.25);
}

TEST(NozzleResponse, RejectsBadInput) {
  NozzleResponseParameters p;
  p.max_speed_radps = 0.0;
  EXPECT_THROW(NozzleTimeline(p, {{0.0, {0.0, 0.0}}}, 1.0), InputError);
  const NozzleResponseParameters ok;
  EXPECT_THROW(NozzleTimeline(ok, {}, 1.0), InputError);
  EXPECT_THROW(NozzleTimeline(ok, {{0.0, {0.0, 0.0}}, {0.0, {1.0, 0.0}}}, 1.0), InputError);
  EXPECT_THROW(NozzleTimeline(ok, {{0.0, {NAN, 0.0}}}, 1.0), InputError);
}

}  // namespace
}  // namespace airtwin
