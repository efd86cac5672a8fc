#include "models/wall_jet_table.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// Solves ln(q) / (q - 1) = x for q > 1, given 0 < x < 1 (the left side falls from 1 to 0).
double solve_peak_ratio(double x) {
  double lo = 1.0 + 1e-12, hi = 2.0;
  while (std::log(hi) / (hi - 1.0) > x) hi *= 2.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (std::log(mid) / (mid - 1.0) > x ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Relative speed factor of direction beta at tilt phi before the global scaling.
double relative_peak(const WallJetDesign& d, double tilt_rad, double beta_rad) {
  return std::cos(tilt_rad) *
         std::pow(oblique_momentum_share(tilt_rad, beta_rad), d.spread_exponent);
}

}  // namespace

void WallJetDesign::validate() const {
  auto bad = [](const std::string& w) { throw InputError("wall-jet design: " + w); };
  if (static_cast<int>(tilts_deg.size()) < FieldTable::kMinTilts) bad("needs at least 3 tilts");
  for (size_t i = 0; i < tilts_deg.size(); ++i) {
    if (!(tilts_deg[i] >= 0 && tilts_deg[i] < 90)) bad("tilts must be in [0, 90) deg");
    if (i && !(tilts_deg[i] > tilts_deg[i - 1])) bad("tilts must be strictly increasing");
  }
  if (!(peak_speed_mps > 0)) bad("peak_speed_mps must be > 0");
  if (!(peak_radius_m > 0)) bad("peak_radius_m must be > 0");
  if (!(reach_radius_m > peak_radius_m)) bad("reach_radius_m must exceed peak_radius_m");
  if (!(reach_speed_mps > 0)) bad("reach_speed_mps must be > 0");
  if (!(spread_exponent >= 0 && spread_exponent <= 1)) bad("spread_exponent must be in [0, 1]");
}

double oblique_momentum_share(double tilt_rad, double beta_rad) {
  // Hasson & Peck (1964): sheet from an oblique jet, t = angle between jet and the floor.
  const double t = kPi / 2 - tilt_rad;
  const double denom = 1.0 - std::cos(t) * std::cos(beta_rad);
  return std::pow(std::sin(t), 3) / (denom * denom);
}

FieldCoefficients profile_from_shape(double peak_speed_mps, double peak_radius_m,
                                     double decay_rate_per_m) {
  const double x = decay_rate_per_m * peak_radius_m;
  if (!(x > 0 && x < 1)) {
    throw InputError("wall-jet design: decay rate x peak radius must be in (0, 1), got " +
                     std::to_string(x));
  }
  // Peak of eq. (3) at r_p = ln(b3/b2) / (b2 - b3) with b2 = -k and b3 = q b2.
  const double q = solve_peak_ratio(x);
  FieldCoefficients c;
  c.b2 = -decay_rate_per_m;
  c.b3 = q * c.b2;
  c.b1 = peak_speed_mps / (std::exp(c.b2 * peak_radius_m) - std::exp(c.b3 * peak_radius_m));
  return c;
}

FieldTable construct_wall_jet_table(const WallJetDesign& d) {
  d.validate();
  const int n_alpha = FieldTable::kAlphaBins;

  // Scale so that the strongest direction of any tilt peaks at peak_speed.
  double max_rel = 0.0;
  for (double tilt_deg : d.tilts_deg) {
    for (int a = 0; a < n_alpha; ++a) {
      max_rel = std::max(max_rel, relative_peak(d, deg_to_rad(tilt_deg), deg_to_rad(a)));
    }
  }
  const double speed_scale = d.peak_speed_mps / max_rel;

  // Decay rate of the normal jet: its profile must pass through (reach_radius, reach_speed).
  // v(reach) falls monotonically with k, so bisect on k in (0, 1 / peak_radius).
  const double u0 = speed_scale * relative_peak(d, 0.0, 0.0);
  if (!(d.reach_speed_mps < u0)) {
    throw InputError("wall-jet design: reach_speed_mps must be below the normal jet's peak (" +
                     std::to_string(u0) + " m/s)");
  }
  double k_lo = 1e-9, k_hi = (1.0 - 1e-9) / d.peak_radius_m;
  for (int it = 0; it < 200; ++it) {
    const double k = 0.5 * (k_lo + k_hi);
    const double v = profile_from_shape(u0, d.peak_radius_m, k).speed(d.reach_radius_m);
    (v > d.reach_speed_mps ? k_lo : k_hi) = k;
  }
  const double k0 = 0.5 * (k_lo + k_hi);

  std::vector<double> tilts_rad;
  std::vector<std::array<FieldCoefficients, FieldTable::kAlphaBins>> blocks(d.tilts_deg.size());
  for (size_t i = 0; i < d.tilts_deg.size(); ++i) {
    const double tilt = deg_to_rad(d.tilts_deg[i]);
    tilts_rad.push_back(tilt);
    const double r_p = d.peak_radius_m / std::cos(tilt);
    for (int a = 0; a < n_alpha; ++a) {
      const double share = std::pow(oblique_momentum_share(tilt, deg_to_rad(a)), d.spread_exponent);
      const double peak = speed_scale * std::cos(tilt) * share;
      const double k = std::min(k0 / share, 0.999 / r_p);  // a peak must exist (k r_p < 1)
      blocks[i][a] = profile_from_shape(peak, r_p, k);
    }
  }
  return FieldTable(std::move(tilts_rad), std::move(blocks));
}

}  // namespace airtwin
