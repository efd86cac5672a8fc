#include "sim/effects.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// One parameter of an effect: its typed name and unit, default, and the closed or open range.
struct ParameterSpec {
  const char* key;
  const char* unit;
  double default_value;
  double min, max;
  bool min_open;  // (min, max] instead of [min, max]
};

struct EffectSpec {
  const char* name;
  const char* what;
  std::vector<ParameterSpec> params;
};

// The catalogue (docs/twin.md, "Effects"): defaults are realistic magnitudes for the rig.
const std::vector<EffectSpec>& catalogue() {
  static const std::vector<EffectSpec> effects = {
      {"pressure_gradient",
       "extra outward push near s, peak acceleration `strength` at r = length / sqrt(2)",
       {{"strength", "m/s^2", 4.0, 0.0, 50.0, false}, {"length", "m", 0.15, 0.0, 1.0, true}}},
      {"response_delay",
       "the field follows the nozzle tau_s later (on top of the default 0.2 s)",
       {{"tau_s", "s", 0.3, 0.0, 5.0, false}}},
      {"flow_deflection",
       "air turned from radial by angle_deg (counter-clockwise +), same speed",
       {{"angle_deg", "deg", 15.0, -90.0, 90.0, false}}},
      {"quadratic_drag",
       "extra drag acceleration coefficient |u_rel| u_rel, u_rel = u_air - v",
       {{"coefficient", "1/m", 0.5, 0.0, 20.0, false}}},
      {"floor_slope",
       "floor tilted by angle_deg, downhill toward direction_deg (from +x, CCW)",
       {{"angle_deg", "deg", 2.0, 0.0, 30.0, false},
        {"direction_deg", "deg", 0.0, -360.0, 360.0, false}}},
      {"stiction",
       "static / kinetic friction ratio of every object (replaces 1.2 / 1.3)",
       {{"ratio", "", 2.0, 1.0, 10.0, false}}},
      {"nozzle_offset",
       "servo calibration bias: the nozzle turns to command + offset",
       {{"pan_deg", "deg", 3.0, -30.0, 30.0, false}, {"tilt_deg", "deg", 2.0, -10.0, 10.0, false}}},
      {"field_scale",
       "air speed times factor (stagnation pressure times factor^2)",
       {{"factor", "", 1.2, 0.0, 3.0, true}}},
  };
  return effects;
}

std::string number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", x);
  return buffer;
}

std::string valid_names() {
  std::string names;
  for (const EffectSpec& e : catalogue()) {
    if (!names.empty()) names += ", ";
    names += e.name;
  }
  return names;
}

std::string valid_keys(const EffectSpec& e) {
  std::string keys;
  for (const ParameterSpec& p : e.params) {
    if (!keys.empty()) keys += ", ";
    keys += p.key;
  }
  return keys;
}

std::string range_text(const ParameterSpec& p) {
  std::string text = p.min_open ? "(" : "[";
  text += number(p.min);
  text += ", ";
  text += number(p.max);
  text += ']';
  if (p.unit[0] != '\0') {
    text += ' ';
    text += p.unit;
  }
  return text;
}

const EffectSpec& find_effect(const std::string& name, const std::string& where) {
  for (const EffectSpec& e : catalogue()) {
    if (name == e.name) return e;
  }
  throw UsageError(where + ": unknown effect '" + name + "'; valid effects: " + valid_names());
}

const ParameterSpec& find_parameter(const EffectSpec& e, const std::string& key,
                                    const std::string& where) {
  for (const ParameterSpec& p : e.params) {
    if (key == p.key) return p;
  }
  throw UsageError(where + ": effect " + e.name + " has no parameter '" + key +
                   "'; its parameters: " + valid_keys(e));
}

// The typed value of `p`, checked to be finite and in range.
void check_value(const EffectSpec& e, const ParameterSpec& p, double value,
                 const std::string& where) {
  const bool above = p.min_open ? value > p.min : value >= p.min;
  if (!(std::isfinite(value) && above && value <= p.max)) {
    throw UsageError(where + ": " + e.name + "." + p.key + " must be a finite number in " +
                     range_text(p) + ", got " + number(value));
  }
}

// Every parameter of `effect` resolved (typed or default), checked, in catalogue order.
std::vector<double> resolve(const Effect& effect) {
  const std::string where = "--effect " + effect.name;
  const EffectSpec& spec = find_effect(effect.name, where);
  std::vector<double> values;
  std::set<std::string> seen;
  for (const auto& [key, value] : effect.params) {
    const ParameterSpec& p = find_parameter(spec, key, where);
    if (!seen.insert(key).second) {
      throw UsageError(where + ": parameter '" + key + "' is given twice");
    }
    check_value(spec, p, value, where);
  }
  for (const ParameterSpec& p : spec.params) {
    double value = p.default_value;
    for (const auto& [key, typed] : effect.params) {
      if (key == p.key) value = typed;
    }
    values.push_back(value);
  }
  return values;
}

std::string trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(" \t");
  return s.substr(begin, end - begin + 1);
}

}  // namespace

