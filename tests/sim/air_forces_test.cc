// Air forces through the one mjcb_passive: the drag law on a free body, the pressure push, and the
// dispatch rules (only the registered model, only on the registering thread).

#include "sim/air_forces.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <thread>

#include "common/errors.h"
#include "common/units.h"
#include "models/cfd_field.h"
#include "sim/mujoco_runtime.h"
#include "sim/scene_builder.h"
#include "tests/support/cfd_cases.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

// One free sphere of the tracer's mass at height z (m), no gravity, nothing to touch: only the
// air acts on it.
std::string floating_xml(double z_m) {
  return R"(
<mujoco>
  <option gravity="0 0 0" timestep="0.001"/>
  <worldbody>
    <body name="obj0" pos="0.3 0.1 )" +
         std::to_string(z_m) + R"(">
      <freejoint/>
      <inertial pos="0 0 0" mass="0.00016" diaginertia="1e-8 1e-8 1e-8"/>
      <geom type="sphere" size="0.015" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>)";
}
const std::string kFloating = floating_xml(0.05);

struct Floating {
  explicit Floating(const std::string& xml = kFloating)
      : model(load_model_from_xml(xml, "floating")), data(make_data(model.get())) {
    object.id = "probe";
    object.type = ObjectType::kTracer;
    object.root_body = 1;
    object.bodies = {1};
    object.area_share = {1.0};
    object.mass_kg = model->body_mass[1];
  }
  ModelPtr model;
  DataPtr data;
  SceneObject object;
};

Eigen::Vector2d planar_acceleration(const mjData* d) { return {d->qacc[0], d->qacc[1]}; }

// Gives the body planar velocity v and evaluates the forces of `air` on it once.
void push_at(Floating& f, AirForces& air, const Eigen::Vector2d& v) {
  f.data->qvel[0] = v.x();
  f.data->qvel[1] = v.y();
  AirForcesScope scope(f.model.get(), &air);
  mj_forward(f.model.get(), f.data.get());
}

TEST(AirForces, DragGivesTheScaledRelativeAirSpeedLaw) {
  Floating f;
  const SceneParameters scene;
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.4, 0.3});
  AirForces air(AirForceParameters::none(), scene, {f.object}, 1, 0.001);
  air.set_air(field, 0.7);
  // Give the body a velocity so that both terms of F = c (k J u - v) matter.
  push_at(f, air, {0.2, -0.1});
  const Eigen::Vector2d p(0.3, 0.1), v(0.2, -0.1);
  const ObjectTypeParameters& t = scene.tracer;
  // a = (c/m)(k J u(p) - v) = -xi1 (xi2/-xi1 J u - v) = xi1 v + xi2 J u: eq. (8) without friction.
  const Eigen::Vector2d expected = t.drag_rate_per_s * (t.air_gain * 0.7 * field.velocity(p) - v);
  EXPECT_LT((planar_acceleration(f.data.get()) - expected).norm(), 1e-9 * expected.norm());
  const ObjectDynamics xi = t.dynamics();
  const Eigen::Vector2d eq8 = xi.xi1 * v + xi.xi2 * 0.7 * field.velocity(p);
  EXPECT_LT((planar_acceleration(f.data.get()) - eq8).norm(), 1e-9 * eq8.norm());
  EXPECT_TRUE(air.fault().empty());
}

