// The effects catalogue: parsing and its errors, what each effect sets, and for every effect a
// short twin run showing that it bends the trajectories the way its physics says.

#include "sim/effects.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/nozzle_geometry.h"
#include "tests/support/eq8_reference.h"

namespace airtwin {
namespace {

// ---------------------------------------------------------------------------------------------
// Parsing.

// Expects parse_effect(text) to throw an InputError whose message contains every one of `parts`
// (the library names the text, not a flag: app/ adds "--effect").
void expect_usage_error(const std::string& text, std::initializer_list<std::string> parts) {
  try {
    parse_effect(text);
    ADD_FAILURE() << "no InputError for '" << text << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const std::string& p : parts) {
      EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' missing from: " << what;
    }
  }
}

TEST(ParseEffect, NameAloneTakesTheDefaults) {
  const Effect e = parse_effect("floor_slope");
  EXPECT_EQ(e.name, "floor_slope");
  EXPECT_TRUE(e.params.empty());
  EXPECT_EQ(effect_parameter(e, "angle_deg"), 2.0);
  EXPECT_EQ(effect_parameter(e, "direction_deg"), 0.0);
  EXPECT_EQ(effect_to_string(e), "floor_slope:angle_deg=2,direction_deg=0");
}

TEST(ParseEffect, KeyValuesAsTyped) {
  const Effect e = parse_effect("nozzle_offset:tilt_deg=-1.5, pan_deg = 4");
  EXPECT_EQ(e.name, "nozzle_offset");
  ASSERT_EQ(e.params.size(), 2u);
  EXPECT_EQ(e.params[0].first, "tilt_deg");
  EXPECT_EQ(e.params[0].second, -1.5);
  EXPECT_EQ(e.params[1].first, "pan_deg");
  EXPECT_EQ(e.params[1].second, 4.0);
  // Partly typed: the rest from the defaults; the canonical text parses back to the same values.
  const Effect p = parse_effect("pressure_gradient:length=0.2");
  EXPECT_EQ(effect_parameter(p, "strength"), 4.0);
  EXPECT_EQ(effect_parameter(p, "length"), 0.2);
  const Effect again = parse_effect(effect_to_string(p));
  EXPECT_EQ(effect_parameter(again, "strength"), 4.0);
  EXPECT_EQ(effect_parameter(again, "length"), 0.2);
}

TEST(ParseEffect, UnknownNamesAndParametersListTheValidOnes) {
  expect_usage_error("field_scael:factor=1.3",
                     {"effect 'field_scael:factor=1.3'", "unknown effect 'field_scael'",
                      "field_scale", "pressure_gradient", "nozzle_offset"});
  expect_usage_error("floor_slope:angel_deg=3",
                     {"floor_slope", "no parameter 'angel_deg'", "angle_deg, direction_deg"});
  expect_usage_error("", {"expected NAME"});
  expect_usage_error("stiction:", {"expected key=value", "ratio"});
  expect_usage_error("stiction:ratio", {"expected key=value", "ratio"});
  expect_usage_error("field_scale:factor=1,3", {"expected key=value", "got '3'"});
  // An object type only on an object's own effect, and only a type the twin has.
  expect_usage_error("field_scale@tracer:factor=1.3",
                     {"field_scale acts on the rig", "without '@tracer'", "linearised_drag"});
  expect_usage_error("linearised_drag@glass", {"unknown object type 'glass'", "tracer or cotton"});
  expect_usage_error("air_lift@", {"air_lift@TYPE"});
  EXPECT_EQ(parse_effect("air_lift@cotton:lift_s2_per_m2=0.1").name, "air_lift@cotton");
}

TEST(ParseEffect, ValuesMustBeFiniteNumbersInRange) {
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "1e999", "", "1.3x", "x", "0x"}) {
    const std::string text = std::string("field_scale:factor=") + bad;
    expect_usage_error(text, {"field_scale", "factor", "must be a finite number in [0.05, 3]"});
  }
  expect_usage_error("stiction:ratio=0.5", {"stiction.ratio", "[1, 10]", "got 0.5"});
  expect_usage_error("floor_slope:angle_deg=45", {"floor_slope.angle_deg", "[0, 30] deg"});
  expect_usage_error("response_delay:tau_s=-0.1", {"response_delay.tau_s", "[0, 5] s"});
  expect_usage_error("field_scale:factor=0", {"[0.05, 3]"});
  expect_usage_error("pressure_gradient:length=0", {"pressure_gradient.length", "[0.01, 1] m"});
  EXPECT_NO_THROW(parse_effect("field_scale:factor=3"));
}

