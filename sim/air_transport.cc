#include "sim/air_transport.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/errors.h"

namespace airtwin {

void AirTransportParameters::validate() const {
  if (!(std::isfinite(front_speed_mps) && front_speed_mps >= 0.0)) {
    throw FieldError("air_transport.front_speed_mps",
                     "expected >= 0 (0: no lag), got " + std::to_string(front_speed_mps));
  }
  if (!(std::isfinite(max_lag_s) && max_lag_s >= 0.0 && max_lag_s <= 60.0)) {
    throw FieldError("air_transport.max_lag_s",
                     "expected [0, 60] s, got " + std::to_string(max_lag_s));
  }
}

AirTransport::AirTransport(const AirTransportParameters& params, double timestep_s,
                           const NozzleOrientation& initial, const CfdStartup* startup,
                           const WallJetFormation* formation, const Eigen::Vector2d& initial_s_W)
    : params_(params),
      startup_(params.cfd_timing ? startup : nullptr),
      formation_(params.formation && startup_ != nullptr ? formation : nullptr),
      timestep_s_(timestep_s) {
  params_.validate();
  AIRTWIN_DEMAND(std::isfinite(timestep_s) && timestep_s > 0.0);
  capacity_ = enabled() ? static_cast<int>(std::ceil(params_.max_lag_s / timestep_s_)) + 1 : 1;
  ring_.assign(static_cast<size_t>(capacity_), initial);
  s_ring_.assign(static_cast<size_t>(capacity_), initial_s_W);
  steps_since_change_ = capacity_;
  // The reach after k steps: the lag's running maximum over r on a 1 mm grid out to 10 m (a
  // point counts as reached once every nearer one is), against lag_steps' rounding: air k steps
  // old has reached r when lag(r) < (k + 1/2) dt.
  reach2_.assign(static_cast<size_t>(capacity_), std::numeric_limits<double>::infinity());
  if (!enabled()) return;
  constexpr double kDr = 1e-3;
  constexpr int kN = 10000;
  std::vector<double> lag_max(kN + 1);
  double m = 0.0;
  for (int i = 0; i <= kN; ++i) lag_max[static_cast<size_t>(i)] = m = std::max(m, lag_s(i * kDr));
  for (int k = 0; k < capacity_ - 1; ++k) {
    const double t = (k + 0.5) * timestep_s_;
    const auto it = std::lower_bound(lag_max.begin(), lag_max.end(), t);
    if (it == lag_max.end()) break;  // everything within 10 m reached: infinite from here on
    const double r = static_cast<double>(it - lag_max.begin()) * kDr;
    reach2_[static_cast<size_t>(k)] = r * r;
  }
}

void AirTransport::push(const NozzleOrientation& effective, const Eigen::Vector2d& s_W) {
  const NozzleOrientation& present = ring_[static_cast<size_t>(newest_)];
  const bool changed =
      effective.pan_rad != present.pan_rad || effective.tilt_rad != present.tilt_rad;
  newest_ = (newest_ + 1) % capacity_;
  ring_[static_cast<size_t>(newest_)] = effective;
  s_ring_[static_cast<size_t>(newest_)] = s_W;
  steps_since_change_ = changed ? 0 : std::min<int64_t>(steps_since_change_ + 1, capacity_);
}

double AirTransport::lag_s(double r_m) const {
  if (!(r_m > 0.0)) return 0.0;
  const double lag = startup_ ? startup_->wall_jet_lag_s(r_m) : r_m / params_.front_speed_mps;
  return formation_ ? std::max(0.0, lag - std::log(2.0) * formation_->time_s(r_m)) : lag;
}

int AirTransport::lag_steps(double r_m) const {
  if (!enabled() || !(r_m > 0.0)) return 0;
  const double steps = lag_s(r_m) / timestep_s_;
  return static_cast<int>(std::min<double>(std::llround(steps), capacity_ - 1));
}

int AirTransport::reached_steps(const Eigen::Vector2d& p_W) const {
  if (!enabled()) return 0;
  for (int k = 0; k < capacity_ - 1; ++k) {
    const int i = (newest_ - k + capacity_) % capacity_;
    if ((p_W - s_ring_[static_cast<size_t>(i)]).squaredNorm() < reach2_[static_cast<size_t>(k)]) {
      return k;
    }
  }
  return capacity_ - 1;
}

double AirTransport::formation_decay(double r_m) const {
  if (!forms()) return 0.0;
  return std::exp(-timestep_s_ / formation_->time_s(std::max(0.0, r_m)));
}

const NozzleOrientation& AirTransport::at_lag(int steps) const {
  const int back = std::clamp(steps, 0, capacity_ - 1);
  return ring_[static_cast<size_t>((newest_ - back + capacity_) % capacity_)];
}

}  // namespace airtwin
