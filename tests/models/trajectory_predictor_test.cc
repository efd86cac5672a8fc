// Trajectory prediction (eqs. 8-9, section V-A): both predictors against closed forms, the fast
// path against the CVODE reference over the Appendix D envelope, the stop event, restarts under a
// new orientation, the paper's numbers, input errors, determinism.

#include "models/trajectory_predictor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/cvode_predictor.h"
#include "models/fast_predictor.h"

namespace airtwin {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

NozzleOrientation deg(double pan, double tilt) { return {deg_to_rad(pan), deg_to_rad(tilt)}; }

// A table whose air speed is constant, U(tilt), for r >> 0: b2 = 0 and b3 = -1000 1/m make eq. (3)
// U (1 - e^{-1000 r}), i.e. exactly U in double precision for r > 0.04 m.
AirFieldModel constant_speed_model(double u0, double u22, double u45) {
  std::vector<std::array<FieldCoefficients, FieldTable::kAlphaBins>> blocks(3);
  const double u[3] = {u0, u22, u45};
  for (int i = 0; i < 3; ++i) blocks[i].fill({u[i], 0.0, -1000.0});
  return AirFieldModel(NozzleGeometry{},
                       FieldTable({0.0, deg_to_rad(22.5), deg_to_rad(45)}, std::move(blocks)));
}

// eq. (8) with constant air speed is linear: v(t) = (v0 - v_inf) e^{xi1 t} + v_inf,
// v_inf = -(xi2 U + xi3) / xi1, and r(t) = r0 + v_inf t + (v0 - v_inf)(e^{xi1 t} - 1) / xi1,
// until v reaches 0 (only when v_inf < 0) at t* = ln(v_inf / (v_inf - v0)) / xi1; then it rests.
struct ClosedForm {
  ObjectDynamics xi;
  double air_speed;
  double v_inf() const { return -xi.drive(air_speed) / xi.xi1; }
  double stop_time(double v0) const {
    if (v_inf() >= 0 || v0 <= 0) return v0 <= 0 && v_inf() <= 0 ? 0.0 : kInf;
    return std::log(v_inf() / (v_inf() - v0)) / xi.xi1;
  }
  double v(double v0, double t) const {
    t = std::min(t, stop_time(v0));
    return v0 <= 0 && v_inf() <= 0 ? 0.0 : (v0 - v_inf()) * std::exp(xi.xi1 * t) + v_inf();
  }
  double distance(double v0, double t) const {
    t = std::min(t, stop_time(v0));
    return v_inf() * t + (v0 - v_inf()) * (std::exp(xi.xi1 * t) - 1) / xi.xi1;
  }
};

struct PredictorCase {
  std::string name;
  std::shared_ptr<const TrajectoryPredictor> predictor;
  double position_tolerance_m;  // against closed forms
  double time_tolerance_s;      // stop times against closed forms
};

class BothPredictors : public ::testing::TestWithParam<PredictorCase> {};

INSTANTIATE_TEST_SUITE_P(
    Predictors, BothPredictors,
    ::testing::Values(PredictorCase{"cvode", std::make_shared<CvodePredictor>(), 1e-9, 1e-8},
                      PredictorCase{"fast", std::make_shared<FastPredictor>(), 5e-5, 1e-4}),
    [](const auto& info) { return info.param.name; });

TEST_P(BothPredictors, MatchesTheClosedFormUnderConstantAir) {
  const TrajectoryPredictor& p = *GetParam().predictor;
  const double tol = GetParam().position_tolerance_m;
  // Tilt 0: s at the origin. U = 3 m/s drives a tracer (drive > 0), U = 1.5 m/s does not.
  for (double u : {3.0, 1.5}) {
    const AirFieldModel model = constant_speed_model(u, u, u);
    const OrientedField f = model.at(deg(0, 0));
    std::vector<ObjectDynamics> dyn;
    std::vector<ObjectState> start;
    for (const ObjectDynamics& xi : {kTracerDynamics, kCottonDynamics}) {
      for (double v0 : {0.0, 0.4, 1.0, 2.5}) {
        for (double angle : {0.0, 1.0, 2.5, -2.0}) {
          dyn.push_back(xi);
          start.push_back({0.25 * Eigen::Vector2d(std::cos(angle), std::sin(angle)), v0});
        }
      }
    }
    PredictionOptions options;
    options.horizon_s = 1.5;
    const Prediction out = p.predict(f, dyn, start, options);
    for (size_t j = 0; j < start.size(); ++j) {
      const ClosedForm cf{dyn[j], u};
      const double v0 = start[j].v;
      const Eigen::Vector2d u_W = start[j].p_W.normalized();
      const Eigen::Vector2d expected = start[j].p_W + cf.distance(v0, 1.5) * u_W;
      EXPECT_NEAR((out.end[j].p_W - expected).norm(), 0.0, tol) << "U " << u << " object " << j;
      EXPECT_NEAR(out.end[j].v, cf.v(v0, 1.5), 10 * tol) << "U " << u << " object " << j;
      const double t_stop = cf.stop_time(v0);
      if (t_stop <= 1.5) {
        // Stopped: v exactly 0, at rest since the closed-form stop time.
        EXPECT_EQ(out.end[j].v, 0.0);
        EXPECT_TRUE(out.at_rest(j));
        EXPECT_NEAR(out.rest_since_s[j], t_stop, GetParam().time_tolerance_s) << "object " << j;
      } else {
        EXPECT_FALSE(out.at_rest(j));
      }
      if (v0 == 0.0 && cf.v_inf() <= 0.0) {
        // At rest where friction wins: stays exactly where it is.
        EXPECT_EQ(out.end[j].p_W, start[j].p_W);
        EXPECT_EQ(out.rest_since_s[j], 0.0);
      }
    }
  }
}

TEST_P(BothPredictors, StoppedObjectRestsWithZeroSpeedAndRestartsUnderANewOrientation) {
  // Tilt 0 gives 1.5 m/s (a tracer stops), tilt 22.5 deg gives 3 m/s (it starts again).
  const TrajectoryPredictor& p = *GetParam().predictor;
  const double tol = GetParam().position_tolerance_m;
  const AirFieldModel model = constant_speed_model(1.5, 3.0, 3.0);
  const OrientationSchedule schedule = {{0.0, deg(0, 0)}, {0.6, deg(90, 22.5)}};
  const std::vector<ObjectDynamics> dyn = {kTracerDynamics};
  const std::vector<ObjectState> start = {{Eigen::Vector2d(0.3, 0.0), 1.0}};
  PredictionOptions options;
  options.sample_rate_hz = 40;
  const Prediction out = p.predict(model, schedule, dyn, start, options);

  // Segment 1: stops on the +x axis at the closed-form time and place.
  const ClosedForm slow{kTracerDynamics, 1.5};
  const double t_stop = slow.stop_time(1.0);
  ASSERT_LT(t_stop, 0.5);
  const Eigen::Vector2d p_stop(0.3 + slow.distance(1.0, t_stop), 0.0);
  // Segment 2: from rest, radially away from the new s.
  const Eigen::Vector2d s2 = stagnation_point(model.geometry(), deg(90, 22.5));
  const double r2 = (p_stop - s2).norm();
  ASSERT_GT(r2, 0.2);
  const ClosedForm fast_air{kTracerDynamics, 3.0};
  const Eigen::Vector2d expected_end = s2 + (r2 + fast_air.distance(0.0, 0.9)) * (p_stop - s2) / r2;
  EXPECT_NEAR((out.end[0].p_W - expected_end).norm(), 0.0, 3 * tol);
  EXPECT_NEAR(out.end[0].v, fast_air.v(0.0, 0.9), 30 * tol);
  EXPECT_FALSE(out.at_rest(0));

  // Samples: never a negative speed; after the stop and until 0.6 s exactly still with v == 0;
  // moving afterwards.
  ASSERT_EQ(out.sample_times_s.size(), 61u);
  const ObjectState* rest = nullptr;
  for (size_t k = 0; k < out.sample_times_s.size(); ++k) {
    const double t = out.sample_times_s[k];
    const ObjectState& s = out.sample(k, 0);
    EXPECT_GE(s.v, 0.0) << "t " << t;
    if (t > t_stop + 1e-3 && t <= 0.6) {
      EXPECT_EQ(s.v, 0.0) << "t " << t;
      EXPECT_NEAR((s.p_W - p_stop).norm(), 0.0, tol) << "t " << t;
      if (rest == nullptr) rest = &s;
      EXPECT_EQ(s.p_W, rest->p_W) << "moved while at rest, t " << t;
    }
    if (t > 0.65) {
      EXPECT_GT(s.v, 0.0) << "t " << t;
    }
  }
  ASSERT_NE(rest, nullptr);
}

TEST_P(BothPredictors, SpeedCarriesOverAndTheDirectionTurnsRadialFromTheNewS) {
  const TrajectoryPredictor& p = *GetParam().predictor;
  const double tol = GetParam().position_tolerance_m;
  const AirFieldModel model = constant_speed_model(3.0, 3.0, 3.0);
  const NozzleOrientation a = deg(30, 22.5), b = deg(-120, 22.5);
  const OrientationSchedule schedule = {{0.0, a}, {0.5, b}};
  const Eigen::Vector2d s1 = stagnation_point(model.geometry(), a);
  const Eigen::Vector2d s2 = stagnation_point(model.geometry(), b);
  const std::vector<ObjectDynamics> dyn = {kCottonDynamics};
  const Eigen::Vector2d p0 = s1 + Eigen::Vector2d(-0.25, 0.1);
  const std::vector<ObjectState> start = {{p0, 0.3}};
  const Prediction out = p.predict(model, schedule, dyn, start);

  const ClosedForm cf{kCottonDynamics, 3.0};
  const Eigen::Vector2d p_switch = p0 + cf.distance(0.3, 0.5) * (p0 - s1).normalized();
  const double v_switch = cf.v(0.3, 0.5);
  const double r2 = (p_switch - s2).norm();
  const Eigen::Vector2d expected = s2 + (r2 + cf.distance(v_switch, 1.0)) / r2 * (p_switch - s2);
  EXPECT_NEAR((out.end[0].p_W - expected).norm(), 0.0, 3 * tol);
  EXPECT_NEAR(out.end[0].v, cf.v(v_switch, 1.0), 30 * tol);
}

TEST_P(BothPredictors, AnObjectAtTheStagnationPointStaysThereWhileItsSpeedDecays) {
  // At s there is no direction and no air: eq. (8) with v_air = 0 until v reaches 0.
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(40, 30));
  const std::vector<ObjectDynamics> dyn = {kTracerDynamics};
  const std::vector<ObjectState> start = {{f.stagnation_point(), 1.5}};
  const Prediction out = p.predict(f, dyn, start);
  EXPECT_EQ(out.end[0].p_W, f.stagnation_point());
  EXPECT_EQ(out.end[0].v, 0.0);
  const ClosedForm still{kTracerDynamics, 0.0};
  EXPECT_NEAR(out.rest_since_s[0], still.stop_time(1.5), GetParam().time_tolerance_s);
}

