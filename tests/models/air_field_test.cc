// The air-field model (section III): eq. (3) along radial directions from s, linear in alpha with
// wrap-around, Makima in tilt, radial direction, zero at s; immutable and shareable across threads.

#include "models/air_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>

#include <Eigen/Geometry>

#include "common/errors.h"
#include "common/units.h"
#include "models/makima.h"

namespace airtwin {
namespace {

NozzleOrientation deg(double pan, double tilt) { return {deg_to_rad(pan), deg_to_rad(tilt)}; }

// Independent evaluation of the model's definition for a tilt that is a table node: coefficients
// of the two neighbouring whole-degree rows of that tilt, mixed linearly, then eq. (3).
double reference_speed_at_node_tilt(const FieldTable& t, size_t tilt_index, double pan_deg,
                                    const Eigen::Vector2d& s, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - s;
  double alpha_deg = rad_to_deg(std::atan2(d.y(), d.x())) - pan_deg;
  alpha_deg = std::fmod(std::fmod(alpha_deg, 360.0) + 360.0, 360.0);
  const int k = static_cast<int>(std::floor(alpha_deg)) % 360;
  const double w = alpha_deg - std::floor(alpha_deg);
  const FieldCoefficients& a = t.at(tilt_index, k);
  const FieldCoefficients& b = t.at(tilt_index, (k + 1) % 360);
  const double b1 = (1 - w) * a.b1 + w * b.b1, b2 = (1 - w) * a.b2 + w * b.b2,
               b3 = (1 - w) * a.b3 + w * b.b3;
  const double r = d.norm();
  return b1 * (std::exp(b2 * r) - std::exp(b3 * r));
}

TEST(AirField, MatchesTheDefiningEquationAtTableTilts) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.2, 1.2), pan(-180, 180);
  const double tilts[] = {0.0, 22.5, 45.0};
  for (size_t ti = 0; ti < 3; ++ti) {
    for (int trial = 0; trial < 20; ++trial) {
      const double pan_deg = pan(rng);
      const OrientedField f = model.at(deg(pan_deg, tilts[ti]));
      for (int i = 0; i < 50; ++i) {
        const Eigen::Vector2d p(u(rng), u(rng));
        const double expected =
            reference_speed_at_node_tilt(model.table(), ti, pan_deg, f.stagnation_point(), p);
        EXPECT_NEAR(f.speed(p), expected, 1e-12 * (1 + std::abs(expected)));
      }
    }
  }
}

TEST(AirField, MakimaInTiltBetweenTableTilts) {
  // At tilt 30 deg the profile of each direction is Makima through the three table tilts.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const FieldTable& t = model.table();
  const OrientedField f = model.at(deg(0, 30));
  for (int a : {0, 45, 90, 180, 271}) {
    std::vector<double> b1, b2, b3;
    for (size_t i = 0; i < 3; ++i) {
      b1.push_back(t.at(i, a).b1);
      b2.push_back(t.at(i, a).b2);
      b3.push_back(t.at(i, a).b3);
    }
    const FieldCoefficients c = f.coefficients(deg_to_rad(a));
    EXPECT_NEAR(c.b1, Makima(t.tilts_rad(), b1)(deg_to_rad(30)), 1e-12);
    EXPECT_NEAR(c.b2, Makima(t.tilts_rad(), b2)(deg_to_rad(30)), 1e-12);
    EXPECT_NEAR(c.b3, Makima(t.tilts_rad(), b3)(deg_to_rad(30)), 1e-12);
  }
}

TEST(AirField, TiltIsClampedToTheFittedRange) {
  // Tilt 50 deg uses the 45 deg profiles (no extrapolation) while s follows the real geometry.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f50 = model.at(deg(10, 50));
  const OrientedField f45 = model.at(deg(10, 45));
  EXPECT_NEAR(f50.coefficient_tilt_rad(), deg_to_rad(45), 1e-15);
  EXPECT_GT((f50.stagnation_point() - f45.stagnation_point()).norm(), 0.1);
  const Eigen::Vector2d offset(0.3, -0.2);
  EXPECT_NEAR(f50.speed(f50.stagnation_point() + offset),
              f45.speed(f45.stagnation_point() + offset), 1e-12);
}

TEST(AirField, ZeroAtTheStagnationPoint) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  for (double tilt : {0.0, 10.0, 22.5, 45.0}) {
    const OrientedField f = model.at(deg(90, tilt));
    EXPECT_EQ(f.speed(f.stagnation_point()), 0.0);
    EXPECT_EQ(f.velocity(f.stagnation_point()).norm(), 0.0);
    // ... and continuous: tiny close to s.
    EXPECT_LT(f.speed(f.stagnation_point() + Eigen::Vector2d(1e-6, 0)), 1e-3);
  }
}

