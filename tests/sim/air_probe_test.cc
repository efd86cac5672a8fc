// The twin's air at fixed points over a nozzle program: against the CFD's steady air when held,
// against the start-up's arrival and the pulses' formation time after a jump (the definitions
// the twin's transport and formation take, sim/air_transport.h), against the twin's own object
// at the same point, and its readers' one-line errors.

#include "sim/air_probe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "common/errors.h"
#include "common/units.h"
#include "sim/twin.h"

namespace airtwin {
namespace {

const std::shared_ptr<const CfdField>& cfd() {
  static const auto f =
      std::make_shared<const CfdField>(CfdField::read_dir(AIRTWIN_SOURCE_DIR "/data/cfd"));
  return f;
}

TEST(AirProbe, AHeldNozzleGivesTheCfdsSteadyAir) {
  const NozzleOrientation o{deg_to_rad(30.0), deg_to_rad(22.5)};
  const std::vector<ProgramKnot> program = {{0.0, o}};
  const std::vector<ProbePoint> points = {{{0.5, 0.3}, 0.015}, {{-0.2, 0.1}, 0.004}};
  AirTransportParameters params;
  params.formation = true;
  AirProbeSettings s;
  s.end_s = 0.1;
  const AirProbeRecord r = probe_air(*cfd(), params, program, points, s);
  ASSERT_EQ(r.t_s.size(), 11u);
  EXPECT_DOUBLE_EQ(r.t_s.back(), 0.1);
  for (size_t k = 0; k < r.t_s.size(); ++k) {
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d u = cfd()->at(o, points[i].p_W, points[i].z_m).u_W;
      EXPECT_EQ(r.u_W[k][i], u) << "record " << k << ", point " << i;
    }
  }
}

// A jump of the nozzle (pan 180 -> 0 deg at tilt 22.5 deg within one step) and a point 0.4 m
// from the new s: g(t), the share of the change from the old air to the new one, reaches half
// when the start-up's front does (transit + its wall-jet lag there) and three quarters one
// ln 2 tau(r) later, tau the pulses' formation time there times the scale.
struct Jump {
  std::vector<double> t_s, g;
  double r_m = 0.0;
};
const NozzleOrientation kFrom{kPi, deg_to_rad(22.5)}, kTo{0.0, deg_to_rad(22.5)};
const ProbePoint kPoint{{0.9, 0.0}, 0.0085};

Jump jump(double time_scale) {
  const std::vector<ProgramKnot> program = {{0.0, kFrom}, {0.0025, kTo}};
  AirTransportParameters params;
  params.formation = true;
  params.formation_time_scale = time_scale;
  AirProbeSettings s;
  s.interval_s = s.timestep_s;
  s.end_s = 2.0;
  const AirProbeRecord r = probe_air(*cfd(), params, program, {kPoint}, s);
  const Eigen::Vector2d ua = cfd()->at(kFrom, kPoint.p_W, kPoint.z_m).u_W;
  const Eigen::Vector2d ub = cfd()->at(kTo, kPoint.p_W, kPoint.z_m).u_W;
  Jump j;
  j.r_m = (kPoint.p_W - cfd()->stagnation_point(kTo)).norm();
  for (size_t k = 0; k < r.t_s.size(); ++k) {
    j.t_s.push_back(r.t_s[k]);
    j.g.push_back((r.u_W[k][0] - ua).dot(ub - ua) / (ub - ua).squaredNorm());
  }
  return j;
}

double first_above(const Jump& j, double level) {
  for (size_t i = 0; i < j.g.size(); ++i) {
    if (j.g[i] >= level) return j.t_s[i];
  }
  return 1e9;
}

TEST(AirProbe, AfterAJumpTheAirArrivesWithTheStartUpAndFormsAtThePulsesRate) {
  ASSERT_NE(cfd()->startup(), nullptr);
  ASSERT_NE(cfd()->formation(), nullptr);
  for (double scale : {1.0, 0.25}) {
    const Jump j = jump(scale);
    const double arrival = cfd()->startup()->transit_s() + cfd()->startup()->wall_jet_lag_s(j.r_m);
    const double tau = scale * cfd()->formation()->time_s(j.r_m);
    const double half = first_above(j, 0.5), three_quarters = first_above(j, 0.75);
    std::printf(
        "tau x%.2f at r %.3f m: half at %.4f s (arrival %.4f s), 3/4 %.4f s later "
        "(ln 2 tau %.4f s)\n",
        scale, j.r_m, half, arrival, three_quarters - half, std::log(2.0) * tau);
    EXPECT_NEAR(j.g.front(), 0.0, 1e-12);  // the old air until the new one arrives
    // The lag's rounding to a step, the program's one-step jump and the sampling: 3 steps.
    EXPECT_NEAR(half, arrival, 0.0075);
    EXPECT_NEAR(three_quarters - half, std::log(2.0) * tau, 0.0075);
    EXPECT_NEAR(j.g.back(), 1.0, 1e-3);
  }
}

// The probe and the twin's own object at the same point feel the same air: a tracer held by
// friction where the probe is, the nozzle jumping (servos 1000x the rig's) as above.
TEST(AirProbe, FeelsWhatTheTwinsObjectThereFeels) {
  static const AirFieldModel model = AirFieldModel::with_default_table();
  TwinParameters p;
  p.air = AirForceParameters::none();
  p.air.stagnation_pressure_pa = 0.0;
  p.scene.tracer.kinetic_friction = 20.0;
  p.cfd_air = cfd();
  p.air_transport.formation = true;
  p.nozzle.max_speed_radps = 7000.0;
  p.nozzle.max_acceleration_radps2 = 1e8;
  p.initial_orientation = kFrom;
  p.jet_on_at_start = true;
  SceneSpec spec;
  spec.objects = {{"t", "tracer", kPoint.p_W, 0.0}};
  Twin twin(spec, p, model, 5);
  twin.settle_jet();
  twin.advance(2.5);
  // Where the twin looks up the object's air (sim/twin.cc): its root body's origin, its centre
  // of mass's height.
  const int body = twin.object(0).root_body;
  const Eigen::Vector2d x(twin.data()->xpos[3 * body], twin.data()->xpos[3 * body + 1]);
  const double z = twin.data()->xipos[3 * body + 2];
  const double t0 = twin.time();
  twin.command_nozzle(kTo);
  // The servos' path (they take a step or two to turn) is the probe's program.
  std::vector<ProgramKnot> program = {{0.0, twin.actual_orientation()}};
  std::vector<Eigen::Vector2d> felt;
  while (twin.time() < t0 + 1.5 - 1e-9) {
    twin.step();
    const Eigen::Vector2d at(twin.data()->xpos[3 * body], twin.data()->xpos[3 * body + 1]);
    ASSERT_LT((at - x).norm(), 1e-6) << "the tracer moved";
    program.push_back({twin.time() - t0, twin.actual_orientation()});
    felt.push_back(twin.air_forces().object_mean_air(0, x, z) / twin.jet_level());
  }
  AirTransportParameters params;
  params.formation = true;
  AirProbeSettings s;
  s.interval_s = s.timestep_s;
  s.end_s = 1.5;
  const AirProbeRecord r = probe_air(*cfd(), params, program, {{x, z}}, s);
  ASSERT_EQ(r.t_s.size(), felt.size() + 1);
  double worst = 0.0, change = 0.0;
  for (size_t k = 0; k < felt.size(); ++k) {
    worst = std::max(worst, (felt[k] - r.u_W[k + 1][0]).norm());
    change = std::max(change, (felt[k] - felt.front()).norm());
  }
  std::printf("the air changed by %.2f m/s; the probe and the twin's object differ by %.1e m/s\n",
              change, worst);
  ASSERT_GT(change, 1.0);
  // The same code, steps and orientations (the transit in whole steps in both): nothing but
  // rounding differs.
  EXPECT_LT(worst, 1e-9);
}

std::string write(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

TEST(AirProbe, ReadersNameTheLineAndColumnOfBadInput) {
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string back = write("back.csv", "t_s,pan_deg,tilt_deg\n0,0,10\n0.5,0,20\n0.4,0,30\n");
  EXPECT_NE(message([&] { read_nozzle_program(back); }).find("back.csv:4: column 't_s'"),
            std::string::npos);
  const std::string tilt = write("tilt.csv", "t_s,pan_deg,tilt_deg\n0,0,95\n");
  EXPECT_NE(message([&] { read_nozzle_program(tilt); }).find("tilt.csv:2: column 'tilt_deg'"),
            std::string::npos);
  const std::string high = write("high.csv", "x_m,y_m,z_m\n0.1,0.2,0.015\n0.1,0.2,0.5\n");
  EXPECT_NE(message([&] { read_probe_points(high); }).find("high.csv:3: column 'z_m'"),
            std::string::npos);
  const std::string ok = write("ok.csv", "x_m,y_m\n0.1,0.2\n");
  EXPECT_DOUBLE_EQ(read_probe_points(ok).front().z_m, 0.015);
  AirProbeSettings s;
  s.interval_s = 0.004;  // not a whole number of 2.5 ms steps
  try {
    s.validate();
    FAIL() << "expected an error";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "air_probe.interval_s");
  }
}

}  // namespace
}  // namespace airtwin
