#include "controller/cem_planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "controller/task.h"
#include "models/cvode_predictor.h"
#include "models/nozzle_response.h"

namespace airtwin {
namespace {

// The reference for the transition: CVODE under the servos' stepped response (NozzleTimeline,
// 1 ms steps) sampled every 2 ms at the middle of each step, the air following a transit later;
// then Delta T = 1.5 s under the new orientation. Objects start at rest.
std::vector<Eigen::Vector2d> continuous_sweep_ends(const AirFieldModel& model,
                                                   const NozzleOrientation& from,
                                                   const NozzleOrientation& to,
                                                   const std::vector<ObjectDynamics>& xi,
                                                   const std::vector<Eigen::Vector2d>& p) {
  const NozzleResponseParameters response;
  const NozzleTimeline timeline(response, {{-1.0, from}, {0.0, to}}, 4.0);
  OrientationSchedule schedule = {{0.0, from}};
  double t = 0.0;
  for (; t < 4.0; t += 0.002) {
    const NozzleOrientation o = timeline.actual(t + 0.001);
    schedule.push_back({response.transit_delay_s + t, o});
    const NozzleOrientation end = timeline.actual(t + 0.002);
    if (end.pan_rad == to.pan_rad && end.tilt_rad == to.tilt_rad) break;
  }
  schedule.push_back({response.transit_delay_s + t + 0.002, to});
  std::vector<ObjectState> start;
  for (const Eigen::Vector2d& q : p) start.push_back({q, 0.0});
  const Prediction ref = CvodePredictor().predict(
      model, schedule, xi, start, PredictionOptions{schedule.back().t_start_s + 1.5, 0.0});
  std::vector<Eigen::Vector2d> ends;
  for (const ObjectState& e : ref.end) ends.push_back(e.p_W);
  return ends;
}

class CemPlannerTest : public ::testing::Test {
 protected:
  AirFieldModel model_ = AirFieldModel::with_constructed_table();
  std::vector<Eigen::Vector2d> p_ = {{0.20, -0.10}, {0.26, 0.02}, {0.12, 0.05}};
  std::vector<Eigen::Vector2d> v_ = {{0.0, 0.0}, {0.05, 0.0}, {0.0, 0.0}};
  std::vector<ObjectDynamics> xi_ = {kTracerDynamics, kTracerDynamics, kCottonDynamics};
  std::vector<Eigen::Vector2d> r_ = std::vector<Eigen::Vector2d>(3, Eigen::Vector2d(0.0, 0.0));

