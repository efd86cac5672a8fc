// The wall jet's transport lag: the history and its lags against their definition (r / U_front,
// or the CFD start-up's lag), and in the twin a far object meeting a re-aimed jet's air that much
// later than a rigid pattern brings it.

#include "sim/air_transport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "sim/twin.h"
#include "tests/support/shipped_cfd.h"

namespace airtwin {
namespace {

constexpr double kDt = 0.0025;

TEST(AirTransport, LagIsDistanceOverFrontSpeedInWholeStepsWithinTheSpan) {
  AirTransportParameters p;
  p.front_speed_mps = 1.5;
  p.max_lag_s = 1.0;
  const AirTransport t(p, kDt, {0.1, 0.2});
  EXPECT_TRUE(t.enabled());
  EXPECT_EQ(t.lag_steps(0.0), 0);
  // 0.3 m at 1.5 m/s is 0.2 s, 80 steps of 2.5 ms.
  EXPECT_EQ(t.lag_steps(0.3), 80);
  EXPECT_EQ(t.lag_steps(0.3 + 0.4 * 1.5 * kDt), 80);  // rounds to the nearest step
  EXPECT_EQ(t.lag_steps(0.3 + 0.6 * 1.5 * kDt), 81);
  // Beyond U_front * max_lag_s = 1.5 m: the span, 400 steps.
  EXPECT_EQ(t.lag_steps(10.0), 400);
  EXPECT_EQ(AirTransport(AirTransportParameters::rigid(), kDt, {0, 0}).lag_steps(1.0), 0);
}

TEST(AirTransport, WithTheCfdStartUpTheLagIsItsWallJetLag) {
  const CfdStartup startup(0.25, {0.1, 0.5}, {0.3, 0.75});  // lag 0.05 s at 0.1 m, 0.5 s at 0.5 m
  AirTransportParameters p;
  p.max_lag_s = 1.0;
  const AirTransport t(p, kDt, {0.1, 0.2}, &startup);
  EXPECT_EQ(t.lag_steps(0.1), 20);   // 0.05 s
  EXPECT_EQ(t.lag_steps(0.3), 110);  // 0.275 s: linear between
  EXPECT_EQ(t.lag_steps(0.05), 10);  // from 0 at s
  EXPECT_EQ(t.lag_steps(2.0), 400);  // past the span
  p.cfd_timing = false;              // r / U_front again: 0.3 m / 1.5 m/s = 0.2 s
  EXPECT_EQ(AirTransport(p, kDt, {0.1, 0.2}, &startup).lag_steps(0.3), 80);
}

TEST(AirTransport, HistoryReturnsWhatWasPushedAndSaysWhenItIsSteady) {
  AirTransportParameters p;
  p.front_speed_mps = 1.0;
  p.max_lag_s = 10 * kDt;  // 11 orientations kept
  AirTransport t(p, kDt, {0.0, 0.0});
  EXPECT_TRUE(t.steady());
  for (int i = 1; i <= 5; ++i) t.push({0.01 * i, 0.0});
  EXPECT_FALSE(t.steady());
  for (int back = 0; back < 5; ++back) EXPECT_DOUBLE_EQ(t.at_lag(back).pan_rad, 0.01 * (5 - back));
  EXPECT_DOUBLE_EQ(t.at_lag(5).pan_rad, 0.0);
  EXPECT_DOUBLE_EQ(t.at_lag(1000).pan_rad, 0.0);  // clamped to the oldest kept
  // Steady once the last change has left the history: 10 more pushes of the same orientation.
  for (int i = 0; i < 9; ++i) t.push({0.05, 0.0});
  EXPECT_FALSE(t.steady());
  t.push({0.05, 0.0});
  EXPECT_TRUE(t.steady());
  EXPECT_DOUBLE_EQ(t.at_lag(10).pan_rad, 0.05);
}

TEST(AirTransport, APointFeelsTheNewestOrientationWhoseAirHasReachedIt) {
  AirTransportParameters p;
  p.front_speed_mps = 1.0;  // lag r / (1 m/s): 0.05 m in 20 steps of 2.5 ms
  p.max_lag_s = 1.0;        // 401 orientations kept
  AirTransport t(p, kDt, {0.0, 0.0}, nullptr, nullptr, {0.0, 0.0});
  for (int i = 0; i < 40; ++i) t.push({1.0, 0.0}, {0.5, 0.0});
  // 0.05 m from the new s: its air 20 steps old has arrived.
  EXPECT_EQ(t.reached_steps({0.55, 0.0}), 20);
  // 0.2 m from it (80 steps, not yet) and 0.7 m from the old s: the old air, 280 steps old.
  EXPECT_EQ(t.reached_steps({0.7, 0.0}), 280);
  // Turned back for 10 steps: the old s's new air is 220 steps from (0.55, 0), so the brief
  // orientation's air, now 20 steps old, is still what arrives there.
  for (int i = 0; i < 10; ++i) t.push({0.0, 0.0}, {0.0, 0.0});
  EXPECT_EQ(t.reached_steps({0.55, 0.0}), 20);
  EXPECT_EQ(t.reached_steps({0.0, 0.0}), 0);  // at s: at once
  // Beyond the history's reach: the oldest kept.
  EXPECT_EQ(t.reached_steps({50.0, 0.0}), 400);
}

// The search against its definition, the smallest k with lag_steps(|p - s_k|, phi) <= k, by
// brute force over a seeded program of holds (runs of one s) and slews (a new s every step),
// wherever the search starts (the box around the kept s). The reach is kept on a 1 mm grid of r,
// so the definition is read at |p - s_k| rounded down to the millimetre. With `random_carry`,
// each query draws phi from the tables' grid 2^(j/8); else phi is 1.
struct SearchCheck {
  int checked = 0, older = 0, carried = 0;  // queries; neither present nor oldest; phi mattered
};
SearchCheck check_search(const AirTransportParameters& p, const Eigen::Vector2d& s0, unsigned seed,
                         int segments, int hold_max, int every, bool random_carry) {
  AirTransport t(p, kDt, {0.0, 0.0}, nullptr, nullptr, s0);
  const int last = static_cast<int>(std::ceil(p.max_lag_s / kDt));
  std::vector<Eigen::Vector2d> history(static_cast<size_t>(last + 1), s0);  // newest first
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-0.8, 0.8);
  std::uniform_int_distribution<int> hold(1, hold_max), slew(1, 60), level(-16, 16);
  Eigen::Vector2d s = s0;
  SearchCheck out;
  for (int segment = 0; segment < segments; ++segment) {
    const bool holding = segment % 2 == 0;
    const int steps = holding ? hold(rng) : slew(rng);
    const Eigen::Vector2d target(pos(rng), pos(rng));
    for (int i = 0; i < steps; ++i) {
      if (!holding) s += (target - s) / static_cast<double>(steps - i);
      t.push({0.0, 0.0}, s);
      history.insert(history.begin(), s);
      history.pop_back();
      if (i % every != 0) continue;
      for (int q = 0; q < 10; ++q) {
        const Eigen::Vector2d x(pos(rng), pos(rng));
        const double carry = random_carry ? std::exp2(level(rng) / 8.0) : 1.0;
        int expected = last;
        for (int k = 0; k < last; ++k) {
          const double r_mm = std::floor((x - history[static_cast<size_t>(k)]).norm() * 1e3);
          if (t.lag_steps(r_mm * 1e-3, carry) <= k) {
            expected = k;
            break;
          }
        }
        const int found = t.reached_steps(x, carry);
        EXPECT_EQ(found, expected) << "segment " << segment << " step " << i << " phi " << carry;
        if (found != expected) return out;
        ++out.checked;
        if (expected > 0 && expected < last) ++out.older;
        if (expected != t.reached_steps(x)) ++out.carried;
      }
    }
  }
  return out;
}

TEST(AirTransport, TheReachSearchFindsWhatTheDefinitionFindsOverHoldsAndSlews) {
  AirTransportParameters p;
  p.front_speed_mps = 1.3;
  p.max_lag_s = 0.6;  // 241 orientations kept
  const SearchCheck c = check_search(p, {0.2, -0.1}, 4242, 40, 300, 7, false);
  EXPECT_GT(c.checked, 1000);
  EXPECT_GT(c.older, c.checked / 4);  // most answers are neither the present nor the oldest
}

// The same with phi drawn per query (the carried front's tables).
TEST(AirTransport, TheReachSearchWithACarriedFrontFindsWhatTheDefinitionFinds) {
  AirTransportParameters p;
  p.front_speed_mps = 1.3;
  p.cfd_timing = false;
  p.max_lag_s = 0.6;
  const SearchCheck c = check_search(p, {0.0, 0.0}, 777, 30, 200, 5, true);
  EXPECT_GT(c.checked, 500);
  EXPECT_GT(c.carried, c.checked / 4);  // phi changes the answer in many queries
}

// The carried front's phi against its definition (sim/air_transport.h): the ratio of the times
// along the path at u_f + co max(w, 0) + counter min(w, 0) and at u_f, here with u_f uniform
// (1.5 m/s) or the start-up's piecewise one, and its limits.
TEST(AirTransport, TheCarriedFrontsFactorIsTheRatioOfItsTimesAlongThePath) {
  AirTransportParameters p;  // co-flow 1, counter-flow 0
  p.front_speed_mps = 1.5;
  p.cfd_timing = false;
  const AirTransport t(p, kDt, {0.0, 0.0});
  ASSERT_TRUE(t.carried());
  EXPECT_NEAR(t.front_speed_mps(0.3), 1.5, 1e-9);
  const std::vector<double> co(8, 1.5), against(8, -1.0);
  EXPECT_NEAR(t.carry_factor(co.data(), 8, 0.4), 0.5, 1e-10);       // 1.5 / (1.5 + 1.5)
  EXPECT_NEAR(t.carry_factor(against.data(), 8, 0.4), 1.0, 1e-10);  // counter-flow 0
  // Half the path with the air, half against: (1/3 + 1/1.5) / (2 / 1.5) = 0.75.
  const std::vector<double> half = {1.5, 1.5, -1.0, -1.0};
  EXPECT_NEAR(t.carry_factor(half.data(), 4, 0.4), 0.75, 1e-10);
  p.front_co_flow = 0.5;
  p.front_counter_flow = 0.5;
  const AirTransport u(p, kDt, {0.0, 0.0});
  EXPECT_NEAR(u.carry_factor(co.data(), 8, 0.4), 1.5 / 2.25, 1e-10);
  EXPECT_NEAR(u.carry_factor(against.data(), 8, 0.4), 1.5 / 1.0, 1e-10);
  // A front held back to a stall (at 5 cm/s) is capped at phi = 4; a carried one at 1/4.
  const std::vector<double> wall(8, -10.0), gale(8, 20.0);
  EXPECT_DOUBLE_EQ(u.carry_factor(wall.data(), 8, 0.4), 4.0);
  EXPECT_DOUBLE_EQ(u.carry_factor(gale.data(), 8, 0.4), 0.25);
  // Both weights 0: the still-air lag, phi 1 whatever the air.
  p.front_co_flow = p.front_counter_flow = 0.0;
  const AirTransport still(p, kDt, {0.0, 0.0});
  EXPECT_FALSE(still.carried());
  EXPECT_DOUBLE_EQ(still.carry_factor(co.data(), 8, 0.4), 1.0);
  // The start-up's front: 0.1 m in 0.05 s (2 m/s), then 0.4 m in 0.45 s (0.889 m/s). A path of
  // 0.2 m with 0.5 m/s of co-flow: (0.05 / 2.5 + 0.05 / 2.5 + 2 x 0.05 / 1.389) / (0.05 / 2 x 2
  // + 0.1 / 0.889).
  const CfdStartup startup(0.25, {0.1, 0.5}, {0.3, 0.75});
  const AirTransport cfd(AirTransportParameters{}, kDt, {0.0, 0.0}, &startup);
  EXPECT_NEAR(cfd.front_speed_mps(0.05), 2.0, 1e-9);
  EXPECT_NEAR(cfd.front_speed_mps(0.3), 0.4 / 0.45, 1e-9);
  const std::vector<double> breeze(4, 0.5);
  const double expected = (0.1 / 2.5 + 0.1 / (0.4 / 0.45 + 0.5)) / (0.1 / 2.0 + 0.1 / (0.4 / 0.45));
  EXPECT_NEAR(cfd.carry_factor(breeze.data(), 4, 0.2), expected, 1e-9);
}

TEST(AirTransport, BadParametersNameTheField) {
  AirTransportParameters p;
  p.front_speed_mps = -1.0;
  try {
    p.validate();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("air_transport.front_speed_mps"), std::string::npos);
  }
  p = AirTransportParameters{};
  p.max_lag_s = std::nan("");
  EXPECT_THROW(p.validate(), InputError);
  const std::pair<double AirTransportParameters::*, const char*> weights[] = {
      {&AirTransportParameters::front_co_flow, "air_transport.front_co_flow"},
      {&AirTransportParameters::front_counter_flow, "air_transport.front_counter_flow"}};
  for (const auto& [weight, field] : weights) {
    for (const double bad : {-0.1, 2.5, std::nan("")}) {
      p = AirTransportParameters{};
      p.*weight = bad;
      try {
        p.validate();
        ADD_FAILURE() << "no error for " << field << " " << bad;
      } catch (const FieldError& e) {
        EXPECT_EQ(e.field(), field);
      }
    }
  }
}

