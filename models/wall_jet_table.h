#pragma once
// Construction of the default coefficient table of eq. (3) from wall-jet physics and the paper's
// own numbers (the paper does not publish its table). The reasoning, with numbers, is in
// docs/field_model.md; in short, per tilt phi and direction beta (= alpha, from downstream):
//
//  * Peak speed. The free jet's centreline speed where it meets the floor falls as 1/L with the
//    slant distance L = h / cos(phi), so the peak scales with cos(phi). Oblique impingement sends
//    more momentum downstream: the inviscid sheet (Hasson & Peck 1964) gives a momentum share
//    m(beta) = sin^3(t) / (1 - cos(t) cos(beta))^2 per radian relative to the normal jet,
//    t = 90 deg - phi. Turbulent mixing smooths this, so the speed follows m^spread_exponent
//    (0.25: half the inviscid sqrt). The largest peak over all tilts and directions is scaled to
//    the paper's 3.4 m/s.
//  * Peak position. The impingement zone grows with the jet width, i.e. with L: the peak radius
//    scales with 1 / cos(phi).
//  * Decay. Set by the paper's evidence rather than the pure wall-jet law: tracers placed 58 cm
//    from s moved, and the identified tracer model moves an object only where v_air > 2.0 m/s, so
//    the normal jet is given reach_speed at reach_radius (2.2 m/s at 0.6 m: 10% above threshold).
//    Weaker directions decay faster: the decay rate scales with 1 / m^spread_exponent.
// Each (peak speed U, peak radius r_p, decay rate k) maps to eq. (3) exactly: b2 = -k,
// b3 = q b2 with ln(q) / (q - 1) = k r_p (the peak of eq. (3) is at ln(b3/b2) / (b2 - b3)), and
// b1 = U / (exp(b2 r_p) - exp(b3 r_p)).

#include <vector>

#include "models/field_table.h"

namespace airtwin {

struct WallJetDesign {
  std::vector<double> tilts_deg = {0.0, 22.5, 45.0};
  double peak_speed_mps = 3.4;    ///< largest peak over all tilts and directions (paper, IV-B)
  double peak_radius_m = 0.13;    ///< radius of the peak for the normal jet (phi = 0)
  double reach_radius_m = 0.6;    ///< the normal jet has reach_speed here ...
  double reach_speed_mps = 2.2;   ///< ... 10% above the tracer threshold 8.53 / 4.26 = 2.0 m/s
  double spread_exponent = 0.25;  ///< speed ~ (momentum share)^spread_exponent

  /// Throws InputError when a number is outside its meaningful range.
  void validate() const;
};

/// Momentum share per radian in direction beta (rad, from downstream) for tilt phi (rad), relative
/// to the normal jet's uniform share (1 for phi = 0).
double oblique_momentum_share(double tilt_rad, double beta_rad);

/// The eq. (3) profile with peak speed U (m/s) at radius r_p (m) and far decay rate k (1/m).
/// Requires k r_p < 1 (a peak exists); throws InputError otherwise.
FieldCoefficients profile_from_shape(double peak_speed_mps, double peak_radius_m,
                                     double decay_rate_per_m);

/// The whole table for a design. Deterministic.
FieldTable construct_wall_jet_table(const WallJetDesign& design);

}  // namespace airtwin
