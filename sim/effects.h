#pragma once
// The twin's side of the effects catalogue (models/effect_catalogue.h): an effect as a person
// types it, "NAME" or "NAME:key=value,...", and how each effect perturbs the simulation. Every
// effect is off unless named; named without values it takes the catalogue's examples. Values are
// typed in the catalogue's units (degrees only there, at the edge); inside they become SI fields
// of TwinParameters (docs/twin.md, "Effects"):
//
//   pressure_gradient  air.extra_push_mps2, air.extra_push_length_m: an extra outward radial push
//                      near s added to the default push (sim/air_forces.h),
//                      a(r) = J^2 f^2 strength sqrt(2e) (r / length) exp(-(r / length)^2)
//                      (a wall-jet impingement zone as wide as the free jet at the floor).
//   response_delay     nozzle.response_delay_s += tau_s (on top of the free jet's transit,
//                      nozzle.field_delay_s).
//   flow_deflection    air.flow_deflection_rad: the mean air turned from radial, same speed.
//   quadratic_drag     scene.{tracer,cotton}.extra_quadratic_drag_per_m: C |u_rel| u_rel
//                      (1/2 rho C_d A / m of a tracer is ~0.6 1/m).
//   floor_slope        scene.floor_slope_rad, scene.floor_slope_direction_rad.
//   stiction           scene.{tracer,cotton}.static_friction_ratio (replaces 1.0 under eq. (8)'s
//                      law; the physical law's calibrated 1.4 and 1.3).
//   nozzle_offset      nozzle.{pan,tilt}_offset_rad: the nozzle turns to command + offset, the
//                      recorded command stays the command.
//   field_scale        air.field_scale: mean air and turbulence times factor.
//   transport_lag      air_transport.front_speed_mps = 1 / pace (analytical transport).
//   air_lift           scene.{tracer,cotton}.extra_lift_s2pm2: an upward lift k m g |u_rel|^2
//                      on each object, which unloads its contact (1/2 rho C_L A_base / (m g) of a
//                      tracer with C_L 0.2 is ~0.054 s^2/m^2).
//   linearised_drag    scene.{tracer,cotton}.drag_intercept_share: eq. (8)'s drag read as the
//                      tangent of a quadratic drag whose intercept is this share of the friction,
//                      taken from it (eq. (8)'s law only: the physical law's drag is quadratic).
//
// The last three are the objects' own (the catalogue's per_type effects): "NAME@TYPE" sets them
// for one type ("linearised_drag@tracer:intercept_share=0.45"), on top of any "NAME" for all.

#include <string>
#include <utility>
#include <vector>

#include "models/effect_catalogue.h"
#include "sim/twin.h"

namespace airtwin {

/// One effect as typed: its name and the parameters given (in the typed units, in order).
struct Effect {
  std::string name;
  std::vector<std::pair<std::string, double>> params;
};

/// Parses "NAME" (all defaults) or "NAME:key=value,key=value", NAME an effect or, for an object's
/// own, EFFECT@TYPE. Throws InputError naming the text, the effect and the parameter: an unknown
/// effect (listing the valid names) or object type, a type on a rig's effect, an unknown or
/// repeated parameter (listing the effect's parameters), a value that is not a finite number, or
/// one outside its range (stating the range and unit).
Effect parse_effect(const std::string& text);

/// The value of parameter `key` of `effect` in its typed unit: as typed, else the default.
/// Throws InputError when the effect or the key is unknown.
double effect_parameter(const Effect& effect, const std::string& key);

/// The effect with every parameter resolved, "name:key=value,...", in catalogue order (for
/// recording what a run used).
std::string effect_to_string(const Effect& effect);

/// Switches `effect` on in `params` (validating it as parse_effect does; throws InputError). The
/// fields it sets are listed in docs/twin.md; effects of different names combine.
void apply_effect(const Effect& effect, TwinParameters* params);

/// Applies the effects for every type in order, then those of one type (EFFECT@TYPE) in order;
/// throws InputError when one name appears twice.
void apply_effects(const std::vector<Effect>& effects, TwinParameters* params);

/// One line per effect: name, parameters with units, defaults and ranges, and what it does.
std::string effect_help();

}  // namespace airtwin