TEST_P(BothPredictors, PapersTracerThirtyCentimetresFromSMovesThenStopsWithinTheRecording) {
  // Appendix D: objects placed 20-58 cm from s move, and stop within the 2 s recording.
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(0, 0));
  std::vector<ObjectDynamics> dyn;
  std::vector<ObjectState> start;
  for (int a = 0; a < 360; a += 45) {
    const double alpha = deg_to_rad(a);
    dyn.push_back(kTracerDynamics);
    start.push_back(
        {f.stagnation_point() + 0.3 * Eigen::Vector2d(std::cos(alpha), std::sin(alpha)), 0.0});
    ASSERT_GT(f.speed(start.back().p_W), 2.0) << "the field must exceed the tracer's threshold";
  }
  PredictionOptions options;
  options.horizon_s = 2.0;
  options.sample_rate_hz = 40;
  const Prediction out = p.predict(f, dyn, start, options);
  for (size_t j = 0; j < start.size(); ++j) {
    EXPECT_GT((out.end[j].p_W - start[j].p_W).norm(), 0.01) << "object " << j << " did not move";
    EXPECT_TRUE(out.at_rest(j)) << "object " << j << " still moving after 2 s";
    EXPECT_GT(out.rest_since_s[j], 0.0);
    EXPECT_EQ(out.end[j].v, 0.0);
    // It moved straight away from s.
    const Eigen::Vector2d d0 = start[j].p_W - f.stagnation_point();
    const Eigen::Vector2d d1 = out.end[j].p_W - f.stagnation_point();
    EXPECT_NEAR(d0.x() * d1.y() - d0.y() * d1.x(), 0.0, 1e-9);
    // After the stop, every sample is the end state, bit for bit.
    for (size_t k = 0; k < out.sample_times_s.size(); ++k) {
      EXPECT_GE(out.sample(k, j).v, 0.0);
      if (out.sample_times_s[k] > out.rest_since_s[j]) {
        EXPECT_EQ(out.sample(k, j).p_W, out.end[j].p_W);
        EXPECT_EQ(out.sample(k, j).v, 0.0);
      }
    }
  }
}