  PlanningProblem problem() const {
    PlanningProblem pr;
    pr.positions_W = p_;
    pr.velocities_W = v_;
    pr.dynamics = xi_;
    pr.references_W = r_;
    return pr;
  }
};

// eq. (10) against a second implementation: the CVODE reference predictor at tight tolerances,
// the orientation from the inverse map, the radial speed carried over.
TEST_F(CemPlannerTest, CostIsEquationTenWithTheReferencePredictor) {
  const CemPlanner planner(model_, CemParameters::line_defaults());
  const CvodePredictor cvode;
  for (const Eigen::Vector2d& s :
       {Eigen::Vector2d(0.55, 0.0), Eigen::Vector2d(0.45, -0.3), Eigen::Vector2d(-0.2, 0.4)}) {
    const AimResult aim = aim_at_stagnation(model_.geometry(), s);
    ASSERT_TRUE(aim.reachable());
    const OrientedField field = model_.at(*aim.orientation);
    std::vector<ObjectState> start(3);
    double expected = 0.0;
    for (size_t j = 0; j < 3; ++j) {
      const Eigen::Vector2d e = (p_[j] - field.stagnation_point()).normalized();
      start[j] = ObjectState{p_[j], std::max(0.0, v_[j].dot(e))};
    }
    const Prediction pred = cvode.predict(field, xi_, start, PredictionOptions{1.5, 0.0});
    for (size_t j = 0; j < 3; ++j) expected += (pred.end[j].p_W - r_[j]).norm();
    std::vector<Eigen::Vector2d> ends;
    const double j = planner.cost(problem(), s, &ends);
    // The fast predictor is good to ~0.35 mm per object near s (docs/dynamics.md).
    EXPECT_NEAR(j, expected, 3 * 0.5e-3) << s.transpose();
    ASSERT_EQ(ends.size(), 3u);
  }
}

// Extended planning with every extension off and no transit: eq. (10) again, now against the
// CVODE reference of eqs. (8)-(9) (objects at rest, so eq. (9)'s radial start is exact). The
// extended predictor's semi-implicit Euler at 1 ms is good to ~1 mm over 2 s
// (models/extended_predictor.h).
TEST_F(CemPlannerTest, ExtendedPlanningWithNothingAddedIsEquationTen) {
  v_.assign(3, Eigen::Vector2d::Zero());
  ExtendedPlanning plain;
  plain.response.transit_delay_s = 0.0;
  plain.step_s = 1e-3;
  const CemPlanner planner(model_, CemParameters::line_defaults(), {}, plain);
  const CvodePredictor cvode;
  for (const Eigen::Vector2d& s : {Eigen::Vector2d(0.55, 0.0), Eigen::Vector2d(-0.2, 0.4)}) {
    const AimResult aim = aim_at_stagnation(model_.geometry(), s);
    ASSERT_TRUE(aim.reachable());
    const OrientedField field = model_.at(*aim.orientation);
    std::vector<ObjectState> start;
    for (const auto& p : p_) start.push_back(ObjectState{p, 0.0});
    const Prediction pred = cvode.predict(field, xi_, start, PredictionOptions{1.5, 0.0});
    double expected = 0.0;
    for (size_t j = 0; j < 3; ++j) expected += (pred.end[j].p_W - r_[j]).norm();
    EXPECT_NEAR(planner.cost(problem(), s), expected, 3 * 1.5e-3) << s.transpose();
  }
}

// Extended planning with extensions: the cost is eq. (10) over ExtendedPredictor::predict, one
// object at a time, under the command with the servo offset taken out, starting from the
// previous command through the servos and the delays, each object under its type's own effects;
// the plan commands that compensated aim.
TEST_F(CemPlannerTest, ExtendedPlanningPredictsTheCompensatedCommand) {
  ExtendedPlanning ext;
  set_extension_values(&ext.extensions, "linearised_drag@tracer", {0.5});
  set_extension_values(&ext.extensions, "air_lift@cotton", {0.05});
  ext.extensions.pan_offset_rad = deg_to_rad(6.0);
  ext.extensions.tilt_offset_rad = deg_to_rad(3.0);
  ext.extensions.extra_delay_s = 0.3;
  ext.extensions.slope_rad = deg_to_rad(2.0);
  ext.extensions.slope_direction_rad = deg_to_rad(200.0);
  ext.extensions.deflection_rad = deg_to_rad(-7.0);
  const CemParameters params = CemParameters::line_defaults();
  const CemPlanner planner(model_, params, {}, ext);
  PlanningProblem pr = problem();
  const std::vector<std::string> types = {"tracer", "tracer", "cotton"};
  EXPECT_THROW(planner.cost(pr, Eigen::Vector2d(0.55, 0.0)), InputError);  // whose effects?
  pr.types = types;
  const NozzleOrientation now{deg_to_rad(100.0), deg_to_rad(20.0)};
  pr.nozzle_now = now;
  const ExtendedPredictor reference(model_, ext.step_s);
  const double t_end = params.horizon_s + ext.response.transit_delay_s + 0.3;
  for (const Eigen::Vector2d& s : {Eigen::Vector2d(0.55, 0.0), Eigen::Vector2d(-0.2, 0.4)}) {
    const AimResult aim = aim_at_stagnation(model_.geometry(), s);
    ASSERT_TRUE(aim.reachable());
    const NozzleOrientation command{wrap_angle(aim.orientation->pan_rad - deg_to_rad(6.0)),
                                    aim.orientation->tilt_rad - deg_to_rad(3.0)};
    ASSERT_GT(command.tilt_rad, 0.0);
    const NozzleTimeline timeline(ext.response, {{-1.0, now}, {0.0, command}}, t_end);
    double expected = 0.0;
    for (size_t j = 0; j < 3; ++j) {
      std::vector<Eigen::Vector2d> end;
      const double times[] = {t_end};
      reference.predict(xi_[j], ext.extensions.for_type(types[j]), timeline,
                        WindowStart{0.0, p_[j], v_[j]}, times, &end);
      expected += (end[0] - r_[j]).norm();
    }
    std::vector<Eigen::Vector2d> ends;
    EXPECT_NEAR(planner.cost(pr, s, &ends), expected, 1e-12) << s.transpose();
    ASSERT_EQ(ends.size(), 3u);
  }
  RandomStream rng(4, RandomPurpose::kController, 0);
  const PlanResult plan = planner.plan(pr, rng);
  const AimResult aim = aim_at_stagnation(model_.geometry(), plan.stagnation_W, 0.0);
  ASSERT_TRUE(aim.reachable());
  EXPECT_NEAR(plan.orientation.pan_rad, wrap_angle(aim.orientation->pan_rad - deg_to_rad(6.0)),
              1e-12);
  EXPECT_NEAR(plan.orientation.tilt_rad, std::max(0.0, aim.orientation->tilt_rad - deg_to_rad(3.0)),
              1e-12);
  // A bad extension is refused when the planner is made.
  ExtendedPlanning bad = ext;
  bad.extensions.static_friction_ratio = 0.2;
  EXPECT_THROW(CemPlanner(model_, params, {}, bad), InputError);
}

// With the transport lag the prediction waits for the new air to reach the farthest object and
// then runs Delta T: for one object at rest, out of the old air's reach, that is a response delay
// of pace times its distance from the new s (the lag's definition, models/extended_predictor.h),
// horizon and all. Servos that turn in a step keep the sweep's orientations out of it.
TEST_F(CemPlannerTest, ExtendedPlanningWaitsForTheLaggedAir) {
  ExtendedPlanning lag;
  lag.response.max_speed_radps = 1e4;
  lag.response.max_acceleration_radps2 = 1e9;
  lag.step_s = 1e-3;
  lag.extensions.transport_pace_s_per_m = 0.8;
  // A short Delta T, so that the tracer is still under way at its end.
  CemParameters params = CemParameters::line_defaults();
  params.horizon_s = 0.5;
  const CemPlanner lagged(model_, params, {}, lag);
  PlanningProblem pr = problem();
  p_ = {{0.3, 0.0}};
  v_ = {Eigen::Vector2d::Zero()};
  xi_ = {kTracerDynamics};
  r_ = {Eigen::Vector2d(1.0, 0.0)};
  pr = problem();
  // The nozzle blows from far away (s ~1.3 m out on -x: too weak to start the tracer).
  pr.nozzle_now = NozzleOrientation{kPi, deg_to_rad(40.0)};
  const Eigen::Vector2d s(0.05, 0.0);
  const double r = (p_[0] - s).norm();
  ExtendedPlanning delay = lag;
  delay.extensions.transport_pace_s_per_m = 0.0;
  delay.extensions.extra_delay_s = 0.8 * r;
  const CemPlanner delayed(model_, params, {}, delay);
  ExtendedPlanning rigid = delay;
  rigid.extensions.extra_delay_s = 0.0;
  const CemPlanner swung(model_, params, {}, rigid);
  std::vector<Eigen::Vector2d> with_lag, with_delay, without;
  lagged.cost(pr, s, &with_lag);
  delayed.cost(pr, s, &with_delay);
  swung.cost(pr, s, &without);
  EXPECT_GT((with_lag[0] - p_[0]).norm(), 0.1);  // it moved
  // One 1 ms step of the moving tracer apart at most (the lag's grid against the delay's).
  EXPECT_LT((with_lag[0] - with_delay[0]).norm(), 2e-3)
      << with_lag[0].transpose() << " against " << with_delay[0].transpose();
  // The same motion as in the rigid field, pace r later: the same end.
  EXPECT_LT((with_lag[0] - without[0]).norm(), 2e-3);
  // Stopped at the rigid field's horizon instead, the lagged prediction falls short.
  const AimResult aim = aim_at_stagnation(model_.geometry(), s);
  ASSERT_TRUE(aim.reachable());
  const double t_short = params.horizon_s + lag.response.transit_delay_s;
  const NozzleTimeline timeline(lag.response, {{-1.0, *pr.nozzle_now}, {0.0, *aim.orientation}},
                                t_short + 1.0);
  std::vector<Eigen::Vector2d> short_end;
  const double times[] = {t_short};
  ExtendedPredictor(model_, lag.step_s)
      .predict(kTracerDynamics, lag.extensions, timeline, WindowStart{0.0, p_[0], v_[0]}, times,
               &short_end);
  EXPECT_GT((with_lag[0] - short_end[0]).norm(), 0.01)
      << with_lag[0].transpose() << " against " << short_end[0].transpose();
}

// A compensated command never leaves the commanded tilt range: with a tilt offset of -3 deg the
// aim of 58.5 deg needs 61.5 deg, which the servos refuse (the run stopped on it: "nozzle
// command: tilt 62.8 deg is outside [0, 60]"), so its stagnation point is out of reach; the
// aim of 55 deg (58 commanded) is not.
TEST_F(CemPlannerTest, ExtendedPlanningNeverCommandsBeyondTheTiltRange) {
  ExtendedPlanning ext;
  ext.extensions.tilt_offset_rad = deg_to_rad(-3.0);
  const CemParameters params = CemParameters::line_defaults();
  const CemPlanner planner(model_, params, {}, ext);
  const double tilt_max = model_.geometry().tilt_max_rad;
  const Eigen::Vector2d far =
      stagnation_point(model_.geometry(), {deg_to_rad(10.0), deg_to_rad(58.5)});
  const Eigen::Vector2d near =
      stagnation_point(model_.geometry(), {deg_to_rad(10.0), deg_to_rad(55.0)});
  PlanningProblem pr = problem();
  EXPECT_EQ(planner.cost(pr, far), params.penalty);
  EXPECT_LT(planner.cost(pr, near), params.penalty);
  // Objects and their references far out, where the best pushes come from the range's edge: the
  // plan's command stays within it.
  std::vector<Eigen::Vector2d> positions, references;
  for (size_t j = 0; j < p_.size(); ++j) {
    positions.push_back(0.7 * far + Eigen::Vector2d(0.05 * static_cast<double>(j), 0.0));
    references.push_back(1.02 * far);
  }
  pr.positions_W = positions;
  pr.references_W = references;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    RandomStream rng(seed, RandomPurpose::kController, 0);
    const PlanResult plan = planner.plan(pr, rng);
    EXPECT_LE(plan.orientation.tilt_rad, tilt_max) << "seed " << seed;
    EXPECT_GE(plan.orientation.tilt_rad, 0.0) << "seed " << seed;
  }
}

TEST_F(CemPlannerTest, PenaltyNearAnObjectOrOutOfReach) {
  const CemParameters params = CemParameters::line_defaults();
  const CemPlanner planner(model_, params);
  // Within delta_min = 10 cm of the third object.
  EXPECT_EQ(planner.cost(problem(), Eigen::Vector2d(0.12, 0.14)), params.penalty);
  // Just outside it, not penalised.
  EXPECT_LT(planner.cost(problem(), Eigen::Vector2d(0.12, 0.1501 + 0.05)), params.penalty);
  // Beyond the stagnation points the tilt range reaches.
  EXPECT_EQ(planner.cost(problem(), Eigen::Vector2d(5.0, 0.0)), params.penalty);
}

TEST_F(CemPlannerTest, SameSeedSameDecisionOtherSeedOtherSamples) {
  const CemPlanner planner(model_, CemParameters::plane_defaults());
  RandomStream a(7, RandomPurpose::kController, 0), b(7, RandomPurpose::kController, 0),
      c(8, RandomPurpose::kController, 0);
  const PlanResult ra = planner.plan(problem(), a);
  const PlanResult rb = planner.plan(problem(), b);
  const PlanResult rc = planner.plan(problem(), c);
  EXPECT_EQ(ra.stagnation_W, rb.stagnation_W);
  EXPECT_EQ(ra.cost, rb.cost);
  EXPECT_NE(ra.stagnation_W, rc.stagnation_W);
}

// The line search ends near the best point of its line: no worse than a dense scan of the
// region its first Gaussian covers (+-3 sigma), by more than a centimetre of summed distance.
TEST_F(CemPlannerTest, LineSearchFindsTheScanMinimum) {
  CemParameters params = CemParameters::line_defaults();
  params.variance0_m2 = 0.01;  // sigma 10 cm: a region with structure for the test
  params.mean0_m = 0.30;
  params.max_iterations = 10;
  const CemPlanner planner(model_, params);
  PlanningProblem pr = problem();
  pr.anchor = 1;
  RandomStream rng(3, RandomPurpose::kController, 0);
  const PlanResult result = planner.plan(pr, rng);
  const Eigen::Vector2d e = (p_[1] - r_[1]).normalized();
  double best = 1e9;
  for (double x = 0.0; x <= 0.6; x += 0.002) best = std::min(best, planner.cost(pr, p_[1] + x * e));
  ASSERT_LT(best, params.penalty);
  EXPECT_LE(result.cost, best + 0.01);
  // s* is on the anchor's line, away from the reference.
  const Eigen::Vector2d d = result.stagnation_W - p_[1];
  EXPECT_NEAR(d.normalized().dot(e), 1.0, 1e-9);
  EXPECT_GT(result.evaluations, 0);
  // Its orientation puts s where it says (eqs. 1-2).
  EXPECT_NEAR(
      (stagnation_point(model_.geometry(), result.orientation) - result.stagnation_W).norm(), 0.0,
      1e-9);
}

TEST_F(CemPlannerTest, PlaneSearchBeatsDoingNothingWhenItCan) {
  // One tracer 30 cm from its reference: some stagnation point must bring it closer.
  p_ = {{0.3, 0.0}};
  v_ = {{0.0, 0.0}};
  xi_ = {kTracerDynamics};
  r_ = {{0.0, 0.0}};
  CemParameters params = CemParameters::plane_defaults();
  params.variance0_m2 = 0.09;
  const CemPlanner planner(model_, params);
  RandomStream rng(1, RandomPurpose::kController, 0);
  const PlanResult result = planner.plan(problem(), rng);
  EXPECT_LT(result.cost, 0.3 - 0.05);
  EXPECT_GE((result.stagnation_W - p_[0]).norm(), params.min_distance_m);
}

TEST_F(CemPlannerTest, BlindLineSearchScansForAPushFromAnotherSide) {
  // A tracer out at r = 0.68 m whose reference lies toward the nozzle's foot (where the square
  // left one after a sweep flung it, seed 2): the ray away from the reference puts s beyond the
  // tracer, which then sits upstream of an oblique jet's s, where the model's air stays under
  // the tracer's start. Every line sample leaves it in place (eq. 10: its distance).
  p_ = {{0.5565, 0.3724}};
  v_ = {{0.0, 0.0}};
  xi_ = {kTracerDynamics};
  r_ = {{0.2728, 0.2429}};
  const double stay = (p_[0] - r_[0]).norm();
  CemParameters params = CemParameters::line_defaults();
  params.variance0_m2 = 0.02;  // the path files' Sigma0
  const Eigen::Vector2d e = (p_[0] - r_[0]).normalized();
  const CemPlanner paper(model_, params);
  for (double x = params.min_distance_m; x <= 1.2; x += 0.01) {
    const double c = paper.cost(problem(), p_[0] + x * e);
    if (c < params.penalty) {
      EXPECT_NEAR(c, stay, 1e-3) << "s " << x << " m out";
    }
  }
  RandomStream rng(5, RandomPurpose::kController, 0);
  const PlanResult blind = paper.plan(problem(), rng);
  EXPECT_FALSE(blind.blind_scan);
  EXPECT_NEAR(blind.cost, stay, 1e-3);
  // With a scan pitch the disc is scanned: a push from elsewhere brings it closer, and the
  // decision's cost is eq. (10) at the s it returns.
  params.scan_step_m = 0.05;
  const CemPlanner scanning(model_, params);
  RandomStream rng2(5, RandomPurpose::kController, 0);
  const PlanResult found = scanning.plan(problem(), rng2);
  EXPECT_TRUE(found.blind_scan);
  EXPECT_LT(found.cost, stay - 0.02);  // measured 4.5 cm closer
  EXPECT_DOUBLE_EQ(found.cost, scanning.cost(problem(), found.stagnation_W));
  // A search that sees something is left as it was, to the bit.
  p_ = {{0.3, 0.0}};
  r_ = {{0.1, 0.0}};
  RandomStream rng3(5, RandomPurpose::kController, 0), rng4(5, RandomPurpose::kController, 0);
  const PlanResult seeing = paper.plan(problem(), rng3);
  const PlanResult seeing_too = scanning.plan(problem(), rng4);
  EXPECT_FALSE(seeing_too.blind_scan);
  EXPECT_LT(seeing.cost, 0.2 - 0.01);
  EXPECT_EQ(seeing.stagnation_W, seeing_too.stagnation_W);
  EXPECT_EQ(seeing.cost, seeing_too.cost);
}

TEST_F(CemPlannerTest, BlindRescueKeepsTheGroupFromSpreading) {
  // An octagon stall in the model's own air: one tracer 33 cm out beyond the corner the group
  // waits at, upstream of every s on its ray, so the paper's line search is blind. Of the disc's
  // 10 cm points the cheapest spreads the group; the rescue takes the cheapest that does not.
  p_ = {{0.1447, -0.6158}, {0.0262, -0.3030}, {0.0573, -0.2662}, {0.0690, -0.2974}};
  v_ = std::vector<Eigen::Vector2d>(4, Eigen::Vector2d::Zero());
  xi_ = std::vector<ObjectDynamics>(4, kTracerDynamics);
  r_ = std::vector<Eigen::Vector2d>(4, Eigen::Vector2d(0.0857, -0.2875));
  double stay = 0.0;
  for (size_t j = 0; j < p_.size(); ++j) stay += (p_[j] - r_[j]).norm();
  const double spread_now = max_pairwise_distance(p_);
  CemParameters params = CemParameters::line_defaults();
  const CemPlanner paper(model_, params);
  RandomStream rng(6, RandomPurpose::kController, 0);
  const PlanResult blind = paper.plan(problem(), rng);
  EXPECT_NEAR(blind.cost, stay, 1e-3);

  // A second implementation of the rescue: every 10 cm point of the reachable disc, eq. (10)
  // with its predicted ends, the cheapest overall and the cheapest that keeps the spread.
  const double pitch = 0.1;
  const double r_max = max_stagnation_radius(model_.geometry());
  double cheapest = std::numeric_limits<double>::infinity();
  double cheapest_spread = 0.0;
  double cheapest_kept = std::numeric_limits<double>::infinity();
  const int half = static_cast<int>(std::floor(r_max / pitch));
  for (int iy = -half; iy <= half; ++iy) {
    for (int ix = -half; ix <= half; ++ix) {
      const Eigen::Vector2d s(ix * pitch, iy * pitch);
      if (s.norm() > r_max) continue;
      std::vector<Eigen::Vector2d> end;
      const double c = paper.cost(problem(), s, &end);
      if (c >= params.penalty) continue;
      if (c < cheapest) {
        cheapest = c;
        cheapest_spread = max_pairwise_distance(end);
      }
      if (max_pairwise_distance(end) <= spread_now + 1e-3)
        cheapest_kept = std::min(cheapest_kept, c);
    }
  }
  // The rule has something to refuse (measured: the cheapest 0.393, spreading 36.0 -> 37.7 cm)
  // and something to take (0.435, against 0.450 where they are).
  ASSERT_GT(cheapest_spread, spread_now + 0.01);
  ASSERT_LT(cheapest, cheapest_kept - 0.02);
  ASSERT_LT(cheapest_kept, stay - 0.01);

  params.scan_step_m = pitch;
  const CemPlanner scanning(model_, params);
  RandomStream rng2(6, RandomPurpose::kController, 0);
  const PlanResult rescue = scanning.plan(problem(), rng2);
  EXPECT_TRUE(rescue.blind_scan);
  EXPECT_DOUBLE_EQ(rescue.cost, cheapest_kept);
  EXPECT_LE(max_pairwise_distance(rescue.predicted_end_W), spread_now + 1e-3);
}

// Weights and reaches against the definition: the weighted sum of the unweighted planner's
// distances (same predictions: the ends do not depend on the weights), plus kOutOfReachCost per
// metre an end lies beyond its reach from the point below the nozzle.
TEST_F(CemPlannerTest, WeightsAndReachesShapeEquationTen) {
  const CemPlanner planner(model_, CemParameters::plane_defaults());
  const Eigen::Vector2d s(0.55, 0.0);
  std::vector<Eigen::Vector2d> ends;
  const double plain = planner.cost(problem(), s, &ends);
  ASSERT_LT(plain, 1e3);
  ASSERT_EQ(ends.size(), 3u);
  const std::vector<double> w = {0.1, 1.0, 0.5};
  // The third object's end lies somewhere past 10 cm from the origin; a reach 5 cm shorter
  // than that costs 10 x 0.05 m. The others are unlimited.
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> reach = {inf, inf, ends[2].norm() - 0.05};
  ASSERT_GT(reach[2], 0.0);
  PlanningProblem pr = problem();
  pr.weights = w;
  pr.reach_m = reach;
  double expected = 0.0;
  for (size_t j = 0; j < 3; ++j) expected += w[j] * (ends[j] - r_[j]).norm();
  expected += kOutOfReachCost * 0.05;
  EXPECT_NEAR(planner.cost(pr, s), expected, 1e-12);
  // Unit weights and no reach: eq. (10) itself, to the bit.
  const std::vector<double> ones(3, 1.0);
  pr.weights = ones;
  pr.reach_m = {};
  EXPECT_EQ(planner.cost(pr, s), plain);
  // Sizes must match; weights are finite and >= 0, reaches > 0.
  const std::vector<double> two = {1.0, 1.0};
  pr.weights = two;
  EXPECT_THROW(planner.cost(pr, s), InputError);
  const std::vector<double> negative = {1.0, -0.1, 1.0};
  pr.weights = negative;
  EXPECT_THROW(planner.cost(pr, s), InputError);
  const std::vector<double> zero_reach = {1.0, 0.0, 1.0};
  pr.weights = {};
  pr.reach_m = zero_reach;
  EXPECT_THROW(planner.cost(pr, s), InputError);
}

// The scan: an object whose only useful push comes from far beyond it. A tracer 0.9 m out,
// its reference 0.6 m farther out: s must lie on the near side, 0.2-0.5 m from it, i.e.
// 0.4-0.7 m from the object's mean (the paper's mu0), where the paper's sigma of 5.6 cm never
// samples. With the scan the decision is at least as cheap as the best point of the 10 cm grid
// (computed here with cost() on every point) and moves the tracer most of the way.
TEST_F(CemPlannerTest, ScanFindsAPushFarFromTheObjectsMean) {
  p_ = {{0.9, 0.0}};
  v_ = {{0.0, 0.0}};
  xi_ = {kTracerDynamics};
  r_ = {{1.5, 0.0}};
  CemParameters paper = CemParameters::plane_defaults();
  const CemPlanner plain(model_, paper);
  RandomStream rng1(1, RandomPurpose::kController, 0);
  const PlanResult without = plain.plan(problem(), rng1);

  CemParameters scanned = paper;
  scanned.scan_step_m = 0.1;
  const CemPlanner planner(model_, scanned);
  double grid_best = 1e9;
  const double r_max = max_stagnation_radius(model_.geometry());
  for (int iy = -20; iy <= 20; ++iy) {
    for (int ix = -20; ix <= 20; ++ix) {
      const Eigen::Vector2d s(ix * 0.1, iy * 0.1);
      if (s.norm() <= r_max) grid_best = std::min(grid_best, planner.cost(problem(), s));
    }
  }
  RandomStream rng2(1, RandomPurpose::kController, 0);
  const PlanResult with = planner.plan(problem(), rng2);
  EXPECT_LE(with.cost, grid_best);
  EXPECT_LT(with.cost, 0.3);  // from 0.6 m
  EXPECT_GT(without.cost, with.cost + 0.2);
  EXPECT_GT(with.evaluations, 300);  // the scan's points count
  // Deterministic: the scan draws nothing.
  RandomStream rng3(1, RandomPurpose::kController, 0);
  EXPECT_EQ(planner.plan(problem(), rng3).stagnation_W, with.stagnation_W);
  // A pitch below 1 cm is refused.
  scanned.scan_step_m = 0.001;
  EXPECT_THROW(scanned.validate("x.yaml"), InputError);
}

// The scan with the sweep clearance: the points are ranked on their prediction and the clearance
// is checked in that order only until the cheapest point it lets pass is found. Against every
// point of the 10 cm grid costed with the clearance checked first (cost()): the decision is a
// point the clearance lets pass, no dearer than the grid's best, while cheaper points of the grid
// are blocked (the nozzle now aims below the second tracer's side, so the re-aims toward the far
// tracer's good pushes sweep past it).
TEST_F(CemPlannerTest, ScanChecksTheSweepInTheRankedOrder) {
  p_ = {{0.9, 0.0}, {0.5, -0.3}};
  v_ = {{0.0, 0.0}, {0.0, 0.0}};
  xi_ = {kTracerDynamics, kTracerDynamics};
  r_ = {{1.5, 0.0}, {0.5, -0.3}};
  CemParameters params = CemParameters::plane_defaults();
  params.scan_step_m = 0.1;
  params.sweep_clearance_m = 0.10;
  PlanningProblem pr = problem();
  pr.nozzle_now = *aim_at_stagnation(model_.geometry(), Eigen::Vector2d(0.2, -0.6)).orientation;
  pr.pan_hint_rad = pr.nozzle_now->pan_rad;
  const CemPlanner planner(model_, params);
  CemParameters unchecked = params;
  unchecked.sweep_clearance_m = 0.0;
  const CemPlanner open(model_, unchecked);
  double grid_best = 1e9;
  std::vector<double> blocked_costs;
  const double r_max = max_stagnation_radius(model_.geometry());
  for (int iy = -20; iy <= 20; ++iy) {
    for (int ix = -20; ix <= 20; ++ix) {
      const Eigen::Vector2d s(ix * 0.1, iy * 0.1);
      if (s.norm() > r_max) continue;
      const double c = planner.cost(pr, s);
      grid_best = std::min(grid_best, c);
      if (c >= params.penalty) blocked_costs.push_back(open.cost(pr, s));
    }
  }
  RandomStream rng(1, RandomPurpose::kController, 0);
  const PlanResult decision = planner.plan(pr, rng);
  EXPECT_LT(decision.cost, params.penalty);
  EXPECT_DOUBLE_EQ(planner.cost(pr, decision.stagnation_W), decision.cost);
  EXPECT_LE(decision.cost, grid_best);
  const auto cheaper = std::count_if(blocked_costs.begin(), blocked_costs.end(),
                                     [&](double c) { return c < grid_best; });
  EXPECT_GT(cheaper, 0) << "no cheaper point was blocked: the test shows nothing";
}

// predict_transition with the nozzle already at the candidate's orientation: no re-aim, nothing
// to add: exactly eq. (10) as the paper predicts it.
TEST_F(CemPlannerTest, TransitionWithoutAReaimIsEquationTen) {
  CemParameters with = CemParameters::line_defaults();
  with.predict_transition = true;
  const CemPlanner plain(model_, CemParameters::line_defaults());
  const CemPlanner transition(model_, with);
  for (const Eigen::Vector2d& s : {Eigen::Vector2d(0.55, 0.0), Eigen::Vector2d(-0.2, 0.4)}) {
    PlanningProblem pr = problem();
    pr.nozzle_now = *aim_at_stagnation(model_.geometry(), s).orientation;
    EXPECT_DOUBLE_EQ(transition.cost(pr, s), plain.cost(pr, s)) << s.transpose();
  }
}

// A re-aim from pan 140 deg to pan -95 deg: the servos do not wrap, so the jet sweeps 235 deg
// through pan 0. A tracer 0.7 m out at pan 0 is beyond the new air's reach (eq. 8 keeps it at
// rest), but the sweep passes over it. Checked against a second implementation: CVODE on the
// continuous sweep (continuous_sweep_ends above). A tracer 1 m out at pan -135 deg, on the short
// way the servos do not take, stays.
TEST_F(CemPlannerTest, TransitionPredictsTheServosSweep) {
  const Eigen::Vector2d s_from =
      0.5 * Eigen::Vector2d(std::cos(deg_to_rad(140.0)), std::sin(deg_to_rad(140.0)));
  const Eigen::Vector2d s_to =
      0.25 * Eigen::Vector2d(std::cos(deg_to_rad(-95.0)), std::sin(deg_to_rad(-95.0)));
  const NozzleOrientation from = *aim_at_stagnation(model_.geometry(), s_from).orientation;
  const NozzleOrientation to = *aim_at_stagnation(model_.geometry(), s_to).orientation;
  const std::vector<Eigen::Vector2d> p = {
      {0.7, 0.0}, Eigen::Vector2d(std::cos(deg_to_rad(-135.0)), std::sin(deg_to_rad(-135.0)))};
  const std::vector<Eigen::Vector2d> v(2, Eigen::Vector2d::Zero());
  const std::vector<ObjectDynamics> xi(2, kTracerDynamics);
  const std::vector<Eigen::Vector2d> r(2, Eigen::Vector2d::Zero());
  PlanningProblem pr;
  pr.positions_W = p;
  pr.velocities_W = v;
  pr.dynamics = xi;
  pr.references_W = r;
  pr.nozzle_now = from;

  CemParameters with = CemParameters::plane_defaults();
  with.predict_transition = true;
  std::vector<Eigen::Vector2d> plain_end, transition_end;
  CemPlanner(model_, CemParameters::plane_defaults()).cost(pr, s_to, &plain_end);
  CemPlanner(model_, with).cost(pr, s_to, &transition_end);
  ASSERT_EQ(transition_end.size(), 2u);
  // Under the new air alone neither moves; the sweep moves the first.
  EXPECT_LT((plain_end[0] - p[0]).norm(), 1e-9);
  EXPECT_LT((plain_end[1] - p[1]).norm(), 1e-9);
  EXPECT_GT((transition_end[0] - p[0]).norm(), 0.05);
  EXPECT_LT((transition_end[1] - p[1]).norm(), 1e-9);

  // Against the continuous sweep (below): the 11 cm push lands within 1 cm.
  const Eigen::Vector2d ref = continuous_sweep_ends(model_, from, to, xi, p)[0];
  EXPECT_LT((transition_end[0] - ref).norm(), 0.01)
      << transition_end[0].transpose() << " vs " << ref.transpose();
}

TEST_F(CemPlannerTest, TransitionConvergesToTheContinuousSweep) {
  // Random re-aims over six objects at rest: the transition's 100 ms midpoint pieces against
  // CVODE on the continuous sweep. The pieces err by millimetres where the paper's prediction,
  // blind to the sweep, misses by decimetres.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-kPi, kPi), radius(0.1, 1.0), xy(-0.8, 0.8);
  auto point = [&] {
    const double a = angle(rng), r = radius(rng);
    return Eigen::Vector2d(r * std::cos(a), r * std::sin(a));
  };
  const std::vector<ObjectDynamics> xi = {kTracerDynamics, kCottonDynamics, kTracerDynamics,
                                          kCottonDynamics, kTracerDynamics, kCottonDynamics};
  double transition_error = 0.0, plain_error = 0.0, worst = 0.0;
  int n = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const NozzleOrientation from = *aim_at_stagnation(model_.geometry(), point()).orientation;
    const Eigen::Vector2d s_to = point();
    const NozzleOrientation to = *aim_at_stagnation(model_.geometry(), s_to).orientation;
    std::vector<Eigen::Vector2d> p;
    for (int j = 0; j < 6; ++j) p.emplace_back(xy(rng), xy(rng));
    const std::vector<Eigen::Vector2d> v(6, Eigen::Vector2d::Zero()), r(6, Eigen::Vector2d::Zero());
    PlanningProblem pr;
    pr.positions_W = p;
    pr.velocities_W = v;
    pr.dynamics = xi;
    pr.references_W = r;
    pr.nozzle_now = from;
    CemParameters plain = CemParameters::plane_defaults();
    plain.min_distance_m = 0.0;
    CemParameters with = plain;
    with.predict_transition = true;
    std::vector<Eigen::Vector2d> plain_end, transition_end;
    CemPlanner(model_, plain).cost(pr, s_to, &plain_end);
    CemPlanner(model_, with).cost(pr, s_to, &transition_end);
    const std::vector<Eigen::Vector2d> ref = continuous_sweep_ends(model_, from, to, xi, p);
    for (size_t j = 0; j < 6; ++j) {
      const double e = (transition_end[j] - ref[j]).norm();
      transition_error += e;
      plain_error += (plain_end[j] - ref[j]).norm();
      worst = std::max(worst, e);
      ++n;
    }
  }
  transition_error /= n;
  plain_error /= n;
  std::printf("re-aims: mean end error %.4f m with the transition (worst %.3f), %.4f m without\n",
              transition_error, worst, plain_error);
  EXPECT_LT(transition_error, 0.01);
  EXPECT_LT(transition_error, 0.2 * plain_error);
}

