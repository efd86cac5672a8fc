#pragma once
// The catalogue of model extensions: named physical causes the nominal model (eqs. 1-3 and 8-9)
// lacks, each with parameters, that the discrepancy analysis (models/discrepancy.h) fits to
// measured data and the extended model (models/extended_model.h) carries. They mirror the effects
// the twin can inject (sim/effects.h), with the same names, keys and typed units, so a finding
// reads like the `--effect` that would reproduce it:
//
//   pressure_gradient  strength (m/s^2), length (m): an outward radial push near s,
//                      a(r) = f^2 strength sqrt(2e) (r / length) exp(-(r / length)^2)
//                      (peak `strength` at r = length / sqrt(2); f the field_scale).
//   response_delay     tau_s (s): the field follows the nozzle tau_s later than the nominal
//                      response (servo travel + transit, models/nozzle_response.h).
//   flow_deflection    angle_deg (deg): the air velocity turned from radial by this angle
//                      (counter-clockwise positive), same speed.
//   quadratic_drag     coefficient (1/m): an extra acceleration C |u - v| (u - v).
//   floor_slope        angle_deg, direction_deg (deg): gravity's pull g sin(angle) downhill toward
//                      direction_deg (world frame, from +x, counter-clockwise).
//   stiction           ratio: an object at rest starts only when the air's pull exceeds `ratio`
//                      times the kinetic friction |xi3| (nominal 1: eq. 8's start condition).
//   nozzle_offset      pan_deg, tilt_deg (deg): the servos go to command + offset.
//   field_scale        factor: the air speed times factor.
//
// Inside, ModelExtensions holds SI values; degrees live only in the typed parameters of the
// catalogue (what a person reads in report.json and extended_model.json).

#include <string>
#include <vector>

namespace airtwin {

/// Every extension's parameters in SI; the defaults are the nominal model (all off).
struct ModelExtensions {
  double push_strength_mps2 = 0.0;  ///< pressure_gradient strength (0: off)
  double push_length_m = 0.15;      ///< pressure_gradient length (> 0)
  double extra_delay_s = 0.0;       ///< response_delay tau_s (>= 0)
  double deflection_rad = 0.0;      ///< flow_deflection
  double quadratic_drag_per_m = 0.0;
  double slope_rad = 0.0;              ///< floor_slope angle
  double slope_direction_rad = 0.0;    ///< floor_slope downhill direction
  double static_friction_ratio = 1.0;  ///< stiction (>= 1)
  double pan_offset_rad = 0.0;         ///< nozzle_offset
  double tilt_offset_rad = 0.0;
  double field_scale = 1.0;  ///< (> 0)

  /// Throws InputError naming the extension and parameter when a value is not finite or out of
  /// its physical range (the ranges of extension_catalogue()).
  void validate() const;
};

/// One parameter of an extension, in its typed unit.
struct ExtensionParameter {
  const char* key;
  const char* unit;  ///< "" when dimensionless
  double nominal;    ///< the value that switches the extension off (or any, when another
                     ///< parameter does: pressure_gradient.length, floor_slope.direction_deg)
  double min, max;   ///< physical range (closed)
  double fit_min, fit_max;  ///< where the analysis searches
};

/// Below this size an extension is not worth adding, however significant (typed units): static
/// friction up to 30 % above kinetic is ordinary for dry contacts and absorbed by eq. (8)'s xi3;
/// 5 % of air speed is within the field table's own fit error; and so on (docs/discrepancy.md).
/// The size of an extension: its largest |parameter - nominal| over the parameters that switch
/// it on (pressure_gradient: strength; floor_slope: angle_deg).
double extension_size(const ModelExtensions& ext, const std::string& name);
double negligible_size(const std::string& name);

struct ExtensionSpec {
  const char* name;
  const char* cause;  ///< the physical cause, one sentence for people
  std::vector<ExtensionParameter> params;
};

/// The catalogue, in a fixed order.
const std::vector<ExtensionSpec>& extension_catalogue();
/// The catalogue's names, comma-separated (for messages).
std::string extension_names();
/// The entry `name`; InputError listing the names when there is none.
const ExtensionSpec& find_extension(const std::string& name);

/// The typed values of extension `name`'s parameters in `ext` (catalogue order).
std::vector<double> extension_values(const ModelExtensions& ext, const std::string& name);
/// Sets extension `name`'s parameters from typed values (catalogue order). Throws InputError
/// when the count is wrong or a value is out of its physical range.
void set_extension_values(ModelExtensions* ext, const std::string& name,
                          const std::vector<double>& typed);
/// Whether extension `name` differs from the nominal model in `ext`.
bool extension_active(const ModelExtensions& ext, const std::string& name);
/// The names of the active extensions, in catalogue order.
std::vector<std::string> active_extensions(const ModelExtensions& ext);
/// "name: key=value unit, ..." for people.
std::string describe_extension(const ModelExtensions& ext, const std::string& name);

}  // namespace airtwin
