#include "sim/reached_air.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace airtwin {

ReachedAir::ReachedAir(const CfdField& cfd, const AirTransportParameters& params, double timestep_s,
                       const NozzleOrientation& initial, size_t points)
    : cfd_(cfd),
      transport_(params, timestep_s, initial, cfd.startup(), cfd.formation(),
                 cfd.stagnation_point(initial)),
      points_(points) {
  for (PointState& f : points_) {
    f.reached = initial;
    f.reached_s = transport_.s_at_lag(0);
  }
  ring_.assign(static_cast<size_t>(transport_.capacity()), cfd.at(initial));
}

void ReachedAir::push(const NozzleOrientation& effective, const CfdOrientedField& present) {
  transport_.push(effective, present.stagnation_point());
  newest_ = (newest_ + 1) % static_cast<int>(ring_.size());
  ring_[static_cast<size_t>(newest_)] = present;
}

bool ReachedAir::begin_step() {
  if (!transport_.enabled() || (transport_.steady() && !forming_)) return false;
  forming_ = false;
  return true;
}

const CfdOrientedField& ReachedAir::lagged(int steps) const {
  const int n = static_cast<int>(ring_.size());
  const int back = std::clamp(steps, 0, n - 1);
  return ring_[static_cast<size_t>((newest_ - back + n) % n)];
}

const CfdOrientedField* ReachedAir::last_reached(const PointState& f) {
  const int before = f.steps + 1;
  const NozzleOrientation& b = transport_.at_lag(before);
  if (b.pan_rad != f.reached.pan_rad || b.tilt_rad != f.reached.tilt_rad) return nullptr;
  return &lagged(before);
}

double ReachedAir::carry_factor(PointState& f, const Eigen::Vector2d& p_W, double z_m) {
  // phi changes slowly along a sweep: it is taken again when the newest s or the reached
  // orientation's s has moved 5 cm or the point 2 cm, from at most kSamples of the old air 10 cm
  // apart (a path's time is a smooth integral; ~1 % of a 25-tracer step while the nozzle moves).
  constexpr double kSMoved2 = 0.05 * 0.05, kPointMoved2 = 0.02 * 0.02;  // m^2
  constexpr double kSegment = 0.10;                                     // m
  constexpr int kSamples = 6;
  const Eigen::Vector2d& s0 = lagged(0).stagnation_point();
  if (f.carry_set && (s0 - f.carry_s).squaredNorm() < kSMoved2 &&
      (p_W - f.carry_p).squaredNorm() < kPointMoved2 &&
      (f.reached_s - f.carry_reached_s).squaredNorm() < kSMoved2) {
    return f.carry;
  }
  f.carry_set = true;
  f.carry_s = s0;
  f.carry_p = p_W;
  f.carry_reached_s = f.reached_s;
  const Eigen::Vector2d d = p_W - s0;
  const double length = d.norm();
  if (length < 0.02) return f.carry = 1.0;
  // The air the point felt last step.
  std::optional<CfdOrientedField> built;
  const CfdOrientedField* old = last_reached(f);
  if (old == nullptr) old = &built.emplace(cfd_.at(f.reached));
  const int n = std::clamp(static_cast<int>(std::ceil(length / kSegment)), 2, kSamples);
  const Eigen::Vector2d e = d / length;
  std::array<double, kSamples> along{};
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector2d q = s0 + ((j + 0.5) * length / n) * e;
    along[static_cast<size_t>(j)] = old->at(q, z_m).u_W.dot(e);
  }
  return f.carry = transport_.carry_factor(along.data(), n, length);
}

ReachedAir::PointAir ReachedAir::at(size_t i, const Eigen::Vector2d& p_W, double z_m) {
  PointAir out;
  PointState& f = points_[i];
  const double carry = transport_.carried() ? carry_factor(f, p_W, z_m) : 1.0;
  const int steps = transport_.reached_steps(p_W, carry);
  if (transport_.forms() || transport_.carried()) {
    const NozzleOrientation& now = transport_.at_lag(steps);
    const bool changed = now.pan_rad != f.reached.pan_rad || now.tilt_rad != f.reached.tilt_rad;
    if (transport_.forms()) {
      const CfdOrientedField& reached = lagged(steps);
      if (changed) {
        const CfdOrientedField* last = last_reached(f);
        const Eigen::Vector2d u_before =
            last ? last->at(p_W, z_m).u_W : cfd_.at(f.reached, p_W, z_m).u_W;
        f.departure -= reached.at(p_W, z_m).u_W - u_before;
      }
      f.departure *= transport_.formation_decay((p_W - reached.stagnation_point()).norm());
      if (f.departure.squaredNorm() < 1e-8) {
        f.departure.setZero();  // below 0.1 mm/s
      } else {
        out.departure = f.departure;
        forming_ = true;
      }
    }
    if (changed) {
      f.reached = now;
      f.reached_s = transport_.s_at_lag(steps);
    }
    f.steps = steps;
  }
  if (steps > 0) out.field = &lagged(steps);
  return out;
}

}  // namespace airtwin