// The closest s comes to `p` while the servos turn from `from` to `to`, by a second
// implementation: the servos stepped at 0.1 ms (NozzleTimeline) instead of their closed-form
// moves, every step's s.
double closest_pass(const NozzleGeometry& g, const NozzleOrientation& from,
                    const NozzleOrientation& to, const Eigen::Vector2d& p) {
  const NozzleTimeline timeline(NozzleResponseParameters{}, {{-1.0, from}, {0.0, to}}, 3.0, 1e-4);
  double closest = std::numeric_limits<double>::infinity();
  for (double t = 0.0; t <= 3.0; t += 1e-4) {
    closest = std::min(closest, (stagnation_point(g, timeline.actual(t)) - p).norm());
  }
  return closest;
}

// A re-aim from pan 140 deg to -95 deg turns the pan the long way, through 0 deg, where an
// object lies off the sweep's path. The clearance penalises the candidate exactly when the path
// comes closer than it (within 5 mm: the 10 ms pieces' chords and the stepped servos differ by
// less); without the previous command, or with no clearance, only s itself counts.
TEST_F(CemPlannerTest, SweepClearancePenalisesAReaimPassingAnObject) {
  const auto at = [](double r, double deg) {
    return Eigen::Vector2d(r * std::cos(deg_to_rad(deg)), r * std::sin(deg_to_rad(deg)));
  };
  const NozzleOrientation from = *aim_at_stagnation(model_.geometry(), at(0.5, 140.0)).orientation;
  const Eigen::Vector2d s_to = at(0.25, -95.0);
  const std::vector<Eigen::Vector2d> v(1, Eigen::Vector2d::Zero());
  const std::vector<ObjectDynamics> xi(1, kTracerDynamics);
  const std::vector<Eigen::Vector2d> r(1, Eigen::Vector2d::Zero());
  const NozzleOrientation to = *aim_at_stagnation(model_.geometry(), s_to).orientation;
  for (const double radius : {0.37, 0.42}) {
    const std::vector<Eigen::Vector2d> p = {at(radius, 10.0)};
    const double pass = closest_pass(model_.geometry(), from, to, p[0]);
    ASSERT_GT(pass, 0.10);  // the paper's delta_min alone lets it through
    ASSERT_LT(pass, 0.30);
    PlanningProblem pr;
    pr.positions_W = p;
    pr.velocities_W = v;
    pr.dynamics = xi;
    pr.references_W = r;
    CemParameters params = CemParameters::plane_defaults();
    const double unpenalised = CemPlanner(model_, params).cost(pr, s_to);
    EXPECT_LT(unpenalised, params.penalty);
    params.sweep_clearance_m = pass + 0.005;
    EXPECT_EQ(CemPlanner(model_, params).cost(pr, s_to), unpenalised);  // no previous command
    pr.nozzle_now = from;
    EXPECT_EQ(CemPlanner(model_, params).cost(pr, s_to), params.penalty) << "pass " << pass;
    params.sweep_clearance_m = pass - 0.005;
    EXPECT_LT(CemPlanner(model_, params).cost(pr, s_to), params.penalty) << "pass " << pass;
  }
}