TEST(ParseEffect, DuplicatesAreRejected) {
  expect_usage_error("floor_slope:angle_deg=1,angle_deg=2", {"'angle_deg'", "given twice"});
  TwinParameters p;
  EXPECT_THROW(
      apply_effects({parse_effect("field_scale"), parse_effect("field_scale:factor=2")}, &p),
      InputError);
  // An Effect built in code is checked the same way.
  Effect e{"stiction", {{"ratio", 2.0}, {"ratio", 3.0}}};
  EXPECT_THROW(apply_effect(e, &p), InputError);
  e = Effect{"stiction", {{"ratio", std::nan("")}}};
  EXPECT_THROW(apply_effect(e, &p), InputError);
}

TEST(EffectCatalogue, OneLinePerEffectWithUnitsAndDefaults) {
  const std::string text = effect_help();
  int lines = 0;
  for (char c : text) lines += c == '\n';
  EXPECT_EQ(lines, static_cast<int>(kEffectCount) + 1);  // and the objects' own, NAME@TYPE
  for (const char* needle : {"pressure_gradient",
                             "strength=4 [0, 50] m/s^2",
                             "length=0.15 [0.01, 1] m",
                             "response_delay",
                             "tau_s=0.3",
                             "flow_deflection",
                             "angle_deg=15",
                             "quadratic_drag",
                             "coefficient=0.5",
                             "1/m",
                             "floor_slope",
                             "direction_deg=0",
                             "stiction",
                             "ratio=2",
                             "nozzle_offset",
                             "pan_deg=3",
                             "tilt_deg=2",
                             "field_scale",
                             "factor=1.2",
                             "transport_lag",
                             "pace_s_per_m=0.6 [0, 5] s/m",
                             "NAME@TYPE"}) {
    EXPECT_NE(text.find(needle), std::string::npos) << needle << " missing from\n" << text;
  }
}

TEST(ApplyEffect, SetsTheDocumentedFieldsInSi) {
  TwinParameters p;
  const TwinParameters nominal;
  apply_effects(
      {parse_effect("pressure_gradient:strength=6,length=0.1"),
       parse_effect("response_delay:tau_s=0.5"), parse_effect("flow_deflection:angle_deg=-30"),
       parse_effect("quadratic_drag:coefficient=0.8"),
       parse_effect("floor_slope:angle_deg=3,direction_deg=90"), parse_effect("stiction:ratio=2.5"),
       parse_effect("nozzle_offset:pan_deg=-2"), parse_effect("field_scale:factor=1.3"),
       parse_effect("transport_lag:pace_s_per_m=0.8"), parse_effect("air_lift:lift_s2_per_m2=0.07"),
       parse_effect("linearised_drag@tracer:intercept_share=0.3"),
       parse_effect("linearised_drag:intercept_share=0.2")},
      &p);
  EXPECT_EQ(p.air.extra_push_mps2, 6.0);
  EXPECT_EQ(p.air.extra_push_length_m, 0.1);
  EXPECT_DOUBLE_EQ(p.nozzle.response_delay_s, nominal.nozzle.response_delay_s + 0.5);
  EXPECT_DOUBLE_EQ(p.nozzle.field_delay_s, nominal.nozzle.field_delay_s);
  EXPECT_DOUBLE_EQ(p.air.flow_deflection_rad, deg_to_rad(-30));
  EXPECT_EQ(p.scene.tracer.extra_quadratic_drag_per_m, 0.8);  // an object's own: every type's
  EXPECT_EQ(p.scene.cotton.extra_quadratic_drag_per_m, 0.8);
  EXPECT_DOUBLE_EQ(p.scene.floor_slope_rad, deg_to_rad(3));
  EXPECT_DOUBLE_EQ(p.scene.floor_slope_direction_rad, deg_to_rad(90));
  EXPECT_EQ(p.scene.tracer.static_friction_ratio, 2.5);
  EXPECT_EQ(p.scene.cotton.static_friction_ratio, 2.5);
  EXPECT_DOUBLE_EQ(p.nozzle.pan_offset_rad, deg_to_rad(-2));
  EXPECT_DOUBLE_EQ(p.nozzle.tilt_offset_rad, deg_to_rad(2));  // the default of the other key
  EXPECT_EQ(p.air.field_scale, 1.3);
  EXPECT_DOUBLE_EQ(p.air_transport.front_speed_mps, 1.25);
  EXPECT_EQ(p.air_transport.max_lag_s, kMaxTransportLagS);
  EXPECT_FALSE(p.air_transport.cfd_timing);
  EXPECT_FALSE(p.air_transport.formation);
  EXPECT_EQ(p.air_transport.front_co_flow, 0.0);
  EXPECT_EQ(p.air_transport.front_counter_flow, 0.0);
  EXPECT_TRUE(p.analytical_air_transport);
  EXPECT_FALSE(nominal.analytical_air_transport);
  EXPECT_EQ(p.scene.tracer.extra_lift_s2pm2, 0.07);
  EXPECT_EQ(p.scene.cotton.extra_lift_s2pm2, 0.07);
  EXPECT_EQ(nominal.scene.tracer.extra_lift_s2pm2, 0.0);
  // One type's own on top of every type's, whatever the order typed.
  EXPECT_EQ(p.scene.tracer.drag_intercept_share, 0.3);
  EXPECT_EQ(p.scene.cotton.drag_intercept_share, 0.2);
  // Nothing else moved.
  EXPECT_EQ(p.air.stagnation_pressure_pa, nominal.air.stagnation_pressure_pa);
  EXPECT_EQ(p.scene.tracer.kinetic_friction, nominal.scene.tracer.kinetic_friction);
  EXPECT_EQ(p.scene.timestep_s, nominal.scene.timestep_s);
}

