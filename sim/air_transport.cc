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
  if (!(std::isfinite(formation_time_scale) && formation_time_scale > 0.0 &&
        formation_time_scale <= 10.0)) {
    throw FieldError("air_transport.formation_time_scale",
                     "expected (0, 10], got " + std::to_string(formation_time_scale));
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
  s_min_ = s_max_ = initial_s_W;
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
  // The box grows with each new s (a larger box only starts the search earlier) and is fitted
  // to the kept points again every 64 steps while some kept orientation differs.
  s_min_ = s_min_.cwiseMin(s_W);
  s_max_ = s_max_.cwiseMax(s_W);
  if (newest_ % 64 == 0 && (changed || steps_since_change_ < capacity_ - 1)) {
    s_min_ = s_max_ = s_W;
    for (const Eigen::Vector2d& s : s_ring_) {
      s_min_ = s_min_.cwiseMin(s);
      s_max_ = s_max_.cwiseMax(s);
    }
  }
  steps_since_change_ = changed ? 0 : std::min<int64_t>(steps_since_change_ + 1, capacity_);
}

double AirTransport::lag_s(double r_m) const {
  if (!(r_m > 0.0)) return 0.0;
  const double lag = startup_ ? startup_->wall_jet_lag_s(r_m) : r_m / params_.front_speed_mps;
  return formation_ ? std::max(0.0, lag - std::log(2.0) * formation_time_s(r_m)) : lag;
}

double AirTransport::formation_time_s(double r_m) const {
  return params_.formation_time_scale * formation_->time_s(r_m);
}

int AirTransport::lag_steps(double r_m) const {
  if (!enabled() || !(r_m > 0.0)) return 0;
  const double steps = lag_s(r_m) / timestep_s_;
  return static_cast<int>(std::min<double>(std::llround(steps), capacity_ - 1));
}

int AirTransport::reached_steps(const Eigen::Vector2d& p_W) const {
  if (!enabled()) return 0;
  // No air younger than the reach of p's distance from the box has arrived: start there.
  const Eigen::Vector2d out =
      (s_min_ - p_W).cwiseMax(p_W - s_max_).cwiseMax(Eigen::Vector2d::Zero());
  const double d2 = out.squaredNorm();
  const int first =
      static_cast<int>(std::upper_bound(reach2_.begin(), reach2_.end() - 1, d2) - reach2_.begin());
  // The ring read backwards from the newest in its two contiguous runs (no index wrapping in the
  // loops: this runs for every object every step while the nozzle moves).
  const int last = capacity_ - 1;  // the oldest is the answer when nothing younger has arrived
  const double px = p_W.x(), py = p_W.y();
  const Eigen::Vector2d* s = s_ring_.data();
  const double* reach2 = reach2_.data();
  int k = first;
  for (int i = newest_ - k; k < last && i >= 0; ++k, --i) {
    const double dx = px - s[i].x(), dy = py - s[i].y();
    if (dx * dx + dy * dy < reach2[k]) return k;
  }
  for (int i = newest_ - k + capacity_; k < last; ++k, --i) {
    const double dx = px - s[i].x(), dy = py - s[i].y();
    if (dx * dx + dy * dy < reach2[k]) return k;
  }
  return last;
}

double AirTransport::formation_decay(double r_m) const {
  if (!forms()) return 0.0;
  return std::exp(-timestep_s_ / formation_time_s(std::max(0.0, r_m)));
}

const NozzleOrientation& AirTransport::at_lag(int steps) const {
  const int back = std::clamp(steps, 0, capacity_ - 1);
  return ring_[static_cast<size_t>((newest_ - back + capacity_) % capacity_)];
}

}  // namespace airtwin