// The sweep check skips the pieces that s cannot bring near an object at the servos' fastest: over
// random re-aims and objects it penalises exactly when the stepped servos' path (0.2 ms steps)
// passes closer than the clearance, outside a 3 mm band for the 10 ms chords.
TEST_F(CemPlannerTest, SweepClearanceMatchesTheSteppedPathOverRandomReaims) {
  std::mt19937 gen(29);
  std::uniform_real_distribution<double> angle(-kPi, kPi), radius(0.0, 1.4), unit(0.0, 1.0);
  const auto at = [](double r, double a) {
    return Eigen::Vector2d(r * std::cos(a), r * std::sin(a));
  };
  CemParameters params = CemParameters::plane_defaults();
  params.sweep_clearance_m = 0.10;
  const CemPlanner planner(model_, params);
  const std::vector<Eigen::Vector2d> v(3, Eigen::Vector2d::Zero());
  const std::vector<ObjectDynamics> xi(3, kTracerDynamics);
  const std::vector<Eigen::Vector2d> r(3, Eigen::Vector2d::Zero());
  int passing = 0, clear = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto from = aim_at_stagnation(model_.geometry(), at(radius(gen), angle(gen)));
    const Eigen::Vector2d s_to = at(radius(gen), angle(gen));
    const auto to = aim_at_stagnation(model_.geometry(), s_to);
    if (!from.reachable() || !to.reachable()) continue;
    std::vector<Eigen::Vector2d> p;
    for (int j = 0; j < 3; ++j) p.push_back(at(radius(gen), angle(gen)));
    bool near_s = false;
    for (const auto& q : p) near_s = near_s || (q - s_to).norm() < params.min_distance_m;
    if (near_s) continue;
    const NozzleTimeline timeline(NozzleResponseParameters{},
                                  {{-1.0, *from.orientation}, {0.0, *to.orientation}}, 2.5, 2e-4);
    double closest = std::numeric_limits<double>::infinity();
    for (double t = 0.0; t <= 2.5; t += 2e-4) {
      const Eigen::Vector2d s = stagnation_point(model_.geometry(), timeline.actual(t));
      for (const auto& q : p) closest = std::min(closest, (s - q).norm());
    }
    if (std::abs(closest - params.sweep_clearance_m) < 0.003) continue;
    PlanningProblem pr;
    pr.positions_W = p;
    pr.velocities_W = v;
    pr.dynamics = xi;
    pr.references_W = r;
    pr.nozzle_now = *from.orientation;
    const bool penalised = planner.cost(pr, s_to) >= params.penalty;
    EXPECT_EQ(penalised, closest < params.sweep_clearance_m)
        << "trial " << trial << ", closest pass " << closest << " m";
    (penalised ? passing : clear) += 1;
  }
  EXPECT_GT(passing, 30);  // both outcomes well represented
  EXPECT_GT(clear, 30);
}

