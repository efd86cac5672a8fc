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
  if (!(std::isfinite(front_co_flow) && front_co_flow >= 0.0 && front_co_flow <= 2.0)) {
    throw FieldError("air_transport.front_co_flow",
                     "expected [0, 2], got " + std::to_string(front_co_flow));
  }
  if (!(std::isfinite(front_counter_flow) && front_counter_flow >= 0.0 &&
        front_counter_flow <= 2.0)) {
    throw FieldError("air_transport.front_counter_flow",
                     "expected [0, 2], got " + std::to_string(front_counter_flow));
  }
}

namespace {
constexpr double kPaceDr = 5e-3;        // m: the grid of the still-air front's pace
constexpr double kSlowestFront = 0.05;  // m/s: a front held back further stalls at this
}  // namespace

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
  // old has reached r when lag(r) < (k + 1/2) dt. One table per level of phi.
  levels_ = carried() ? 2 * kCarryLevels + 1 : 1;
  reach2_.assign(static_cast<size_t>(levels_ * capacity_), std::numeric_limits<double>::infinity());
  if (!enabled()) return;
  constexpr double kDr = 1e-3;
  constexpr int kN = 10000;
  std::vector<double> still(kN + 1), shortening(kN + 1, 0.0);
  for (int i = 0; i <= kN; ++i) {
    const size_t u = static_cast<size_t>(i);
    still[u] = still_lag_s(i * kDr);
    if (formation_ && i > 0) shortening[u] = std::log(2.0) * formation_time_s(i * kDr);
  }
  std::vector<double> lag_max(kN + 1);
  for (int level = 0; level < levels_; ++level) {
    const double carry = levels_ == 1 ? 1.0 : std::exp2((level - kCarryLevels) / 8.0);
    double m = 0.0;
    for (size_t i = 0; i < still.size(); ++i) {
      lag_max[i] = m = std::max(m, std::max(0.0, carry * still[i] - shortening[i]));
    }
    double* reach2 = reach2_.data() + static_cast<size_t>(level) * static_cast<size_t>(capacity_);
    for (int k = 0; k < capacity_ - 1; ++k) {
      const double t = (k + 0.5) * timestep_s_;
      const auto it = std::lower_bound(lag_max.begin(), lag_max.end(), t);
      if (it == lag_max.end()) break;  // everything within 10 m reached: infinite from here on
      const double r = static_cast<double>(it - lag_max.begin()) * kDr;
      reach2[k] = r * r;
    }
  }
  // The still-air front's pace, the still lag's slope (the carried front's u_f).
  {
    const int n = static_cast<int>(std::ceil(10.0 / kPaceDr));
    pace_.resize(static_cast<size_t>(n));
    for (int j = 0; j < n; ++j) {
      const double slope = (still_lag_s((j + 1) * kPaceDr) - still_lag_s(j * kPaceDr)) / kPaceDr;
      pace_[static_cast<size_t>(j)] = std::max(slope, 1e-3);
    }
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

double AirTransport::still_lag_s(double r_m) const {
  if (!(r_m > 0.0)) return 0.0;
  return startup_ ? startup_->wall_jet_lag_s(r_m) : r_m / params_.front_speed_mps;
}

double AirTransport::lag_s(double r_m, double carry) const {
  if (!(r_m > 0.0)) return 0.0;
  const double lag = carry * still_lag_s(r_m);
  return formation_ ? std::max(0.0, lag - std::log(2.0) * formation_time_s(r_m)) : lag;
}

double AirTransport::front_speed_mps(double r_m) const {
  if (pace_.empty()) return std::numeric_limits<double>::infinity();  // the lag is off
  const double j = std::max(0.0, r_m) / kPaceDr;
  const size_t i = std::min(static_cast<size_t>(j), pace_.size() - 1);
  return 1.0 / pace_[i];
}

double AirTransport::carry_factor(const double* along, int n, double length_m) const {
  if (!carried() || n <= 0 || !(length_m > 0.0)) return 1.0;
  const double dr = length_m / n;
  double still = 0.0, carried_time = 0.0;
  for (int j = 0; j < n; ++j) {
    const double uf = front_speed_mps((j + 0.5) * dr);
    const double w = along[j];
    const double v = uf + params_.front_co_flow * std::max(w, 0.0) +
                     params_.front_counter_flow * std::min(w, 0.0);
    still += 1.0 / uf;
    carried_time += 1.0 / std::max(v, kSlowestFront);
  }
  return std::clamp(carried_time / still, std::exp2(-kCarryLevels / 8.0),
                    std::exp2(kCarryLevels / 8.0));
}

const double* AirTransport::reach2_for(double carry) const {
  int level = 0;
  if (levels_ > 1) {
    level = kCarryLevels + static_cast<int>(std::lround(8.0 * std::log2(carry)));
    level = std::clamp(level, 0, levels_ - 1);
  }
  return reach2_.data() + static_cast<size_t>(level) * static_cast<size_t>(capacity_);
}

double AirTransport::formation_time_s(double r_m) const {
  return params_.formation_time_scale * formation_->time_s(r_m);
}

int AirTransport::lag_steps(double r_m, double carry) const {
  if (!enabled() || !(r_m > 0.0)) return 0;
  const double steps = lag_s(r_m, carried() ? carry : 1.0) / timestep_s_;
  return static_cast<int>(std::min<double>(std::llround(steps), capacity_ - 1));
}

int AirTransport::reached_steps(const Eigen::Vector2d& p_W, double carry) const {
  if (!enabled()) return 0;
  const double* reach2 = reach2_for(carry);
  // No air younger than the reach of p's distance from the box has arrived: start there.
  const Eigen::Vector2d out =
      (s_min_ - p_W).cwiseMax(p_W - s_max_).cwiseMax(Eigen::Vector2d::Zero());
  const double d2 = out.squaredNorm();
  const int first = static_cast<int>(std::upper_bound(reach2, reach2 + capacity_ - 1, d2) - reach2);
  // The ring read backwards from the newest in its two contiguous runs (no index wrapping in the
  // loops: this runs for every object every step while the nozzle moves).
  const int last = capacity_ - 1;  // the oldest is the answer when nothing younger has arrived
  const double px = p_W.x(), py = p_W.y();
  const Eigen::Vector2d* s = s_ring_.data();
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

const Eigen::Vector2d& AirTransport::s_at_lag(int steps) const {
  const int back = std::clamp(steps, 0, capacity_ - 1);
  return s_ring_[static_cast<size_t>((newest_ - back + capacity_) % capacity_)];
}

}  // namespace airtwin