// Physical drag: 1/2 rho C_D(Re) A |u_rel| u_rel with C_D(Re) = C_D + 24 / Re, written here as
// the drag coefficient's law; at high and at low relative speed (where the viscous part counts).
TEST(AirForces, PhysicalDragIsQuadraticWithAViscousPart) {
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.4, 0.3});
  SceneParameters scene;
  scene.tracer.drag_law = DragLaw::kPhysical;
  const ObjectTypeParameters& t = scene.tracer;
  const Eigen::Vector2d p(0.3, 0.1);
  for (const double jet : {1.0, 0.02}) {
    Floating f;
    AirForces air(AirForceParameters::none(), scene, {f.object}, 1, 0.001);
    air.set_air(field, jet);
    push_at(f, air, Eigen::Vector2d(0.2, -0.1) * jet);
    const Eigen::Vector2d u_rel = jet * field.velocity(p) - Eigen::Vector2d(0.2, -0.1) * jet;
    const double re = u_rel.norm() * t.drag_length_m / scene.air_viscosity_m2ps;
    const double cd = t.drag_coefficient + 24.0 / re;
    const Eigen::Vector2d expected = 0.5 * scene.air_density_kgpm3 * cd * t.frontal_area_m2 *
                                     u_rel.norm() * u_rel / f.object.mass_kg;
    std::printf("physical drag at |u_rel| %.3f m/s: Re %.0f, C_D(Re) %.3f, a %.3f m/s^2\n",
                u_rel.norm(), re, cd, expected.norm());
    EXPECT_LT((planar_acceleration(f.data.get()) - expected).norm(), 1e-9 * expected.norm());
    // The lift, upward: 1/2 rho C_L pi r^2 |u_rel|^2 on the footprint.
    const double r = 0.5 * t.diameter_m;
    const double lift = 0.5 * scene.air_density_kgpm3 * t.lift_coefficient * kPi * r * r *
                        u_rel.squaredNorm() / f.object.mass_kg;
    EXPECT_GT(lift, 0.0);
    EXPECT_NEAR(f.data->qacc[2], lift, 1e-9 * lift);
  }
  // A bad parameter is one clear error naming the type.
  scene.tracer.frontal_area_m2 = 0.0;
  Floating f;
  EXPECT_THROW(AirForces(AirForceParameters::none(), scene, {f.object}, 1, 0.001), InputError);
}

// An object's own physics (ObjectSpec::physics, objects that differ) replaces its type's in the
// force law: the same formula with the object's C_D, area and C_L.
TEST(AirForces, AnObjectsOwnPhysicsReplacesItsTypes) {
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.4, 0.3});
  SceneParameters scene;
  scene.tracer.use_physical_drag();
  ObjectTypeParameters own = scene.tracer;
  own.drag_coefficient = 0.8;
  own.frontal_area_m2 = 2.0 * scene.tracer.frontal_area_m2;
  own.lift_coefficient = 0.05;
  const Eigen::Vector2d p(0.3, 0.1), v(0.2, -0.1);
  const Eigen::Vector2d u_rel = field.velocity(p) - v;
  const double re = u_rel.norm() * own.drag_length_m / scene.air_viscosity_m2ps;
  Eigen::Vector2d a[2];
  for (int k = 0; k < 2; ++k) {
    Floating f;
    if (k == 1) f.object.physics = own;
    AirForces air(AirForceParameters::none(), scene, {f.object}, 1, 0.001);
    air.set_air(field, 1.0);
    push_at(f, air, v);
    a[k] = planar_acceleration(f.data.get());
    if (k == 0) continue;
    const Eigen::Vector2d expected = 0.5 * scene.air_density_kgpm3 *
                                     (own.drag_coefficient + 24.0 / re) * own.frontal_area_m2 *
                                     u_rel.norm() * u_rel / f.object.mass_kg;
    EXPECT_LT((a[1] - expected).norm(), 1e-9 * expected.norm());
    const double r = 0.5 * own.diameter_m;
    const double lift = 0.5 * scene.air_density_kgpm3 * own.lift_coefficient * kPi * r * r *
                        u_rel.squaredNorm() / f.object.mass_kg;
    EXPECT_NEAR(f.data->qacc[2], lift, 1e-9 * lift);
  }
  // The type's own force is another one (C_D 0.38, A half): over twice as strong here.
  EXPECT_GT(a[1].norm(), 2.0 * a[0].norm());
}

// The tracer's centre of mass sits above its body origin (the flat face, where the force acts).
// The drag must take the velocity of that point, not the centre's: a spinning body then loses
// energy to the drag, never gains it. (On the centre's velocity, a tumbling tracer gained spin
// until it flew off the floor.)
constexpr const char* kOffsetCentre = R"(
<mujoco>
  <option gravity="0 0 0" timestep="0.001"/>
  <worldbody>
    <body name="obj0" pos="0.3 0.1 0.0">
      <freejoint/>
      <inertial pos="0 0 0.0056" mass="0.00016" diaginertia="9e-9 9e-9 1.4e-8"/>
      <geom type="sphere" size="0.015" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>)";

