#include "sim/air_transport.h"

#include <algorithm>
#include <cmath>
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
                           const NozzleOrientation& initial, const CfdStartup* startup)
    : params_(params), startup_(params.cfd_timing ? startup : nullptr), timestep_s_(timestep_s) {
  params_.validate();
  AIRTWIN_DEMAND(std::isfinite(timestep_s) && timestep_s > 0.0);
  capacity_ = enabled() ? static_cast<int>(std::ceil(params_.max_lag_s / timestep_s_)) + 1 : 1;
  ring_.assign(static_cast<size_t>(capacity_), initial);
  steps_since_change_ = capacity_;
}

void AirTransport::push(const NozzleOrientation& effective) {
  const NozzleOrientation& present = ring_[static_cast<size_t>(newest_)];
  const bool changed =
      effective.pan_rad != present.pan_rad || effective.tilt_rad != present.tilt_rad;
  newest_ = (newest_ + 1) % capacity_;
  ring_[static_cast<size_t>(newest_)] = effective;
  steps_since_change_ = changed ? 0 : std::min<int64_t>(steps_since_change_ + 1, capacity_);
}

int AirTransport::lag_steps(double r_m) const {
  if (!enabled() || !(r_m > 0.0)) return 0;
  const double lag_s = startup_ ? startup_->wall_jet_lag_s(r_m) : r_m / params_.front_speed_mps;
  const double steps = lag_s / timestep_s_;
  return static_cast<int>(std::min<double>(std::llround(steps), capacity_ - 1));
}

const NozzleOrientation& AirTransport::at_lag(int steps) const {
  const int back = std::clamp(steps, 0, capacity_ - 1);
  return ring_[static_cast<size_t>((newest_ - back + capacity_) % capacity_)];
}

}  // namespace airtwin