// Every push the line search can choose lies on the ray from the object straight away from its
// reference (+y: pan 90 deg; s 50 +- 14 cm from the object), and the pan turns there from -160
// deg through -90 deg, where the object lies: s passes it at 15 cm or less, within the 18 cm
// clearance. Every candidate blocked, the decision is the paper's: on the ray, its sweep passing
// the object, and so marked.
TEST_F(CemPlannerTest, SweepClearanceBlockingEveryPushLeavesThePapersDecision) {
  const std::vector<Eigen::Vector2d> p = {{0.0, -0.25}};
  const std::vector<Eigen::Vector2d> v(1, Eigen::Vector2d::Zero());
  const std::vector<ObjectDynamics> xi(1, kTracerDynamics);
  const std::vector<Eigen::Vector2d> r = {{0.0, -0.5}};
  PlanningProblem pr;
  pr.positions_W = p;
  pr.velocities_W = v;
  pr.dynamics = xi;
  pr.references_W = r;
  pr.nozzle_now = *aim_at_stagnation(model_.geometry(), Eigen::Vector2d(-0.38, -0.14)).orientation;
  pr.pan_hint_rad = pr.nozzle_now->pan_rad;
  CemParameters params = CemParameters::line_defaults();
  params.mean0_m = 0.5;
  RandomStream paper_rng(3, RandomPurpose::kController, 0);
  const PlanResult paper = CemPlanner(model_, params).plan(pr, paper_rng);
  EXPECT_FALSE(paper.sweep_blocked);

  params.sweep_clearance_m = 0.18;
  const CemPlanner planner(model_, params);
  RandomStream rng(3, RandomPurpose::kController, 0);
  const PlanResult blocked = planner.plan(pr, rng);
  EXPECT_TRUE(blocked.sweep_blocked);
  EXPECT_LT(blocked.cost, params.penalty);
  EXPECT_NEAR(blocked.orientation.pan_rad, kPi / 2.0, 1e-9);
  EXPECT_NEAR(blocked.stagnation_W.x(), 0.0, 1e-9);
  EXPECT_LT(closest_pass(model_.geometry(), *pr.nozzle_now, blocked.orientation, p[0]), 0.18);
  // Its cost is the paper's eq. (10) at its s, which the clearance would penalise.
  params.sweep_clearance_m = 0.0;
  EXPECT_EQ(blocked.cost, CemPlanner(model_, params).cost(pr, blocked.stagnation_W));
  EXPECT_EQ(planner.cost(pr, blocked.stagnation_W), params.penalty);

  // With no push the paper's search could take either (every s beyond the reachable disc), the
  // clearance blocked nothing: the decision is infeasible and not marked.
  params.sweep_clearance_m = 0.18;
  params.mean0_m = 3.0;
  RandomStream far_rng(3, RandomPurpose::kController, 0);
  const PlanResult none = CemPlanner(model_, params).plan(pr, far_rng);
  EXPECT_EQ(none.cost, params.penalty);
  EXPECT_FALSE(none.sweep_blocked);
}