TEST(AirField, ContinuousAcrossAlpha359To0) {
  // Around the downstream direction alpha wraps from 359 to 0: the profile must not jump.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  for (double pan : {0.0, 90.0, -170.0}) {
    const OrientedField f = model.at(deg(pan, 22.5));
    const double r = 0.4;
    auto at_alpha = [&](double alpha_deg) {
      const double a = deg_to_rad(pan + alpha_deg);
      return f.speed(f.stagnation_point() + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
    };
    const double below = at_alpha(-1e-7), above = at_alpha(1e-7), at0 = at_alpha(0.0);
    EXPECT_NEAR(below, at0, 1e-6);
    EXPECT_NEAR(above, at0, 1e-6);
    // Just below 360 the profile mixes row 359 with row 0: at 359.5 deg it is the midpoint.
    const FieldCoefficients c = f.coefficients(deg_to_rad(359.5));
    const FieldCoefficients c359 = f.coefficients(deg_to_rad(359.0));
    const FieldCoefficients c0 = f.coefficients(0.0);
    EXPECT_NEAR(c.b1, 0.5 * (c359.b1 + c0.b1), 1e-12);
    EXPECT_NEAR(c.b3, 0.5 * (c359.b3 + c0.b3), 1e-12);
  }
}

TEST(AirField, DirectionIsRadialFromTheStagnationPoint) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(-60, 22.5));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d p(u(rng), u(rng));
    const Eigen::Vector2d d = p - f.stagnation_point();
    const Eigen::Vector2d v = f.velocity(p);
    EXPECT_NEAR(d.x() * v.y() - d.y() * v.x(), 0.0, 1e-12);  // parallel
    EXPECT_GT(d.dot(v), 0.0);                                // pointing away from s
    EXPECT_NEAR(v.norm(), f.speed(p), 1e-12);
  }
}

TEST(AirField, PanRotatesTheWholeField) {
  // Rotational symmetry of the rig: the field at pan theta is the field at pan 0 rotated.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f0 = model.at(deg(0, 22.5));
  const double theta = deg_to_rad(123.0);
  const OrientedField fr = model.at({theta, deg_to_rad(22.5)});
  const Eigen::Rotation2Dd rot(theta);
  for (double x = -1; x <= 1; x += 0.25) {
    for (double y = -1; y <= 1; y += 0.25) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector2d expected = rot * f0.velocity(p);
      EXPECT_NEAR((fr.velocity(rot * p) - expected).norm(), 0.0, 1e-9);
    }
  }
}

TEST(AirField, DownstreamStrongerThanUpstreamForTiltedJet) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(90, 22.5));  // downstream is +y
  const Eigen::Vector2d s = f.stagnation_point();
  EXPECT_GT(f.speed(s + Eigen::Vector2d(0, 0.4)), f.speed(s - Eigen::Vector2d(0, 0.4)));
}

TEST(AirField, BatchEqualsPointwise) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at(deg(33, 17));
  Eigen::Matrix2Xd p = Eigen::Matrix2Xd::Random(2, 1000);
  p.col(5) = f.stagnation_point();
  Eigen::VectorXd speeds(1000);
  Eigen::Matrix2Xd v(2, 1000);
  f.speeds(p, speeds);
  f.velocities(p, v);
  for (int j = 0; j < 1000; ++j) {
    EXPECT_EQ(speeds[j], f.speed(p.col(j)));
    EXPECT_EQ(v.col(j), f.velocity(p.col(j)));
  }
}

TEST(AirField, SharedModelIsSafeAcrossThreads) {
  // The model is immutable: four threads building fields and evaluating concurrently must get
  // exactly the single-threaded numbers.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const Eigen::Matrix2Xd p = Eigen::Matrix2Xd::Random(2, 2000);
  auto run = [&](int seed, Eigen::VectorXd* out) {
    out->resize(p.cols() * 20);
    for (int k = 0; k < 20; ++k) {
      const OrientedField f = model.at(deg(seed * 17.0 + k, 2.0 * k));
      Eigen::VectorXd s(p.cols());
      f.speeds(p, s);
      out->segment(k * p.cols(), p.cols()) = s;
    }
  };
  std::vector<Eigen::VectorXd> serial(4), parallel(4);
  for (int t = 0; t < 4; ++t) run(t, &serial[t]);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) threads.emplace_back(run, t, &parallel[t]);
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(serial[t], parallel[t]);
}

