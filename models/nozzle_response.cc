#include "models/nozzle_response.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/errors.h"

namespace airtwin {

void NozzleResponseParameters::validate() const {
  auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  if (!positive(max_speed_radps)) {
    throw InputError("nozzle response: max_speed_radps must be finite and > 0");
  }
  if (!positive(max_acceleration_radps2)) {
    throw InputError("nozzle response: max_acceleration_radps2 must be finite and > 0");
  }
  if (!(std::isfinite(transit_delay_s) && transit_delay_s >= 0.0)) {
    throw InputError("nozzle response: transit_delay_s must be finite and >= 0");
  }
}

void servo_axis_step(double target, double max_speed, double max_acceleration, double h,
                     double* angle, double* rate) {
  const double error = target - *angle;
  // The fastest rate toward the target from which the axis can still brake to a stop on it.
  const double stoppable = std::sqrt(2.0 * max_acceleration * std::abs(error));
  const double wanted = std::copysign(std::min(max_speed, stoppable), error);
  const double dv = std::clamp(wanted - *rate, -max_acceleration * h, max_acceleration * h);
  *rate += dv;
  const double next = *angle + *rate * h;
  // Arrived (or would pass the target in this step): stop on it.
  if ((target - next) * error <= 0.0) {
    *angle = target;
    *rate = 0.0;
  } else {
    *angle = next;
  }
}

ServoMove::ServoMove(double from, double to, double max_speed, double max_acceleration)
    : from_(from), to_(to), sign_(to >= from ? 1.0 : -1.0), acceleration_(max_acceleration) {
  const double distance = std::abs(to - from);
  if (distance == 0.0) return;
  // Accelerating to max_speed covers v^2 / (2 a); braking the same again.
  if (max_speed * max_speed / max_acceleration >= distance) {
    accelerating_s_ = std::sqrt(distance / max_acceleration);  // triangular
    peak_speed_ = max_acceleration * accelerating_s_;
  } else {
    accelerating_s_ = max_speed / max_acceleration;
    peak_speed_ = max_speed;
    cruise_s_ = (distance - max_speed * accelerating_s_) / max_speed;
  }
  duration_ = 2.0 * accelerating_s_ + cruise_s_;
}

double ServoMove::angle(double t) const {
  if (!(t > 0.0)) return from_;
  if (t >= duration_) return to_;
  const double a = acceleration_, ta = accelerating_s_;
  double travelled;
  if (t < ta) {
    travelled = 0.5 * a * t * t;
  } else if (t < ta + cruise_s_) {
    travelled = 0.5 * a * ta * ta + peak_speed_ * (t - ta);
  } else {
    const double left = duration_ - t;  // braking: the mirror image of accelerating
    travelled = std::abs(to_ - from_) - 0.5 * a * left * left;
  }
  return from_ + sign_ * travelled;
}

NozzleTimeline::NozzleTimeline(const NozzleResponseParameters& params,
                               const std::vector<TimedCommand>& commands, double t_end_s,
                               double step_s)
    : params_(params), step_(step_s) {
  params_.validate();
  if (commands.empty()) throw InputError("nozzle timeline: no command");
  if (!(std::isfinite(step_s) && step_s > 0.0)) {
    throw InputError("nozzle timeline: step must be finite and > 0");
  }
  for (size_t i = 0; i < commands.size(); ++i) {
    const TimedCommand& c = commands[i];
    if (!(std::isfinite(c.t_s) && std::isfinite(c.command.pan_rad) &&
          std::isfinite(c.command.tilt_rad))) {
      throw InputError("nozzle timeline: command " + std::to_string(i) + " is not finite");
    }
    if (i > 0 && !(c.t_s > commands[i - 1].t_s)) {
      throw InputError("nozzle timeline: command times must increase (command " +
                       std::to_string(i) + ")");
    }
  }
  t0_ = commands.front().t_s;
  const double span = std::max(0.0, t_end_s - t0_);
  if (!(std::isfinite(span) && span / step_s < 1e8)) {
    throw InputError("nozzle timeline: the span is not finite or too long for the step");
  }
  const size_t n = static_cast<size_t>(std::ceil(span / step_s - 1e-9)) + 1;
  pan_.resize(n);
  tilt_.resize(n);
  double pan = commands.front().command.pan_rad, tilt = commands.front().command.tilt_rad;
  double pan_rate = 0.0, tilt_rate = 0.0;
  size_t next = 1;
  NozzleOrientation target = commands.front().command;
  pan_[0] = pan;
  tilt_[0] = tilt;
  for (size_t k = 1; k < n; ++k) {
    // The command in force during step k - 1 -> k is the last one issued at or before its start.
    const double t_start = t0_ + step_ * static_cast<double>(k - 1);
    while (next < commands.size() && commands[next].t_s <= t_start + 1e-12) {
      target = commands[next].command;
      ++next;
    }
    servo_axis_step(target.pan_rad, params_.max_speed_radps, params_.max_acceleration_radps2, step_,
                    &pan, &pan_rate);
    servo_axis_step(target.tilt_rad, params_.max_speed_radps, params_.max_acceleration_radps2,
                    step_, &tilt, &tilt_rate);
    pan_[k] = pan;
    tilt_[k] = tilt;
  }
  size_t last = n - 1;
  while (last > 0 && pan_[last - 1] == pan_[n - 1] && tilt_[last - 1] == tilt_[n - 1]) --last;
  settled_from_s_ = t0_ + step_ * static_cast<double>(last);
}

NozzleOrientation NozzleTimeline::actual(double t_s) const {
  const double x = (t_s - t0_) / step_;
  if (!(x > 0.0)) return {pan_.front(), tilt_.front()};
  const double last = static_cast<double>(pan_.size() - 1);
  if (x >= last) return {pan_.back(), tilt_.back()};
  const size_t k = static_cast<size_t>(x);
  const double f = x - static_cast<double>(k);
  return {pan_[k] + f * (pan_[k + 1] - pan_[k]), tilt_[k] + f * (tilt_[k + 1] - tilt_[k])};
}

NozzleOrientation NozzleTimeline::effective(double t_s, double extra_delay_s) const {
  return actual(t_s - params_.transit_delay_s - extra_delay_s);
}

bool NozzleTimeline::at_rest_between(double t0_s, double t1_s) const {
  const NozzleOrientation a = actual(t0_s);
  const double x0 = std::max(0.0, (t0_s - t0_) / step_);
  const double x1 = std::min(static_cast<double>(pan_.size() - 1), (t1_s - t0_) / step_);
  for (size_t k = static_cast<size_t>(x0); static_cast<double>(k) <= x1; ++k) {
    if (pan_[k] != a.pan_rad || tilt_[k] != a.tilt_rad) return false;
  }
  const NozzleOrientation b = actual(t1_s);
  return b.pan_rad == a.pan_rad && b.tilt_rad == a.tilt_rad;
}

}  // namespace airtwin
