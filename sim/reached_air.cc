#include "sim/reached_air.h"

namespace airtwin {

ReachedAir::ReachedAir(const CfdField& cfd, const AirTransportParameters& params, double timestep_s,
                       const NozzleOrientation& initial, size_t points)
    : cfd_(cfd),
      transport_(params, timestep_s, initial, cfd.startup(), cfd.formation(),
                 cfd.stagnation_point(initial)),
      formation_(points, Formation{initial, 0, {0.0, 0.0}}) {
  // At most two lookups per point a step (the reached orientation, and the formation's
  // orientation before it): no reallocation, so the fields handed out stay valid through the
  // step.
  lagged_.reserve(2 * points);
}

void ReachedAir::push(const NozzleOrientation& effective, const CfdOrientedField& present) {
  transport_.push(effective, present.stagnation_point());
  present_ = &present;
}

bool ReachedAir::begin_step() {
  lagged_.clear();
  if (!transport_.enabled() || (transport_.steady() && !forming_)) return false;
  forming_ = false;
  return true;
}

const CfdOrientedField& ReachedAir::lagged(int steps) {
  for (const auto& [k, f] : lagged_) {
    if (k == steps) return f;
  }
  lagged_.emplace_back(steps, cfd_.at(transport_.at_lag(steps)));
  return lagged_.back().second;
}

ReachedAir::PointAir ReachedAir::at(size_t i, const Eigen::Vector2d& p_W, double z_m) {
  PointAir out;
  const int steps = transport_.reached_steps(p_W);
  if (transport_.forms()) {
    const CfdOrientedField& reached = steps == 0 ? *present_ : lagged(steps);
    Formation& f = formation_[i];
    const NozzleOrientation& now = transport_.at_lag(steps);
    if (now.pan_rad != f.reached.pan_rad || now.tilt_rad != f.reached.tilt_rad) {
      // Last step's orientation is one step further back now, usually already built.
      const int before = f.steps + 1;
      const NozzleOrientation& b = transport_.at_lag(before);
      const bool cached = b.pan_rad == f.reached.pan_rad && b.tilt_rad == f.reached.tilt_rad;
      const Eigen::Vector2d u_before =
          cached ? lagged(before).at(p_W, z_m).u_W : cfd_.at(f.reached, p_W, z_m).u_W;
      f.departure -= reached.at(p_W, z_m).u_W - u_before;
      f.reached = now;
    }
    f.steps = steps;
    f.departure *= transport_.formation_decay((p_W - reached.stagnation_point()).norm());
    if (f.departure.squaredNorm() < 1e-8) {
      f.departure.setZero();  // below 0.1 mm/s
    } else {
      out.departure = f.departure;
      forming_ = true;
    }
  }
  if (steps > 0) out.field = &lagged(steps);
  return out;
}

}  // namespace airtwin