Effect parse_effect(const std::string& text) {
  const std::string where = "--effect '" + text + "'";
  Effect effect;
  const size_t colon = text.find(':');
  effect.name = trim(text.substr(0, colon));
  if (effect.name.empty()) {
    throw UsageError(where +
                     ": expected NAME or NAME:key=value,...; valid effects: " + valid_names());
  }
  const EffectSpec& spec = find_effect(effect.name, where);
  if (colon != std::string::npos) {
    // key=value pairs, comma-separated; every value a whole finite number.
    const std::string list = text.substr(colon + 1);
    size_t start = 0;
    std::set<std::string> seen;
    while (true) {
      const size_t comma = list.find(',', start);
      const std::string item = trim(list.substr(start, comma - start));
      const size_t equals = item.find('=');
      if (equals == std::string::npos) {
        throw UsageError(where + ": expected key=value after '" + effect.name + ":', got '" + item +
                         "'; parameters of " + effect.name + ": " + valid_keys(spec));
      }
      const std::string key = trim(item.substr(0, equals));
      const std::string value_text = trim(item.substr(equals + 1));
      const ParameterSpec& p = find_parameter(spec, key, where);
      if (!seen.insert(key).second) {
        throw UsageError(where + ": parameter '" + key + "' of " + effect.name + " is given twice");
      }
      errno = 0;
      char* end = nullptr;
      const double value = std::strtod(value_text.c_str(), &end);
      if (value_text.empty() || end != value_text.c_str() + value_text.size() || errno == ERANGE) {
        throw UsageError(where + ": " + effect.name + "." + key + " must be a finite number in " +
                         range_text(p) + ", got '" + value_text + "'");
      }
      check_value(spec, p, value, where);
      effect.params.emplace_back(key, value);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return effect;
}

double effect_parameter(const Effect& effect, const std::string& key) {
  const std::string where = "--effect " + effect.name;
  const EffectSpec& spec = find_effect(effect.name, where);
  find_parameter(spec, key, where);
  const std::vector<double> values = resolve(effect);
  for (size_t i = 0; i < spec.params.size(); ++i) {
    if (key == spec.params[i].key) return values[i];
  }
  AIRTWIN_DEMAND(false);
  return 0.0;
}

std::string effect_to_string(const Effect& effect) {
  const EffectSpec& spec = find_effect(effect.name, "--effect " + effect.name);
  std::string out = effect.name;
  for (size_t i = 0; i < spec.params.size(); ++i) {
    double value = spec.params[i].default_value;
    for (const auto& [key, typed] : effect.params) {
      if (key == spec.params[i].key) value = typed;
    }
    // Appended piece by piece: GCC 12 -O3 reports a false -Wrestrict on "x" + std::string.
    out += i == 0 ? ':' : ',';
    out += spec.params[i].key;
    out += '=';
    out += number(value);
  }
  return out;
}

void apply_effect(const Effect& effect, TwinParameters* params) {
  AIRTWIN_DEMAND(params != nullptr);
  const std::vector<double> v = resolve(effect);
  const std::string& name = effect.name;
  // Each effect sets the SI fields that carry it (sim/air_forces.h, nozzle_actuator.h,
  // scene_spec.h); degrees are converted here, at the edge.
  if (name == "pressure_gradient") {
    params->air.extra_push_mps2 = v[0];
    params->air.extra_push_length_m = v[1];
  } else if (name == "response_delay") {
    params->nozzle.field_delay_s += v[0];
  } else if (name == "flow_deflection") {
    params->air.flow_deflection_rad = deg_to_rad(v[0]);
  } else if (name == "quadratic_drag") {
    params->air.quadratic_drag_per_m = v[0];
  } else if (name == "floor_slope") {
    params->scene.floor_slope_rad = deg_to_rad(v[0]);
    params->scene.floor_slope_direction_rad = deg_to_rad(v[1]);
  } else if (name == "stiction") {
    params->scene.tracer.static_friction_ratio = v[0];
    params->scene.cotton.static_friction_ratio = v[0];
  } else if (name == "nozzle_offset") {
    params->nozzle.pan_offset_rad = deg_to_rad(v[0]);
    params->nozzle.tilt_offset_rad = deg_to_rad(v[1]);
  } else if (name == "field_scale") {
    params->air.field_scale = v[0];
  } else {
    AIRTWIN_DEMAND(false);  // resolve() accepted a name the catalogue does not apply
  }
}

void apply_effects(const std::vector<Effect>& effects, TwinParameters* params) {
  std::set<std::string> names;
  for (const Effect& e : effects) {
    if (!names.insert(e.name).second) {
      throw UsageError("--effect " + e.name +
                       " is given twice; combine its parameters in one "
                       "--effect " +
                       e.name + ":key=value,...");
    }
  }
  for (const Effect& e : effects) apply_effect(e, params);
}

std::string effect_catalogue() {
  std::string out;
  for (const EffectSpec& e : catalogue()) {
    std::string line = "  " + std::string(e.name);
    line.resize(20, ' ');
    for (size_t i = 0; i < e.params.size(); ++i) {
      const ParameterSpec& p = e.params[i];
      if (i > 0) line += ", ";
      line += p.key;
      line += '=';
      line += number(p.default_value);
      line += ' ';
      line += range_text(p);
    }
    line += ": " + std::string(e.what) + "\n";
    out += line;
  }
  return out;
}

}  // namespace airtwin
