#include "models/model_extensions.h"

#include <cstdio>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// The typed values of effect `id` in `x`: the one place that maps the catalogue's typed
// parameters onto the model's SI fields (and set_values() below back).
std::vector<double> typed_values(const ModelExtensions& x, EffectId id) {
  switch (id) {
    case EffectId::kPressureGradient:
      return {x.push_strength_mps2, x.push_length_m};
    case EffectId::kResponseDelay:
      return {x.extra_delay_s};
    case EffectId::kFlowDeflection:
      return {rad_to_deg(x.deflection_rad)};
    case EffectId::kQuadraticDrag:
      return {x.quadratic_drag_per_m};
    case EffectId::kFloorSlope:
      return {rad_to_deg(x.slope_rad), rad_to_deg(x.slope_direction_rad)};
    case EffectId::kStiction:
      return {x.static_friction_ratio};
    case EffectId::kNozzleOffset:
      return {rad_to_deg(x.pan_offset_rad), rad_to_deg(x.tilt_offset_rad)};
    case EffectId::kFieldScale:
      return {x.field_scale};
    case EffectId::kTransportLag:
      return {x.transport_pace_s_per_m};
    case EffectId::kAirLift:
      return {x.lift_s2_per_m2};
    case EffectId::kLinearisedDrag:
      return {x.drag_intercept_share};
  }
  AIRTWIN_DEMAND(false);
  return {};
}

void set_values(ModelExtensions* x, EffectId id, const std::vector<double>& v) {
  switch (id) {
    case EffectId::kPressureGradient:
      x->push_strength_mps2 = v[0];
      x->push_length_m = v[1];
      return;
    case EffectId::kResponseDelay:
      x->extra_delay_s = v[0];
      return;
    case EffectId::kFlowDeflection:
      x->deflection_rad = deg_to_rad(v[0]);
      return;
    case EffectId::kQuadraticDrag:
      x->quadratic_drag_per_m = v[0];
      return;
    case EffectId::kFloorSlope:
      x->slope_rad = deg_to_rad(v[0]);
      x->slope_direction_rad = deg_to_rad(v[1]);
      return;
    case EffectId::kStiction:
      x->static_friction_ratio = v[0];
      return;
    case EffectId::kNozzleOffset:
      x->pan_offset_rad = deg_to_rad(v[0]);
      x->tilt_offset_rad = deg_to_rad(v[1]);
      return;
    case EffectId::kFieldScale:
      x->field_scale = v[0];
      return;
    case EffectId::kTransportLag:
      x->transport_pace_s_per_m = v[0];
      return;
    case EffectId::kAirLift:
      x->lift_s2_per_m2 = v[0];
      return;
    case EffectId::kLinearisedDrag:
      x->drag_intercept_share = v[0];
      return;
  }
  AIRTWIN_DEMAND(false);
}

}  // namespace

std::vector<double> extension_values(const ModelExtensions& x, const std::string& name) {
  return typed_values(x, find_effect(name).id);
}

void set_extension_values(ModelExtensions* x, const std::string& name,
                          const std::vector<double>& v) {
  const EffectSpec& spec = find_effect(name);
  if (v.size() != spec.params.size()) {
    throw InputError("effect " + name + ": expected " + std::to_string(spec.params.size()) +
                     " parameters, got " + std::to_string(v.size()));
  }
  for (size_t i = 0; i < v.size(); ++i) check_effect_value(spec, spec.params[i], v[i]);
  set_values(x, spec.id, v);
}

void ModelExtensions::validate() const {
  for (const EffectSpec& e : effect_catalogue()) {
    const std::vector<double> v = typed_values(*this, e.id);
    for (size_t i = 0; i < v.size(); ++i) check_effect_value(e, e.params[i], v[i]);
  }
}

double extension_size(const ModelExtensions& x, const std::string& name) {
  const EffectSpec& spec = find_effect(name);
  return effect_size(spec, typed_values(x, spec.id));
}

double negligible_size(const std::string& name) { return find_effect(name).negligible_size; }

bool extension_active(const ModelExtensions& x, const std::string& name) {
  return extension_size(x, name) > 0.0;
}

std::vector<std::string> active_extensions(const ModelExtensions& x) {
  std::vector<std::string> names;
  for (const EffectSpec& e : effect_catalogue()) {
    if (effect_size(e, typed_values(x, e.id)) > 0.0) names.push_back(e.name);
  }
  return names;
}

std::string describe_extension(const ModelExtensions& x, const std::string& name) {
  const EffectSpec& spec = find_effect(name);
  const std::vector<double> v = typed_values(x, spec.id);
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
