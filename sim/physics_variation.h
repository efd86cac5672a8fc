#pragma once
// Objects of one type that differ: each object of a run gets its own physical parameters, drawn
// from the run's seed, instead of its type's calibrated set (domain randomisation). Two ways:
//
//   documented  each parameter uniform over the range docs/twin.md gives for the type: the
//               literature's values for a hemisphere and a fibre wad, masses within +-10 % of
//               the paper's (what the calibration is allowed to move them by)
//   F           each parameter uniform within +-F (0 < F <= 0.5) of the type's present value:
//               a batch of objects made alike, F their spread
//
// Varied: mass, C_D, kinetic friction, the static / kinetic ratio and C_L (sim/object_physics.h);
// under eq. (8)'s law only the mass (its drag and friction are eq. (8)'s coefficients, which
// are no object's property). The frontal area and the diameter stay the type's: they are the
// geometry. A drawn value is kept inside the catalogue's physical range (the ratio >= 1).
//
// Each object has its own random stream (RandomPurpose::kObjectPhysics, its index), which draws
// one number per catalogue key in catalogue order whether the key is varied or not: the same seed
// gives the same objects under either law and whatever else the run does with its seed.

#include <cstdint>
#include <string>

#include "sim/object_physics.h"
#include "sim/scene_spec.h"

namespace airtwin {

/// How the objects of a run differ from their type.
struct PhysicsVariation {
  enum class Kind { kNone, kDocumented, kRelative };
  Kind kind = Kind::kNone;
  double fraction = 0.0;  ///< kRelative: +- this share of the type's value, in (0, 0.5]

  bool active() const { return kind != Kind::kNone; }
  /// "none", "documented" or a fraction in (0, 0.5] ("0.1"); FieldError on field `field` naming
  /// the text and what was expected otherwise.
  static PhysicsVariation parse(const std::string& text,
                                const std::string& field = "physics_variation");
  /// The text parse() reads back to this variation.
  std::string to_string() const;
};

/// The documented range of one key for one object type (typed units, sim/object_physics.h), and
/// where it comes from. `varied` is false for the keys that stay the type's (the area).
struct DocumentedPhysicsRange {
  bool varied = false;
  double min = 0.0, max = 0.0;
  const char* source = "";
};

/// The table, indexed by type and key.
const DocumentedPhysicsRange& documented_physics_range(ObjectType type, ObjectPhysicsKey key);

/// One object's parameters drawn as `variation` says from `type_params` (its type's), with the
/// stream of (seed, object_index).
ObjectTypeParameters draw_object_physics(const PhysicsVariation& variation, ObjectType type,
                                         const ObjectTypeParameters& type_params, uint64_t seed,
                                         uint64_t object_index);

/// Gives every object of `spec` its own parameters (ObjectSpec::physics) drawn from `seed`; an
/// inactive variation leaves `spec` as it is. InputError naming the object for an unknown type.
void vary_object_physics(const PhysicsVariation& variation, const SceneParameters& params,
                         uint64_t seed, SceneSpec* spec);

}  // namespace airtwin
