#include "sim/physics_variation.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>

#include "common/errors.h"
#include "common/random_stream.h"
#include "common/text.h"
#include "sim/scene_builder.h"

namespace airtwin {
namespace {

using Ranges = std::array<DocumentedPhysicsRange, kObjectPhysicsKeyCount>;

// Indexed by ObjectPhysicsKey (mass, C_D, area, mu_k, mu_s / mu_k, C_L); the sources are those of
// docs/twin.md, "Physical drag".
const std::array<Ranges, 2> kDocumented = {{
    // Tracer: polystyrene hemisphere, 3 cm, 0.16 g.
    {{{true, 0.144, 0.176, "the paper's 0.16 g +-10 %"},
      {true, 0.34, 0.42, "hemisphere, convex side to the flow (Hoerner 1965)"},
      {false, 0.0, 0.0, "geometry"},
      {true, 0.3, 0.5, "polystyrene foam on a smooth hard floor"},
      {true, 1.0, 1.4, "foam on a hard floor"},
      {true, 0.0, 0.3, "a hemisphere on a floor, its separated flow (the calibration's window)"}}},
    // Cotton wad: ~5 cm, 0.22 g.
    {{{true, 0.198, 0.242, "the paper's 0.22 g +-10 %"},
      {true, 0.3, 1.2, "a porous fibre wad, below a solid bluff body's ~1"},
      {false, 0.0, 0.0, "geometry"},
      {true, 0.3, 0.6, "cotton fibre on a smooth hard floor"},
      {true, 1.0, 1.4, "fibres on a hard floor"},
      {true, 0.0, 0.3, "a porous wad lets air through and under it"}}},
}};

size_t type_index(ObjectType type) { return type == ObjectType::kTracer ? 0 : 1; }

}  // namespace

PhysicsVariation PhysicsVariation::parse(const std::string& text, const std::string& field) {
  const std::string t = trim_blanks(text);
  PhysicsVariation v;
  if (t == "none") return v;
  if (t == "documented") {
    v.kind = Kind::kDocumented;
    return v;
  }
  errno = 0;
  char* end = nullptr;
  const double f = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || errno == ERANGE || !(f > 0.0 && f <= 0.5)) {
    throw FieldError(field,
                     "expected none, documented or a spread in (0, 0.5] (0.1: each "
                     "parameter within +-10 % of its type's), got '" +
                         text + "'");
  }
  v.kind = Kind::kRelative;
  v.fraction = f;
  return v;
}

std::string PhysicsVariation::to_string() const {
  switch (kind) {
    case Kind::kNone:
      return "none";
    case Kind::kDocumented:
      return "documented";
    case Kind::kRelative:
      return format_number(fraction);
  }
  return "none";
}

const DocumentedPhysicsRange& documented_physics_range(ObjectType type, ObjectPhysicsKey key) {
  return kDocumented[type_index(type)][static_cast<size_t>(key)];
}

ObjectTypeParameters draw_object_physics(const PhysicsVariation& variation, ObjectType type,
                                         const ObjectTypeParameters& type_params, uint64_t seed,
                                         uint64_t object_index) {
  ObjectTypeParameters p = type_params;
  if (!variation.active()) return p;
  RandomStream stream(seed, RandomPurpose::kObjectPhysics, object_index);
  const bool physical = type_params.drag_law == DragLaw::kPhysical;
  for (const ObjectPhysicsSpec& spec : object_physics_catalogue()) {
    const double u = stream.uniform(0.0, 1.0);  // drawn for every key: see the header
    const DocumentedPhysicsRange& range = documented_physics_range(type, spec.id);
    if (!range.varied || (!physical && spec.id != ObjectPhysicsKey::kMass)) continue;
    double value = 0.0;
    if (variation.kind == PhysicsVariation::Kind::kDocumented) {
      value = range.min + u * (range.max - range.min);
    } else {
      value =
          object_physics_value(type_params, spec.id) * (1.0 + variation.fraction * (2.0 * u - 1.0));
    }
    set_object_physics_value(spec.id, std::clamp(value, spec.min, spec.max), &p);
  }
  return p;
}

void vary_object_physics(const PhysicsVariation& variation, const SceneParameters& params,
                         uint64_t seed, SceneSpec* spec) {
  AIRTWIN_DEMAND(spec != nullptr);
  if (!variation.active()) return;
  for (size_t i = 0; i < spec->objects.size(); ++i) {
    ObjectSpec& o = spec->objects[i];
    const ObjectType type =
        parse_object_type(o.type, spec->source + " objects[" + std::to_string(i) + "]");
    o.physics = draw_object_physics(variation, type, params.of(type), seed, i);
  }
}

}  // namespace airtwin