// keep_cheapest changes only the last step: the draws are the same (same seed), so the decision
// is the paper's final mean or, when that costs more, the cheapest sample drawn. The problem is
// the octagon's where the final mean flung the group (docs/controller.md, "The cheapest
// candidate"): four tracers near the corner at (0.21, -0.21) and the nozzle aimed 40 cm to their
// left, so that the sweep clearance and delta_min make most of the ray's samples J_P.
TEST_F(CemPlannerTest, KeepCheapestDecidesNoWorseThanTheSearchsSamples) {
  p_ = {{0.213, -0.203}, {0.127, -0.156}, {0.156, -0.175}, {0.144, -0.112}};
  v_.assign(4, Eigen::Vector2d::Zero());
  xi_.assign(4, kTracerDynamics);
  r_.assign(4, Eigen::Vector2d(0.2121, -0.2121));
  PlanningProblem pr = problem();
  pr.nozzle_now = *aim_at_stagnation(model_.geometry(), Eigen::Vector2d(-0.4, -0.1)).orientation;
  pr.pan_hint_rad = pr.nozzle_now->pan_rad;
  CemParameters params = CemParameters::line_defaults();
  params.sweep_clearance_m = 0.10;
  const CemPlanner paper_planner(model_, params);
  params.keep_cheapest = true;
  const CemPlanner planner(model_, params);
  params.sweep_clearance_m = 0.0;
  const CemPlanner unblocked(model_, params);  // the search plan() falls back to when blocked
  int improved = 0;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    RandomStream paper_rng(seed, RandomPurpose::kController, 0);
    RandomStream rng(seed, RandomPurpose::kController, 0);
    const PlanResult paper = paper_planner.plan(pr, paper_rng);
    const PlanResult kept = planner.plan(pr, rng);
    // The same samples: the same number of them predicted (the cheapest's re-evaluation aside).
    EXPECT_LE(std::abs(kept.evaluations - paper.evaluations), 1) << "seed " << seed;
    EXPECT_LE(kept.cost, paper.cost) << "seed " << seed;
    // The cost recorded is the decision's own eq. (10).
    EXPECT_EQ(kept.cost, (kept.sweep_blocked ? unblocked : planner).cost(pr, kept.stagnation_W))
        << "seed " << seed;
    if (kept.cost < paper.cost) {
      ++improved;
      // A sample of the line search: on the ray from the anchor away from its reference.
      const Eigen::Vector2d e = (p_[3] - r_[3]).normalized();
      const Eigen::Vector2d d = kept.stagnation_W - p_[3];
      EXPECT_NEAR(d.x() * e.y() - d.y() * e.x(), 0.0, 1e-12) << "seed " << seed;
    } else {
      EXPECT_EQ(kept.stagnation_W, paper.stagnation_W) << "seed " << seed;
    }
  }
  // The failure it mends is common in this problem: 27 of the 40 seeds (a property of the
  // fixture's air and eq. 8 coefficients, not a tolerance; a quarter is asked).
  EXPECT_GE(improved, 10);
}