TEST(AirForces, DragActsOnTheVelocityOfThePointItPushes) {
  Floating f(kOffsetCentre);
  mjData* data = f.data.get();
  const SceneParameters scene;
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.4, 0.3});
  AirForces air(AirForceParameters::none(), scene, {f.object}, 1, 0.001);
  air.set_air(field, 1.0);
  // Sliding and tumbling about the body's y axis: the centre moves 40 * 5.6 mm = 0.22 m/s faster
  // in x than the origin.
  const Eigen::Vector2d v_origin(0.2, -0.1);
  data->qvel[0] = v_origin.x();
  data->qvel[1] = v_origin.y();
  data->qvel[4] = 40.0;
  {
    AirForcesScope scope(f.model.get(), &air);
    mj_forward(f.model.get(), data);
  }
  const ObjectTypeParameters& t = scene.tracer;
  const double c = f.object.mass_kg * t.drag_rate_per_s;
  const Eigen::Vector2d p(data->xipos[3], data->xipos[4]);
  const Eigen::Vector2d force = c * (t.air_gain * field.velocity(p) - v_origin);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(data->qfrc_passive[i], force[i], 1e-12) << i;
  for (int i = 2; i < 6; ++i) EXPECT_EQ(data->qfrc_passive[i], 0.0) << i;
  // Its power is the air's work minus c |v_origin|^2: the drag part never feeds the spin.
  double power = 0.0;
  for (int i = 0; i < 6; ++i) power += data->qfrc_passive[i] * data->qvel[i];
  const double drag_power = power - c * t.air_gain * field.velocity(p).dot(v_origin);
  EXPECT_NEAR(drag_power, -c * v_origin.squaredNorm(), 1e-15);
}

TEST(AirForces, PressurePushIsRadialAndPeaksNearTheStagnationPoint) {
  Floating f;
  const SceneParameters scene;
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  // Tilt 0: s is the origin. Put the body at r = b / sqrt(2), where the push peaks.
  const OrientedField field = field_model.at({0.0, 0.0});
  AirForceParameters params = AirForceParameters::none();
  params.stagnation_pressure_pa = 11.0;
  params.pressure_radius_m = 0.06;
  const double r = 0.06 / std::sqrt(2.0);
  AirForces with(params, scene, {f.object}, 1, 0.001);
  AirForces without(AirForceParameters::none(), scene, {f.object}, 1, 0.001);
  with.set_air(field, 1.0);
  without.set_air(field, 1.0);
  DataPtr d2 = make_data(f.model.get());
  for (mjData* d : {f.data.get(), d2.get()}) {
    d->qpos[0] = r;  // along +x from s
    d->qpos[1] = 0.0;
  }
  {
    AirForcesScope scope(f.model.get(), &with);
    mj_forward(f.model.get(), f.data.get());
  }
  {
    AirForcesScope scope(f.model.get(), &without);
    mj_forward(f.model.get(), d2.get());
  }
  const Eigen::Vector2d push = planar_acceleration(f.data.get()) - planar_acceleration(d2.get());
  // F = V p_s (2 r / b^2) exp(-r^2 / b^2), outward.
  const double expected = scene.tracer.pressure_volume_m3 * 11.0 * 2.0 * r / (0.06 * 0.06) *
                          std::exp(-0.5) / scene.tracer.mass_kg;
  EXPECT_NEAR(push.x(), expected, 1e-9 * expected);
  EXPECT_NEAR(push.y(), 0.0, 1e-12);
  EXPECT_GT(expected, 3.0);  // a few m/s^2: comparable to, but below, the tracer's friction
  EXPECT_LT(expected, 8.53);
}

