#include "models/effect_catalogue.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/errors.h"
#include "common/text.h"

namespace airtwin {

const std::array<EffectSpec, kEffectCount>& effect_catalogue() {
  // Examples are realistic magnitudes for the rig; fit ranges cover what a rig plausibly shows.
  //                key          unit     example off   switches min    max    fit_min fit_max
  static const std::array<EffectSpec, kEffectCount> catalogue = {{
      {EffectId::kPressureGradient,
       "pressure_gradient",
       "the jet's stagnation pressure pushes objects outward near s, beyond the air's drag",
       "extra outward push near s, peak acceleration `strength` at r = length / sqrt(2)",
       {{"strength", "m/s^2", 4.0, 0.0, true, 0.0, 50.0, 0.0, 40.0},
        {"length", "m", 0.15, 0.15, false, 0.01, 1.0, 0.03, 0.5}},
       1.0},  // m/s^2: an eighth of tracer friction
      {EffectId::kResponseDelay,
       "response_delay",
       "the air on the floor answers a new nozzle orientation later than servo travel and transit",
       "the field follows the nozzle tau_s later (on top of the default 0.2 s)",
       {{"tau_s", "s", 0.3, 0.0, true, 0.0, 5.0, 0.0, 1.5}},
       0.05},  // s: two camera frames
      {EffectId::kFlowDeflection,
       "flow_deflection",
       "the wall jet swirls: the air moves at an angle to the radial direction from s",
       "air turned from radial by angle_deg (counter-clockwise +), same speed",
       {{"angle_deg", "deg", 15.0, 0.0, true, -90.0, 90.0, -45.0, 45.0}},
       3.0},
      {EffectId::kQuadraticDrag,
       "quadratic_drag",
       "drag grows with the square of the relative air speed (a higher Reynolds number regime)",
       "extra drag acceleration coefficient |u_rel| u_rel, u_rel = u_air - v",
       {{"coefficient", "1/m", 0.5, 0.0, true, 0.0, 20.0, 0.0, 5.0}},
       0.1,  // 1/m: 10 % of linear drag at ~1 m/s
       true},
      {EffectId::kFloorSlope,
       "floor_slope",
       "the floor is not level: gravity pulls objects downhill",
       "floor tilted by angle_deg, downhill toward direction_deg (from +x, CCW)",
       {{"angle_deg", "deg", 2.0, 0.0, true, 0.0, 30.0, 0.0, 10.0},
        {"direction_deg", "deg", 0.0, 0.0, false, -360.0, 360.0, -180.0, 180.0}},
       0.5},  // deg: a level floor's tolerance
      {EffectId::kStiction,
       "stiction",
       "static friction exceeds kinetic friction: objects at rest need more air to start",
       "static / kinetic friction ratio of every object (replaces the twin's own)",
       {{"ratio", "", 2.0, 1.0, true, 1.0, 10.0, 1.0, 5.0}},
       0.3},  // up to 1.3 is ordinary for dry contacts and absorbed by eq. (8)'s xi3
      {EffectId::kNozzleOffset,
       "nozzle_offset",
       "the servos' calibration is biased: the nozzle points elsewhere than commanded",
       "servo calibration bias: the nozzle turns to command + offset",
       {{"pan_deg", "deg", 3.0, 0.0, true, -30.0, 30.0, -15.0, 15.0},
        {"tilt_deg", "deg", 2.0, 0.0, true, -10.0, 10.0, -8.0, 8.0}},
       1.0},
      {EffectId::kFieldScale,
       "field_scale",
       "the air on the floor is faster or slower than the field table says",
       "air speed times factor (stagnation pressure times factor^2)",
       {{"factor", "", 1.2, 1.0, true, 0.05, 3.0, 0.3, 2.5}},
       0.05},  // within the field table's own fit error
      {EffectId::kTransportLag,
       "transport_lag",
       "a new nozzle orientation's air spreads from its stagnation point as the wall jet's front: "
       "farther objects feel a re-aim later",
       "each object feels the orientation whose air, spreading from s at 1 / pace, has reached it",
       {{"pace_s_per_m", "s/m", 0.6, 0.0, true, 0.0, 5.0, 0.0, 2.0}},
       0.1},  // s/m: 0.04 s at 0.4 m from s, about a camera frame
      {EffectId::kAirLift,
       "air_lift",
       "the air flowing past an object lifts it, unloading its contact: friction falls as the "
       "relative air speed grows",
       "upward lift of lift_s2_per_m2 |u_rel|^2 times each object's weight, u_rel = u_air - v",
       {{"lift_s2_per_m2", "s^2/m^2", 0.05, 0.0, true, 0.0, 1.0, 0.0, 0.2}},
       0.01,  // s^2/m^2: 4 % of friction at 2 m/s of relative air
       true},
      {EffectId::kLinearisedDrag,
       "linearised_drag",
       "eq. (8)'s linear drag is the tangent of a quadratic drag at a working relative air speed "
       "and its friction holds the tangent's intercept: slower relative air pushes harder, and an "
       "object that outruns the air coasts farther",
       "eq. (8)'s drag c (k u - v) turns into the quadratic it is the tangent of, whose intercept "
       "takes intercept_share of the friction (eq. (8)'s law only)",
       {{"intercept_share", "", 0.5, 0.0, true, 0.0, 0.95, 0.0, 0.9}},
       0.05,  // 5 % of the friction
       true},
  }};
  return catalogue;
}

const EffectSpec& effect_spec(EffectId id) {
  const EffectSpec& spec = effect_catalogue()[static_cast<size_t>(id)];
  AIRTWIN_DEMAND(spec.id == id);
  return spec;
}

std::string effect_names() {
  std::string names;
  for (const EffectSpec& e : effect_catalogue()) {
    if (!names.empty()) names += ", ";
    names += e.name;
  }
  return names;
}

const EffectSpec& find_effect(const std::string& name) {
  const size_t at = name.find('@');
  const std::string base = name.substr(0, at);
  for (const EffectSpec& e : effect_catalogue()) {
    if (base != e.name) continue;
    if (at == std::string::npos) return e;
    if (!e.per_type) {
      throw InputError("effect " + base + " acts on the rig, not on one object type: write '" +
                       base + "' without '@" + name.substr(at + 1) +
                       "' (per type: " + per_type_effect_names() + ")");
    }
    const std::string type = name.substr(at + 1);
    if (type.empty() || type.find_first_of("@:, \t") != std::string::npos) {
      throw InputError("effect '" + name + "': expected " + base +
                       "@TYPE with TYPE an object type (tracer, cotton)");
    }
    return e;
  }
  throw InputError("unknown effect '" + base + "'; valid effects: " + effect_names());
}

std::string effect_object_type(const std::string& name) {
  find_effect(name);
  const size_t at = name.find('@');
  return at == std::string::npos ? std::string() : name.substr(at + 1);
}

std::string per_type_effect_names() {
  std::string names;
  for (const EffectSpec& e : effect_catalogue()) {
    if (!e.per_type) continue;
    if (!names.empty()) names += ", ";
    names += e.name;
  }
  return names;
}

size_t effect_parameter_index(const EffectSpec& spec, const std::string& key) {
  std::string keys;
  for (size_t i = 0; i < spec.params.size(); ++i) {
    if (key == spec.params[i].key) return i;
    if (!keys.empty()) keys += ", ";
    keys += spec.params[i].key;
  }
  throw InputError("effect " + std::string(spec.name) + " has no parameter '" + key +
                   "'; its parameters: " + keys);
}

std::string effect_range_text(const EffectParameter& p) {
  // Appended piece by piece: GCC 12 -O3 reports a false -Wrestrict on "x" + std::string.
  std::string text = "[";
  text += format_number(p.min);
  text += ", ";
  text += format_number(p.max);
  text += ']';
  if (p.unit[0] != '\0') {
    text += ' ';
    text += p.unit;
  }
  return text;
}

void check_effect_value(const EffectSpec& spec, const EffectParameter& p, double value) {
  if (!(std::isfinite(value) && value >= p.min && value <= p.max)) {
    throw InputError(std::string(spec.name) + "." + p.key + " must be a finite number in " +
                     effect_range_text(p) + ", got " + format_number(value));
  }
}

double effect_size(const EffectSpec& spec, const std::vector<double>& typed) {
  AIRTWIN_DEMAND(typed.size() == spec.params.size());
  double size = 0.0;
  for (size_t i = 0; i < typed.size(); ++i) {
    if (spec.params[i].switches) size = std::max(size, std::abs(typed[i] - spec.params[i].off));
  }
  return size;
}

}  // namespace airtwin