TEST_P(BothPredictors, SamplesAreAtTheRequestedRateFromStartToEnd) {
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientationSchedule schedule = {{0.0, deg(10, 10)}, {0.3123, deg(100, 30)}};
  const std::vector<ObjectDynamics> dyn = {kTracerDynamics, kCottonDynamics};
  const std::vector<ObjectState> start = {{Eigen::Vector2d(0.4, 0.1), 0.2},
                                          {Eigen::Vector2d(-0.3, 0.2), 0.0}};
  PredictionOptions options;
  options.horizon_s = 1.5;
  options.sample_rate_hz = 40;
  const Prediction sampled = p.predict(model, schedule, dyn, start, options);
  ASSERT_EQ(sampled.sample_times_s.size(), 61u);
  ASSERT_EQ(sampled.samples.size(), 61u * 2);
  for (size_t k = 0; k < 61; ++k) EXPECT_DOUBLE_EQ(sampled.sample_times_s[k], k / 40.0);
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(sampled.sample(0, j).p_W, start[j].p_W);
    EXPECT_EQ(sampled.sample(60, j).p_W, sampled.end[j].p_W);
    EXPECT_EQ(sampled.sample(60, j).v, sampled.end[j].v);
  }
  // Sampling does not change the answer beyond the integrator's accuracy.
  const Prediction plain = p.predict(model, schedule, dyn, start);
  EXPECT_TRUE(plain.samples.empty());
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_NEAR((plain.end[j].p_W - sampled.end[j].p_W).norm(), 0.0, 1e-5);
  }
}

