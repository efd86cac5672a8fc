#pragma once
// Where the jet meets the floor: the projection point c (eq. 1), the stagnation point s (eq. 2),
// and the inverse the controller needs, a desired stagnation point -> nozzle orientation.
//
// World frame W: origin on the floor directly below the tilt axis, z up; pan theta is measured in
// the floor plane from +x, tilt phi from the vertical (phi = 0 points straight down).

#include <Eigen/Core>
#include <optional>
#include <string>

namespace airtwin {

/// A nozzle orientation, in radians: pan theta in [-pi, pi], tilt phi in [0, pi/2).
struct NozzleOrientation {
  double pan_rad = 0.0;
  double tilt_rad = 0.0;
};

/// Fixed geometry of the rig and the fitted constants of eq. (2).
struct NozzleGeometry {
  double height_m = 1.43;  ///< h: tilt servo shaft above the floor (paper, section II-A).
  double a1 = 0.1;         ///< eq. (2) gain, in m^(1-a2) so that |c - s| is in metres.
  double a2 = 2.33;        ///< eq. (2) exponent.
  double tilt_min_rad = 0.0;
  /// Largest tilt the inverse will command. 60 deg keeps eq. (2) monotone (its fold is at ~64 deg)
  /// and covers the idle orientation (50 deg) of Appendix D.
  double tilt_max_rad = 60.0 * 3.14159265358979323846 / 180.0;

  /// Throws InputError when the numbers cannot describe a rig (h <= 0, a1 < 0, a2 <= 1, tilt range
  /// outside [0, 90) deg or beyond the fold of eq. (2) where s stops moving away from the origin).
  void validate() const;
};

/// eq. (1): c = h tan(phi) [cos theta, sin theta], metres in W.
Eigen::Vector2d projection_point(const NozzleGeometry& g, const NozzleOrientation& o);

/// eq. (2): |c - s| = a1 |c|^a2, with s on the line through the origin and c, displaced from c
/// toward the origin (oblique impingement puts the stagnation point upstream of the geometric
/// impingement point). Returns the radius |s| for a projection radius |c| (metres).
double stagnation_radius(const NozzleGeometry& g, double projection_radius_m);

/// eq. (1) then eq. (2): the stagnation point s in W (metres).
Eigen::Vector2d stagnation_point(const NozzleGeometry& g, const NozzleOrientation& o);

/// The tilt (rad) at eq. (2)'s fold, where |s| stops growing with |c| (64.4 deg for the paper's
/// constants); beyond it eq. (2) would move s back toward, and past, the origin, so the field
/// model is not defined there. pi/2 when a1 = 0.
double fold_tilt_rad(const NozzleGeometry& g);

/// Largest |s| the geometry can reach within its tilt range (metres).
double max_stagnation_radius(const NozzleGeometry& g);

/// The result of aiming: an orientation, or the reason the target cannot be reached.
struct AimResult {
  std::optional<NozzleOrientation> orientation;
  std::string unreachable_reason;  ///< set when orientation is empty
  bool reachable() const { return orientation.has_value(); }
};

/// The inverse of eqs. (1)-(2): the orientation whose stagnation point is `s_W` (metres).
/// Pan is the direction of s (for s at the origin: `pan_hint_rad`, tilt 0). Tilt comes from a
/// safeguarded Newton solve of |s| = rho - a1 rho^a2 for rho = |c| = h tan(phi), to ~1e-13 m.
/// Targets outside the reachable disc (|s| > max_stagnation_radius) or needing a tilt outside
/// [tilt_min, tilt_max] come back unreachable with a reason; non-finite input too.
AimResult aim_at_stagnation(const NozzleGeometry& g, const Eigen::Vector2d& s_W,
                            double pan_hint_rad = 0.0);

/// Wraps an angle to (-pi, pi].
double wrap_angle(double rad);

}  // namespace airtwin
