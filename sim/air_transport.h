#pragma once
// Which nozzle orientation's air reaches a point of the floor: the wall jet's transport lag.
//
// The floor air is not a rigid pattern that swings with the nozzle. Air reaches the floor at s
// (after the free jet's transit, the nozzle's field delay, sim/nozzle_actuator.h) and then flows
// out along the wall jet; after a re-aim the new wall jet spreads from the new s as a front, and
// the old one keeps flowing where the front has not arrived. A point at distance r from s
// therefore feels the air of the orientation of r / U_front earlier. U_front is the front's
// speed: a starting turbulent jet's front advances at about half the steady jet's local speed
// (Witze 1980, the impulsively started jet; the ring vortex at the head of an impinging jet's
// wall jet, the downburst model, likewise moves out at about half the jet's speed), and the
// wall jet near the floor carries 2-3.4 m/s here (docs/cfd.md): U_front = 1.5 m/s by default.
//
// In the CFD's air the lag is the CFD's own when its cases come with the jet's start-up
// (models/cfd_startup.h): the wall jet's arrival at r from s less the free jet's transit, 0.015 s
// at 0.11 m, 0.18 s at 0.41 m, 1.05 s at 1.01 m (the front slows with its air), instead of
// r / U_front (0.07, 0.27, 0.67 s).
//
// This matters while the nozzle turns (up to 7 rad/s, 400 deg/s): a rigid pattern would sweep
// the strong downstream wall jet 0.6 m long across the floor at up to 4 m/s at its tip, faster
// than its own air, and fling objects that the moving air never reaches. With the lag, a point
// r from the sweeping s sees the orientation r / U_front ago; at rest (no change within the
// longest lag) every point sees the present one.
//
// AirTransport keeps the effective orientations of the last max_lag_s, one per physics step,
// and answers which one reaches a point; the twin (sim/twin.h) gives each object the air of
// that orientation (sim/air_forces.h). The lag is found by one fixed-point step: r0 from the
// present s gives an orientation, r1 from that orientation's s the one used.

#include <cstdint>
#include <vector>

#include "models/cfd_startup.h"
#include "models/nozzle_geometry.h"

namespace airtwin {

struct AirTransportParameters {
  /// U_front (m/s), the speed at which a new wall jet's front spreads from s; 0 switches the lag
  /// off (the floor pattern then swings rigidly with the effective orientation).
  double front_speed_mps = 1.5;
  /// Longest lag kept (s): points whose lag would be longer get this one.
  double max_lag_s = 2.0;
  /// In the CFD's air, when its cases come with the jet's start-up (CfdField::startup): the
  /// wall jet's lag from it instead of front_speed_mps, and the free jet's transit from it
  /// instead of NozzleActuatorParameters::field_delay_s (sim/twin.h). front_speed_mps 0 still
  /// switches the lag off.
  bool cfd_timing = true;
  /// No lag: the floor pattern swings rigidly with the effective orientation.
  static AirTransportParameters rigid() { return {0.0, 0.0, false}; }
  /// Throws InputError naming the field unless both are finite and in range.
  void validate() const;
};

class AirTransport {
 public:
  /// `initial` fills the history: the air has been at rest there. `startup` (may be null; must
  /// outlive the transport) gives the lag when params.cfd_timing is set.
  AirTransport(const AirTransportParameters& params, double timestep_s,
               const NozzleOrientation& initial, const CfdStartup* startup = nullptr);

  /// Records this step's effective orientation (call once per physics step, before the lags).
  void push(const NozzleOrientation& effective);
  /// False when the lag is switched off.
  bool enabled() const { return params_.front_speed_mps > 0.0; }
  /// True when every orientation of the kept history is the present one: every point then
  /// feels the present air.
  bool steady() const { return steps_since_change_ >= capacity_ - 1; }
  /// Steps back whose orientation reaches a point r_m from s (0: the present), at most the
  /// history's span.
  int lag_steps(double r_m) const;
  /// The effective orientation `steps` steps ago (0: the present), clamped to the history.
  const NozzleOrientation& at_lag(int steps) const;

 private:
  AirTransportParameters params_;
  const CfdStartup* startup_;  // the lag's source when set, else r / front_speed_mps
  double timestep_s_;
  int capacity_;  // orientations kept: max_lag_s / dt + 1
  std::vector<NozzleOrientation> ring_;
  int newest_ = 0;              // index of the present orientation in ring_
  int64_t steps_since_change_;  // steps since the orientation last changed
};

}  // namespace airtwin