TEST(AirForces, OnlyTheRegisteredModelOnTheRegisteringThreadIsPushed) {
  Floating a, b;
  const SceneParameters scene;
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.0, 0.2});
  AirForces air(AirForceParameters::none(), scene, {a.object}, 1, 0.001);
  air.set_air(field, 1.0);
  {
    AirForcesScope scope(a.model.get(), &air);
    // Another model stepped on this thread: no air.
    mj_forward(b.model.get(), b.data.get());
    EXPECT_EQ(planar_acceleration(b.data.get()).norm(), 0.0);
    // The registered model on another thread: no air either (that thread registered nothing).
    DataPtr other = make_data(a.model.get());
    std::thread worker([&] { mj_forward(a.model.get(), other.get()); });
    worker.join();
    EXPECT_EQ(planar_acceleration(other.get()).norm(), 0.0);
    // The registered model here: pushed.
    mj_forward(a.model.get(), a.data.get());
    EXPECT_GT(planar_acceleration(a.data.get()).norm(), 1.0);
  }
  // Outside the scope: nothing.
  DataPtr after = make_data(a.model.get());
  mj_forward(a.model.get(), after.get());
  EXPECT_EQ(planar_acceleration(after.get()).norm(), 0.0);
}

TEST(AirForces, EffectTermsFollowTheirLaws) {
  // The free sphere at p with velocity v, one effect at a time, against the law in the header.
  const SceneParameters scene;
  const ObjectTypeParameters& t = scene.tracer;
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.0, 0.0});  // s at the origin
  const Eigen::Vector2d p(0.3, 0.1), v(0.2, -0.1);
  const double jet = 0.9;
  auto acceleration_in = [&](const AirForceParameters& params, const SceneParameters& in) {
    Floating f;
    AirForces air(params, in, {f.object}, 1, 0.001);
    air.set_air(field, jet);
    f.data->qvel[0] = v.x();
    f.data->qvel[1] = v.y();
    AirForcesScope scope(f.model.get(), &air);
    mj_forward(f.model.get(), f.data.get());
    return planar_acceleration(f.data.get());
  };
  auto acceleration = [&](const AirForceParameters& params) {
    return acceleration_in(params, scene);
  };
  auto drag = [&](const Eigen::Vector2d& u) { return t.drag_rate_per_s * (t.air_gain * u - v); };
  const Eigen::Vector2d u = jet * field.velocity(p);
  auto near = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - b).norm() < 1e-9 * b.norm();
  };
  AirForceParameters params = AirForceParameters::none();
  // field_scale: u -> f u.
  params.field_scale = 1.3;
  EXPECT_TRUE(near(acceleration(params), drag(1.3 * u)));
  // flow_deflection: u turned by the angle, counter-clockwise.
  params = AirForceParameters::none();
  params.flow_deflection_rad = 0.35;
  EXPECT_TRUE(near(acceleration(params), drag(Eigen::Rotation2Dd(0.35) * u)));
  // quadratic_drag (the tracer type's): + C |u - v| (u - v); a cotton wad's leaves it alone.
  params = AirForceParameters::none();
  SceneParameters quadratic = scene;
  quadratic.tracer.extra_quadratic_drag_per_m = 0.7;
  EXPECT_TRUE(near(acceleration_in(params, quadratic), drag(u) + 0.7 * (u - v).norm() * (u - v)));
  quadratic = scene;
  quadratic.cotton.extra_quadratic_drag_per_m = 0.7;
  EXPECT_TRUE(near(acceleration_in(params, quadratic), drag(u)));
  // pressure_gradient: + J^2 A sqrt(2e) (r / l) exp(-(r / l)^2) radially; its peak is A.
  params = AirForceParameters::none();
  params.extra_push_mps2 = 5.0;
  params.extra_push_length_m = 0.2;
  const double r = p.norm(), l = 0.2;
  const double push =
      jet * jet * 5.0 * std::sqrt(2.0 * std::exp(1.0)) * (r / l) * std::exp(-(r / l) * (r / l));
  EXPECT_TRUE(near(acceleration(params), drag(u) + push * p / r));
  EXPECT_NEAR(std::sqrt(2.0 * std::exp(1.0)) * std::sqrt(0.5) * std::exp(-0.5), 1.0, 1e-15);
}