// A tracer 0.4 m downstream of the new s, upstream of the old one (1.4 m away, weak air): after
// the re-aim it starts moving when the new wall jet reaches it. The lag delays that by about
// r / U_front beside the rigid pattern, and twice as long at half the front speed; with the CFD's
// timings (cfd_timing), by the CFD start-up's lag at r, after the CFD's transit. The formation
// is off and the front is still air's (not carried): these check the lag alone.
double onset_s(double front_speed_mps, bool cfd_timing) {
  static const std::shared_ptr<const CfdField> cfd = testing::shipped_cfd();
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  TwinParameters p;
  p.air = AirForceParameters::none();
  p.scene.tracer.static_friction_ratio = 1.0;
  p.cfd_air = cfd;
  p.air_transport.front_speed_mps = front_speed_mps;
  p.air_transport.cfd_timing = cfd_timing;
  p.air_transport.formation = false;
  p.air_transport.front_co_flow = 0.0;
  p.initial_orientation = {kPi, deg_to_rad(22.5)};
  p.jet_on_at_start = true;
  SceneSpec spec;
  spec.objects = {{"t", "tracer", {0.9, 0.0}, 0.0}};
  Twin twin(spec, p, model, 5);
  twin.settle_jet();
  twin.advance(0.5);  // the old air, long established
  const Eigen::Vector2d p0 = twin.object_state(0).p_W;
  twin.command_nozzle({0.0, deg_to_rad(22.5)});
  while (twin.time() < 5.0) {
    twin.step();
    if ((twin.object_state(0).p_W - p0).norm() > 1e-3) return twin.time();
  }
  return 1e9;
}

