// The object-physics catalogue: typed values land in the SI fields they name, every bad input is
// one error naming the text and the key, and the record of a type's parameters reads back to the
// same parameters.

#include "sim/object_physics.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "common/errors.h"

namespace airtwin {
namespace {

SceneParameters physical_scene() {
  SceneParameters scene;
  scene.tracer.use_physical_drag();
  scene.cotton.use_physical_drag();
  return scene;
}

TEST(ObjectPhysics, TheCatalogueIsIndexedByItsKeys) {
  for (size_t i = 0; i < kObjectPhysicsKeyCount; ++i) {
    const ObjectPhysicsSpec& s = object_physics_catalogue()[i];
    EXPECT_EQ(static_cast<size_t>(s.id), i);
    ASSERT_NE(s.key, nullptr) << i;
    EXPECT_LT(s.min, s.max) << s.key;
    EXPECT_GT(s.si_per_unit, 0.0) << s.key;
  }
}

TEST(ObjectPhysics, TypedValuesSetTheirSiFields) {
  SceneParameters scene = physical_scene();
  const ObjectTypeParameters cotton_before = scene.cotton;
  apply_object_physics("tracer:mass_g=0.15,cd=0.38,area_cm2=3.2,mu_k=0.5,mu_s_ratio=1.4,cl=0.25",
                       &scene);
  EXPECT_DOUBLE_EQ(scene.tracer.mass_kg, 0.15e-3);
  EXPECT_DOUBLE_EQ(scene.tracer.drag_coefficient, 0.38);
  EXPECT_DOUBLE_EQ(scene.tracer.frontal_area_m2, 3.2e-4);
  EXPECT_DOUBLE_EQ(scene.tracer.physical_kinetic_friction, 0.5);
  EXPECT_DOUBLE_EQ(scene.tracer.kinetic_friction, 0.5);  // the contacts' mu under physical drag
  EXPECT_DOUBLE_EQ(scene.tracer.static_friction_ratio, 1.4);
  EXPECT_DOUBLE_EQ(scene.tracer.lift_coefficient, 0.25);
  EXPECT_EQ(scene.cotton.mass_kg, cotton_before.mass_kg);  // the other type is untouched
  EXPECT_EQ(scene.cotton.drag_coefficient, cotton_before.drag_coefficient);
  // Spaces around items are allowed; later texts override earlier ones.
  apply_object_physics(" cotton : cd = 0.9 ", &scene);
  EXPECT_DOUBLE_EQ(scene.cotton.drag_coefficient, 0.9);
}

TEST(ObjectPhysics, TheRecordReadsBackToTheSameParameters) {
  SceneParameters scene = physical_scene();
  apply_object_physics("cotton:mass_g=0.2,cd=0.75,mu_k=0.31", &scene);
  const std::string record = object_physics_to_string(scene, ObjectType::kCotton);
  EXPECT_EQ(record.rfind("cotton:mass_g=0.2,cd=0.75,", 0), 0u) << record;
  SceneParameters again = physical_scene();
  apply_object_physics(record, &again);
  for (const ObjectPhysicsSpec& s : object_physics_catalogue()) {
    // The record keeps nine significant digits.
    const double want = object_physics_value(scene.cotton, s.id);
    EXPECT_NEAR(object_physics_value(again.cotton, s.id), want, 1e-8 * want) << s.key;
  }
  // Under eq. (8) the physical law's keys are not part of the record.
  const SceneParameters eq8;
  EXPECT_EQ(object_physics_to_string(eq8, ObjectType::kTracer).find("cd="), std::string::npos);
}

void expect_error(const std::string& text, std::initializer_list<std::string> parts,
                  bool physical = true) {
  SceneParameters scene = physical ? physical_scene() : SceneParameters{};
  try {
    apply_object_physics(text, &scene);
    ADD_FAILURE() << "no InputError for '" << text << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'" + text + "'"), std::string::npos) << what;
    for (const std::string& p : parts) {
      EXPECT_NE(what.find(p), std::string::npos) << "'" << p << "' missing from: " << what;
    }
  }
}

TEST(ObjectPhysics, BadInputIsOneErrorNamingTheKey) {
  expect_error("marble:cd=0.4", {"tracer or cotton", "mass_g, cd, area_cm2, mu_k, mu_s_ratio"});
  expect_error("tracer", {"TYPE:key=value"});
  expect_error("tracer:cd", {"expected key=value", "'cd'"});
  expect_error("tracer:drag=0.4", {"unknown key 'drag'", "mu_s_ratio"});
  expect_error("tracer:cd=0.4,cd=0.5", {"tracer.cd is given twice"});
  expect_error("tracer:cd=abc", {"tracer.cd must be a number in [0.05, 3]", "'abc'"});
  expect_error("tracer:cd=nan", {"tracer.cd must be a number in [0.05, 3]"});
  expect_error("tracer:cd=inf", {"tracer.cd must be a number"});
  expect_error("tracer:mass_g=1e6", {"tracer.mass_g must be a number in [0.01, 100] g"});
  expect_error("tracer:mu_s_ratio=0.9", {"[1, 5]"});
  expect_error("cotton:area_cm2=", {"cotton.area_cm2 must be a number in [0.1, 200] cm^2"});
  // The physical law's keys need the physical law; mass and stiction fit either.
  expect_error("tracer:mu_k=0.4", {"physical drag law", "eq. (8)"}, /*physical=*/false);
  SceneParameters eq8;
  apply_object_physics("tracer:mass_g=0.17,mu_s_ratio=2", &eq8);
  EXPECT_DOUBLE_EQ(eq8.tracer.mass_kg, 0.17e-3);
  EXPECT_DOUBLE_EQ(eq8.tracer.static_friction_ratio, 2.0);
}

}  // namespace
}  // namespace airtwin