TEST(AirForces, FastPathMatchesMjApplyFT) {
  // A tracer (free joint: written straight into its dofs) and a cotton wad (elements on sliders
  // inside a free joint: J^T F over each chain) on a sloped floor, every effect of the force law
  // on, objects slowly moving (stiction partly faded). The fast path must give MuJoCo's own
  // Jacobian-transpose forces (mj_applyFT) to rounding.
  SceneParameters scene;
  scene.floor_slope_rad = 0.05;
  scene.floor_slope_direction_rad = 1.0;
  SceneSpec spec;
  spec.objects = {{"t", "tracer", {0.25, 0.1}, 0.3}, {"c", "cotton", {-0.2, 0.15}, std::nullopt}};
  const BuiltScene built = build_scene(spec, scene, 4);
  const mjModel* m = built.model.get();
  DataPtr d = make_data(m);
  mj_resetData(m, d.get());
  for (int i = 0; i < m->nv; ++i) d->qvel[i] = 0.002 * std::sin(1.0 + 0.7 * i);
  mj_forward(m, d.get());  // no scope registered: no air in qfrc_passive yet

  scene.tracer.extra_quadratic_drag_per_m = 0.5;
  scene.cotton.extra_quadratic_drag_per_m = 0.3;
  AirForceParameters params;
  params.field_scale = 1.2;
  params.flow_deflection_rad = 0.3;
  params.extra_push_mps2 = 4.0;
  const AirFieldModel field_model = AirFieldModel::with_constructed_table();
  const OrientedField field = field_model.at({0.4, 0.15});
  AirForces fast(params, scene, built.objects, 9, scene.timestep_s);
  AirForces slow(params, scene, built.objects, 9, scene.timestep_s);
  fast.set_air(field, 0.8);
  slow.set_air(field, 0.8);
  const std::vector<double> before(d->qfrc_passive, d->qfrc_passive + m->nv);
  fast.apply(m, d.get());
  std::vector<double> by_fast(m->nv), by_slow(m->nv);
  for (int i = 0; i < m->nv; ++i) by_fast[i] = d->qfrc_passive[i] - before[i];
  std::copy(before.begin(), before.end(), d->qfrc_passive);
  slow.apply_reference(m, d.get());
  for (int i = 0; i < m->nv; ++i) by_slow[i] = d->qfrc_passive[i] - before[i];
  ASSERT_TRUE(fast.fault().empty() && slow.fault().empty());
  double largest = 0.0, worst = 0.0;
  for (int i = 0; i < m->nv; ++i) {
    largest = std::max(largest, std::abs(by_slow[i]));
    worst = std::max(worst, std::abs(by_fast[i] - by_slow[i]));
  }
  EXPECT_GT(largest, 1e-4);  // there is a force to compare (mN)
  EXPECT_LT(worst, 1e-12 * largest);
}

TEST(AirForces, TurbulenceIsAUnitVarianceProcessFromTheSeed) {
  Floating f;
  const SceneParameters scene;
  AirForces a(AirForceParameters{}, scene, {f.object}, 5, 0.001);
  AirForces b(AirForceParameters{}, scene, {f.object}, 5, 0.001);
  AirForces c(AirForceParameters{}, scene, {f.object}, 6, 0.001);
  double sum2 = 0.0, lag = 0.0;
  Eigen::Vector2d previous = a.turbulence_state(0);
  const int n = 200000;
  for (int k = 0; k < n; ++k) {
    a.advance_turbulence();
    b.advance_turbulence();
    c.advance_turbulence();
    ASSERT_EQ(a.turbulence_state(0), b.turbulence_state(0));
    sum2 += a.turbulence_state(0).squaredNorm();
    lag += a.turbulence_state(0).dot(previous);
    previous = a.turbulence_state(0);
  }
  EXPECT_NE(a.turbulence_state(0), c.turbulence_state(0));
  // 200 s of a 0.05 s process: ~4000 independent samples, so a few % of sampling error.
  EXPECT_NEAR(sum2 / n / 2.0, 1.0, 0.1);
  // One-step correlation exp(-dt / tau).
  EXPECT_NEAR(lag / sum2, std::exp(-0.001 / 0.05), 1e-3);
}

