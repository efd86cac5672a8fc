#include "models/model_extensions.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {

const std::vector<ExtensionSpec>& extension_catalogue() {
  // Physical ranges follow sim/effects.h; the fit ranges cover what a rig plausibly shows.
  static const std::vector<ExtensionSpec> catalogue = {
      {"pressure_gradient",
       "the jet's stagnation pressure pushes objects outward near s, beyond the air's drag",
       {{"strength", "m/s^2", 0.0, 0.0, 50.0, 0.0, 40.0},
        {"length", "m", 0.15, 0.01, 1.0, 0.03, 0.5}}},
      {"response_delay",
       "the air on the floor answers a new nozzle orientation later than servo travel and transit",
       {{"tau_s", "s", 0.0, 0.0, 5.0, 0.0, 1.5}}},
      {"flow_deflection",
       "the wall jet swirls: the air moves at an angle to the radial direction from s",
       {{"angle_deg", "deg", 0.0, -90.0, 90.0, -45.0, 45.0}}},
      {"quadratic_drag",
       "drag grows with the square of the relative air speed (a higher Reynolds number regime)",
       {{"coefficient", "1/m", 0.0, 0.0, 20.0, 0.0, 5.0}}},
      {"floor_slope",
       "the floor is not level: gravity pulls objects downhill",
       {{"angle_deg", "deg", 0.0, 0.0, 30.0, 0.0, 10.0},
        {"direction_deg", "deg", 0.0, -360.0, 360.0, -180.0, 180.0}}},
      {"stiction",
       "static friction exceeds kinetic friction: objects at rest need more air to start",
       {{"ratio", "", 1.0, 1.0, 10.0, 1.0, 5.0}}},
      {"nozzle_offset",
       "the servos' calibration is biased: the nozzle points elsewhere than commanded",
       {{"pan_deg", "deg", 0.0, -30.0, 30.0, -15.0, 15.0},
        {"tilt_deg", "deg", 0.0, -10.0, 10.0, -8.0, 8.0}}},
      {"field_scale",
       "the air on the floor is faster or slower than the field table says",
       {{"factor", "", 1.0, 0.05, 3.0, 0.3, 2.5}}},
  };
  return catalogue;
}

std::string extension_names() {
  std::string names;
  for (const ExtensionSpec& e : extension_catalogue()) {
    if (!names.empty()) names += ", ";
    names += e.name;
  }
  return names;
}

const ExtensionSpec& find_extension(const std::string& name) {
  for (const ExtensionSpec& e : extension_catalogue()) {
    if (name == e.name) return e;
  }
  throw InputError("unknown model extension '" + name + "'; known: " + extension_names());
}

std::vector<double> extension_values(const ModelExtensions& x, const std::string& name) {
  find_extension(name);
  if (name == "pressure_gradient") return {x.push_strength_mps2, x.push_length_m};
  if (name == "response_delay") return {x.extra_delay_s};
  if (name == "flow_deflection") return {rad_to_deg(x.deflection_rad)};
  if (name == "quadratic_drag") return {x.quadratic_drag_per_m};
  if (name == "floor_slope") return {rad_to_deg(x.slope_rad), rad_to_deg(x.slope_direction_rad)};
  if (name == "stiction") return {x.static_friction_ratio};
  if (name == "nozzle_offset") return {rad_to_deg(x.pan_offset_rad), rad_to_deg(x.tilt_offset_rad)};
  return {x.field_scale};  // field_scale
}

void set_extension_values(ModelExtensions* x, const std::string& name,
                          const std::vector<double>& v) {
  const ExtensionSpec& spec = find_extension(name);
  if (v.size() != spec.params.size()) {
    throw InputError("extension " + name + ": expected " + std::to_string(spec.params.size()) +
                     " parameters, got " + std::to_string(v.size()));
  }
  for (size_t i = 0; i < v.size(); ++i) {
    const ExtensionParameter& p = spec.params[i];
    if (!(std::isfinite(v[i]) && v[i] >= p.min && v[i] <= p.max)) {
      char range[96];
      std::snprintf(range, sizeof(range), "[%g, %g]", p.min, p.max);
      throw InputError("extension " + name + "." + p.key + " must be a finite number in " + range +
                       (p.unit[0] ? std::string(" ") + p.unit : std::string()));
    }
  }
  if (name == "pressure_gradient") {
    x->push_strength_mps2 = v[0];
    x->push_length_m = v[1];
  } else if (name == "response_delay") {
    x->extra_delay_s = v[0];
  } else if (name == "flow_deflection") {
    x->deflection_rad = deg_to_rad(v[0]);
  } else if (name == "quadratic_drag") {
    x->quadratic_drag_per_m = v[0];
  } else if (name == "floor_slope") {
    x->slope_rad = deg_to_rad(v[0]);
    x->slope_direction_rad = deg_to_rad(v[1]);
  } else if (name == "stiction") {
    x->static_friction_ratio = v[0];
  } else if (name == "nozzle_offset") {
    x->pan_offset_rad = deg_to_rad(v[0]);
    x->tilt_offset_rad = deg_to_rad(v[1]);
  } else {
    x->field_scale = v[0];
  }
}

void ModelExtensions::validate() const {
  for (const ExtensionSpec& e : extension_catalogue()) {
    ModelExtensions copy;
    set_extension_values(&copy, e.name, extension_values(*this, e.name));
  }
}

bool extension_active(const ModelExtensions& x, const std::string& name) {
  const ExtensionSpec& spec = find_extension(name);
  const std::vector<double> v = extension_values(x, name);
  if (name == "pressure_gradient") return v[0] != 0.0;
  if (name == "floor_slope") return v[0] != 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    if (v[i] != spec.params[i].nominal) return true;
  }
  return false;
}

double extension_size(const ModelExtensions& x, const std::string& name) {
  const ExtensionSpec& spec = find_extension(name);
  const std::vector<double> v = extension_values(x, name);
  if (name == "pressure_gradient" || name == "floor_slope") return std::abs(v[0]);
  double size = 0.0;
  for (size_t i = 0; i < v.size(); ++i)
    size = std::max(size, std::abs(v[i] - spec.params[i].nominal));
  return size;
}

double negligible_size(const std::string& name) {
  find_extension(name);
  if (name == "pressure_gradient") return 1.0;  // m/s^2: an eighth of tracer friction
  if (name == "response_delay") return 0.05;    // s: two camera frames
  if (name == "flow_deflection") return 3.0;    // deg
  if (name == "quadratic_drag") return 0.1;     // 1/m: 10 % of linear drag at ~1 m/s
  if (name == "floor_slope") return 0.5;        // deg: a level floor's tolerance
  if (name == "stiction") return 0.3;           // ratio 1.3
  if (name == "nozzle_offset") return 1.0;      // deg
  return 0.05;                                  // field_scale: 5 % of air speed
}

std::vector<std::string> active_extensions(const ModelExtensions& x) {
  std::vector<std::string> names;
  for (const ExtensionSpec& e : extension_catalogue()) {
    if (extension_active(x, e.name)) names.push_back(e.name);
  }
  return names;
}

std::string describe_extension(const ModelExtensions& x, const std::string& name) {
  const ExtensionSpec& spec = find_extension(name);
  const std::vector<double> v = extension_values(x, name);
  std::string out = name;
  for (size_t i = 0; i < v.size(); ++i) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.4g", v[i]);
    out += i == 0 ? ": " : ", ";
    out += spec.params[i].key;
    out += '=';
    out += text;
    if (spec.params[i].unit[0] != '\0') {
      out += ' ';
      out += spec.params[i].unit;
    }
  }
  return out;
}

}  // namespace airtwin