TEST(AirField, RaysViewEqualsTheFullField) {
  // OrientedRays interpolates each profile on demand, OrientedField all 360 up front: the same
  // arithmetic, so the same bits, in every direction (the wrap at 360 included) and at every
  // tilt (clamped ones included).
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pan(-400.0, 400.0), tilt(0.0, 64.0), alpha(-7.0, 13.0);
  for (int trial = 0; trial < 50; ++trial) {
    const NozzleOrientation o = deg(pan(rng), trial == 0 ? 0.0 : tilt(rng));
    const OrientedField f = model.at(o);
    const OrientedRays rays = model.rays_at(o);
    EXPECT_EQ(rays.stagnation_point(), f.stagnation_point());
    EXPECT_EQ(rays.projection_point(), f.projection_point());
    EXPECT_EQ(rays.coefficient_tilt_rad(), f.coefficient_tilt_rad());
    EXPECT_EQ(&rays.model(), &model);
    for (int k = 0; k < 40; ++k) {
      const double a = k == 0   ? std::nextafter(2 * kPi, 0.0)
                       : k == 1 ? deg_to_rad(359.5)
                                : alpha(rng);
      const FieldCoefficients x = rays.coefficients(a), y = f.coefficients(a);
      ASSERT_EQ(x.b1, y.b1) << "trial " << trial << " alpha " << a;
      ASSERT_EQ(x.b2, y.b2);
      ASSERT_EQ(x.b3, y.b3);
    }
    const OrientedField g = rays.field();
    const Eigen::Vector2d p = f.stagnation_point() + Eigen::Vector2d(0.31, -0.17);
    EXPECT_EQ(g.speed(p), f.speed(p));
  }
  // Between table tilts, against Makima itself (an independent truth, as above).
  const FieldTable& t = model.table();
  const OrientedRays r30 = model.rays_at(deg(0, 30));
  for (int a : {0, 90, 271}) {
    std::vector<double> b2;
    for (size_t i = 0; i < 3; ++i) b2.push_back(t.at(i, a).b2);
    EXPECT_NEAR(r30.coefficients(deg_to_rad(a)).b2, Makima(t.tilts_rad(), b2)(deg_to_rad(30)),
                1e-12);
  }
  // The same validation as at().
  EXPECT_THROW(model.rays_at({0.0, deg_to_rad(65.0)}), InputError);
  EXPECT_THROW(model.rays_at({NAN, 0.1}), InputError);
}

TEST(AirField, VelocityAlongRaysEqualsTheFullField) {
  // OrientedRays::velocity reads two profiles where OrientedField reads its ring: the same
  // profiles and formula, so equal to rounding (the ring's kernel may contract to FMA), at points
  // near s, far away, on the 359-0 deg seam and at s itself.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pan(-400.0, 400.0), tilt(0.0, 64.0), xy(-2.0, 2.0);
  for (int trial = 0; trial < 50; ++trial) {
    const NozzleOrientation o = deg(pan(rng), tilt(rng));
    const OrientedField f = model.at(o);
    const OrientedRays rays = model.rays_at(o);
    const Eigen::Vector2d s = f.stagnation_point();
    const Eigen::Vector2d downstream(std::cos(o.pan_rad), std::sin(o.pan_rad));
    std::vector<Eigen::Vector2d> points{
        s, s + 0.4 * downstream, s + Eigen::Vector2d(-downstream.y(), downstream.x()) * 1e-3};
    for (int k = 0; k < 40; ++k) points.emplace_back(xy(rng), xy(rng));
    for (const Eigen::Vector2d& p : points) {
      const Eigen::Vector2d a = rays.velocity(p), b = f.velocity(p);
      ASSERT_LE((a - b).norm(), 1e-13 * (1.0 + b.norm()))
          << "trial " << trial << " at " << p.x() << ", " << p.y();
    }
    EXPECT_EQ(rays.velocity(s), Eigen::Vector2d::Zero());
  }
}

TEST(AirField, RejectsInvalidOrientation) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  EXPECT_THROW(model.at({0.0, deg_to_rad(90)}), InputError);
  EXPECT_THROW(model.at({0.0, -0.1}), InputError);
  EXPECT_THROW(model.at({NAN, 0.1}), InputError);
  // Beyond eq. (2)'s fold (64.4 deg) s would land on the far side of the origin.
  EXPECT_NO_THROW(model.at({0.0, deg_to_rad(64.0)}));
  EXPECT_THROW(model.at({0.0, deg_to_rad(65.0)}), InputError);
  EXPECT_NEAR(rad_to_deg(fold_tilt_rad(model.geometry())), 64.44008882357566, 1e-9);
}

}  // namespace
}  // namespace airtwin
