#pragma once
// How the rig's nozzle answers its commands, as the model knows it from the hardware's
// specification: two servos (Dynamixel XM430-W210-T class) that turn at most max_speed with at
// most max_acceleration toward the command, and an air field on the floor that follows the
// nozzle's actual orientation after the jet's transit time from nozzle to floor.
//
//   recorded commands --(servo limits)--> actual orientation --(transit delay)--> field
//
// The eq. (8)-(9) model of the paper applies a command at once. For a prediction that starts while
// the nozzle is still turning (every trajectory recorded right after a re-aim, every decision of
// a closed loop), the orientation the air follows lags the command by the servo's travel plus the
// transit, ~0.2-1 s. NozzleTimeline turns a recorded command history into the orientation the
// field follows at any time, so a replay can account for it (models/extended_model.h).
//
// Defaults: 7.0 rad/s and 30 rad/s^2 (the XM430's 77 rpm no-load speed, loaded by the nozzle, and
// its position-mode profile acceleration), transit 0.2 s (a free round jet of kinematic momentum
// ~0.86 m^4/s^2 covers 1.43 m in ~0.16 s, the wall jet re-forms in ~0.05 s; docs/twin.md).
// Before the first recorded command the nozzle is taken to have rested at it: a recording that
// starts at a re-aim shows the servo's travel only if it includes a lead-in at the previous
// command (`airtwin collect --lead-in`).

#include <vector>

#include "models/nozzle_geometry.h"

namespace airtwin {

struct NozzleResponseParameters {
  double max_speed_radps = 7.0;           ///< servo speed limit, both axes (rad/s)
  double max_acceleration_radps2 = 30.0;  ///< servo acceleration limit (rad/s^2)
  double transit_delay_s = 0.2;           ///< actual orientation -> field on the floor (s)

  /// Throws InputError naming the field unless the limits are finite and > 0 and the delay
  /// finite and >= 0.
  void validate() const;
};

/// A command recorded from time t_s on (rad).
struct TimedCommand {
  double t_s = 0.0;
  NozzleOrientation command;
};

/// The actual servo orientation over a span of time, sampled every `step_s`, from a command
/// history. Immutable after construction; share freely.
class NozzleTimeline {
 public:
  /// `commands` non-empty with strictly increasing times; the servos rest at commands[0] before
  /// commands[0].t_s. The timeline covers [commands[0].t_s, t_end_s]. Throws InputError on bad
  /// parameters or commands that are not finite or not increasing.
  NozzleTimeline(const NozzleResponseParameters& params, const std::vector<TimedCommand>& commands,
                 double t_end_s, double step_s = 1e-3);

  /// The servos' actual orientation at time t (linear between steps; the first command before
  /// the start, the last state after the end).
  NozzleOrientation actual(double t_s) const;
  /// The orientation the field follows at time t: actual(t - transit_delay - extra_delay_s).
  NozzleOrientation effective(double t_s, double extra_delay_s = 0.0) const;
  /// Whether the actual orientation is constant over [t0_s, t1_s] (no servo motion inside).
  bool at_rest_between(double t0_s, double t1_s) const;
  /// The time from which the actual orientation no longer changes (the last servo motion's end;
  /// the start when it never moves).
  double settled_from_s() const { return settled_from_s_; }

  double t_end_s() const { return t0_ + step_ * static_cast<double>(pan_.size() - 1); }
  const NozzleResponseParameters& parameters() const { return params_; }

 private:
  NozzleResponseParameters params_;
  double t0_ = 0.0, step_ = 1e-3;
  std::vector<double> pan_, tilt_;  // actual orientation at t0 + k step
  double settled_from_s_ = 0.0;
};

/// One servo axis over one step h (s): `angle` (rad) and `rate` (rad/s) move toward `target`
/// with |rate| <= max_speed and |d rate/dt| <= max_acceleration, braking so that the axis stops on
/// the target (the rate that still allows a stop, sqrt(2 a |error|), caps the speed).
void servo_axis_step(double target, double max_speed, double max_acceleration, double h,
                     double* angle, double* rate);

/// One servo axis moving from rest at `from` to rest at `to` (rad), in closed form: the limit of
/// servo_axis_step as h -> 0. Full acceleration, cruise at max_speed, full braking onto `to`; a
/// move too short to reach max_speed brakes from the midpoint (triangular profile). Time 0 is the
/// command. For predictions that sample the sweep without stepping the servo (the planner's).
class ServoMove {
 public:
  /// Limits as in NozzleResponseParameters (finite, > 0; not checked here).
  ServoMove(double from, double to, double max_speed, double max_acceleration);
  /// Time (s) from the command to the stop on `to`; 0 when from == to.
  double duration_s() const { return duration_; }
  /// The angle (rad) at time t_s: `from` until 0, `to` from duration_s() on.
  double angle(double t_s) const;
  /// The fastest the axis turns during the move (rad/s); 0 when from == to.
  double peak_speed() const { return peak_speed_; }

 private:
  double from_, to_, sign_, acceleration_;
  double accelerating_s_ = 0.0;  // length of the acceleration (and braking) phase
  double cruise_s_ = 0.0;        // length of the phase at peak speed
  double peak_speed_ = 0.0;
  double duration_ = 0.0;
};

}  // namespace airtwin
