#include "models/extended_predictor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/cvode_predictor.h"

namespace airtwin {
namespace {

const AirFieldModel& field() {
  static const AirFieldModel m = AirFieldModel::with_constructed_table();
  return m;
}

// A timeline settled at `o` from long before t = 0 (no servo motion in the window).
NozzleTimeline settled(const NozzleOrientation& o) {
  return NozzleTimeline(NozzleResponseParameters{}, {{-10.0, o}}, 5.0);
}

std::vector<double> frames(double t_end) {
  std::vector<double> t;
  for (int k = 1; k <= static_cast<int>(std::round(t_end * 40)); ++k) t.push_back(k / 40.0);
  return t;
}

std::vector<Eigen::Vector2d> predict(const ObjectDynamics& xi, const ModelExtensions& ext,
                                     const NozzleTimeline& tl, const Eigen::Vector2d& p0,
                                     const Eigen::Vector2d& v0, const std::vector<double>& t) {
  const ExtendedPredictor pred(field(), 1e-3);
  std::vector<Eigen::Vector2d> out;
  WindowStart start;
  start.p_W = p0;
  start.v_W = v0;
  pred.predict(xi, ext, tl, start, t, &out);
  return out;
}

// Eigen's default constructor leaves a vector uninitialised: the start velocity is spelt out.
const Eigen::Vector2d kAtRest = Eigen::Vector2d::Zero();
const NozzleOrientation kO{deg_to_rad(30.0), deg_to_rad(22.5)};

// With every extension off and the nozzle settled, the vector form is eqs. (8)-(9): compare with
// the CVODE reference at every frame.
TEST(ExtendedPredictor, NominalIsEquations8And9) {
  const CvodePredictor reference;
  const OrientedField f = field().at(kO);
  const std::vector<double> t = frames(2.0);
  for (double r : {0.2, 0.35, 0.5}) {
    for (double a : {0.0, 1.5, 3.0}) {
      const Eigen::Vector2d p0 =
          f.stagnation_point() + r * Eigen::Vector2d(std::cos(a), std::sin(a));
      const std::vector<Eigen::Vector2d> ours =
          predict(kTracerDynamics, {}, settled(kO), p0, Eigen::Vector2d::Zero(), t);
      ObjectState s0;
      s0.p_W = p0;
      PredictionOptions po;
      po.horizon_s = 2.0;
      po.sample_rate_hz = 40.0;
      const Prediction ref =
          reference.predict(f, std::span(&kTracerDynamics, 1), std::span(&s0, 1), po);
      for (size_t k = 0; k < t.size(); ++k) {
        // 1 ms semi-implicit Euler against an adaptive solver: a few mm over 2 s.
        EXPECT_LT((ours[k] - ref.sample(k + 1, 0).p_W).norm(), 4e-3) << "r " << r << " k " << k;
      }
    }
  }
}

// Extra terms along the ray, checked against a 1-D RK4 integration of
//   dv/dt = D(f u(r), v) + xi3' max(0, 1 - k (f u - v)^2) + C (f u - v)|f u - v|
//           + f^2 A sqrt(2e) (r/l) exp(-(r/l)^2)
// from r0 at v0 >= 0, where D = xi1 v + xi2 u and xi3' = xi3 (eq. (8)) or, with the share s of the
// friction that is a linearised drag's intercept, D = (c |w| - s |xi3|) sign(w) for |w| >= w0 and
// (c / 2 w0) |w| w below, w = (xi2 / c) u - v, c = -xi1, w0 = 2 s |xi3| / c, and xi3' = (1 - s)
// xi3.
double ray_reference(const ObjectDynamics& xi, double f, double c, double A, double l, double r0,
                     const Eigen::Vector2d& s, const Eigen::Vector2d& e, const OrientedField& of,
                     double t_end, double k = 0.0, double share = 0.0, double v0 = 0.0) {
  const double c_lin = -xi.xi1, intercept = share * -xi.xi3, w0 = 2.0 * intercept / c_lin;
  auto drag = [&](double u, double v) {
    if (w0 == 0.0) return xi.xi1 * v + xi.xi2 * u;
    const double w = xi.xi2 / c_lin * u - v;
    const double n = std::abs(w);
    return n >= w0 ? std::copysign(c_lin * n - intercept, w) : 0.5 * c_lin / w0 * n * w;
  };
  auto acc = [&](double r, double v) {
    const double u = f * of.speed(s + r * e);
    const double x = r / l;
    const double friction = (xi.xi3 + intercept) * std::max(0.0, 1.0 - k * (u - v) * (u - v));
    double a = drag(u, v) + friction + c * (u - v) * std::abs(u - v);
    a += f * f * A * std::sqrt(2.0 * std::exp(1.0)) * x * std::exp(-x * x);
    return a;
  };
  double r = r0, v = v0;
  const double h = 1e-5;
  for (double t = 0.0; t < t_end - 1e-12; t += h) {
    const double k1r = v, k1v = acc(r, v);
    const double k2r = v + 0.5 * h * k1v, k2v = acc(r + 0.5 * h * k1r, v + 0.5 * h * k1v);
    const double k3r = v + 0.5 * h * k2v, k3v = acc(r + 0.5 * h * k2r, v + 0.5 * h * k2v);
    const double k4r = v + h * k3v, k4v = acc(r + h * k3r, v + h * k3v);
    r += h / 6 * (k1r + 2 * k2r + 2 * k3r + k4r);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (v <= 0.0) break;  // stopped (the drive is negative there: it stays)
  }
  return r;
}

TEST(ExtendedPredictor, QuadraticDragPushAndScaleAlongARay) {
  const OrientedField of = field().at(kO);
  const Eigen::Vector2d s = of.stagnation_point(), e(0.6, 0.8);
  const double t_end = 0.6;  // still moving: compares the motion, not only where it stops
  for (const auto& [f, c, A, l] :
       std::vector<std::tuple<double, double, double, double>>{{1.2, 0.0, 0.0, 0.15},
                                                               {1.0, 1.0, 0.0, 0.15},
                                                               {1.0, 0.0, 12.0, 0.2},
                                                               {0.9, 0.5, 6.0, 0.1}}) {
    ModelExtensions ext;
    ext.field_scale = f;
    ext.object.quadratic_drag_per_m = c;
    ext.push_strength_mps2 = A;
    ext.push_length_m = l;
    const double r0 = 0.25;
    const std::vector<Eigen::Vector2d> ours =
        predict(kTracerDynamics, ext, settled(kO), s + r0 * e, Eigen::Vector2d::Zero(), {t_end});
    const double r_ref = ray_reference(kTracerDynamics, f, c, A, l, r0, s, e, of, t_end);
    EXPECT_NEAR((ours[0] - s).norm(), r_ref, 4e-3) << f << " " << c << " " << A;
    EXPECT_LT(std::abs((ours[0] - s).normalized().dot(Eigen::Vector2d(-e.y(), e.x()))), 1e-6);
  }
}

// The air's lift: friction times max(0, 1 - k |u - v|^2) along the ray, alone and beside the
// quadratic drag; and an object the full friction holds starts once the lift unloads it.
TEST(ExtendedPredictor, AirLiftUnloadsTheFrictionAlongARay) {
  const OrientedField of = field().at(kO);
  const Eigen::Vector2d s = of.stagnation_point(), e(0.6, 0.8);
  const double t_end = 0.6;
  const double r0 = 0.25;
  const Eigen::Vector2d p0 = s + r0 * e;
  const double plain =
      (predict(kTracerDynamics, {}, settled(kO), p0, kAtRest, {t_end})[0] - s).norm();
  for (const auto& [k, c] : std::vector<std::pair<double, double>>{{0.05, 0.0}, {0.1, 0.5}}) {
    ModelExtensions ext;
    ext.object.lift_s2_per_m2 = k;
    ext.object.quadratic_drag_per_m = c;
    const std::vector<Eigen::Vector2d> ours =
        predict(kTracerDynamics, ext, settled(kO), p0, kAtRest, {t_end});
    const double r_ref = ray_reference(kTracerDynamics, 1.0, c, 0.0, 0.15, r0, s, e, of, t_end, k);
    EXPECT_NEAR((ours[0] - s).norm(), r_ref, 4e-3) << "k " << k << " C " << c;
    // Less friction, a longer slide: more than the step's error apart.
    EXPECT_GT((ours[0] - s).norm(), plain + 0.02) << "k " << k;
  }

  // Where the drive is between 0.8 and 0.9 times the friction, held at k = 0; with the lift the
  // friction left is 1 - k u^2 of it, below the drive once k u^2 > 0.2.
  const ObjectDynamics& xi = kTracerDynamics;
  double r = 0.2;
  while (xi.xi2 * of.speed(s + r * e) > 0.9 * -xi.xi3 && r < 2.0) r += 0.005;
  const double u = of.speed(s + r * e);
  ASSERT_GT(xi.xi2 * u, 0.8 * -xi.xi3);
  const Eigen::Vector2d held = s + r * e;
  EXPECT_EQ(predict(xi, {}, settled(kO), held, kAtRest, {1.0})[0], held);
  ModelExtensions weak, strong;
  weak.object.lift_s2_per_m2 = 0.05 / (u * u);    // leaves 95 % of the friction: still held
  strong.object.lift_s2_per_m2 = 0.25 / (u * u);  // leaves 75 %: starts
  EXPECT_EQ(predict(xi, weak, settled(kO), held, kAtRest, {1.0})[0], held);
  EXPECT_GT((predict(xi, strong, settled(kO), held, kAtRest, {1.0})[0] - held).norm(), 0.005);
}

// The drag read as the tangent of a quadratic at w0: along the ray from rest, alone and beside
// the lift; and an object launched at 1 m/s where the air is weak.
TEST(ExtendedPredictor, LinearisedDragBendsTheDragAndLightensTheFrictionAlongARay) {
  const OrientedField of = field().at(kO);
  const Eigen::Vector2d s = of.stagnation_point(), e(0.6, 0.8);
  const double t_end = 1.2;  // past where the object's relative air falls below w0
  const double r0 = 0.25;
  const Eigen::Vector2d p0 = s + r0 * e;
  const double plain =
      (predict(kTracerDynamics, {}, settled(kO), p0, kAtRest, {t_end})[0] - s).norm();
  // Moving with the air, the relative speed stays near |xi3| / c = 3.2 m/s (where the drag
  // balances the friction): only a tangent beyond it, a share above 1/2, bends the slide.
  for (const auto& [share, k] : std::vector<std::pair<double, double>>{{0.55, 0.0}, {0.62, 0.03}}) {
    ModelExtensions ext;
    ext.object.drag_intercept_share = share;
    ext.object.lift_s2_per_m2 = k;
    const double ours =
        (predict(kTracerDynamics, ext, settled(kO), p0, kAtRest, {t_end})[0] - s).norm();
    const double r_ref =
        ray_reference(kTracerDynamics, 1.0, 0.0, 0.0, 0.15, r0, s, e, of, t_end, k, share);
    EXPECT_NEAR(ours, r_ref, 4e-3) << "share " << share << " k " << k;
    EXPECT_GT(ours, plain + 0.02) << "share " << share;
  }

  // The coast: 2.5 m out the drive is about a third of the friction. Launched outward at 1 m/s
  // there, the object is braked at |xi3| + c v - drive by eq. (8) and, with |w| < w0, at
  // (1 - s) |xi3| + (c / 2 w0) |w| w - drive: it slides farther.
  const double r_far = 2.5;
  ASSERT_LT(kTracerDynamics.xi2 * of.speed(s + r_far * e), 0.4 * -kTracerDynamics.xi3);
  const Eigen::Vector2d launched = s + r_far * e;
  double coast[2];
  for (int bent = 0; bent < 2; ++bent) {
    ModelExtensions ext;
    ext.object.drag_intercept_share = bent ? 0.5 : 0.0;
    coast[bent] =
        (predict(kTracerDynamics, ext, settled(kO), launched, 1.0 * e, {1.0})[0] - s).norm() -
        r_far;
    const double r_ref = ray_reference(kTracerDynamics, 1.0, 0.0, 0.0, 0.15, r_far, s, e, of, 1.0,
                                       0.0, ext.object.drag_intercept_share, 1.0);
    EXPECT_NEAR(coast[bent], r_ref - r_far, 2e-3) << "share " << ext.object.drag_intercept_share;
  }
  std::printf("coast from 1 m/s at 2.5 m: eq. (8) %.1f cm, bent at share 0.5 %.1f cm\n",
              coast[0] * 100, coast[1] * 100);
  EXPECT_GT(coast[1], coast[0] + 0.02);
}

TEST(ExtendedPredictor, OffsetAndDelayAreShiftsOfTheCommands) {
  const std::vector<double> t = frames(2.5);
  const Eigen::Vector2d p0(0.9, 0.4);
  const NozzleOrientation a{0.0, 0.0}, b{deg_to_rad(20.0), deg_to_rad(22.5)};
  ModelExtensions offset;
  offset.pan_offset_rad = deg_to_rad(5.0);
  offset.tilt_offset_rad = deg_to_rad(3.0);
  const NozzleOrientation b_off{b.pan_rad + offset.pan_offset_rad,
                                b.tilt_rad + offset.tilt_offset_rad};
  const auto x = predict(kTracerDynamics, offset, settled(b), p0, kAtRest, t);
  const auto y = predict(kTracerDynamics, {}, settled(b_off), p0, kAtRest, t);
  for (size_t k = 0; k < t.size(); ++k) EXPECT_LT((x[k] - y[k]).norm(), 1e-9);

  const NozzleResponseParameters p;
  ModelExtensions delay;
  delay.extra_delay_s = 0.3;
  const auto d = predict(kTracerDynamics, delay, NozzleTimeline(p, {{-5.0, a}, {0.2, b}}, 5.0), p0,
                         kAtRest, t);
  const auto s =
      predict(kTracerDynamics, {}, NozzleTimeline(p, {{-5.0, a}, {0.5, b}}, 5.0), p0, kAtRest, t);
  for (size_t k = 0; k < t.size(); ++k) EXPECT_LT((d[k] - s[k]).norm(), 2e-3) << k;
  // And the delay matters: the object leaves later.
  const auto n =
      predict(kTracerDynamics, {}, NozzleTimeline(p, {{-5.0, a}, {0.2, b}}, 5.0), p0, kAtRest, t);
  double most = 0.0;
  for (size_t k = 0; k < t.size(); ++k) most = std::max(most, (n[k] - d[k]).norm());
  EXPECT_GT(most, 0.05);
}

// A point r from the new s feels a re-aim pace r after it reaches s: for an object held at rest
// until then, the transport lag is a response delay of pace r (the defining equation), whatever
// the re-aim. Servos that turn in a step keep intermediate orientations out of the comparison.
TEST(ExtendedPredictor, TransportLagDelaysTheNewAirByPaceTimesTheDistanceFromItsS) {
  const std::vector<double> t = frames(2.5);
  NozzleResponseParameters fast;
  fast.max_speed_radps = 1e4;
  fast.max_acceleration_radps2 = 1e9;
  // From far away (s 1.3 m out on -x: too weak to start a tracer) to straight down (s at 0).
  const NozzleOrientation far{kPi, deg_to_rad(40.0)}, down{0.0, 0.0};
  const NozzleTimeline reaim(fast, {{-5.0, far}, {0.2, down}}, 5.0);
  ModelExtensions lag;
  lag.transport_pace_s_per_m = 0.8;
  for (const Eigen::Vector2d& p0 : {Eigen::Vector2d(0.3, 0.0), Eigen::Vector2d(0.0, -0.45)}) {
    const double r = p0.norm();  // from the new s, the origin
    ModelExtensions delay;
    delay.extra_delay_s = lag.transport_pace_s_per_m * r;
    const auto x = predict(kTracerDynamics, lag, reaim, p0, kAtRest, t);
    const auto d = predict(kTracerDynamics, delay, reaim, p0, kAtRest, t);
    const auto n = predict(kTracerDynamics, {}, reaim, p0, kAtRest, t);
    double most = 0.0;
    for (size_t k = 0; k < t.size(); ++k) {
      // One step (1 ms) of a moving tracer apart at most.
      EXPECT_LT((x[k] - d[k]).norm(), 2e-3) << "r " << r << " m, frame " << k;
      most = std::max(most, (x[k] - n[k]).norm());
    }
    EXPECT_GT((x.back() - p0).norm(), 0.1);  // it moved
    EXPECT_GT(most, 0.05);                   // and the lag mattered
  }
  // Before any re-aim nothing lags: a settled nozzle gives the nominal model exactly.
  const auto settled_lag = predict(kTracerDynamics, lag, settled(kO), {0.6, 0.3}, kAtRest, t);
  const auto settled_nominal = predict(kTracerDynamics, {}, settled(kO), {0.6, 0.3}, kAtRest, t);
  for (size_t k = 0; k < t.size(); ++k) EXPECT_EQ(settled_lag[k], settled_nominal[k]) << k;
}

TEST(ExtendedPredictor, DeflectionTurnsTheStartAndStictionHolds) {
  const OrientedField of = field().at(kO);
  const Eigen::Vector2d s = of.stagnation_point(), e(1.0, 0.0);
  ModelExtensions turn;
  turn.deflection_rad = deg_to_rad(15.0);
  const auto p = predict(kTracerDynamics, turn, settled(kO), s + 0.25 * e, kAtRest, {0.05});
  const Eigen::Vector2d d = p[0] - (s + 0.25 * e);
  EXPECT_NEAR(rad_to_deg(std::atan2(d.y(), d.x())), 15.0, 1.0);

  // Where the drive is between kinetic friction and 1.5 times it: moves at ratio 1, not at 1.6.
  double r = 0.2;
  const ObjectDynamics& xi = kTracerDynamics;
  while (xi.xi2 * of.speed(s + r * e) > 1.3 * -xi.xi3 && r < 1.5) r += 0.005;
  ASSERT_GT(xi.xi2 * of.speed(s + r * e), -xi.xi3);
  ModelExtensions sticky;
  sticky.static_friction_ratio = 1.6;
  const Eigen::Vector2d p0 = s + r * e;
  EXPECT_GT((predict(xi, {}, settled(kO), p0, kAtRest, {1.0})[0] - p0).norm(), 0.01);
  EXPECT_EQ(predict(xi, sticky, settled(kO), p0, kAtRest, {1.0})[0], p0);
}

TEST(ExtendedPredictor, SlopePullsAMovingObjectDownhill) {
  // A launched object on a tilted floor against a fine-step RK4 of the vector equation,
  //   dv/dt = xi1 v + xi2 u(p) + xi3 v / |v| + g sin(angle) d,
  // while it moves (an independent integration of the definition).
  const OrientedField of = field().at(kO);
  const Eigen::Vector2d p0 = of.stagnation_point() + Eigen::Vector2d(0.0, 0.6);
  ModelExtensions slope;
  slope.slope_rad = deg_to_rad(4.0);
  slope.slope_direction_rad = deg_to_rad(-120.0);
  const Eigen::Vector2d v0(1.5, 0.0),
      d(std::cos(slope.slope_direction_rad), std::sin(slope.slope_direction_rad));
  const double t_end = 0.15;
  const ObjectDynamics& xi = kTracerDynamics;
  auto reference = [&](double tilt_rad) {
    const Eigen::Vector2d a_slope = 9.81 * std::sin(tilt_rad) * d;
    auto acc = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& v) -> Eigen::Vector2d {
      return xi.xi1 * v + xi.xi2 * of.velocity(p) + xi.xi3 * v.normalized() + a_slope;
    };
    Eigen::Vector2d p = p0, v = v0;
    const double h = 1e-5;
    for (double t = 0.0; t < t_end - 1e-12; t += h) {
      const Eigen::Vector2d k1p = v, k1v = acc(p, v);
      const Eigen::Vector2d k2p = v + 0.5 * h * k1v,
                            k2v = acc(p + 0.5 * h * k1p, v + 0.5 * h * k1v);
      const Eigen::Vector2d k3p = v + 0.5 * h * k2v,
                            k3v = acc(p + 0.5 * h * k2p, v + 0.5 * h * k2v);
      const Eigen::Vector2d k4p = v + h * k3v, k4v = acc(p + h * k3p, v + h * k3v);
      p += h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p);
      v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
    EXPECT_GT(v.norm(), 0.1);  // still moving: the comparison is of the motion
    return p;
  };
  const auto ours = predict(xi, slope, settled(kO), p0, v0, {t_end});
  const auto level = predict(xi, {}, settled(kO), p0, v0, {t_end});
  EXPECT_LT((ours[0] - reference(slope.slope_rad)).norm(), 2e-3);  // 1 ms Euler steps
  // The slope's own displacement (the steps' error cancels in the difference) within 10 %.
  const Eigen::Vector2d shift_ref = reference(slope.slope_rad) - reference(0.0);
  ASSERT_GT(shift_ref.norm(), 2e-3);
  EXPECT_LT(((ours[0] - level[0]) - shift_ref).norm(), 0.1 * shift_ref.norm());
}

// predict_ends (all objects in lockstep, what the controller plans with) against predict (one
// object at a time): the same numbers, under every extension at once, each type with its own
// object effects, and a moving nozzle.
TEST(ExtendedPredictor, EndsOfManyAreEndsOfEach) {
  ModelExtensions ext;
  ext.push_strength_mps2 = 8.0;
  ext.push_length_m = 0.2;
  ext.extra_delay_s = 0.1;
  ext.deflection_rad = deg_to_rad(8.0);
  ext.object.quadratic_drag_per_m = 0.5;
  ext.slope_rad = deg_to_rad(2.0);
  ext.slope_direction_rad = deg_to_rad(60.0);
  ext.static_friction_ratio = 1.4;
  ext.pan_offset_rad = deg_to_rad(3.0);
  ext.tilt_offset_rad = deg_to_rad(2.0);
  ext.field_scale = 1.1;
  ext.object_by_type["tracer"].drag_intercept_share = 0.4;
  ext.object_by_type["cotton"].lift_s2_per_m2 = 0.03;
  const NozzleTimeline timeline(NozzleResponseParameters{},
                                {{-1.0, {0.3, deg_to_rad(10.0)}}, {0.0, {-0.8, deg_to_rad(25.0)}}},
                                3.0);
  const std::vector<ObjectDynamics> xi = {kTracerDynamics, kCottonDynamics, kTracerDynamics,
                                          kCottonDynamics};
  const std::vector<std::string> types = {"tracer", "cotton", "tracer", "cotton"};
  std::vector<ObjectExtensions> own;
  for (const std::string& t : types) own.push_back(ext.object_for(t));
  const std::vector<WindowStart> starts = {{0.0, {0.5, 0.2}, {0.0, 0.0}},
                                           {0.0, {-0.3, -0.6}, {0.1, -0.2}},
                                           {0.0, {0.05, 0.7}, {0.0, 0.0}},
                                           {0.0, {-0.9, 0.1}, {-0.3, 0.0}}};
  const ExtendedPredictor predictor(field(), 2e-3);
  // Without and with the transport lag (each object then feels its own orientation).
  for (double pace : {0.0, 0.7}) {
    ext.transport_pace_s_per_m = pace;
    for (double t_end : {0.0, 0.0013, 0.7, 1.7}) {
      std::vector<Eigen::Vector2d> ends(starts.size());
      predictor.predict_ends(xi, ext, own, timeline, starts, t_end, ends);
      for (size_t j = 0; j < starts.size(); ++j) {
        std::vector<Eigen::Vector2d> one;
        const double times[] = {t_end};
        predictor.predict(xi[j], ext.for_type(types[j]), timeline, starts[j], times, &one);
        EXPECT_EQ(ends[j], one[0]) << "object " << j << " at " << t_end << " s, pace " << pace;
      }
      if (t_end > 1.0) {
        EXPECT_GT((ends[0] - starts[0].p_W).norm(), 0.05);  // something moved
      }
    }
  }
  std::vector<Eigen::Vector2d> two(2);
  const std::vector<WindowStart> apart = {{0.0, {0.5, 0.2}, {0.0, 0.0}},
                                          {0.1, {0.5, 0.2}, {0.0, 0.0}}};
  EXPECT_THROW(
      predictor.predict_ends({xi.data(), 2}, ext, {own.data(), 2}, timeline, apart, 1.0, two),
      InputError);
  EXPECT_THROW(predictor.predict_ends(xi, ext, own, timeline, starts, 1.0, two), InputError);
  // A type's own effects are never dropped: the predictor refuses them unresolved.
  std::vector<Eigen::Vector2d> four(starts.size());
  EXPECT_THROW(predictor.predict_ends(xi, ext, {}, timeline, starts, 1.0, four), InputError);
  std::vector<Eigen::Vector2d> one;
  const double times[] = {1.0};
  EXPECT_THROW(predictor.predict(xi[0], ext, timeline, starts[0], times, &one), InputError);
}

// A track holds the orientations predict() works out: with it the positions are the same bits;
// a track of another response delay, nozzle offset, start or step is not read.
TEST(ExtendedPredictor, ATrackGivesTheSamePositionsAndOnlyWhereItServes) {
  ModelExtensions ext;
  ext.push_strength_mps2 = 8.0;
  ext.push_length_m = 0.2;
  ext.extra_delay_s = 0.1;
  ext.pan_offset_rad = deg_to_rad(3.0);
  ext.tilt_offset_rad = deg_to_rad(2.0);
  ext.object.drag_intercept_share = 0.4;
  // A re-aim at t = 0: the servos turn for a few tenths of a second inside the window.
  const NozzleTimeline timeline(NozzleResponseParameters{},
                                {{-1.0, {0.3, deg_to_rad(10.0)}}, {0.0, {-0.8, deg_to_rad(25.0)}}},
                                3.0);
  const ExtendedPredictor predictor(field(), 1e-3);
  std::vector<double> times;
  for (int k = -8; k <= 80; ++k) times.push_back(k / 40.0);
  // 25 cm downstream of the s the re-aim ends at.
  const Eigen::Vector2d s_end =
      field()
          .at({-0.8 + ext.pan_offset_rad, deg_to_rad(25.0) + ext.tilt_offset_rad})
          .stagnation_point();
  const WindowStart start{-0.2, s_end + 0.25 * s_end.normalized(), {0.0, 0.0}};
  std::vector<Eigen::Vector2d> plain, tracked;
  predictor.predict(kTracerDynamics, ext, timeline, start, times, &plain);
  const OrientationTrack track = predictor.track(ext, timeline, start.t_s, times.back());
  ASSERT_TRUE(track.serves(ext, timeline, start.t_s, 1e-3));
  predictor.predict(kTracerDynamics, ext, timeline, start, times, &tracked, &track);
  ASSERT_EQ(tracked.size(), plain.size());
  for (size_t k = 0; k < plain.size(); ++k) EXPECT_EQ(tracked[k], plain[k]) << "sample " << k;
  EXPECT_GT((plain.back() - start.p_W).norm(), 0.05);  // it moved
  // Other extensions than the delay and the offset leave the track serving.
  ModelExtensions pushed = ext;
  pushed.push_strength_mps2 = 3.0;
  pushed.field_scale = 1.2;
  EXPECT_TRUE(track.serves(pushed, timeline, start.t_s, 1e-3));
  predictor.predict(kTracerDynamics, pushed, timeline, start, times, &plain);
  predictor.predict(kTracerDynamics, pushed, timeline, start, times, &tracked, &track);
  for (size_t k = 0; k < plain.size(); ++k) EXPECT_EQ(tracked[k], plain[k]) << "sample " << k;
  // Another offset, delay, start or step: not served, and not read (the positions are those of
  // the predictor's own orientations, which differ from the track's).
  ModelExtensions offset = ext;
  offset.pan_offset_rad = deg_to_rad(8.0);
  ModelExtensions delayed = ext;
  delayed.extra_delay_s = 0.3;
  ModelExtensions lagged = ext;
  lagged.transport_pace_s_per_m = 0.7;
  for (const ModelExtensions& other : {offset, delayed, lagged}) {
    EXPECT_FALSE(track.serves(other, timeline, start.t_s, 1e-3));
    predictor.predict(kTracerDynamics, other, timeline, start, times, &plain);
    predictor.predict(kTracerDynamics, other, timeline, start, times, &tracked, &track);
    for (size_t k = 0; k < plain.size(); ++k) EXPECT_EQ(tracked[k], plain[k]) << "sample " << k;
  }
  EXPECT_FALSE(track.serves(ext, timeline, start.t_s + 1e-3, 1e-3));
  EXPECT_FALSE(track.serves(ext, timeline, start.t_s, 2e-3));
  const ExtendedPredictor coarser(field(), 2e-3);
  coarser.predict(kTracerDynamics, ext, timeline, start, times, &plain);
  coarser.predict(kTracerDynamics, ext, timeline, start, times, &tracked, &track);
  for (size_t k = 0; k < plain.size(); ++k) EXPECT_EQ(tracked[k], plain[k]) << "sample " << k;
  // The transport lag gives each point its own orientation: no track holds that.
  EXPECT_THROW(predictor.track(lagged, timeline, start.t_s, times.back()), InputError);
}

TEST(ExtendedPredictor, RejectsBadInput) {
  ModelExtensions bad;
  bad.static_friction_ratio = 0.5;
  EXPECT_THROW(predict(kTracerDynamics, bad, settled(kO), {0.5, 0.5}, kAtRest, {0.1}), InputError);
  EXPECT_THROW(predict(kTracerDynamics, {}, settled(kO), {NAN, 0.5}, kAtRest, {0.1}), InputError);
  EXPECT_THROW(predict(kTracerDynamics, {}, settled(kO), {0.5, 0.5}, kAtRest, {0.2, 0.1}),
               InputError);
  EXPECT_THROW(ExtendedPredictor(field(), 0.0), InputError);
}

}  // namespace
}  // namespace airtwin
