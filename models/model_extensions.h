#pragma once
// The extended model's parameters: the effects of the catalogue (models/effect_catalogue.h) as
// the model carries them, in SI, with the nominal model (every effect off) as the default. The
// discrepancy analysis (models/discrepancy.h) fits them; the extended predictor
// (models/extended_predictor.h) predicts with them; extended_model.json stores them in the
// catalogue's typed units, so a finding reads like the `--effect` that would reproduce it.

#include <map>
#include <string>
#include <vector>

#include "models/effect_catalogue.h"

namespace airtwin {

/// The per_type effects of the catalogue (effect_catalogue.h): the object's drag and contact, in
/// SI; the defaults are off.
struct ObjectExtensions {
  double quadratic_drag_per_m = 0.0;
  /// air_lift: friction times max(0, 1 - k |u - v|^2) (s^2/m^2, >= 0; 0: eq. (8)'s constant)
  double lift_s2_per_m2 = 0.0;
  /// linearised_drag: the share of eq. (8)'s friction |xi3| that is the intercept of its linear
  /// drag read as the tangent of a quadratic ([0, 0.95]; 0: eq. (8)'s linear drag and friction)
  double drag_intercept_share = 0.0;

  /// Member by member (values: -0.0 equals 0.0, NaN equals nothing).
  bool operator==(const ObjectExtensions&) const = default;
};

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
  /// transport_lag: a point r from s feels an orientation min(pace r, kMaxTransportLagS) after
  /// it reached s (s/m, >= 0; 0: the field swings rigidly)
  double transport_pace_s_per_m = 0.0;
  /// The per_type effects of every object ("NAME").
  ObjectExtensions object;
  /// One object type's own ("NAME@TYPE"): an effect switched on here replaces `object`'s for
  /// objects of that type (an effect off here leaves `object`'s).
  std::map<std::string, ObjectExtensions> object_by_type;

  /// The per_type effects objects of `type` move under.
  ObjectExtensions object_for(const std::string& type) const;
  /// These extensions as objects of `type` feel them: `object` = object_for(type), no
  /// object_by_type (what the predictor takes, models/extended_predictor.h).
  ModelExtensions for_type(const std::string& type) const;

  /// Throws InputError naming the effect and parameter when a value is not finite or out of its
  /// physical range (the catalogue's).
  void validate() const;

  /// Member by member, every type's own effects included (values: -0.0 equals 0.0, NaN equals
  /// nothing): equal extensions predict the same.
  bool operator==(const ModelExtensions&) const = default;
};

// Extension names are the catalogue's, "NAME" or, for a per_type effect, "NAME@TYPE" (the
// extension of objects of TYPE alone, ModelExtensions::object_by_type).

/// The size of extension `name` in `ext` (effect_size of its typed values) and the size below
/// which it is negligible (the catalogue's).
double extension_size(const ModelExtensions& ext, const std::string& name);
double negligible_size(const std::string& name);

/// The typed values of extension `name`'s parameters in `ext` (catalogue order).
std::vector<double> extension_values(const ModelExtensions& ext, const std::string& name);
/// Sets extension `name`'s parameters from typed values (catalogue order). Throws InputError
/// when the count is wrong or a value is out of its physical range.
void set_extension_values(ModelExtensions* ext, const std::string& name,
                          const std::vector<double>& typed);
/// Whether extension `name` differs from the nominal model in `ext`.
bool extension_active(const ModelExtensions& ext, const std::string& name);
/// The names of the active extensions, in catalogue order (each per_type effect's shared one,
/// then its types' in their names' order).
std::vector<std::string> active_extensions(const ModelExtensions& ext);
/// "name: key=value unit, ..." for people.
std::string describe_extension(const ModelExtensions& ext, const std::string& name);

}  // namespace airtwin