// The same free body 1 cm above the floor, between two of the synthetic CFD cases' heights.
const std::string kLow = floating_xml(0.01);

// The synthetic case's kinematic pressure (m^2/s^2), linear in x and y: its gradient is
// (3, 2) on the y >= 0 side.
double linear_cfd_pressure(double x, double y) { return 4.0 + 3.0 * x + 2.0 * y; }

// A CFD case whose air and pressure are linear in x, y and z (so the interpolation reproduces
// them exactly) and whose turbulence is uniform: k and epsilon given.
CfdField linear_cfd(const std::string& dir, double k, double epsilon) {
  testing::write_cfd_case(dir, "tilt10.0_mesh1_d20", 10.0, 0.1, [=](double x, double y, double z) {
    return std::array<double, 6>{0.5 + 2.0 * x - y + 40.0 * z, 1.0 + x + 3.0 * y, 0.0, k, epsilon,
                                 linear_cfd_pressure(x, y)};
  });
  return CfdField::read_dir(dir);
}

// The pressure gradient the twin should see at a world point under pan theta: central differences
// one pitch (0.1 m) wide of the mirrored formula in the case frame, turned to the world frame.
Eigen::Vector2d linear_cfd_pressure_gradient(const Eigen::Vector2d& p_W, double pan) {
  const double c = std::cos(pan), s = std::sin(pan), h = 0.1;
  const double x = c * p_W.x() + s * p_W.y(), y = -s * p_W.x() + c * p_W.y();
  const auto p = [](double xx, double yy) { return linear_cfd_pressure(xx, std::abs(yy)); };
  const Eigen::Vector2d g((p(x + h, y) - p(x - h, y)) / (2 * h),
                          (p(x, y + h) - p(x, y - h)) / (2 * h));
  return {c * g.x() - s * g.y(), s * g.x() + c * g.y()};
}

// The case's air at a world point under pan theta, from its formula: into the case frame, the
// mirror for y < 0, back to the world frame.
Eigen::Vector2d linear_cfd_air(const Eigen::Vector2d& p_W, double z, double pan) {
  const double c = std::cos(pan), s = std::sin(pan);
  const double x = c * p_W.x() + s * p_W.y(), y = -s * p_W.x() + c * p_W.y();
  const double ya = std::abs(y);
  Eigen::Vector2d u(0.5 + 2.0 * x - ya + 40.0 * z, 1.0 + x + 3.0 * ya);
  if (y < 0.0) u.y() = -u.y();
  return {c * u.x() - s * u.y(), s * u.x() + c * u.y()};
}

TEST(AirForces, InCfdAirTheDragAndPushTakeTheCfdsAirAtTheBodysHeight) {
  Floating f(kLow);
  const SceneParameters scene;
  const CfdField cfd = linear_cfd(testing::fresh_scratch_dir("cfd_mean"), 0.0, 1.0);
  for (double pan : {0.0, 0.4, -2.5}) {
    const CfdOrientedField field = cfd.at(NozzleOrientation{pan, deg_to_rad(10.0)});
    AirForces air(AirForceParameters{}, scene, {f.object}, 1, 0.001);  // turbulence from k = 0
    air.set_air(field, 0.7);
    mj_resetData(f.model.get(), f.data.get());
    push_at(f, air, {0.2, -0.1});
    const Eigen::Vector2d p(0.3, 0.1), v(0.2, -0.1);
    const ObjectTypeParameters& t = scene.tracer;
    const Eigen::Vector2d u = linear_cfd_air(p, 0.01, pan);
    // The pressure push is the CFD's: -V rho J^2 grad(p / rho).
    const Eigen::Vector2d push = -t.pressure_volume_m3 * scene.air_density_kgpm3 * 0.49 *
                                 linear_cfd_pressure_gradient(p, pan) / f.object.mass_kg;
    EXPECT_GT(push.norm(), 0.01 * (t.drag_rate_per_s * (t.air_gain * 0.7 * u - v)).norm());
    const Eigen::Vector2d expected = t.drag_rate_per_s * (t.air_gain * 0.7 * u - v) + push;
    EXPECT_LT((planar_acceleration(f.data.get()) - expected).norm(), 1e-5 * expected.norm())
        << "pan " << pan;
    EXPECT_TRUE(air.fault().empty());
  }
}