TEST_P(BothPredictors, ScheduleEntriesBeforeZeroAndAfterTheHorizonAreHandled) {
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const std::vector<ObjectDynamics> dyn = {kTracerDynamics};
  const std::vector<ObjectState> start = {{Eigen::Vector2d(0.3, -0.2), 0.1}};
  const Prediction single = p.predict(model.at(deg(20, 22.5)), dyn, start);
  const Prediction scheduled = p.predict(
      model, {{-2.0, deg(170, 40)}, {0.0, deg(20, 22.5)}, {1.5, deg(-90, 45)}}, dyn, start);
  EXPECT_EQ(single.end[0].p_W, scheduled.end[0].p_W);
  EXPECT_EQ(single.end[0].v, scheduled.end[0].v);
}

TEST_P(BothPredictors, TheRaysViewPredictsWhatTheFullFieldDoes) {
  // Fast: the rays' profiles are the full field's, bit for bit. CVODE: it builds the full field
  // from the rays. Either way the same bits, samples and rest times included.
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::vector<ObjectDynamics> dyn;
  std::vector<ObjectState> start;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.7, 0.7), v(0, 0.8);
  for (int j = 0; j < 12; ++j) {
    dyn.push_back(j % 2 ? kTracerDynamics : kCottonDynamics);
    start.push_back({Eigen::Vector2d(u(rng), u(rng)), j % 3 ? v(rng) : 0.0});
  }
  PredictionOptions options;
  options.sample_rate_hz = 40;
  for (const NozzleOrientation& o : {deg(35, 30), deg(-150, 12), deg(400, 50)}) {
    const Prediction full = p.predict(model.at(o), dyn, start, options);
    const Prediction rays = p.predict(model.rays_at(o), dyn, start, options);
    ASSERT_EQ(full.samples.size(), rays.samples.size());
    for (size_t j = 0; j < dyn.size(); ++j) {
      EXPECT_EQ(full.end[j].p_W, rays.end[j].p_W) << "object " << j;
      EXPECT_EQ(full.end[j].v, rays.end[j].v);
      EXPECT_EQ(full.rest_since_s[j], rays.rest_since_s[j]);
    }
    for (size_t i = 0; i < full.samples.size(); ++i) {
      EXPECT_EQ(full.samples[i].p_W, rays.samples[i].p_W);
    }
  }
}

