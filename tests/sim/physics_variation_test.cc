// Objects that differ (sim/physics_variation.h): the text read and written back, the draws
// against their definition (uniform over the documented range, or within +-F of the type's value;
// only the mass under eq. (8)'s law; the geometry never), one stream per object from the seed, and
// a scene's objects given their own physics.

#include "sim/physics_variation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "common/errors.h"

namespace airtwin {
namespace {

TEST(PhysicsVariation, ReadsItsTextAndWritesItBack) {
  EXPECT_FALSE(PhysicsVariation::parse("none").active());
  EXPECT_EQ(PhysicsVariation::parse("documented").kind, PhysicsVariation::Kind::kDocumented);
  const PhysicsVariation spread = PhysicsVariation::parse(" 0.25 ");
  EXPECT_EQ(spread.kind, PhysicsVariation::Kind::kRelative);
  EXPECT_EQ(spread.fraction, 0.25);
  for (const char* text : {"none", "documented", "0.1", "0.5"}) {
    EXPECT_EQ(PhysicsVariation::parse(PhysicsVariation::parse(text).to_string()).to_string(),
              PhysicsVariation::parse(text).to_string());
  }
  for (const char* bad : {"", "0", "-0.1", "0.6", "nan", "0.1x", "Documented", "1e999"}) {
    try {
      PhysicsVariation::parse(bad, "vary");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const FieldError& e) {
      EXPECT_EQ(e.field(), "vary");
      EXPECT_NE(std::string(e.what()).find("'" + std::string(bad) + "'"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("documented"), std::string::npos) << e.what();
    }
  }
}

SceneParameters physical_scene() {
  SceneParameters p;
  p.tracer.use_physical_drag();
  p.cotton.use_physical_drag();
  return p;
}

// Over many objects every varied key of both types stays in its documented range and fills it
// (uniform: the mean within 4 standard errors of the middle, both ends reached within 1 %); the
// area and the diameter stay the type's.
TEST(PhysicsVariation, DocumentedDrawsAreUniformOverTheDocumentedRanges) {
  const SceneParameters scene = physical_scene();
  const PhysicsVariation documented = PhysicsVariation::parse("documented");
  constexpr int kN = 4000;
  for (const ObjectType type : {ObjectType::kTracer, ObjectType::kCotton}) {
    const ObjectTypeParameters& base = scene.of(type);
    std::vector<std::vector<double>> values(kObjectPhysicsKeyCount);
    for (int i = 0; i < kN; ++i) {
      const ObjectTypeParameters p = draw_object_physics(documented, type, base, 17, i);
      EXPECT_EQ(p.diameter_m, base.diameter_m);
      EXPECT_EQ(p.frontal_area_m2, base.frontal_area_m2);
      EXPECT_EQ(p.drag_law, DragLaw::kPhysical);
      EXPECT_EQ(p.kinetic_friction, p.physical_kinetic_friction);  // the law's friction is set
      for (const ObjectPhysicsSpec& s : object_physics_catalogue()) {
        values[static_cast<size_t>(s.id)].push_back(object_physics_value(p, s.id));
      }
    }
    for (const ObjectPhysicsSpec& s : object_physics_catalogue()) {
      const DocumentedPhysicsRange& r = documented_physics_range(type, s.id);
      const std::vector<double>& v = values[static_cast<size_t>(s.id)];
      if (!r.varied) continue;
      const double width = r.max - r.min;
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      EXPECT_GE(*lo, r.min) << s.key;
      EXPECT_LE(*hi, r.max) << s.key;
      EXPECT_LT(*lo, r.min + 0.01 * width) << s.key;
      EXPECT_GT(*hi, r.max - 0.01 * width) << s.key;
      double mean = 0.0;
      for (double x : v) mean += x / kN;
      const double standard_error = width / std::sqrt(12.0 * kN);
      EXPECT_NEAR(mean, 0.5 * (r.min + r.max), 4.0 * standard_error) << s.key;
    }
  }
  // The ranges are those docs/twin.md gives: the hemisphere's C_D, masses +-10 % of the paper's.
  EXPECT_EQ(documented_physics_range(ObjectType::kTracer, ObjectPhysicsKey::kDragCoefficient).min,
            0.34);
  EXPECT_NEAR(documented_physics_range(ObjectType::kCotton, ObjectPhysicsKey::kMass).max,
              1.1 * 0.22, 1e-12);
  EXPECT_FALSE(
      documented_physics_range(ObjectType::kCotton, ObjectPhysicsKey::kFrontalArea).varied);
}

// A spread F keeps each varied value within +-F of the type's and centred on it.
TEST(PhysicsVariation, SpreadDrawsStayWithinTheirShareOfTheTypesValue) {
  const SceneParameters scene = physical_scene();
  const PhysicsVariation spread = PhysicsVariation::parse("0.1");
  constexpr int kN = 4000;
  const ObjectTypeParameters& base = scene.cotton;
  for (const ObjectPhysicsSpec& s : object_physics_catalogue()) {
    const double centre = object_physics_value(base, s.id);
    double mean = 0.0, lo = centre, hi = centre;
    for (int i = 0; i < kN; ++i) {
      const double x =
          object_physics_value(draw_object_physics(spread, ObjectType::kCotton, base, 3, i), s.id);
      mean += x / kN;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    if (!documented_physics_range(ObjectType::kCotton, s.id).varied) {
      EXPECT_EQ(lo, centre) << s.key;
      EXPECT_EQ(hi, centre) << s.key;
      continue;
    }
    EXPECT_GE(lo, 0.9 * centre * (1 - 1e-12)) << s.key;
    EXPECT_LE(hi, 1.1 * centre * (1 + 1e-12)) << s.key;
    EXPECT_LT(lo, 0.905 * centre) << s.key;
    EXPECT_GT(hi, 1.095 * centre) << s.key;
    EXPECT_NEAR(mean, centre, 4.0 * 0.2 * centre / std::sqrt(12.0 * kN)) << s.key;
  }
}

// Under eq. (8)'s law only the mass varies, and it is the mass the physical law draws for the
// same object: every key takes its number from the stream whether it is varied or not.
TEST(PhysicsVariation, UnderEquationEightOnlyTheMassVariesAndItIsTheSameDraw) {
  const SceneParameters eq8;
  const SceneParameters physical = physical_scene();
  const PhysicsVariation documented = PhysicsVariation::parse("documented");
  for (int i = 0; i < 20; ++i) {
    const ObjectTypeParameters a =
        draw_object_physics(documented, ObjectType::kTracer, eq8.tracer, 5, i);
    const ObjectTypeParameters b =
        draw_object_physics(documented, ObjectType::kTracer, physical.tracer, 5, i);
    EXPECT_EQ(a.mass_kg, b.mass_kg);
    EXPECT_NE(a.mass_kg, eq8.tracer.mass_kg);
    ObjectTypeParameters same = a;
    same.mass_kg = eq8.tracer.mass_kg;
    EXPECT_EQ(object_physics_to_string(same, ObjectType::kTracer),
              object_physics_to_string(eq8.tracer, ObjectType::kTracer));
    EXPECT_EQ(same.drag_rate_per_s, eq8.tracer.drag_rate_per_s);
    EXPECT_EQ(same.static_friction_ratio, eq8.tracer.static_friction_ratio);
  }
}

// One stream per (seed, object): the same pair gives the same bytes, another object or seed
// another object; an inactive variation changes nothing.
TEST(PhysicsVariation, EachObjectsDrawComesFromTheSeedAndItsIndex) {
  const SceneParameters scene = physical_scene();
  const PhysicsVariation spread = PhysicsVariation::parse("0.2");
  auto text = [&](uint64_t seed, uint64_t i) {
    return object_physics_to_string(
        draw_object_physics(spread, ObjectType::kTracer, scene.tracer, seed, i),
        ObjectType::kTracer);
  };
  EXPECT_EQ(text(8, 2), text(8, 2));
  EXPECT_NE(text(8, 2), text(8, 3));
  EXPECT_NE(text(8, 2), text(9, 2));
  EXPECT_EQ(object_physics_to_string(
                draw_object_physics(PhysicsVariation{}, ObjectType::kTracer, scene.tracer, 8, 2),
                ObjectType::kTracer),
            object_physics_to_string(scene.tracer, ObjectType::kTracer));

  SceneSpec spec;
  spec.source = "two.yaml";
  spec.objects = {{"a", "tracer", {0.0, 0.3}, 0.0}, {"b", "cotton", {0.3, 0.3}, 0.0}};
  SceneSpec unchanged = spec;
  vary_object_physics(PhysicsVariation{}, scene, 8, &unchanged);
  EXPECT_FALSE(unchanged.objects[0].physics || unchanged.objects[1].physics);
  vary_object_physics(spread, scene, 8, &spec);
  ASSERT_TRUE(spec.objects[0].physics && spec.objects[1].physics);
  EXPECT_EQ(object_physics_to_string(*spec.objects[0].physics, ObjectType::kTracer), text(8, 0));
  EXPECT_EQ(
      object_physics_to_string(*spec.objects[1].physics, ObjectType::kCotton),
      object_physics_to_string(draw_object_physics(spread, ObjectType::kCotton, scene.cotton, 8, 1),
                               ObjectType::kCotton));
  spec.objects[1].type = "foam";
  try {
    vary_object_physics(spread, scene, 8, &spec);
    ADD_FAILURE() << "an unknown type was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two.yaml objects[1]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace airtwin