TEST(AirTransport, InCfdAirAFarObjectMeetsTheNewAirItsTransportTimeLater) {
  const double rigid = onset_s(0.0, false), lag_15 = onset_s(1.5, false),
               lag_30 = onset_s(3.0, false);
  std::printf("onset after the re-aim: rigid %.3f s, U_front 3 m/s %.3f s, 1.5 m/s %.3f s\n", rigid,
              lag_30, lag_15);
  ASSERT_LT(rigid, 3.0);
  // r ~ 0.4 m from the new s: 0.27 s at 1.5 m/s, 0.13 s at 3 m/s. The sweep (pan 180 -> 0 deg
  // in ~0.45 s) moves s toward the tracer faster than either front, so the first air to arrive
  // is the final orientation's, lag(r) after the sweep ends; the rigid pattern already pushes
  // during the sweep's last ~30 deg (~0.075 s at 7 rad/s). So at least r / U_front later (less
  // two steps of rounding), at most 0.12 s beyond it.
  EXPECT_GE(lag_15 - rigid, 0.4 / 1.5 - 0.005);
  EXPECT_LE(lag_15 - rigid, 0.4 / 1.5 + 0.12);
  EXPECT_GE(lag_30 - rigid, 0.4 / 3.0 - 0.005);
  EXPECT_LE(lag_30 - rigid, 0.4 / 3.0 + 0.12);
}