// The candidates predicted on several threads give the decision of one thread, bit for bit: the
// plane search after a scan with the re-aim and the sweep clearance, the same planned with an
// extended model, and a blind line search's rescue scan.
TEST_F(CemPlannerTest, AnyNumberOfThreadsDecidesTheSame) {
  auto same = [](const PlanResult& a, const PlanResult& b, const std::string& what) {
    EXPECT_EQ(a.stagnation_W, b.stagnation_W) << what;
    EXPECT_EQ(a.cost, b.cost) << what;
    EXPECT_EQ(a.evaluations, b.evaluations) << what;
    EXPECT_EQ(a.iterations, b.iterations) << what;
    EXPECT_EQ(a.blind_scan, b.blind_scan) << what;
    EXPECT_EQ(a.predicted_end_W, b.predicted_end_W) << what;
  };
  auto decide = [&](const CemParameters& params, std::optional<ExtendedPlanning> ext,
                    const PlanningProblem& pr, int threads) {
    CemPlanner planner(model_, params, {}, ext);
    planner.set_threads(threads);
    EXPECT_EQ(planner.threads(), threads);
    RandomStream rng(3, RandomPurpose::kController, 0);
    return planner.plan(pr, rng);
  };
  r_ = {{0.6, 0.0}, {0.6, 0.0}, {-0.6, 0.0}};
  PlanningProblem pr = problem();
  pr.nozzle_now = NozzleOrientation{140.0 * kPi / 180.0, 0.45};
  CemParameters plane = CemParameters::plane_defaults();
  plane.scan_step_m = 0.1;
  plane.predict_transition = true;
  plane.sweep_clearance_m = 0.1;
  plane.keep_cheapest = true;
  const PlanResult one = decide(plane, std::nullopt, pr, 1);
  EXPECT_GT(one.evaluations, 300);  // the scan's grid and the samples
  for (int threads : {2, 3, 8}) {
    same(one, decide(plane, std::nullopt, pr, threads), "plane, " + std::to_string(threads));
  }
  ExtendedPlanning ext;
  ext.extensions.pan_offset_rad = 0.05;
  ext.extensions.extra_delay_s = 0.2;
  plane.scan_step_m = 0.2;
  plane.samples = 30;
  plane.elite = 5;
  same(decide(plane, ext, pr, 1), decide(plane, ext, pr, 2), "extended");

  p_ = {{0.5565, 0.3724}};
  v_ = {{0.0, 0.0}};
  xi_ = {kTracerDynamics};
  r_ = {{0.2728, 0.2429}};
  CemParameters line = CemParameters::line_defaults();
  line.variance0_m2 = 0.02;
  line.scan_step_m = 0.05;
  const PlanResult blind = decide(line, std::nullopt, problem(), 1);
  EXPECT_TRUE(blind.blind_scan);
  same(blind, decide(line, std::nullopt, problem(), 2), "blind line search");

  CemPlanner planner(model_, line);
  EXPECT_THROW(planner.set_threads(0), InputError);
  EXPECT_THROW(planner.set_threads(257), InputError);
}

