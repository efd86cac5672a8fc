#pragma once
// The catalogue of physical effects that the controller's model (eqs. 1-3 and 8-9) lacks, each
// defined once, here: its name, its parameters (typed unit, the value the twin takes when the
// effect is named without values, the value that switches it off, the physical range, where the
// discrepancy analysis searches), the size below which it is negligible, and one line of physics.
// Three users read this table and nothing else about an effect's identity:
//   - the twin injects an effect (sim/effects.h: how it perturbs the simulation);
//   - the extended model predicts it (models/model_extensions.h, models/extended_predictor.h);
//   - the discrepancy analysis fits it and names it (models/discrepancy.h).
// Typed units are what people read and type (degrees among them); inside, SI. Adding an effect:
// docs/effects.md.
//
//   pressure_gradient  strength (m/s^2), length (m): an outward radial push near s,
//                      a(r) = f^2 strength sqrt(2e) (r / length) exp(-(r / length)^2),
//                      peak `strength` at r = length / sqrt(2) (f the field_scale).
//   response_delay     tau_s (s): the field follows the nozzle tau_s later than servo travel and
//                      transit.
//   flow_deflection    angle_deg (deg): the air velocity turned from radial by this angle
//                      (counter-clockwise positive), same speed: a swirl of the wall jet.
//   quadratic_drag     coefficient (1/m): an extra acceleration C |u - v| (u - v).
//   floor_slope        angle_deg, direction_deg (deg): gravity's pull g sin(angle) downhill toward
//                      direction_deg (world frame, from +x, counter-clockwise).
//   stiction           ratio: static / kinetic friction; an object at rest starts only when the
//                      air's pull exceeds ratio times the kinetic friction.
//   nozzle_offset      pan_deg, tilt_deg (deg): servo calibration bias, the nozzle turns to
//                      command + offset.
//   field_scale        factor: the air speed times factor (stagnation pressure times factor^2).
//   transport_lag      pace_s_per_m (s/m): a new orientation's air spreads from its s as the wall
//                      jet's front, 1 / pace fast: a point r from s feels it pace r later (at
//                      most kMaxTransportLagS).
//   air_lift           lift_s2_per_m2 (s^2/m^2): the air flowing past an object lifts the
//                      fraction k |u - v|^2 of its weight, so its friction is
//                      |xi3| max(0, 1 - k |u - v|^2) (1/2 rho C_L A_base / (m g) of a body).
//   linearised_drag    intercept_share: eq. (8)'s linear drag c (k u - v) = c w is the tangent
//                      at |w| = w0 of the quadratic drag (c / 2 w0) |w| w, and its friction
//                      holds the tangent's intercept c w0 / 2, this share of |xi3|. Below w0 the
//                      drag follows the quadratic, and the friction keeps (1 - share) |xi3|: an
//                      object that outruns the air coasts farther (c = -xi1, k = xi2 / c,
//                      w0 = 2 share |xi3| / c; off when xi1 >= 0 or xi3 >= 0).

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace airtwin {

/// The effects, in catalogue order (the order of reports and of effect_catalogue()).
enum class EffectId {
  kPressureGradient,
  kResponseDelay,
  kFlowDeflection,
  kQuadraticDrag,
  kFloorSlope,
  kStiction,
  kNozzleOffset,
  kFieldScale,
  kTransportLag,
  kAirLift,
  kLinearisedDrag,
};
inline constexpr size_t kEffectCount = 11;

/// The longest transport lag (s) the twin and the model carry: a point farther from s than
/// this times the front's speed feels the orientation of this long ago.
inline constexpr double kMaxTransportLagS = 2.0;

/// One parameter of an effect, in its typed unit.
struct EffectParameter {
  const char* key;
  const char* unit;  ///< "" when dimensionless
  double example;    ///< the twin's value when the effect is named without values
  double off;        ///< the value of the nominal model
  bool switches;     ///< its distance from `off` switches the effect on (else it only shapes it)
  double min, max;   ///< physical range, closed
  double fit_min, fit_max;  ///< where the discrepancy analysis searches
};

struct EffectSpec {
  EffectId id;
  const char* name;
  const char* cause;  ///< the physical cause, one sentence for people (reports)
  const char* twin;   ///< what the twin does when it is on, one line (the CLI's help)
  std::vector<EffectParameter> params;
  /// Below this size (the largest |value - off| over the switching parameters, typed units) the
  /// effect is not worth adding to a model, however significant (docs/discrepancy.md).
  double negligible_size;
  /// An effect of the object (its drag, lift, contact) rather than of the rig: a model may carry
  /// it per object type, written NAME@TYPE ("linearised_drag@tracer"), which the discrepancy
  /// analysis fits when the data hold several types. Stiction is the object's too, but stays
  /// shared: the analysis carries it as a nuisance of every fit (models/discrepancy_fit.h).
  bool per_type = false;
};

/// The catalogue, indexed by EffectId.
const std::array<EffectSpec, kEffectCount>& effect_catalogue();
const EffectSpec& effect_spec(EffectId id);
/// The entry named `name`, "NAME" or "NAME@TYPE" (a per_type effect for objects of one type);
/// InputError naming it and listing the names when there is none, or when a rig's effect is
/// given a type.
const EffectSpec& find_effect(const std::string& name);
/// TYPE of "NAME@TYPE", "" for "NAME" (InputError as find_effect's).
std::string effect_object_type(const std::string& name);
/// The per_type effects' names, comma-separated, in catalogue order (for messages).
std::string per_type_effect_names();
/// The names, comma-separated, in catalogue order (for messages).
std::string effect_names();

/// The index of parameter `key` of `spec`; InputError listing the effect's keys otherwise.
size_t effect_parameter_index(const EffectSpec& spec, const std::string& key);
/// "[min, max] unit".
std::string effect_range_text(const EffectParameter& p);
/// InputError "<name>.<key> must be a finite number in [min, max] unit, got <value>" unless the
/// value is finite and in range.
void check_effect_value(const EffectSpec& spec, const EffectParameter& p, double value);

/// The size of an effect given its typed values (catalogue order): the largest |value - off| over
/// the parameters that switch it on; 0 when off.
double effect_size(const EffectSpec& spec, const std::vector<double>& typed);

}  // namespace airtwin