TEST(AirTransport, TheCfdStartUpGivesTheTransitAndTheLag) {
  const CfdField& cfd = *testing::shipped_cfd();
  ASSERT_NE(cfd.startup(), nullptr);
  const CfdStartup& s = *cfd.startup();
  const double rigid = onset_s(0.0, false), rigid_cfd = onset_s(0.0, true),
               lag_cfd = onset_s(1.5, true);
  std::printf(
      "onset after the re-aim: rigid %.3f s, rigid with the CFD's transit %.3f s, the "
      "CFD's lag %.3f s\n",
      rigid, rigid_cfd, lag_cfd);
  // The transit replaces the 0.2 s delay: the same air, that much later (+- two 2.5 ms steps:
  // each onset is a whole step).
  EXPECT_NEAR(rigid_cfd - rigid, s.transit_s() - NozzleActuatorParameters{}.field_delay_s,
              2 * SceneParameters{}.timestep_s);
  // The wall jet's lag at the tracer's distance from the new s, r = 0.397 m. Every s the sweep
  // passes (pan 180 -> 0 deg at tilt 22.5 deg: a circle of radius 0.503 m about the origin) is at
  // least that far from the tracer, so the onset comes at least lag(r) later than the rigid one
  // (less two steps of rounding); at most 0.12 s more, as with U_front above.
  const double lag = s.wall_jet_lag_s(0.397);
  EXPECT_GE(lag_cfd - rigid_cfd, lag - 0.004);
  EXPECT_LE(lag_cfd - rigid_cfd, lag + 0.12);
  // U_front no longer counts.
  EXPECT_EQ(onset_s(3.0, true), lag_cfd);
}