// ---------------------------------------------------------------------------------------------
// Physics: short twin runs, each against the nominal twin or an independent truth.

const AirFieldModel& field_model() {
  static const AirFieldModel model = AirFieldModel::with_constructed_table();
  return model;
}

// Deterministic drag only (no turbulence, no push, static = kinetic), jet running steadily.
TwinParameters quiet(const NozzleOrientation& o = {0.0, 0.0}) {
  TwinParameters p;
  p.air = AirForceParameters::none();
  p.scene.tracer.static_friction_ratio = 1.0;
  p.initial_orientation = o;
  p.jet_on_at_start = true;
  return p;
}

TwinParameters with(TwinParameters p, const std::string& effect) {
  apply_effect(parse_effect(effect), &p);
  return p;
}

SceneSpec one_tracer(const Eigen::Vector2d& p_W) {
  SceneSpec spec;
  spec.objects = {{"t", "tracer", p_W, 0.0}};
  return spec;
}

// The fixture turns MuJoCo warnings into failures (STYLE.md).
class EffectPhysics : public ::testing::Test {
 protected:
  // A tracer at p_W in a steady jet for `duration_s`: its positions every `sample_s`.
  std::vector<ObjectMotion> run(const TwinParameters& p, const Eigen::Vector2d& p_W,
                                double duration_s, double sample_s = 0.025) {
    Twin twin(one_tracer(p_W), p, field_model(), 3);
    twin.settle_jet();
    std::vector<ObjectMotion> out{twin.object_state(0)};
    const int n = static_cast<int>(std::lround(duration_s / sample_s));
    for (int i = 1; i <= n; ++i) {
      twin.advance_to(i * sample_s);
      out.push_back(twin.object_state(0));
    }
    EXPECT_EQ(twin.warning_count(), 0) << twin.last_warning();
    return out;
  }
  // A tracer at `at` under the jet blowing from far away (s at ~1.3 m on the -x side: too weak
  // to move it); at t = 0.1 s the nozzle is re-aimed straight down (s at the origin). When the
  // tracer starts (moved 2 mm; 99 if not within 3 s).
  double onset_after_reaim(const TwinParameters& p, const Eigen::Vector2d& at) {
    Twin twin(one_tracer(at), p, field_model(), 4);
    twin.settle_jet();
    const Eigen::Vector2d p0 = twin.object_state(0).p_W;
    twin.advance(0.1);
    EXPECT_LT((twin.object_state(0).p_W - p0).norm(), 1e-3);
    twin.command_nozzle({kPi, 0.0});
    while (twin.time() < 3.0) {
      twin.step();
      if ((twin.object_state(0).p_W - p0).norm() > 0.002) return twin.time();
    }
    return 99.0;
  }
};

