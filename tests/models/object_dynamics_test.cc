// Object dynamics (section IV): eq. (8) coefficients per object type, the shipped and user
// coefficient files with strict validation, and the reduction of eqs. (8)-(9) to a ray from s.

#include "models/object_dynamics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <string>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// Expects parse_csv to throw an InputError whose message contains every one of `parts`.
void expect_input_error(const std::string& text, std::initializer_list<std::string> parts) {
  try {
    ObjectTypes::parse_csv(text, "types.csv");
    ADD_FAILURE() << "no InputError for:\n" << text;
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const std::string& p : parts) {
      EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' missing from: " << what;
    }
  }
}

TEST(ObjectTypes, DefaultsAreThePapersIdentifiedCoefficients) {
  // Sections IV-B and IV-C.
  const ObjectTypes& t = ObjectTypes::defaults();
  ASSERT_EQ(t.size(), 2u);
  const ObjectDynamics& tracer = t.at("tracer");
  EXPECT_EQ(tracer.xi1, -2.66);
  EXPECT_EQ(tracer.xi2, 4.26);
  EXPECT_EQ(tracer.xi3, -8.53);
  const ObjectDynamics& cotton = t.at("cotton");
  EXPECT_EQ(cotton.xi1, -4.25);
  EXPECT_EQ(cotton.xi2, 3.46);
  EXPECT_EQ(cotton.xi3, -4.12);
  EXPECT_EQ(kTracerDynamics.xi3, tracer.xi3);
  EXPECT_EQ(kCottonDynamics.xi1, cotton.xi1);
  EXPECT_TRUE(t.contains("tracer"));
  EXPECT_FALSE(t.contains("Tracer"));
}

TEST(ObjectTypes, ShippedFileLoadsLikeTheCompiledInCopy) {
  const ObjectTypes file =
      ObjectTypes::load_csv(std::string(AIRTWIN_SOURCE_DIR) + "/models/data/object_types.csv");
  const ObjectTypes& built_in = ObjectTypes::defaults();
  ASSERT_EQ(file.size(), built_in.size());
  for (size_t i = 0; i < file.size(); ++i) {
    EXPECT_EQ(file.entries()[i].name, built_in.entries()[i].name);
    EXPECT_EQ(file.entries()[i].dynamics.xi1, built_in.entries()[i].dynamics.xi1);
    EXPECT_EQ(file.entries()[i].dynamics.xi2, built_in.entries()[i].dynamics.xi2);
    EXPECT_EQ(file.entries()[i].dynamics.xi3, built_in.entries()[i].dynamics.xi3);
  }
}

TEST(ObjectTypes, AcceptsAnyColumnOrderCommentsAndCrlf) {
  const ObjectTypes t = ObjectTypes::parse_csv(
      "# my objects\r\nxi3,object,xi2,xi1\r\n\r\n-1.5,paper_ball,2.0,-3\r\n", "mine.csv");
  const ObjectDynamics& d = t.at("paper_ball");
  EXPECT_EQ(d.xi1, -3.0);
  EXPECT_EQ(d.xi2, 2.0);
  EXPECT_EQ(d.xi3, -1.5);
}

TEST(ObjectTypes, MalformedFilesAreInputErrorsNamingFileLineAndColumn) {
  expect_input_error("object,xi1,xi2\ntracer,-1,2\n", {"types.csv", "missing column 'xi3'"});
  expect_input_error("object,xi1,xi2,xi3,mass\ntracer,-1,2,-3,1\n",
                     {"types.csv", "unknown column 'mass'"});
  expect_input_error("object,xi1,xi2,xi3\ntracer,nan,2,-3\n", {"types.csv:2", "'xi1'", "nan"});
  expect_input_error("object,xi1,xi2,xi3\ntracer,-1,2,\n", {"types.csv:2", "'xi3'"});
  expect_input_error("object,xi1,xi2,xi3\ntracer,-1,2\n", {"types.csv:2", "fields"});
  expect_input_error("object,xi1,xi2,xi3\na,-1,2,-3\n\n# c\nb,-1,2,-3\na,-2,2,-3\n",
                     {"types.csv:6", "'object'", "duplicate object 'a'", "line 2"});
  expect_input_error("object,xi1,xi2,xi3\nmy ball,-1,2,-3\n", {"types.csv:2", "'object'"});
  expect_input_error("object,xi1,xi2,xi3\n,-1,2,-3\n", {"types.csv:2", "'object'"});
  expect_input_error("object,xi1,xi2,xi3\n", {"types.csv", "no object types"});
  expect_input_error("", {"types.csv", "empty"});
  // Unphysical signs: no damping, air pulling upstream, friction that pushes.
  expect_input_error("object,xi1,xi2,xi3\nt,0.1,2,-3\n", {"types.csv:2", "'xi1'", "0.1"});
  expect_input_error("object,xi1,xi2,xi3\nt,-1,-2,-3\n", {"types.csv:2", "'xi2'"});
  expect_input_error("object,xi1,xi2,xi3\nt,-1,2,0.5\n", {"types.csv:2", "'xi3'", "0.5"});
}

