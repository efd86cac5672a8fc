#include "models/model_extensions.h"

#include <cstdio>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// The typed values of effect `id` in `x`, a per_type effect's in `o`: the one place that maps the
// catalogue's typed parameters onto the model's SI fields (and set_values() below back).
std::vector<double> typed_values(const ModelExtensions& x, const ObjectExtensions& o, EffectId id) {
  switch (id) {
    case EffectId::kPressureGradient:
      return {x.push_strength_mps2, x.push_length_m};
    case EffectId::kResponseDelay:
      return {x.extra_delay_s};
    case EffectId::kFlowDeflection:
      return {rad_to_deg(x.deflection_rad)};
    case EffectId::kQuadraticDrag:
      return {o.quadratic_drag_per_m};
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
      return {o.lift_s2_per_m2};
    case EffectId::kLinearisedDrag:
      return {o.drag_intercept_share};
  }
  AIRTWIN_DEMAND(false);
  return {};
}

void set_values(ModelExtensions* x, ObjectExtensions* o, EffectId id,
                const std::vector<double>& v) {
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
      o->quadratic_drag_per_m = v[0];
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
      o->lift_s2_per_m2 = v[0];
      return;
    case EffectId::kLinearisedDrag:
      o->drag_intercept_share = v[0];
      return;
  }
  AIRTWIN_DEMAND(false);
}

// The object extensions named by `name` in `x`: `object`, or a type's (off when it has none).
const ObjectExtensions& object_of(const ModelExtensions& x, const std::string& type) {
  static const ObjectExtensions kOff;
  if (type.empty()) return x.object;
  const auto it = x.object_by_type.find(type);
  return it == x.object_by_type.end() ? kOff : it->second;
}

bool all_off(const ModelExtensions& x, const ObjectExtensions& o) {
  for (const EffectSpec& e : effect_catalogue()) {
    if (e.per_type && effect_size(e, typed_values(x, o, e.id)) > 0.0) return false;
  }
  return true;
}

}  // namespace

ObjectExtensions ModelExtensions::object_for(const std::string& type) const {
  const auto it = object_by_type.find(type);
  if (it == object_by_type.end()) return object;
  ModelExtensions out;  // a per_type effect's values go to `out.object` alone
  out.object = object;
  for (const EffectSpec& e : effect_catalogue()) {
    if (!e.per_type) continue;
    const std::vector<double> own = typed_values(*this, it->second, e.id);
    if (effect_size(e, own) > 0.0) set_values(&out, &out.object, e.id, own);
  }
  return out.object;
}

ModelExtensions ModelExtensions::for_type(const std::string& type) const {
  ModelExtensions out = *this;
  out.object = object_for(type);
  out.object_by_type.clear();
  return out;
}

std::vector<double> extension_values(const ModelExtensions& x, const std::string& name) {
  const EffectSpec& spec = find_effect(name);
  return typed_values(x, object_of(x, effect_object_type(name)), spec.id);
}

void set_extension_values(ModelExtensions* x, const std::string& name,
                          const std::vector<double>& v) {
  const EffectSpec& spec = find_effect(name);
  if (v.size() != spec.params.size()) {
    throw InputError("effect " + name + ": expected " + std::to_string(spec.params.size()) +
                     " parameters, got " + std::to_string(v.size()));
  }
  for (size_t i = 0; i < v.size(); ++i) check_effect_value(spec, spec.params[i], v[i]);
  const std::string type = effect_object_type(name);
  if (type.empty()) {
    set_values(x, &x->object, spec.id, v);
    return;
  }
  ObjectExtensions& o = x->object_by_type[type];
  set_values(x, &o, spec.id, v);
  // A type with every effect off is no entry: one model, one written form.
  if (all_off(*x, o)) x->object_by_type.erase(type);
}

void ModelExtensions::validate() const {
  for (const EffectSpec& e : effect_catalogue()) {
    const std::vector<double> v = typed_values(*this, object, e.id);
    for (size_t i = 0; i < v.size(); ++i) check_effect_value(e, e.params[i], v[i]);
  }
  for (const auto& [type, o] : object_by_type) {
    for (const EffectSpec& e : effect_catalogue()) {
      if (!e.per_type) continue;
      const std::string name = std::string(e.name) + "@" + type;
      find_effect(name);  // the type is a name
      const std::vector<double> v = typed_values(*this, o, e.id);
      for (size_t i = 0; i < v.size(); ++i) {
        try {
          check_effect_value(e, e.params[i], v[i]);
        } catch (const InputError& error) {
          throw InputError(name + ": " + error.what());
        }
      }
    }
  }
}

double extension_size(const ModelExtensions& x, const std::string& name) {
  return effect_size(find_effect(name), extension_values(x, name));
}

double negligible_size(const std::string& name) { return find_effect(name).negligible_size; }

bool extension_active(const ModelExtensions& x, const std::string& name) {
  return extension_size(x, name) > 0.0;
}

std::vector<std::string> active_extensions(const ModelExtensions& x) {
  std::vector<std::string> names;
  for (const EffectSpec& e : effect_catalogue()) {
    if (effect_size(e, typed_values(x, x.object, e.id)) > 0.0) names.push_back(e.name);
    if (!e.per_type) continue;
    for (const auto& [type, o] : x.object_by_type) {
      if (effect_size(e, typed_values(x, o, e.id)) > 0.0) {
        names.push_back(std::string(e.name) + "@" + type);
      }
    }
  }
  return names;
}

std::string describe_extension(const ModelExtensions& x, const std::string& name) {
  const EffectSpec& spec = find_effect(name);
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