// The largest gap between the tracer's distance from s and an eq. (8) reference's, per sample.
double worst_distance_gap(const std::vector<ObjectMotion>& motion, const Eigen::Vector2d& s,
                          const std::vector<double>& truth) {
  EXPECT_EQ(motion.size(), truth.size());
  double worst = 0.0;
  for (size_t i = 0; i < std::min(motion.size(), truth.size()); ++i) {
    worst = std::max(worst, std::abs((motion[i].p_W - s).norm() - truth[i]));
  }
  return worst;
}

double angle_between(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));  // from a to b, CCW +
}

TEST_F(EffectPhysics, FieldScaleDrivesFartherAsEquationEightWithTheScaledSpeed) {
  const Eigen::Vector2d start(0.35, 0.1);
  const std::vector<ObjectMotion> nominal = run(quiet(), start, 1.5);
  const std::vector<ObjectMotion> scaled = run(with(quiet(), "field_scale:factor=1.3"), start, 1.5);
  const OrientedField field = field_model().at({0.0, 0.0});
  const std::vector<double> truth = testing::eq8_ray_reference(
      field, quiet().scene.tracer.dynamics(), scaled.front().p_W, 1.5, 0.025, {.air_scale = 1.3});
  const double worst = worst_distance_gap(scaled, field.stagnation_point(), truth);
  const double travel_nominal = (nominal.back().p_W - nominal.front().p_W).norm();
  const double travel_scaled = (scaled.back().p_W - scaled.front().p_W).norm();
  EXPECT_GT(travel_scaled, travel_nominal + 0.1);
  // The same agreement the nominal twin has with eq. (8) (twin_test): 4 % of the travel + 2 mm.
  EXPECT_LT(worst, 0.04 * (truth.back() - truth.front()) + 0.002);
}

TEST_F(EffectPhysics, FloorSlopeSlidesDownhillAtGSinMinusMuGCos) {
  // Jet off, a slippery tracer (mu_k 0.05, no stiction): on a 5 deg slope toward 30 deg it slides
  // down with a = g (sin 5 - 0.05 cos 5) = 0.366 m/s^2; on the level floor it stays.
  for (const bool sloped : {false, true}) {
    TwinParameters p;
    p.air = AirForceParameters::none();
    p.scene.tracer.kinetic_friction = 0.05;
    p.scene.tracer.static_friction_ratio = 1.0;
    p.settle_time_s = 0.0;
    if (sloped) p = with(p, "floor_slope:angle_deg=5,direction_deg=30");
    Twin twin(one_tracer({0.2, -0.3}), p, field_model(), 1);
    twin.advance(0.05);  // landed from its 0.2 mm drop
    const ObjectMotion a = twin.object_state(0);
    twin.advance(0.6);
    const ObjectMotion b = twin.object_state(0);
    const Eigen::Vector2d moved = b.p_W - a.p_W;
    EXPECT_EQ(twin.warning_count(), 0);
    if (!sloped) {
      EXPECT_LT(moved.norm(), 1e-3);
      continue;
    }
    const double g = 9.81, th = deg_to_rad(5), mu = 0.05;
    const double accel = g * (std::sin(th) - mu * std::cos(th));
    const Eigen::Vector2d downhill(std::cos(deg_to_rad(30)), std::sin(deg_to_rad(30)));
    const double expected = a.v_W.dot(downhill) * 0.6 + 0.5 * accel * 0.36;
    EXPECT_NEAR(moved.norm(), expected, 0.1 * expected);
    EXPECT_LT(std::abs(angle_between(downhill, moved)), deg_to_rad(2));
  }
}

TEST_F(EffectPhysics, FloorSlopeBendsAnAirDrivenSlideDownhill) {
  // The paper's tracer (mu_k 0.87) never slides on 3 deg alone, but while the jet drives it along
  // +x, a slope toward +y pulls it off its ray toward +y.
  const Eigen::Vector2d start(0.3, 0.0);
  const std::vector<ObjectMotion> flat = run(quiet(), start, 1.0);
  const std::vector<ObjectMotion> tilted =
      run(with(quiet(), "floor_slope:angle_deg=3,direction_deg=90"), start, 1.0);
  const double drift_flat = flat.back().p_W.y() - flat.front().p_W.y();
  const double drift_tilted = tilted.back().p_W.y() - tilted.front().p_W.y();
  std::printf("floor_slope 3 deg: drift toward +y %.1f mm (level floor: %.1f mm)\n",
              drift_tilted * 1e3, drift_flat * 1e3);
  EXPECT_LT(std::abs(drift_flat), 0.005);  // the disc's wobble (twin_test: off-ray < 5 mm)
  EXPECT_GT(drift_tilted, drift_flat + 0.01);
}

