#pragma once
// The physical parameters of an object type that a person may set, defined once: key, typed unit,
// physical range, the SI field of ObjectTypeParameters it sets, and whether only the physical drag
// law (DragLaw::kPhysical) has it. Typed as "TYPE:key=value,..." (e.g. "tracer:cd=0.38,mu_k=0.5"),
// in the units below; inside, SI:
//
//   mass_g       g      the object's mass                          ObjectTypeParameters::mass_kg
//   cd           -      C_D of the physical drag law (high Re)     drag_coefficient
//   area_cm2     cm^2   frontal area A of the physical drag law    frontal_area_m2
//   mu_k         -      kinetic friction with physical drag        physical_kinetic_friction
//   mu_s_ratio   -      static / kinetic friction                  static_friction_ratio
//   cl           -      lift coefficient on the footprint area     lift_coefficient
//
// These are what the calibration of physical drag tunes (docs/twin.md); eq. (8)'s coefficients
// are not among them.

#include <array>
#include <cstddef>
#include <string>

#include "sim/scene_spec.h"

namespace airtwin {

enum class ObjectPhysicsKey {
  kMass,
  kDragCoefficient,
  kFrontalArea,
  kKineticFriction,
  kStaticRatio,
  kLiftCoefficient
};
inline constexpr size_t kObjectPhysicsKeyCount = 6;

struct ObjectPhysicsSpec {
  ObjectPhysicsKey id;
  const char* key;
  const char* unit;    ///< typed unit, "" when dimensionless
  double si_per_unit;  ///< SI value = typed value * si_per_unit
  double min, max;     ///< physical range, typed units, closed
  bool physical_law_only;
  const char* meaning;
};

/// The catalogue, indexed by ObjectPhysicsKey.
const std::array<ObjectPhysicsSpec, kObjectPhysicsKeyCount>& object_physics_catalogue();

/// The value of `key` in `p`, in the key's typed unit.
double object_physics_value(const ObjectTypeParameters& p, ObjectPhysicsKey key);

/// Sets `key` of `p` from a typed value (no checks; see apply_object_physics).
void set_object_physics_value(ObjectPhysicsKey key, double typed, ObjectTypeParameters* p);

/// Sets every object type's drag law in `scene` by name: "eq8" (eq. (8) read as physics, the
/// default) or "physical" (ObjectTypeParameters::use_physical_drag). Throws FieldError on field
/// "drag" for any other name.
void apply_drag_law(const std::string& law, SceneParameters* scene);

/// Parses "TYPE:key=value,..." and sets those parameters of that object type in `scene`. Throws
/// InputError naming the text and the key: an unknown type or key (listing the valid ones), a key
/// given twice, a value that is not a finite number or is outside its range (stating range and
/// unit), or a key of the physical drag law for a type whose law is eq. (8).
void apply_object_physics(const std::string& text, SceneParameters* scene);

/// Every settable parameter of `type` in `scene`, "type:key=value,..." in catalogue order (the
/// physical law's keys only when the type uses it), for recording what a run used.
std::string object_physics_to_string(const SceneParameters& scene, ObjectType type);
/// The same for the parameters `p` of one object of `type`.
std::string object_physics_to_string(const ObjectTypeParameters& p, ObjectType type);

/// One line per key: unit, range, meaning (for --help).
std::string object_physics_help();

}  // namespace airtwin