TEST(ObjectTypes, UnknownObjectAndMissingFileAreInputErrors) {
  try {
    ObjectTypes::defaults().at("marble");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown object 'marble'"), std::string::npos) << what;
    EXPECT_NE(what.find("tracer"), std::string::npos) << what;
  }
  EXPECT_THROW(ObjectTypes::load_csv("/nonexistent/types.csv"), InputError);
}

TEST(ObjectDynamics, AccelerationIsEquationEightAndTheThresholdZeroesTheDrive) {
  const ObjectDynamics xi = kTracerDynamics;
  EXPECT_DOUBLE_EQ(xi.acceleration(0.5, 3.0), -2.66 * 0.5 + 4.26 * 3.0 - 8.53);
  EXPECT_DOUBLE_EQ(xi.drive(3.0), xi.acceleration(0.0, 3.0));
  // The tracer needs ~2.0 m/s of air to start moving (physics notes), cotton ~1.19 m/s.
  EXPECT_NEAR(xi.threshold_air_speed(), 2.0023, 1e-4);
  EXPECT_NEAR(xi.drive(xi.threshold_air_speed()), 0.0, 1e-12);
  EXPECT_NEAR(kCottonDynamics.threshold_air_speed(), 1.1908, 1e-4);
}

TEST(Ray, ReproducesTheFieldAlongTheRayThroughAPoint) {
  // Independent truth: the field model's own evaluation at points along the ray.
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> pan(-kPi, kPi), tilt(0, deg_to_rad(50)), offset(-0.9, 0.9),
      scale(0.0, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const OrientedField f = model.at({pan(rng), tilt(rng)});
    const Eigen::Vector2d p = f.stagnation_point() + Eigen::Vector2d(offset(rng), offset(rng));
    const Ray ray = ray_through(f, p);
    EXPECT_EQ(ray.radial, 1.0);
    EXPECT_NEAR((ray.point(ray.r0) - p).norm(), 0.0, 1e-15);
    EXPECT_NEAR(ray.u_W.norm(), 1.0, 1e-15);
    for (double k : {0.0, 0.5, 1.0, scale(rng)}) {
      const double r = k * ray.r0;
      EXPECT_NEAR(ray.profile.speed(r), f.speed(ray.point(r)), 1e-12);
      // The air moves along the ray (away from s).
      if (r > 0) {
        const Eigen::Vector2d q = ray.point(r);
        EXPECT_NEAR((f.velocity(q) - f.speed(q) * ray.u_W).norm(), 0.0, 1e-12);
      }
    }
  }
}

TEST(Ray, AtTheStagnationPointThereIsNoDirectionAndNoAir) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at({0.4, deg_to_rad(20)});
  const Ray ray = ray_through(f, f.stagnation_point());
  EXPECT_EQ(ray.r0, 0.0);
  EXPECT_EQ(ray.radial, 0.0);
  EXPECT_EQ(ray.u_W, Eigen::Vector2d::Zero());
  EXPECT_EQ(ray.profile.speed(0.0), 0.0);
  // The planar right-hand side agrees: no motion at s, eq. (8) with v_air = 0.
  const PlanarRate rate = moving_rate(f, kTracerDynamics, f.stagnation_point(), 0.7);
  EXPECT_EQ(rate.p_dot_W, Eigen::Vector2d::Zero());
  EXPECT_DOUBLE_EQ(rate.v_dot, kTracerDynamics.acceleration(0.7, 0.0));
}

TEST(MovingRate, IsEquationsEightAndNineWithTheFieldModel) {
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  const OrientedField f = model.at({-1.0, deg_to_rad(30)});
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> offset(-0.7, 0.7), speed(0.0, 2.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector2d p = f.stagnation_point() + Eigen::Vector2d(offset(rng), offset(rng));
    const double v = speed(rng);
    const PlanarRate rate = moving_rate(f, kCottonDynamics, p, v);
    const Eigen::Vector2d u = (p - f.stagnation_point()).normalized();
    EXPECT_NEAR((rate.p_dot_W - v * u).norm(), 0.0, 1e-14);
    EXPECT_DOUBLE_EQ(rate.v_dot, kCottonDynamics.acceleration(v, f.speed(p)));
  }
}

}  // namespace
}  // namespace airtwin