TEST(CemParameters, DefaultsAreThePapersAndValidateNamesTheField) {
  const CemParameters line = CemParameters::line_defaults();
  EXPECT_EQ(line.samples, 25);
  EXPECT_EQ(line.elite, 3);
  EXPECT_DOUBLE_EQ(line.mean0_m, 0.418);
  EXPECT_DOUBLE_EQ(line.variance0_m2, 20.9e-4);
  const CemParameters plane = CemParameters::plane_defaults();
  EXPECT_EQ(plane.samples, 100);
  EXPECT_EQ(plane.elite, 10);
  EXPECT_DOUBLE_EQ(plane.converged_variance_m2, 0.5e-4);
  CemParameters bad = line;
  bad.elite = 30;
  try {
    bad.validate("s.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("controller.elite"), std::string::npos);
  }
  bad = line;
  bad.horizon_s = std::nan("");
  EXPECT_THROW(bad.validate("s.yaml"), InputError);
}

TEST_F(CemPlannerTest, BadProblemsAreInputErrors) {
  const CemPlanner planner(model_, CemParameters::line_defaults());
  RandomStream rng(1, RandomPurpose::kController, 0);
  PlanningProblem pr = problem();
  std::vector<Eigen::Vector2d> two(2, Eigen::Vector2d::Zero());
  pr.references_W = two;
  EXPECT_THROW(planner.plan(pr, rng), InputError);
  p_[0].x() = std::nan("");
  EXPECT_THROW(planner.plan(problem(), rng), InputError);
}

}  // namespace
}  // namespace airtwin