TEST_F(EffectPhysics, NozzleOffsetMovesTheStagnationPointByEquationsOneAndTwo) {
  const NozzleOrientation command{0.5, deg_to_rad(20)};
  const NozzleOrientation biased{0.5 + deg_to_rad(5), deg_to_rad(23)};
  TwinParameters p = with(quiet(command), "nozzle_offset:pan_deg=5,tilt_deg=3");
  const NozzleGeometry geometry = field_model().geometry();
  const Eigen::Vector2d s_biased = stagnation_point(geometry, biased);
  const Eigen::Vector2d s_nominal = stagnation_point(geometry, command);
  ASSERT_GT((s_biased - s_nominal).norm(), 0.05);
  // A tracer 0.3 m from the biased s, 30 deg off the line between the two stagnation points.
  const Eigen::Vector2d from =
      Eigen::Rotation2Dd(deg_to_rad(30)) * (s_nominal - s_biased).normalized();
  Twin twin(one_tracer(s_biased + 0.3 * from), p, field_model(), 2);
  twin.settle_jet();
  const Eigen::Vector2d p0 = twin.object_state(0).p_W;
  twin.advance(0.5);
  // The recorded command is the command; the nozzle and the air follow command + offset.
  EXPECT_EQ(twin.commanded_orientation().pan_rad, command.pan_rad);
  EXPECT_EQ(twin.commanded_orientation().tilt_rad, command.tilt_rad);
  EXPECT_DOUBLE_EQ(twin.actual_orientation().tilt_rad, biased.tilt_rad);
  EXPECT_LT((twin.field().stagnation_point() - s_biased).norm(), 1e-12);
  // The tracer leaves radially from the biased s, not from the commanded one.
  const Eigen::Vector2d moved = twin.object_state(0).p_W - p0;
  ASSERT_GT(moved.norm(), 0.05);
  EXPECT_LT(std::abs(angle_between(p0 - s_biased, moved)), deg_to_rad(2));
  EXPECT_GT(std::abs(angle_between(p0 - s_nominal, moved)), deg_to_rad(5));
  // A later command is biased the same way.
  twin.command_nozzle({-1.0, deg_to_rad(10)});
  twin.advance(1.0);
  EXPECT_DOUBLE_EQ(twin.actual_orientation().pan_rad, -1.0 + deg_to_rad(5));
  EXPECT_DOUBLE_EQ(twin.effective_orientation().tilt_rad, deg_to_rad(13));
  EXPECT_EQ(twin.warning_count(), 0);
}

TEST_F(EffectPhysics, FlowDeflectionTurnsTheMotionFromRadial) {
  const Eigen::Vector2d start(0.3, 0.0);  // tilt 0: s at the origin, radial = +x
  const std::vector<ObjectMotion> nominal = run(quiet(), start, 0.15);
  const std::vector<ObjectMotion> turned =
      run(with(quiet(), "flow_deflection:angle_deg=20"), start, 0.15);
  const Eigen::Vector2d s = field_model().at({0.0, 0.0}).stagnation_point();
  const ObjectMotion n = nominal.back(), t = turned.back();
  ASSERT_GT(t.v_W.norm(), 0.2);
  EXPECT_LT(std::abs(angle_between(n.p_W - s, n.v_W)), deg_to_rad(1));
  // Counter-clockwise positive: the velocity is 20 deg off the radial at its current position.
  EXPECT_NEAR(rad_to_deg(angle_between(t.p_W - s, t.v_W)), 20.0, 2.0);
}

TEST_F(EffectPhysics, ResponseDelayStartsTheMotionLaterByTau) {
  // The tracer starts when the field follows the re-aim.
  const TwinParameters p = quiet({kPi, deg_to_rad(40)});
  const Eigen::Vector2d at(0.3, 0.0);
  const double nominal = onset_after_reaim(p, at);
  const double delayed = onset_after_reaim(with(p, "response_delay:tau_s=0.5"), at);
  ASSERT_LT(nominal, 1.0);
  EXPECT_NEAR(delayed - nominal, 0.5, 0.02);
}

