#include "models/nozzle_geometry.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

// Derivative of eq. (2)'s radius map rho_s(rho_c) = rho_c - a1 rho_c^a2.
double stagnation_radius_slope(const NozzleGeometry& g, double rho_c) {
  return 1.0 - g.a1 * g.a2 * std::pow(rho_c, g.a2 - 1.0);
}

// The projection radius where rho_s(rho_c) stops growing (eq. (2)'s fold), infinite for a1 = 0.
double fold_radius(const NozzleGeometry& g) {
  if (g.a1 == 0.0) return INFINITY;
  return std::pow(1.0 / (g.a1 * g.a2), 1.0 / (g.a2 - 1.0));
}

}  // namespace

void NozzleGeometry::validate() const {
  auto bad = [](const std::string& what) { throw InputError("nozzle geometry: " + what); };
  if (!(std::isfinite(height_m) && height_m > 0)) bad("height_m must be > 0");
  if (!(std::isfinite(a1) && a1 >= 0)) bad("a1 must be >= 0");
  if (!(std::isfinite(a2) && a2 > 1)) bad("a2 must be > 1");
  if (!(tilt_min_rad >= 0 && tilt_min_rad < tilt_max_rad && tilt_max_rad < kPi / 2)) {
    bad("tilt range must satisfy 0 <= tilt_min < tilt_max < 90 deg");
  }
  if (height_m * std::tan(tilt_max_rad) >= fold_radius(*this)) {
    bad("tilt_max " + std::to_string(rad_to_deg(tilt_max_rad)) +
        " deg is beyond the fold of eq. (2) at " +
        std::to_string(rad_to_deg(std::atan(fold_radius(*this) / height_m))) +
        " deg, where the stagnation point moves back toward the origin");
  }
}

Eigen::Vector2d projection_point(const NozzleGeometry& g, const NozzleOrientation& o) {
  // eq. (1)
  const double rho_c = g.height_m * std::tan(o.tilt_rad);
  return rho_c * Eigen::Vector2d(std::cos(o.pan_rad), std::sin(o.pan_rad));
}

double stagnation_radius(const NozzleGeometry& g, double projection_radius_m) {
  // eq. (2): s lies between the origin and c, a1 |c|^a2 short of c.
  return projection_radius_m - g.a1 * std::pow(projection_radius_m, g.a2);
}

Eigen::Vector2d stagnation_point(const NozzleGeometry& g, const NozzleOrientation& o) {
  const double rho_c = g.height_m * std::tan(o.tilt_rad);
  const double rho_s = stagnation_radius(g, rho_c);
  return rho_s * Eigen::Vector2d(std::cos(o.pan_rad), std::sin(o.pan_rad));
}

double fold_tilt_rad(const NozzleGeometry& g) {
  return std::atan(fold_radius(g) / g.height_m);  // atan(inf) = pi/2
}

double max_stagnation_radius(const NozzleGeometry& g) {
  return stagnation_radius(g, g.height_m * std::tan(g.tilt_max_rad));
}

double wrap_angle(double rad) {
  double r = std::remainder(rad, 2.0 * kPi);  // in [-pi, pi]
  if (r <= -kPi) r += 2.0 * kPi;
  return r;
}

AimResult aim_at_stagnation(const NozzleGeometry& g, const Eigen::Vector2d& s_W,
                            double pan_hint_rad) {
  AimResult out;
  if (!s_W.allFinite() || !std::isfinite(pan_hint_rad)) {
    out.unreachable_reason = "target is not a finite point";
    return out;
  }
  const double rho_s = s_W.norm();
  const double rho_c_min = g.height_m * std::tan(g.tilt_min_rad);
  const double rho_c_max = g.height_m * std::tan(g.tilt_max_rad);
  const double rho_s_min = stagnation_radius(g, rho_c_min);
  const double rho_s_max = stagnation_radius(g, rho_c_max);
  if (rho_s > rho_s_max) {
    out.unreachable_reason = "stagnation point " + std::to_string(rho_s) +
                             " m from the origin is outside the reachable disc of radius " +
                             std::to_string(rho_s_max) +
                             " m (tilt <= " + std::to_string(rad_to_deg(g.tilt_max_rad)) + " deg)";
    return out;
  }
  if (rho_s < rho_s_min) {
    out.unreachable_reason = "stagnation point " + std::to_string(rho_s) +
                             " m from the origin needs a tilt below the minimum " +
                             std::to_string(rad_to_deg(g.tilt_min_rad)) + " deg";
    return out;
  }

  // Pan: s lies on the ray from the origin through c.
  NozzleOrientation o;
  o.pan_rad = rho_s > 0 ? std::atan2(s_W.y(), s_W.x()) : wrap_angle(pan_hint_rad);

  // Tilt: solve rho_s(rho_c) = target on [rho_c_min, rho_c_max], where the map is increasing.
  // Newton steps, kept inside a shrinking bracket (bisection when a step would leave it).
  double lo = rho_c_min, hi = rho_c_max;
  double rho_c = std::clamp(rho_s, lo, hi);  // rho_c >= rho_s; a good start for small offsets
  for (int it = 0; it < 100; ++it) {
    const double f = stagnation_radius(g, rho_c) - rho_s;
    if (f == 0.0) break;
    if (f > 0)
      hi = rho_c;
    else
      lo = rho_c;
    const double slope = stagnation_radius_slope(g, rho_c);
    double next = rho_c - f / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double step = std::abs(next - rho_c);
    rho_c = next;
    if (step < 1e-15 * (1.0 + rho_c) || hi - lo < 1e-15) break;
  }
  o.tilt_rad = std::atan(rho_c / g.height_m);
  out.orientation = o;
  return out;
}

}  // namespace airtwin