TEST_P(BothPredictors, RerunsAreBitIdentical) {
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientationSchedule schedule = {
      {0.0, deg(0, 22.5)}, {0.4, deg(60, 10)}, {0.9, deg(-45, 45)}};
  std::vector<ObjectDynamics> dyn;
  std::vector<ObjectState> start;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.6, 0.6), v(0, 1);
  for (int j = 0; j < 40; ++j) {
    dyn.push_back(j % 2 ? kTracerDynamics : kCottonDynamics);
    start.push_back({Eigen::Vector2d(u(rng), u(rng)), v(rng) < 0.5 ? 0.0 : v(rng)});
  }
  PredictionOptions options;
  options.sample_rate_hz = 40;
  const Prediction a = p.predict(model, schedule, dyn, start, options);
  Prediction b;
  p.predict(model, schedule, dyn, start, options, b);
  p.predict(model, schedule, dyn, start, options, b);  // reused buffers
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(a.samples[i].p_W, b.samples[i].p_W);
    ASSERT_EQ(a.samples[i].v, b.samples[i].v);
  }
  for (size_t j = 0; j < start.size(); ++j) {
    ASSERT_EQ(a.end[j].p_W, b.end[j].p_W);
    ASSERT_EQ(a.rest_since_s[j], b.rest_since_s[j]);
  }
}

TEST_P(BothPredictors, ConcurrentCallsOnOnePredictorMatchSerialOnes) {
  // predict() is const and owns its scratch: threads sharing a predictor and a model agree with a
  // serial run bit for bit.
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::vector<OrientationSchedule> schedules;
  for (int i = 0; i < 4; ++i) {
    schedules.push_back({{0.0, deg(40.0 * i, 7.5 * i)}, {0.7, deg(-30.0 * i, 45 - 5.0 * i)}});
  }
  std::vector<ObjectDynamics> dyn;
  std::vector<ObjectState> start;
  for (int j = 0; j < 12; ++j) {
    dyn.push_back(j % 2 ? kTracerDynamics : kCottonDynamics);
    start.push_back({Eigen::Vector2d(0.05 * j - 0.3, 0.4 - 0.03 * j), 0.1 * (j % 3)});
  }
  std::vector<Prediction> serial(4), parallel(4);
  for (int i = 0; i < 4; ++i) serial[i] = p.predict(model, schedules[i], dyn, start);
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i) {
    threads.emplace_back([&, i] { parallel[i] = p.predict(model, schedules[i], dyn, start); });
  }
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < 4; ++i) {
    for (size_t j = 0; j < start.size(); ++j) {
      EXPECT_EQ(serial[i].end[j].p_W, parallel[i].end[j].p_W);
      EXPECT_EQ(serial[i].end[j].v, parallel[i].end[j].v);
    }
  }
}

