#pragma once
// The effects catalogue: named physical effects that the controller's model (eqs. 1-3 and 8-9)
// lacks, switched on one by one with `--effect NAME[:key=value,...]` for the discrepancy
// analysis. Every effect is off unless named; named without values it takes the realistic
// defaults below. Parameters are typed in the units shown (degrees only here, at the edge); inside
// they become SI fields of TwinParameters (docs/twin.md, "Effects").
//
//   pressure_gradient  strength (m/s^2, 4), length (m, 0.15): an extra outward radial push near s,
//                      added to the twin's default push (sim/air_forces.h):
//                      a(r) = J^2 f^2 strength sqrt(2e) (r / length) exp(-(r / length)^2),
//                      peak `strength` at r = length / sqrt(2) (a wall-jet impingement zone as
//                      wide as the free jet at the floor, ~0.1 x 1.43 m).
//   response_delay     tau_s (s, 0.3): the field follows the nozzle tau_s later than the default
//                      0.2 s transit delay (sim/nozzle_actuator.h): field_delay_s += tau_s.
//   flow_deflection    angle_deg (deg, 15): the mean air velocity turned from radial by this angle,
//                      counter-clockwise positive, at the same speed (a swirl of the wall jet).
//   quadratic_drag     coefficient (1/m, 0.5): an extra drag acceleration C |u_rel| u_rel with
//                      u_rel = u_air - v (1/2 rho C_d A / m of a tracer: ~0.6 1/m).
//   floor_slope        angle_deg (deg, 2), direction_deg (deg, 0): the floor tilted by angle_deg,
//                      downhill toward direction_deg (world frame, from +x, counter-clockwise).
//   stiction           ratio (1, 2): static / kinetic friction of every object type (replaces
//                      the defaults 1.2 tracer, 1.3 cotton).
//   nozzle_offset      pan_deg (deg, 3), tilt_deg (deg, 2): servo calibration bias; the nozzle
//                      turns to command + offset, the recorded command stays the command.
//   field_scale        factor (1, 1.2): the air speed times factor (mean and turbulence; the
//                      stagnation pressure times factor^2).

#include <string>
#include <utility>
#include <vector>

#include "sim/twin.h"

namespace airtwin {

/// One effect as typed: its name and the parameters given (in the typed units, in order).
struct Effect {
  std::string name;
  std::vector<std::pair<std::string, double>> params;
};

/// Parses "NAME" (all defaults) or "NAME:key=value,key=value". Throws UsageError naming the text,
/// the effect and the parameter: an unknown effect (listing the valid names), an unknown or
/// repeated parameter (listing the effect's parameters), a value that is not a finite number, or
/// one outside its range (stating the range and unit).
Effect parse_effect(const std::string& text);

/// The value of parameter `key` of `effect` in its typed unit: as typed, else the default.
/// Throws UsageError when the effect or the key is unknown.
double effect_parameter(const Effect& effect, const std::string& key);

/// The effect with every parameter resolved, "name:key=value,...", in catalogue order (for
/// recording what a run used).
std::string effect_to_string(const Effect& effect);

/// Switches `effect` on in `params` (validating it as parse_effect does; throws UsageError). The
/// fields it sets are listed in docs/twin.md; effects of different names combine.
void apply_effect(const Effect& effect, TwinParameters* params);

/// Applies each effect in order; throws UsageError when one name appears twice.
void apply_effects(const std::vector<Effect>& effects, TwinParameters* params);

/// One line per effect: name, parameters with units, defaults and ranges, and what it does.
std::string effect_catalogue();

}  // namespace airtwin