TEST_F(EffectPhysics, TransportLagStartsATracerLaterByPaceTimesItsDistanceFromTheNewS) {
  // The re-aim's air spreads from the new s at 1 / pace: a tracer r from it starts pace r later
  // than in the rigid field. Servos that turn in a few steps: the orientations of a slow turn
  // would reach the tracer each at its own lag, and one of them, not the last, may start it.
  TwinParameters p = quiet({kPi, deg_to_rad(40)});
  p.nozzle.max_speed_radps = 1e3;
  p.nozzle.max_acceleration_radps2 = 1e7;
  for (const Eigen::Vector2d& at : {Eigen::Vector2d(0.3, 0.0), Eigen::Vector2d(0.0, 0.45)}) {
    const double nominal = onset_after_reaim(p, at);
    const double lagged = onset_after_reaim(with(p, "transport_lag:pace_s_per_m=1.5"), at);
    ASSERT_LT(nominal, 1.0);
    // Within a few of the twin's 2 ms steps: the lag's rounding to a half step and the onset's
    // 2 mm test each take one or two (2 % of the lag).
    EXPECT_NEAR(lagged - nominal, 1.5 * at.norm(), 0.01) << at.transpose();
  }
}

TEST_F(EffectPhysics, QuadraticDragAddsCTimesTheSquaredRelativeSpeed) {
  // From rest, the extra acceleration is C |u - v| (u - v) ~ C u^2 along u; over the first 20 ms
  // (v << u) the speed gained beyond the nominal is ~ C u^2 * 20 ms. Later it drives farther.
  const Eigen::Vector2d start(0.3, 0.0);
  const std::vector<ObjectMotion> nominal = run(quiet(), start, 1.0, 0.02);
  const std::vector<ObjectMotion> quadratic =
      run(with(quiet(), "quadratic_drag:coefficient=0.5"), start, 1.0, 0.02);
  const double u = field_model().at({0.0, 0.0}).speed(nominal.front().p_W);
  const double gained = quadratic[1].v_W.norm() - nominal[1].v_W.norm();
  EXPECT_NEAR(gained, 0.5 * u * u * 0.02, 0.25 * 0.5 * u * u * 0.02);
  EXPECT_GT((quadratic.back().p_W - start).norm(), (nominal.back().p_W - start).norm() + 0.02);
}

TEST_F(EffectPhysics, AirLiftSlidesAsEquationEightWithTheFrictionItLeaves) {
  // The lift k m g |u - v|^2 unloads MuJoCo's contact: the slide follows eq. (8) with friction
  // xi3 max(0, 1 - k (u - v)^2), within the nominal twin's agreement with eq. (8), and reaches
  // farther than without it.
  const Eigen::Vector2d start(0.35, 0.1);
  const std::vector<ObjectMotion> nominal = run(quiet(), start, 1.5);
  const std::vector<ObjectMotion> lifted =
      run(with(quiet(), "air_lift:lift_s2_per_m2=0.06"), start, 1.5);
  const OrientedField field = field_model().at({0.0, 0.0});
  const std::vector<double> truth = testing::eq8_ray_reference(
      field, quiet().scene.tracer.dynamics(), lifted.front().p_W, 1.5, 0.025, {.lift_s2pm2 = 0.06});
  const double worst = worst_distance_gap(lifted, field.stagnation_point(), truth);
  const double travel_nominal = (nominal.back().p_W - nominal.front().p_W).norm();
  const double travel_lifted = (lifted.back().p_W - lifted.front().p_W).norm();
  std::printf(
      "air_lift 0.06 s^2/m^2: travel %.1f cm (without %.1f), eq. (8) with it %.1f cm, "
      "worst %.1f mm\n",
      travel_lifted * 100, travel_nominal * 100, (truth.back() - truth.front()) * 100, worst * 1e3);
  EXPECT_GT(travel_lifted, travel_nominal + 0.05);
  EXPECT_LT(worst, 0.04 * (truth.back() - truth.front()) + 0.002);
}

