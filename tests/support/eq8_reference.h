#pragma once
// An independent integration of eqs. (8)-(9) along one ray from s, for tests that compare a
// simulation with the model: dr/dt = v, dv/dt = xi1 v + xi2 scale u(r) + xi3 L by RK4 at 0.1 ms,
// starting at rest, with the stop of eq. (9) (v reaches 0 where the drive is <= 0). L is 1, or
// with the air's lift k, max(0, 1 - k (scale u - v)^2) (the air_lift effect). With the share s of
// the friction that is a linearised drag's intercept (the linearised_drag effect),
// xi1 v + xi2 scale u = c w, c = -xi1, w = (xi2 / c) scale u - v, becomes (c |w| - s |xi3|)
// sign(w) for |w| >= w0 = 2 s |xi3| / c and (c / 2 w0) |w| w below, and xi3 becomes (1 - s) xi3.

#include <Eigen/Core>
#include <vector>

#include "models/air_field.h"
#include "models/object_dynamics.h"

namespace airtwin::testing {

/// The effects the reference carries (each off by default).
struct Eq8RayTerms {
  double air_scale = 1.0;        ///< the air speed's factor
  double lift_s2pm2 = 0.0;       ///< k (s^2/m^2)
  double intercept_share = 0.0;  ///< s
};

/// The distance r (m) from s at t = 0, sample_dt, ..., duration for an object starting at rest at
/// p0_W.
std::vector<double> eq8_ray_reference(const OrientedField& field, const ObjectDynamics& xi,
                                      const Eigen::Vector2d& p0_W, double duration_s,
                                      double sample_dt_s, const Eq8RayTerms& terms = {});

}  // namespace airtwin::testing
