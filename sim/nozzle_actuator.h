#pragma once
// The nozzle as the air sees it: two servos that move at a finite rate toward the commanded
// orientation, a field that follows the nozzle's actual orientation after a delay, and a jet whose
// strength builds up over seconds after it is switched on.
//
//   commanded --(servo: speed and acceleration limits)--> actual --(delay)--> effective
//   jet on/off --(first-order rise / fall)--> jet level in [0, 1] (scales the air speed)
//
// Servo: Dynamixel XM430-W210-T in position mode with a trapezoidal velocity profile. No-load
// speed 77 rpm (8.06 rad/s) at 12 V (ROBOTIS e-manual); the nozzle, bracket and hose load it, so
// the default speed limit is 7.0 rad/s (~67 rpm). Profile acceleration 30 rad/s^2: full speed in
// 0.23 s (the firmware's profile, not the motor's torque, limits it). A 90 deg tilt takes ~0.46 s.
// Pan does not wrap: it turns within [-pi, pi] like the rig's one-turn position mode (and hose).
//
// Delay: the air at the floor answers a new orientation only after the jet has travelled to it.
// A free round jet (kinematic momentum K ~ 0.86 m^4/s^2, shared/notes/physics.md) decays as
// U(x) = 6 sqrt(4K/pi) / x, so it covers h = 1.43 m in x^2 / (2 * 6.3 m^2/s) = 0.16 s; the wall
// jet then needs ~0.05-0.1 s to re-form around s. Default: a pure delay of 0.2 s (the paper's
// earlier time-delay model is not public; this is a parameter). The CFD of the jet's start-up
// measures 0.27 s (docs/cfd.md), which the twin uses in the CFD's air. It is quantised to whole
// steps, with any response delay added.
//
// Servo calibration bias (the nozzle_offset effect, sim/effects.h; zero by default): the servos
// go to command + offset, clamped to the ranges; commanded() stays the command, as a recording
// of the rig would show it, while actual() and effective() carry the bias.
//
// Jet ramp: the paper's CFD reaches steady state ~8 s after the jet starts (Appendix B), so the
// level rises as 1 - exp(-t / tau_on) with tau_on = 8 s / ln(100) = 1.74 s (99 % at 8 s). Switched
// off, the wall jet drains in ~ r / U ~ 1 m / (3 m/s): tau_off = 0.3 s.

#include <vector>

#include "models/nozzle_geometry.h"

namespace airtwin {

struct NozzleActuatorParameters {
  double max_speed_radps = 7.0;           ///< servo speed limit (rad/s), both axes
  double max_acceleration_radps2 = 30.0;  ///< servo acceleration limit (rad/s^2)
  /// The free jet's transit: actual -> effective orientation delay (s). In the CFD's air the
  /// twin takes the CFD's (sim/twin.h, AirTransportParameters::cfd_timing).
  double field_delay_s = 0.2;
  /// A further delay of the response on top of the transit (s): the response_delay effect.
  double response_delay_s = 0.0;
  double jet_rise_time_constant_s = 1.73717793;  ///< tau_on (s): 8 s / ln(100)
  double jet_fall_time_constant_s = 0.3;         ///< tau_off (s)
  double pan_min_rad = -3.14159265358979323846;
  double pan_max_rad = 3.14159265358979323846;
  double tilt_min_rad = 0.0;
  /// 60 deg: the field model's tilt limit (models/nozzle_geometry.h), covers the idle 50 deg.
  double tilt_max_rad = 60.0 * 3.14159265358979323846 / 180.0;
  /// Servo calibration bias (rad): the servos go to command + offset (clamped to the ranges).
  double pan_offset_rad = 0.0;
  double tilt_offset_rad = 0.0;

  /// Throws InputError naming the field unless limits are positive, ranges ordered and the
  /// offsets finite and within +-0.5 rad.
  void validate() const;
};

class NozzleActuator {
 public:
  /// Servos at rest at `initial` (also commanded; actual and effective = initial + offset,
  /// clamped), jet off (level 0).
  /// `timestep_s` is the fixed step of step(). Throws InputError on bad parameters or an
  /// initial orientation outside the ranges.
  NozzleActuator(const NozzleActuatorParameters& params, const NozzleOrientation& initial,
                 double timestep_s);

  /// New target (rad). Throws InputError when not finite or outside the pan / tilt ranges.
  void command(const NozzleOrientation& target);
  /// Switches the jet on (level rises toward 1) or off (falls toward 0).
  void set_jet(bool on) { jet_on_ = on; }
  /// Puts the jet level at its target at once (a jet that has been running for long).
  void settle_jet() { jet_level_ = jet_on_ ? 1.0 : 0.0; }

  /// Advances servos, delay line and jet by one timestep.
  void step();

  const NozzleOrientation& commanded() const { return commanded_; }
  /// Where the servos are heading: the command plus the calibration offset, clamped (rad).
  const NozzleOrientation& actual() const { return actual_; }
  /// The orientation the air field currently follows: actual, field_delay_s ago.
  const NozzleOrientation& effective() const { return history_[head_]; }
  /// Servo angular speeds (rad/s): pan, tilt.
  double pan_rate_radps() const { return pan_rate_; }
  double tilt_rate_radps() const { return tilt_rate_; }
  /// Air-speed scale in [0, 1].
  double jet_level() const { return jet_level_; }
  const NozzleActuatorParameters& parameters() const { return params_; }

 private:
  NozzleActuatorParameters params_;
  double dt_;
  NozzleOrientation commanded_, servo_target_, actual_;
  double pan_rate_ = 0.0, tilt_rate_ = 0.0;
  // Delay line of actual orientations, one per step: history_[head_] is the oldest.
  std::vector<NozzleOrientation> history_;
  size_t head_ = 0;
  bool jet_on_ = false;
  double jet_level_ = 0.0;
  double rise_factor_, fall_factor_;  // 1 - exp(-dt / tau)
};

/// One servo axis over one step dt (s): moves `angle` (rad) and `rate` (rad/s) toward `target`
/// under |rate| <= max_speed and |d rate / dt| <= max_acceleration, braking so as to stop on the
/// target without overshoot. Exposed for tests.
void servo_step(double target, double max_speed, double max_acceleration, double dt, double* angle,
                double* rate);

}  // namespace airtwin