TEST_P(BothPredictors, BadInputIsAnInputError) {
  const TrajectoryPredictor& p = *GetParam().predictor;
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(0, 0));
  const std::vector<ObjectDynamics> one = {kTracerDynamics};
  const std::vector<ObjectState> ok = {{Eigen::Vector2d(0.3, 0), 0.0}};
  const double nan = std::nan("");
  EXPECT_THROW(p.predict(f, std::vector<ObjectDynamics>{}, ok), InputError);
  EXPECT_THROW(p.predict(f, one, std::vector<ObjectState>{{Eigen::Vector2d(nan, 0), 0}}),
               InputError);
  EXPECT_THROW(p.predict(f, one, std::vector<ObjectState>{{Eigen::Vector2d(0.3, 0), -0.1}}),
               InputError);
  EXPECT_THROW(p.predict(f, std::vector<ObjectDynamics>{{nan, 1, -1}}, ok), InputError);
  PredictionOptions bad;
  bad.horizon_s = 0;
  EXPECT_THROW(p.predict(f, one, ok, bad), InputError);
  bad = {};
  bad.sample_rate_hz = -40;
  EXPECT_THROW(p.predict(f, one, ok, bad), InputError);
  EXPECT_THROW(p.predict(model, {}, one, ok), InputError);
  EXPECT_THROW(p.predict(model, {{0.1, deg(0, 0)}}, one, ok), InputError);
  EXPECT_THROW(p.predict(model, {{0.0, deg(0, 0)}, {0.0, deg(0, 10)}}, one, ok), InputError);
  EXPECT_THROW(p.predict(model, {{0.0, deg(0, 0)}, {nan, deg(0, 10)}}, one, ok), InputError);
  EXPECT_THROW(p.predict(model, {{0.0, deg(0, 0)}, {0.5, deg(0, 95)}}, one, ok), InputError);
  // Nothing to predict is not an error.
  EXPECT_TRUE(p.predict(f, std::vector<ObjectDynamics>{}, std::vector<ObjectState>{}).end.empty());
}

// The fast path against the reference over the envelope of Appendix D: starts 20-58 cm from s in
// all directions, at rest and moving, tilts 0-45 deg (table and non-table tilts), varied pans,
// both object types.
TEST(FastPredictor, AgreesWithCvodeWithinOneMillimetreOverTheAppendixDEnvelope) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const CvodePredictor reference;
  const FastPredictor fast;
  const FastPredictor too_coarse({0.5});  // shows that the envelope can tell steps apart
  double max_error = 0.0, max_coarse_error = 0.0;
  int stopped = 0, moving = 0;
  for (double tilt : {0.0, 10.0, 22.5, 30.0, 45.0}) {
    for (double pan : {-135.0, -30.0, 60.0, 170.0}) {
      const OrientedField f = model.at(deg(pan, tilt));
      std::vector<ObjectDynamics> dyn;
      std::vector<ObjectState> start;
      for (const ObjectDynamics& xi : {kTracerDynamics, kCottonDynamics}) {
        for (int a = 0; a < 360; a += 30) {
          const double alpha = deg_to_rad(pan + a + 7);
          for (double r : {0.20, 0.33, 0.46, 0.58}) {
            for (double v0 : {0.0, 0.7}) {
              dyn.push_back(xi);
              start.push_back(
                  {f.stagnation_point() + r * Eigen::Vector2d(std::cos(alpha), std::sin(alpha)),
                   v0});
            }
          }
        }
      }
      const Prediction ref = reference.predict(f, dyn, start);
      const Prediction got = fast.predict(f, dyn, start);
      const Prediction rough = too_coarse.predict(f, dyn, start);
      for (size_t j = 0; j < start.size(); ++j) {
        const double e = (got.end[j].p_W - ref.end[j].p_W).norm();
        max_error = std::max(max_error, e);
        max_coarse_error = std::max(max_coarse_error, (rough.end[j].p_W - ref.end[j].p_W).norm());
        EXPECT_LT(e, 1e-3) << "tilt " << tilt << " pan " << pan << " object " << j;
        EXPECT_EQ(got.at_rest(j), ref.at_rest(j)) << "tilt " << tilt << " object " << j;
        (ref.at_rest(j) ? stopped : moving)++;
      }
    }
  }
  // The envelope must exercise both outcomes.
  EXPECT_GT(stopped, 100);
  EXPECT_GT(moving, 100);
  EXPECT_GT(max_coarse_error, 1e-3) << "the envelope does not discriminate a 0.5 s step";
  RecordProperty("max_error_m", std::to_string(max_error));
  std::printf(
      "fast vs CVODE, Appendix D envelope: max end-position error %.3g m (%d stopped, "
      "%d moving)\n",
      max_error, stopped, moving);
}