// The turbulent air a body at rest feels, read back from the drag over 100 s: its variance and
// its one-step correlation exp(-dt / T).
struct TurbulenceSeen {
  double variance = 0.0;     // per component, m^2/s^2
  double correlation = 0.0;  // one step (1 ms)
};
TurbulenceSeen turbulence_seen(double k, double epsilon, bool swept, const std::string& dir) {
  Floating f(kLow);
  const SceneParameters scene;
  const CfdField cfd = linear_cfd(testing::fresh_scratch_dir(dir), k, epsilon);
  const CfdOrientedField field = cfd.at(NozzleOrientation{0.0, deg_to_rad(10.0)});
  AirForceParameters params;
  params.stagnation_pressure_pa = 0.0;
  params.turbulence_swept = swept;
  AirForces air(params, scene, {f.object}, 3, 0.001);
  air.set_air(field, 1.0);
  const ObjectTypeParameters& t = scene.tracer;
  const Eigen::Vector2d mean = t.drag_rate_per_s * t.air_gain * linear_cfd_air({0.3, 0.1}, 0.01, 0);
  double sum2 = 0.0, lag = 0.0;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    {
      AirForcesScope scope(f.model.get(), &air);
      mj_forward(f.model.get(), f.data.get());
    }
    // The air's turbulent velocity, read back from the drag: a = c/m (k u' + ...).
    const Eigen::Vector2d u_prime =
        (planar_acceleration(f.data.get()) - mean) / (t.drag_rate_per_s * t.air_gain);
    sum2 += u_prime.squaredNorm();
    lag += u_prime.dot(previous);
    previous = u_prime;
    air.advance_turbulence();
  }
  return {sum2 / n / 2.0, lag / sum2};
}

TEST(AirForces, InCfdAirTheTurbulenceHasTheCfdsVarianceAndTimeScale) {
  // sigma = sqrt(2k/3) = 0.2 m/s; T_L = 0.15 k / epsilon = 0.025 s.
  const double k = 0.06, epsilon = 0.36;
  const TurbulenceSeen seen = turbulence_seen(k, epsilon, false, "cfd_turbulence");
  // 100 s of a 0.025 s process: ~4000 independent samples per component.
  EXPECT_NEAR(seen.variance, 2.0 * k / 3.0, 0.1 * 2.0 * k / 3.0);
  EXPECT_NEAR(seen.correlation, std::exp(-0.001 / (0.15 * k / epsilon)), 2e-3);
}

TEST(AirForces, SweptTurbulenceDecorrelatesAsItsEddiesPassTheBody) {
  // The body rests in 2.13 m/s of mean air (linear_cfd_air at (0.3, 0.1), 1 cm up), which sweeps
  // eddies of L11 = 0.43 k^1.5 / epsilon = 17.6 mm past it: it sees them for
  // 1 / (1 / T_L + 2.13 / L11) = 6.2 ms instead of T_L = 25 ms.
  const double k = 0.06, epsilon = 0.36;
  const double swept = std::hypot(1.4, 1.6);
  ASSERT_NEAR(swept, linear_cfd_air({0.3, 0.1}, 0.01, 0).norm(), 1e-12);
  const double t_s =
      1.0 / (1.0 / (0.15 * k / epsilon) + swept / (0.43 * std::pow(k, 1.5) / epsilon));
  const TurbulenceSeen seen = turbulence_seen(k, epsilon, true, "cfd_turbulence_swept");
  // ~16 000 independent samples per component; the one-step correlation's standard error is
  // sqrt((1 - rho^2) / 2n) = 1.2e-3, bounded at 4 of them (T_L alone would give 0.961).
  EXPECT_NEAR(seen.variance, 2.0 * k / 3.0, 0.1 * 2.0 * k / 3.0);
  EXPECT_NEAR(seen.correlation, std::exp(-0.001 / t_s), 5e-3);
}

}  // namespace
}  // namespace airtwin