TEST_F(EffectPhysics, LinearisedDragSlidesAsTheQuadraticItIsTheTangentOf) {
  // With 60 % of the friction the intercept of a tangent at w0 = 2 0.6 |xi3| / c = 3.5 m/s: below
  // |k u - v| = w0 the drag follows (c / 2 w0) |w| w, above it c |w| - 0.6 |xi3|, and the contact
  // keeps 40 % of the friction. The slide follows eq. (8) so bent, within the nominal twin's
  // agreement with eq. (8), and reaches farther than without it (the quadratic lies above its
  // tangent everywhere but at w0).
  const Eigen::Vector2d start(0.35, 0.1);
  const std::vector<ObjectMotion> nominal = run(quiet(), start, 1.5);
  const std::vector<ObjectMotion> bent =
      run(with(quiet(), "linearised_drag:intercept_share=0.6"), start, 1.5);
  const OrientedField field = field_model().at({0.0, 0.0});
  const std::vector<double> truth =
      testing::eq8_ray_reference(field, quiet().scene.tracer.dynamics(), bent.front().p_W, 1.5,
                                 0.025, {.intercept_share = 0.6});
  const double worst = worst_distance_gap(bent, field.stagnation_point(), truth);
  const double travel_nominal = (nominal.back().p_W - nominal.front().p_W).norm();
  const double travel_bent = (bent.back().p_W - bent.front().p_W).norm();
  std::printf(
      "linearised_drag 0.6: travel %.1f cm (without %.1f), eq. (8) bent %.1f cm, worst %.1f mm\n",
      travel_bent * 100, travel_nominal * 100, (truth.back() - truth.front()) * 100, worst * 1e3);
  EXPECT_GT(travel_bent, travel_nominal + 0.02);
  EXPECT_LT(worst, 0.04 * (truth.back() - truth.front()) + 0.002);
}

TEST_F(EffectPhysics, LinearisedDragRefusesThePhysicalLaw) {
  // The physical law's drag is quadratic already: one error naming the law and the object.
  TwinParameters physical = with(quiet(), "linearised_drag:intercept_share=0.5");
  physical.scene.tracer.use_physical_drag();
  try {
    run(physical, {0.35, 0.1}, 0.1);
    ADD_FAILURE() << "the physical law was bent";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has the physical drag law"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("object '"), std::string::npos) << e.what();
  }
}

TEST_F(EffectPhysics, StictionHoldsATracerThatSlidesNominally) {
  // Where the drive of eq. (8) is 0.6 mu_k g: above the default static limit (1.2 mu_k), below
  // stiction 3's (3 mu_k).
  const OrientedField field = field_model().at({0.0, 0.0});
  double r = 0.2;
  while (r < 1.5 && kTracerDynamics.drive(field.speed({r, 0.0})) > 0.6 * -kTracerDynamics.xi3) {
    r += 0.002;
  }
  ASSERT_LT(r, 1.5);
  TwinParameters p = quiet();
  p.scene.tracer.static_friction_ratio = TwinParameters{}.scene.tracer.static_friction_ratio;
  const std::vector<ObjectMotion> nominal = run(p, {r, 0.0}, 1.0);
  const std::vector<ObjectMotion> sticky = run(with(p, "stiction:ratio=3"), {r, 0.0}, 1.0);
  EXPECT_GT((nominal.back().p_W - nominal.front().p_W).norm(), 0.02);
  EXPECT_LT((sticky.back().p_W - sticky.front().p_W).norm(), 0.005);
}

TEST_F(EffectPhysics, PressureGradientPushesOutwardNearS) {
  // 10 cm from s, where the extra push (length 0.15 m) is near its peak, the tracer is pushed out
  // farther; at 0.8 m, where exp(-(r/l)^2) ~ 5e-13, nothing changes.
  const std::vector<ObjectMotion> nominal = run(quiet(), {0.1, 0.0}, 0.5);
  const std::vector<ObjectMotion> pushed =
      run(with(quiet(), "pressure_gradient:strength=8,length=0.15"), {0.1, 0.0}, 0.5);
  const double out_nominal = nominal.back().p_W.x() - nominal.front().p_W.x();
  const double out_pushed = pushed.back().p_W.x() - pushed.front().p_W.x();
  EXPECT_GT(out_pushed, out_nominal + 0.02);
  EXPECT_LT(std::abs(pushed.back().p_W.y()), 0.003);
  const std::vector<ObjectMotion> far_nominal = run(quiet(), {0.8, 0.0}, 0.3);
  const std::vector<ObjectMotion> far_pushed =
      run(with(quiet(), "pressure_gradient:strength=8,length=0.15"), {0.8, 0.0}, 0.3);
  EXPECT_LT((far_pushed.back().p_W - far_nominal.back().p_W).norm(), 1e-6);
}

}  // namespace
}  // namespace airtwin