// The wall jet's formation in the twin: a tracer held by friction 0.4 m from the new s. The
// nozzle jumps (servos 1000x the rig's) from pan 180 deg to 0 at tilt 22.5 deg. g(t) is the
// share of the change from the old orientation's air to the new one's that the tracer feels
// (AirForces::object_mean_air against the CFD's air of either orientation at the tracer). (A
// pulse, a jump there and back, is not checked here: the first air back then comes from a
// jump's two sides at once, which real servos never make; the pulses are checked against the
// CFD's in tests/models/wall_jet_formation_test.cc.)
struct Formed {
  std::vector<double> t_s, g;
  double r_m = 0.0;
  double command_s = 0.0;
};
Formed formed(double time_scale = 1.0) {
  static const std::shared_ptr<const CfdField> cfd = testing::shipped_cfd();
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  const NozzleOrientation a{kPi, deg_to_rad(22.5)}, b{0.0, deg_to_rad(22.5)};
  TwinParameters p;
  p.air = AirForceParameters::none();
  p.air.stagnation_pressure_pa = 0.0;
  // Held in place by static friction (MuJoCo's kinetic contacts alone let it creep): the air
  // alone changes.
  p.scene.tracer.kinetic_friction = 20.0;
  p.scene.tracer.static_friction_ratio = 2.0;
  p.cfd_air = cfd;
  p.air_transport.formation = true;
  p.air_transport.formation_time_scale = time_scale;
  p.air_transport.front_co_flow = 0.0;  // the start-up's front, as the definition
  p.nozzle.max_speed_radps = 7000.0;
  p.nozzle.max_acceleration_radps2 = 1e8;
  p.initial_orientation = a;
  p.jet_on_at_start = true;
  SceneSpec spec;
  spec.objects = {{"t", "tracer", {0.9, 0.0}, 0.0}};
  Twin twin(spec, p, model, 5);
  twin.settle_jet();
  twin.advance(2.5);  // the old air, long established
  Formed f;
  f.command_s = twin.time();
  twin.command_nozzle(b);
  while (twin.time() < f.command_s + 2.5) {
    twin.step();
    const Eigen::Vector2d x = twin.object_state(0).p_W;
    const double z = twin.data()->xipos[3 * twin.object(0).root_body + 2];
    const Eigen::Vector2d u = twin.air_forces().object_mean_air(0, x, z);
    const Eigen::Vector2d ua = twin.jet_level() * cfd->at(a, x, z).u_W;
    const Eigen::Vector2d ub = twin.jet_level() * cfd->at(b, x, z).u_W;
    f.t_s.push_back(twin.time() - f.command_s);
    f.g.push_back((u - ua).dot(ub - ua) / (ub - ua).squaredNorm());
    f.r_m = (x - cfd->stagnation_point(b)).norm();
  }
  return f;
}

TEST(AirTransport, TheNewAirFormsAtTheCfdPulsesRateAndArrivesWithTheStartUp) {
  const CfdField& cfd = *testing::shipped_cfd();
  ASSERT_NE(cfd.formation(), nullptr);
  auto first_above = [](const Formed& f, double level) {
    for (size_t i = 0; i < f.g.size(); ++i) {
      if (f.g[i] >= level) return f.t_s[i];
    }
    return 1e9;
  };
  // The pulses' formation, and the same at half their time (formation_time_scale 0.5).
  for (double scale : {1.0, 0.5}) {
    const Formed step = formed(scale);
    const double tau = scale * cfd.formation()->time_s(step.r_m);
    const double arrival = cfd.startup()->transit_s() + cfd.startup()->wall_jet_lag_s(step.r_m);
    const double half = first_above(step, 0.5), three_quarters = first_above(step, 0.75);
    std::printf(
        "tau x%.1f, step at r %.3f m: half at %.3f s (start-up's arrival %.3f s), 3/4 %.3f s "
        "later (tau ln 2 = %.3f s)\n",
        scale, step.r_m, half, arrival, three_quarters - half, tau * std::log(2.0));
    // Half the new air when the start-up's front is at half: the lag less ln 2 tau, plus the
    // first-order rise's ln 2 tau (the lag's rounding to a 2.5 ms step and the sampling: 3
    // steps).
    EXPECT_NEAR(half, arrival, 0.0075);
    // From a half to three quarters: one more ln 2 tau.
    EXPECT_NEAR(three_quarters - half, tau * std::log(2.0), 0.0075);
    EXPECT_NEAR(step.g.back(), 1.0, 1e-3);  // then the new air whole
  }
  AirTransportParameters bad;
  bad.formation_time_scale = 0.0;
  try {
    bad.validate();
    FAIL() << "no error";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "air_transport.formation_time_scale");
  }
}

}  // namespace
}  // namespace airtwin
