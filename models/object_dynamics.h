#pragma once
// The object motion model of section IV: the identified speed dynamics, eq. (8),
//   dv/dt = xi1 v + xi2 v_air + xi3,
// and the planar motion, eq. (9): the object moves along the radial direction alpha from the
// stagnation point s with speed max(v, 0).
//
// This header holds the fixed part: one object type's coefficients (ObjectDynamics), the table of
// named types shipped in models/data/object_types.csv or read from a user file (ObjectTypes), the
// right-hand side, and the reduction of eqs. (8)-(9) to one ray from s under a fixed orientation
// (Ray). Integrating it over time is the job of the predictors (models/trajectory_predictor.h).
//
// Stopping. At rest the drive xi2 v_air + xi3 decides: > 0 sets the object in motion; <= 0 means
// friction wins and the object stays put. A moving object stops when v reaches 0, which can only
// happen where the drive is <= 0 (v falls through 0 only if dv/dt = drive <= 0 there). Stopped is
// a state, not a negative speed: v is exactly 0 and the position is frozen while the drive stays
// <= 0, i.e. under the same orientation for good, and until an orientation makes it positive.

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "models/air_field.h"
#include "models/field_table.h"

namespace airtwin {

/// The coefficients of eq. (8) for one object type.
struct ObjectDynamics {
  double xi1 = 0.0;  ///< 1/s: speed damping (negative for a physical object)
  double xi2 = 0.0;  ///< dimensionless: air-speed gain
  double xi3 = 0.0;  ///< m/s^2: constant term, friction (negative or zero)

  /// eq. (8): dv/dt (m/s^2) for object speed v (m/s) in air of speed v_air (m/s).
  double acceleration(double v, double v_air) const { return xi1 * v + xi2 * v_air + xi3; }
  /// xi2 v_air + xi3 (m/s^2): the acceleration of an object at rest in air of speed v_air (m/s).
  /// An object at rest starts moving only when this is > 0.
  double drive(double v_air) const { return xi2 * v_air + xi3; }
  /// The air speed (m/s) above which an object at rest starts to move: -xi3 / xi2.
  double threshold_air_speed() const { return -xi3 / xi2; }

  /// Throws InputError (prefixed by `where`) unless the coefficients describe a physical object:
  /// finite, xi1 < 0 (speed decays without air), xi2 > 0 (air pushes downstream),
  /// xi3 <= 0 (friction opposes motion; an object at rest in still air stays at rest).
  void validate(const std::string& where) const;
};

/// The paper's identified coefficients (sections IV-B and IV-C).
inline constexpr ObjectDynamics kTracerDynamics{-2.66, 4.26, -8.53};
inline constexpr ObjectDynamics kCottonDynamics{-4.25, 3.46, -4.12};

/// Named object types and their eq. (8) coefficients. Immutable after loading; share freely.
///
/// File format: CSV with header `object,xi1,xi2,xi3` (any column order), one row per type; xi1 in
/// 1/s, xi2 dimensionless, xi3 in m/s^2; `#` comments and blank lines allowed. Names are 1-64
/// characters from [A-Za-z0-9_-] and unique.
class ObjectTypes {
 public:
  struct Entry {
    std::string name;
    ObjectDynamics dynamics;
  };

  /// Reads and validates a file. Every problem is an InputError naming file, line and column:
  /// missing/unknown column, non-finite number, bad or duplicate name, unphysical sign, no rows.
  static ObjectTypes load_csv(const std::string& path);
  /// Same, from text in memory; `source` names it in messages.
  static ObjectTypes parse_csv(std::string_view text, const std::string& source);
  /// The types shipped in models/data/object_types.csv (compiled in): tracer and cotton.
  static const ObjectTypes& defaults();

  /// The coefficients of type `name`; InputError listing the known names when there is none.
  const ObjectDynamics& at(std::string_view name) const;
  /// Whether a type of that name exists.
  bool contains(std::string_view name) const;
  const std::vector<Entry>& entries() const { return entries_; }
  size_t size() const { return entries_.size(); }

 private:
  std::string source_;
  std::vector<Entry> entries_;  // in file order
};

/// Under one nozzle orientation the air velocity is radial from s, so an object never leaves its
/// ray from s: the direction alpha is fixed and eqs. (8)-(9) reduce to the pair (r, v) with the
/// eq. (3) profile of that alpha, dr/dt = max(v, 0), dv/dt = xi1 v + xi2 v_air(r) + xi3.
///
/// At s itself (r = 0) there is no direction: the air speed is 0 (eq. 3 is exactly 0 there) and,
/// as OrientedField::velocity does, the object's velocity is taken as zero. Such an object does
/// not move under this orientation; its speed still follows eq. (8) with v_air = 0 (so it decays
/// and stops, since xi3 <= 0). `radial` is 0 for it and 1 otherwise.
struct Ray {
  Eigen::Vector2d s_W = Eigen::Vector2d::Zero();  ///< stagnation point (m)
  Eigen::Vector2d u_W = Eigen::Vector2d::Zero();  ///< unit direction from s; zero at s
  FieldCoefficients profile;                      ///< eq. (3) along this ray
  double r0 = 0.0;      ///< distance (m) of the point the ray was made from
  double radial = 0.0;  ///< 1 on a ray, 0 at s (the object cannot move)

  /// The point at distance r (m) along the ray.
  Eigen::Vector2d point(double r) const { return s_W + r * u_W; }
};

/// The ray from `field`'s stagnation point through p_W (m), with its eq. (3) profile. The two
/// views of one orientation give the same ray, bit for bit.
Ray ray_through(const OrientedField& field, const Eigen::Vector2d& p_W);
Ray ray_through(const OrientedRays& rays, const Eigen::Vector2d& p_W);

/// Time derivative of the planar state (p_W, v) while the object moves (eqs. 8-9). Uses the
/// smooth continuation dp/dt = v u (no max): while moving v >= 0, so it equals eq. (9), and the
/// max's kink is kept out of the integrand (the stop event handles v = 0). u is the unit direction
/// from s (zero at s). Units: m/s and m/s^2.
struct PlanarRate {
  Eigen::Vector2d p_dot_W;
  double v_dot;
};
PlanarRate moving_rate(const OrientedField& field, const ObjectDynamics& xi,
                       const Eigen::Vector2d& p_W, double v);

}  // namespace airtwin