// Within a few cm of s eq. (3) rises steeply (b3 ~ -28 1/m) and the dynamics are ~10x faster: the
// fast path shortens the steps of the objects there. Objects starting 0.5-15 cm from s.
TEST(FastPredictor, AgreesWithCvodeWithinOneMillimetreNearTheStagnationPoint) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const CvodePredictor reference;
  const FastPredictor fast;
  FastPredictor::Options fixed_step;
  fixed_step.rate_factor = 1e9;  // the same RK4 without the near-s rule
  const FastPredictor without_rule(fixed_step);
  double max_error = 0.0, max_error_without = 0.0;
  for (double tilt : {0.0, 22.5, 45.0}) {
    for (double pan : {0.0, 100.0}) {
      const OrientedField f = model.at(deg(pan, tilt));
      std::vector<ObjectDynamics> dyn;
      std::vector<ObjectState> start;
      for (const ObjectDynamics& xi : {kTracerDynamics, kCottonDynamics}) {
        for (int a = 0; a < 360; a += 30) {
          const double alpha = deg_to_rad(pan + a + 3);
          for (double r : {0.005, 0.01, 0.02, 0.05, 0.1, 0.15}) {
            for (double v0 : {0.0, 0.5}) {
              dyn.push_back(xi);
              start.push_back(
                  {f.stagnation_point() + r * Eigen::Vector2d(std::cos(alpha), std::sin(alpha)),
                   v0});
            }
          }
        }
      }
      const Prediction ref = reference.predict(f, dyn, start);
      const Prediction got = fast.predict(f, dyn, start);
      const Prediction plain = without_rule.predict(f, dyn, start);
      for (size_t j = 0; j < start.size(); ++j) {
        const double e = (got.end[j].p_W - ref.end[j].p_W).norm();
        max_error = std::max(max_error, e);
        max_error_without = std::max(max_error_without, (plain.end[j].p_W - ref.end[j].p_W).norm());
        EXPECT_LT(e, 1e-3) << "tilt " << tilt << " pan " << pan << " object " << j;
      }
    }
  }
  EXPECT_GT(max_error_without, 1e-3) << "near s the step rule should matter";
  std::printf("fast vs CVODE near s: max end-position error %.3g m (%.3g m without the rule)\n",
              max_error, max_error_without);
}

