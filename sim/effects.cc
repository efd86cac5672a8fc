#include "sim/effects.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "common/errors.h"
#include "common/text.h"
#include "common/units.h"

namespace airtwin {
namespace {

// Runs `f`, prefixing any InputError's message with `where`.
template <typename F>
decltype(auto) located(const std::string& where, F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
}

// Every parameter of `effect` resolved (typed or the catalogue's example), checked, in catalogue
// order.
std::vector<double> resolve(const Effect& effect) {
  const std::string where = "effect " + effect.name;
  const EffectSpec& spec =
      located(where, [&]() -> const EffectSpec& { return find_effect(effect.name); });
  std::vector<double> values;
  for (const EffectParameter& p : spec.params) values.push_back(p.example);
  std::set<std::string> seen;
  for (const auto& [key, value] : effect.params) {
    const size_t i = located(where, [&, &key = key] { return effect_parameter_index(spec, key); });
    if (!seen.insert(key).second) {
      throw InputError(where + ": parameter '" + key + "' is given twice");
    }
    located(where, [&, value = value] { check_effect_value(spec, spec.params[i], value); });
    values[i] = value;
  }
  return values;
}

std::string keys_of(const EffectSpec& spec) {
  std::string keys;
  for (const EffectParameter& p : spec.params)
    keys += (keys.empty() ? "" : ", ") + std::string(p.key);
  return keys;
}

}  // namespace

Effect parse_effect(const std::string& text) {
  const std::string where = "effect '" + text + "'";
  Effect effect;
  const size_t colon = text.find(':');
  effect.name = trim_blanks(text.substr(0, colon));
  if (effect.name.empty()) {
    throw InputError(where +
                     ": expected NAME or NAME:key=value,...; valid effects: " + effect_names());
  }
  const EffectSpec& spec =
      located(where, [&]() -> const EffectSpec& { return find_effect(effect.name); });
  const std::string type = effect_object_type(effect.name);
  if (!type.empty() && type != object_type_name(ObjectType::kTracer) &&
      type != object_type_name(ObjectType::kCotton)) {
    throw InputError(where + ": unknown object type '" + type + "' (expected tracer or cotton)");
  }
  if (colon != std::string::npos) {
    // key=value pairs, comma-separated; every value a whole finite number.
    const std::string list = text.substr(colon + 1);
    size_t start = 0;
    std::set<std::string> seen;
    while (true) {
      const size_t comma = list.find(',', start);
      const std::string item = trim_blanks(list.substr(start, comma - start));
      const size_t equals = item.find('=');
      if (equals == std::string::npos) {
        throw InputError(where + ": expected key=value after '" + effect.name + ":', got '" + item +
                         "'; parameters of " + effect.name + ": " + keys_of(spec));
      }
      const std::string key = trim_blanks(item.substr(0, equals));
      const std::string value_text = trim_blanks(item.substr(equals + 1));
      const size_t i = located(where, [&] { return effect_parameter_index(spec, key); });
      const EffectParameter& p = spec.params[i];
      if (!seen.insert(key).second) {
        throw InputError(where + ": parameter '" + key + "' of " + effect.name + " is given twice");
      }
      errno = 0;
      char* end = nullptr;
      const double value = std::strtod(value_text.c_str(), &end);
      if (value_text.empty() || end != value_text.c_str() + value_text.size() || errno == ERANGE) {
        throw InputError(where + ": " + effect.name + "." + key + " must be a finite number in " +
                         effect_range_text(p) + ", got '" + value_text + "'");
      }
      located(where, [&] { check_effect_value(spec, p, value); });
      effect.params.emplace_back(key, value);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return effect;
}

double effect_parameter(const Effect& effect, const std::string& key) {
  const std::vector<double> values = resolve(effect);
  const EffectSpec& spec = find_effect(effect.name);
  return values[located("effect " + effect.name,
                        [&] { return effect_parameter_index(spec, key); })];
}

std::string effect_to_string(const Effect& effect) {
  const std::vector<double> values = resolve(effect);
  const EffectSpec& spec = find_effect(effect.name);
  std::string out = effect.name;
  for (size_t i = 0; i < spec.params.size(); ++i) {
    // Appended piece by piece: GCC 12 -O3 reports a false -Wrestrict on "x" + std::string.
    out += i == 0 ? ':' : ',';
    out += spec.params[i].key;
    out += '=';
    out += format_number(values[i]);
  }
  return out;
}

void apply_effect(const Effect& effect, TwinParameters* params) {
  AIRTWIN_DEMAND(params != nullptr);
  const std::vector<double> v = resolve(effect);
  // An object's own effect acts on its type's objects (NAME@TYPE) or on every type's (NAME).
  std::vector<ObjectTypeParameters*> types;
  const std::string type = effect_object_type(effect.name);
  if (type.empty() || type == object_type_name(ObjectType::kTracer)) {
    types.push_back(&params->scene.tracer);
  }
  if (type.empty() || type == object_type_name(ObjectType::kCotton)) {
    types.push_back(&params->scene.cotton);
  }
  if (types.empty()) {
    throw InputError("effect " + effect.name + ": unknown object type '" + type +
                     "' (expected tracer or cotton)");
  }
  // Each effect sets the SI fields that carry it (sim/air_forces.h, nozzle_actuator.h,
  // scene_spec.h); degrees are converted here, at the edge.
  switch (find_effect(effect.name).id) {
    case EffectId::kPressureGradient:
      params->air.extra_push_mps2 = v[0];
      params->air.extra_push_length_m = v[1];
      return;
    case EffectId::kResponseDelay:
      params->nozzle.response_delay_s += v[0];
      return;
    case EffectId::kFlowDeflection:
      params->air.flow_deflection_rad = deg_to_rad(v[0]);
      return;
    case EffectId::kQuadraticDrag:
      for (ObjectTypeParameters* t : types) t->extra_quadratic_drag_per_m = v[0];
      return;
    case EffectId::kFloorSlope:
      params->scene.floor_slope_rad = deg_to_rad(v[0]);
      params->scene.floor_slope_direction_rad = deg_to_rad(v[1]);
      return;
    case EffectId::kStiction:
      params->scene.tracer.static_friction_ratio = v[0];
      params->scene.cotton.static_friction_ratio = v[0];
      return;
    case EffectId::kNozzleOffset:
      params->nozzle.pan_offset_rad = deg_to_rad(v[0]);
      params->nozzle.tilt_offset_rad = deg_to_rad(v[1]);
      return;
    case EffectId::kFieldScale:
      params->air.field_scale = v[0];
      return;
    case EffectId::kTransportLag:
      // A front at the constant speed 1 / pace in either air: no start-up timing, formation or
      // carry (the CFD's own lag is replaced).
      params->air_transport.front_speed_mps = v[0] > 0.0 ? 1.0 / v[0] : 0.0;
      params->air_transport.max_lag_s = kMaxTransportLagS;
      params->air_transport.cfd_timing = false;
      params->air_transport.formation = false;
      params->air_transport.front_co_flow = 0.0;
      params->air_transport.front_counter_flow = 0.0;
      params->analytical_air_transport = true;
      return;
    case EffectId::kAirLift:
      for (ObjectTypeParameters* t : types) t->extra_lift_s2pm2 = v[0];
      return;
    case EffectId::kLinearisedDrag:
      for (ObjectTypeParameters* t : types) t->drag_intercept_share = v[0];
      return;
  }
  AIRTWIN_DEMAND(false);
}

void apply_effects(const std::vector<Effect>& effects, TwinParameters* params) {
  std::set<std::string> names;
  for (const Effect& e : effects) {
    if (!names.insert(e.name).second) {
      throw InputError("effect " + e.name + " is given twice; combine its parameters in one " +
                       e.name + ":key=value,...");
    }
  }
  // Every type's effects first, then one type's own on top (NAME@TYPE replaces NAME for it).
  for (const Effect& e : effects) {
    if (effect_object_type(e.name).empty()) apply_effect(e, params);
  }
  for (const Effect& e : effects) {
    if (!effect_object_type(e.name).empty()) apply_effect(e, params);
  }
}

std::string effect_help() {
  std::string out;
  for (const EffectSpec& e : effect_catalogue()) {
    std::string line = "  " + std::string(e.name);
    line.resize(20, ' ');
    for (size_t i = 0; i < e.params.size(); ++i) {
      const EffectParameter& p = e.params[i];
      if (i > 0) line += ", ";
      line += p.key;
      line += '=';
      line += format_number(p.example);
      line += ' ';
      line += effect_range_text(p);
    }
    line += ": " + std::string(e.twin) + "\n";
    out += line;
  }
  out += "  " + per_type_effect_names() + ": NAME@TYPE (tracer, cotton) for one type's objects\n";
  return out;
}

}  // namespace airtwin
