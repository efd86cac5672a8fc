#include "sim/object_physics.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "common/errors.h"
#include "common/text.h"

namespace airtwin {
namespace {

// Ranges: wide physical bounds, not calibration windows (those are in docs/twin.md). Mass: light
// objects a jet can move (0.01 g to 100 g); C_D: streamlined to a flat plate's ~2 with margin;
// area: a grain to a palm; friction: PTFE-like 0.02 to rubber's ~2; static/kinetic 1 to 5; lift:
// none to beyond a hemisphere's potential-flow 0.69.
const std::array<ObjectPhysicsSpec, kObjectPhysicsKeyCount> kCatalogue = {{
    {ObjectPhysicsKey::kMass, "mass_g", "g", 1e-3, 0.01, 100.0, false, "mass"},
    {ObjectPhysicsKey::kDragCoefficient, "cd", "", 1.0, 0.05, 3.0, true,
     "drag coefficient C_D at high Re, on the frontal area"},
    {ObjectPhysicsKey::kFrontalArea, "area_cm2", "cm^2", 1e-4, 0.1, 200.0, true,
     "frontal area A the horizontal air meets"},
    {ObjectPhysicsKey::kKineticFriction, "mu_k", "", 1.0, 0.02, 2.0, true,
     "kinetic (Coulomb) friction against the floor"},
    {ObjectPhysicsKey::kStaticRatio, "mu_s_ratio", "", 1.0, 1.0, 5.0, false,
     "static / kinetic friction"},
    {ObjectPhysicsKey::kLiftCoefficient, "cl", "", 1.0, 0.0, 1.0, true,
     "lift coefficient C_L on the footprint area"},
}};

std::string keys() {
  std::string out;
  for (const ObjectPhysicsSpec& s : kCatalogue)
    out += (out.empty() ? "" : ", ") + std::string(s.key);
  return out;
}

std::string range_text(const ObjectPhysicsSpec& s) {
  std::string out = "[";
  out += format_number(s.min);
  out += ", ";
  out += format_number(s.max);
  out += ']';
  if (*s.unit != '\0') {
    out += ' ';
    out += s.unit;
  }
  return out;
}

}  // namespace

const std::array<ObjectPhysicsSpec, kObjectPhysicsKeyCount>& object_physics_catalogue() {
  return kCatalogue;
}

double object_physics_value(const ObjectTypeParameters& p, ObjectPhysicsKey key) {
  const double si_per_unit = kCatalogue[static_cast<size_t>(key)].si_per_unit;
  switch (key) {
    case ObjectPhysicsKey::kMass:
      return p.mass_kg / si_per_unit;
    case ObjectPhysicsKey::kDragCoefficient:
      return p.drag_coefficient;
    case ObjectPhysicsKey::kFrontalArea:
      return p.frontal_area_m2 / si_per_unit;
    case ObjectPhysicsKey::kKineticFriction:
      return p.physical_kinetic_friction;
    case ObjectPhysicsKey::kStaticRatio:
      return p.static_friction_ratio;
    case ObjectPhysicsKey::kLiftCoefficient:
      return p.lift_coefficient;
  }
  return 0.0;
}

void set_object_physics_value(ObjectPhysicsKey key, double typed, ObjectTypeParameters* p) {
  AIRTWIN_DEMAND(p != nullptr);
  const double si = typed * kCatalogue[static_cast<size_t>(key)].si_per_unit;
  switch (key) {
    case ObjectPhysicsKey::kMass:
      p->mass_kg = si;
      break;
    case ObjectPhysicsKey::kDragCoefficient:
      p->drag_coefficient = si;
      break;
    case ObjectPhysicsKey::kFrontalArea:
      p->frontal_area_m2 = si;
      break;
    case ObjectPhysicsKey::kKineticFriction:
      p->physical_kinetic_friction = si;
      if (p->drag_law == DragLaw::kPhysical) p->kinetic_friction = si;
      break;
    case ObjectPhysicsKey::kStaticRatio:
      p->static_friction_ratio = si;
      break;
    case ObjectPhysicsKey::kLiftCoefficient:
      p->lift_coefficient = si;
      break;
  }
}

void apply_drag_law(const std::string& law, SceneParameters* scene) {
  if (law == "physical") {
    scene->tracer.use_physical_drag();
    scene->cotton.use_physical_drag();
  } else if (law != "eq8") {
    throw FieldError("drag", "expected eq8 or physical, got '" + law + "'");
  }
}

void apply_object_physics(const std::string& text, SceneParameters* scene) {
  AIRTWIN_DEMAND(scene != nullptr);
  const std::string where = "object physics '" + text + "'";
  const size_t colon = text.find(':');
  const std::string type = trim_blanks(text.substr(0, colon));
  ObjectTypeParameters* p = type == "tracer"   ? &scene->tracer
                            : type == "cotton" ? &scene->cotton
                                               : nullptr;
  if (p == nullptr || colon == std::string::npos) {
    throw InputError(where + ": expected TYPE:key=value,... with TYPE tracer or cotton and keys " +
                     keys());
  }
  const std::string list = text.substr(colon + 1);
  std::set<std::string> seen;
  for (size_t start = 0;;) {
    const size_t comma = list.find(',', start);
    const std::string item = trim_blanks(list.substr(start, comma - start));
    const size_t equals = item.find('=');
    if (equals == std::string::npos) {
      throw InputError(where + ": expected key=value, got '" + item + "'; keys: " + keys());
    }
    const std::string key = trim_blanks(item.substr(0, equals));
    const std::string value_text = trim_blanks(item.substr(equals + 1));
    const ObjectPhysicsSpec* spec = nullptr;
    for (const ObjectPhysicsSpec& s : kCatalogue) {
      if (key == s.key) spec = &s;
    }
    if (spec == nullptr) {
      throw InputError(where + ": unknown key '" + key + "'; keys: " + keys());
    }
    if (!seen.insert(key).second) {
      throw InputError(where + ": " + type + "." + key + " is given twice");
    }
    errno = 0;
    char* end = nullptr;
    const double value = std::strtod(value_text.c_str(), &end);
    if (value_text.empty() || end != value_text.c_str() + value_text.size() || errno == ERANGE ||
        !(value >= spec->min && value <= spec->max)) {
      throw InputError(where + ": " + type + "." + key + " must be a number in " +
                       range_text(*spec) + ", got '" + value_text + "'");
    }
    if (spec->physical_law_only && p->drag_law != DragLaw::kPhysical) {
      throw InputError(where + ": " + type + "." + key +
                       " belongs to the physical drag law, and this type's law is eq. (8)");
    }
    set_object_physics_value(spec->id, value, p);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
}

std::string object_physics_to_string(const SceneParameters& scene, ObjectType type) {
  return object_physics_to_string(scene.of(type), type);
}

std::string object_physics_to_string(const ObjectTypeParameters& p, ObjectType type) {
  std::string out = object_type_name(type);
  char sep = ':';
  for (const ObjectPhysicsSpec& s : kCatalogue) {
    if (s.physical_law_only && p.drag_law != DragLaw::kPhysical) continue;
    out += sep;
    out += s.key;
    out += '=';
    out += format_number(object_physics_value(p, s.id));
    sep = ',';
  }
  return out;
}

std::string object_physics_help() {
  std::string out;
  for (const ObjectPhysicsSpec& s : kCatalogue) {
    out += "  " + std::string(s.key) + " " + range_text(s) + ": " + s.meaning +
           (s.physical_law_only ? " (physical drag only)" : "") + "\n";
  }
  return out;
}

}  // namespace airtwin
