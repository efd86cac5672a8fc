#include "sim/nozzle_actuator.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

std::string deg(double rad) { return std::to_string(rad_to_deg(rad)) + " deg"; }

}  // namespace

void NozzleActuatorParameters::validate() const {
  auto positive = [](double v, const char* field) {
    if (!(std::isfinite(v) && v > 0)) {
      throw InputError(std::string("nozzle parameters: ") + field + " must be > 0, got " +
                       std::to_string(v));
    }
  };
  positive(max_speed_radps, "max_speed_radps");
  positive(max_acceleration_radps2, "max_acceleration_radps2");
  positive(jet_rise_time_constant_s, "jet_rise_time_constant_s");
  positive(jet_fall_time_constant_s, "jet_fall_time_constant_s");
  for (const auto& [v, field] : {std::pair{field_delay_s, "field_delay_s"},
                                 std::pair{response_delay_s, "response_delay_s"}}) {
    if (!(std::isfinite(v) && v >= 0 && v <= 10)) {
      throw InputError(std::string("nozzle parameters: ") + field + " must be in [0, 10] s, got " +
                       std::to_string(v));
    }
  }
  if (!(pan_min_rad < pan_max_rad && std::isfinite(pan_min_rad) && std::isfinite(pan_max_rad))) {
    throw InputError("nozzle parameters: pan range must be finite and ordered");
  }
  if (!(tilt_min_rad >= 0 && tilt_min_rad < tilt_max_rad && tilt_max_rad < kPi / 2)) {
    throw InputError("nozzle parameters: tilt range must satisfy 0 <= min < max < 90 deg");
  }
  for (const auto& [v, field] : {std::pair{pan_offset_rad, "pan_offset_rad"},
                                 std::pair{tilt_offset_rad, "tilt_offset_rad"}}) {
    if (!(std::isfinite(v) && std::abs(v) <= 0.5)) {
      throw InputError(std::string("nozzle parameters: ") + field +
                       " must be in [-0.5, 0.5] rad, got " + std::to_string(v));
    }
  }
}

void servo_step(double target, double max_speed, double max_acceleration, double dt, double* angle,
                double* rate) {
  const double error = target - *angle;
  const double distance = std::abs(error);
  // The fastest speed v from which the servo can still stop on the target after moving at v for
  // this step: v dt + v^2 / (2 a) <= distance. Capped by the speed limit and by what reaches the
  // target within this step.
  const double a_dt = max_acceleration * dt;
  const double brake = -a_dt + std::sqrt(a_dt * a_dt + 2.0 * max_acceleration * distance);
  const double reachable = std::min({max_speed, brake, distance / dt});
  const double desired = std::copysign(reachable, error);
  // Change the speed toward it no faster than the acceleration limit.
  const double dv = std::clamp(desired - *rate, -max_acceleration * dt, max_acceleration * dt);
  *rate += dv;
  const double next = *angle + *rate * dt;
  // Snap onto the target when this step reaches or crosses it.
  if ((target - next) * error <= 0.0) {
    *angle = target;
    *rate = 0.0;
  } else {
    *angle = next;
  }
}

NozzleActuator::NozzleActuator(const NozzleActuatorParameters& params,
                               const NozzleOrientation& initial, double timestep_s)
    : params_(params), dt_(timestep_s) {
  params_.validate();
  AIRTWIN_DEMAND(std::isfinite(dt_) && dt_ > 0);
  command(initial);
  actual_ = servo_target_;
  // A delay of n steps needs n + 1 slots: the oldest is read after the newest is written.
  const size_t n =
      static_cast<size_t>(std::lround((params_.field_delay_s + params_.response_delay_s) / dt_));
  history_.assign(n + 1, actual_);
  head_ = 0;
  rise_factor_ = -std::expm1(-dt_ / params_.jet_rise_time_constant_s);
  fall_factor_ = -std::expm1(-dt_ / params_.jet_fall_time_constant_s);
}

void NozzleActuator::command(const NozzleOrientation& target) {
  if (!(std::isfinite(target.pan_rad) && target.pan_rad >= params_.pan_min_rad &&
        target.pan_rad <= params_.pan_max_rad)) {
    throw InputError("nozzle command: pan " + deg(target.pan_rad) + " is outside [" +
                     deg(params_.pan_min_rad) + ", " + deg(params_.pan_max_rad) + "]");
  }
  if (!(std::isfinite(target.tilt_rad) && target.tilt_rad >= params_.tilt_min_rad &&
        target.tilt_rad <= params_.tilt_max_rad)) {
    throw InputError("nozzle command: tilt " + deg(target.tilt_rad) + " is outside [" +
                     deg(params_.tilt_min_rad) + ", " + deg(params_.tilt_max_rad) + "]");
  }
  commanded_ = target;
  // The servos' calibration bias: they turn to command + offset, within their ranges.
  servo_target_.pan_rad =
      std::clamp(target.pan_rad + params_.pan_offset_rad, params_.pan_min_rad, params_.pan_max_rad);
  servo_target_.tilt_rad = std::clamp(target.tilt_rad + params_.tilt_offset_rad,
                                      params_.tilt_min_rad, params_.tilt_max_rad);
}

void NozzleActuator::step() {
  // Servos.
  servo_step(servo_target_.pan_rad, params_.max_speed_radps, params_.max_acceleration_radps2, dt_,
             &actual_.pan_rad, &pan_rate_);
  servo_step(servo_target_.tilt_rad, params_.max_speed_radps, params_.max_acceleration_radps2, dt_,
             &actual_.tilt_rad, &tilt_rate_);
  // Delay line: overwrite the oldest slot with the newest, the next slot is now the oldest.
  history_[head_] = actual_;
  head_ = (head_ + 1) % history_.size();
  // Jet level: exact first-order response over one step.
  const double target = jet_on_ ? 1.0 : 0.0;
  jet_level_ += (target - jet_level_) * (target > jet_level_ ? rise_factor_ : fall_factor_);
}

}  // namespace airtwin