// Same, under piecewise-constant schedules with 2-3 orientation changes, sampled at 40 Hz.
TEST(FastPredictor, AgreesWithCvodeWithinOneMillimetreUnderSchedules) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const CvodePredictor reference;
  const FastPredictor fast;
  std::mt19937_64 rng(1234);
  std::uniform_real_distribution<double> pan(-180, 180), tilt(0, 45), angle(-kPi, kPi),
      radius(0.20, 0.58), u01(0, 1);
  double max_error = 0.0, max_end_error = 0.0;
  for (int trial = 0; trial < 24; ++trial) {
    OrientationSchedule schedule = {{0.0, deg(pan(rng), tilt(rng))}};
    const int changes = 2 + trial % 2;
    for (int c = 0; c < changes; ++c) {
      schedule.push_back({0.2 + 0.4 * c + 0.3 * u01(rng), deg(pan(rng), tilt(rng))});
    }
    const Eigen::Vector2d s0 = stagnation_point(model.geometry(), schedule[0].orientation);
    std::vector<ObjectDynamics> dyn;
    std::vector<ObjectState> start;
    for (int j = 0; j < 25; ++j) {
      const double a = angle(rng);
      dyn.push_back(u01(rng) < 0.5 ? kTracerDynamics : kCottonDynamics);
      start.push_back({s0 + radius(rng) * Eigen::Vector2d(std::cos(a), std::sin(a)),
                       u01(rng) < 0.5 ? 0.0 : u01(rng)});
    }
    PredictionOptions options;
    options.sample_rate_hz = 40;
    const Prediction ref = reference.predict(model, schedule, dyn, start, options);
    const Prediction got = fast.predict(model, schedule, dyn, start, options);
    for (size_t i = 0; i < ref.samples.size(); ++i) {
      const double e = (got.samples[i].p_W - ref.samples[i].p_W).norm();
      max_error = std::max(max_error, e);
      EXPECT_LT(e, 1e-3) << "trial " << trial << " sample " << i;
    }
    // Without samples the fast path takes its full steps (sampling cuts them at 25 ms).
    const Prediction end_only = fast.predict(model, schedule, dyn, start);
    for (size_t j = 0; j < start.size(); ++j) {
      const double e = (end_only.end[j].p_W - ref.end[j].p_W).norm();
      max_end_error = std::max(max_end_error, e);
      EXPECT_LT(e, 1e-3) << "trial " << trial << " object " << j;
    }
  }
  std::printf("fast vs CVODE, schedules: max error %.3g m sampled at 40 Hz, %.3g m at the end\n",
              max_error, max_end_error);
}

TEST(FastPredictor, BatchingDoesNotChangeTheAnswer) {
  // Objects are independent lanes: one at a time or 70 together (3 blocks) give the same bits.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(75, 17));
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-0.6, 0.6), v(0, 1);
  std::vector<ObjectDynamics> dyn;
  std::vector<ObjectState> start;
  for (int j = 0; j < 70; ++j) {
    dyn.push_back(j % 3 ? kTracerDynamics : kCottonDynamics);
    start.push_back({f.stagnation_point() + Eigen::Vector2d(u(rng), u(rng)), v(rng)});
  }
  const FastPredictor fast;
  const Prediction all = fast.predict(f, dyn, start);
  for (size_t j = 0; j < start.size(); ++j) {
    const Prediction one = fast.predict(f, std::span(&dyn[j], 1), std::span(&start[j], 1));
    EXPECT_EQ(one.end[0].p_W, all.end[j].p_W) << "object " << j;
    EXPECT_EQ(one.end[0].v, all.end[j].v) << "object " << j;
  }
}

TEST(FastPredictor, RejectsAStepOutsideItsRange) {
  EXPECT_THROW(FastPredictor({0.0}), InputError);
  EXPECT_THROW(FastPredictor({std::nan("")}), InputError);
  EXPECT_NO_THROW(FastPredictor({0.025}));
}

TEST(CvodePredictor, SolverFailuresAreExceptionsWithSundialsWords) {
  CvodePredictor::Options o;
  o.max_num_steps = 2;  // far too few for 1.5 s at rtol 1e-10
  const CvodePredictor starved(o);
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const std::vector<ObjectDynamics> dyn = {kTracerDynamics};
  const std::vector<ObjectState> start = {{Eigen::Vector2d(0.3, 0.0), 0.5}};
  try {
    starved.predict(model.at(deg(0, 0)), dyn, start);
    ADD_FAILURE() << "no IntegrationError";
  } catch (const IntegrationError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("CV_TOO_MUCH_WORK"), std::string::npos) << what;
    EXPECT_NE(what.find("object 0"), std::string::npos) << what;
  }
  EXPECT_THROW(CvodePredictor({-1.0, 1e-12, 100}), InputError);
  EXPECT_THROW(CvodePredictor({1e-10, 0.0, 100}), InputError);
  EXPECT_THROW(CvodePredictor({1e-10, 1e-12, 0}), InputError);
}

}  // namespace
}  // namespace airtwin
