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
// The wall jet also takes time to form (models/wall_jet_formation.h, the CFD's pulses): a point
// feels the air of the orientation that reaches it through a first-order formation of time
// tau(r), so a point the sweeping jet's footprint passes in 0.1 s gets ~60 % of its air near s
// and less farther out, where a rigid hand-over gave it all. The twin keeps each object's
// departure from the reached air and lets it decay by exp(-dt / tau(r)) a step (sim/twin.cc);
// the departure only grows when the reached orientation changes, never as an object moves
// through still air. So that a step's air still reaches half its value when the start-up's
// front does, the lag is shortened by ln 2 tau(r) (never below 0).
//
// The front is carried by the air it runs into (docs/cfd.md, "A front carried by the old air"):
// where the old wall jet flows the new front's way, the front moves at its still-air speed u_f(r)
// plus that air's component along its path (Galilean: co_flow 1), which the 3-D CFD of a re-aim
// shows downstream of the new s (its front arrives 0.16 s before the still-air lag says 0.4-0.7 m
// out); where the old air flows against it the new jet, strongest near its s, turns it aside
// rather than being held back by it (counter_flow 0). Per point the lag from s is the still-air
// one times phi = (the carried front's time along the straight path from the newest s through the
// air the point last felt) / (the still-air front's time along it); the reaches are tabled for
// phi on a grid of 2^(1/8) steps.
//
// AirTransport keeps the effective orientations of the last max_lag_s and their stagnation
// points, one per physics step, and answers which one reaches a point: the newest whose air
// has had time to get there, i.e. the smallest k with lag(|p - s_k|) <= k steps. The air of a
// newer orientation is still on its way, that of an older one has been displaced by it; after
// a brief turn away and back the point keeps the brief orientation's air until the return's
// own air arrives. The lag grows with r, so "reached after k steps" is "within reach(k) of s_k",
// and the reaches are tabled once. The twin (sim/twin.h) gives each object the air of that
// orientation (sim/air_forces.h).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "models/cfd_startup.h"
#include "models/nozzle_geometry.h"
#include "models/wall_jet_formation.h"

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
  /// In the CFD's air, when its cases come with pulses (CfdField::formation) and cfd_timing is
  /// set: the wall jet's first-order formation (top of this file); false hands each point the
  /// reached orientation's whole air at once.
  bool formation = true;
  /// With the formation: the pulses' tau(r) times this, in (0, 10]. 0.5 by default: the 3-D CFD
  /// of a re-aim (docs/cfd.md, "A re-aim in 3-D") rises from a quarter to three quarters of its
  /// new air in a median 0.09-0.10 s 0.1-0.7 m from the new s, half the pulses' time there
  /// (URANS k-epsilon smears a pulse's head, and a re-aimed jet meets air already moving).
  double formation_time_scale = 0.5;
  /// The front's speed gains this share of the old air's component along its path where that
  /// air flows its way (1: carried like a Galilean front), in [0, 2].
  double front_co_flow = 1.0;
  /// ... and loses this share of it where the old air flows against it, in [0, 2] (0: the new
  /// jet turns the old wall jet aside without being slowed). Both 0: the lag of still air.
  double front_counter_flow = 0.0;
  /// No lag: the floor pattern swings rigidly with the effective orientation.
  static AirTransportParameters rigid() { return {0.0, 0.0, false, false}; }
  /// Throws InputError naming the field unless every value is finite and in range.
  void validate() const;
};

class AirTransport {
 public:
  /// `initial` (with its stagnation point initial_s_W) fills the history: the air has been at
  /// rest there. `startup` (may be null; must outlive the transport) gives the lag when
  /// params.cfd_timing is set; `formation` (may be null; must outlive it) the formation when
  /// params.formation is set too.
  AirTransport(const AirTransportParameters& params, double timestep_s,
               const NozzleOrientation& initial, const CfdStartup* startup = nullptr,
               const WallJetFormation* formation = nullptr,
               const Eigen::Vector2d& initial_s_W = Eigen::Vector2d::Zero());

  /// Records this step's effective orientation and its stagnation point (m, world frame; call
  /// once per physics step, before the lags).
  void push(const NozzleOrientation& effective,
            const Eigen::Vector2d& s_W = Eigen::Vector2d::Zero());
  /// False when the lag is switched off.
  bool enabled() const { return params_.front_speed_mps > 0.0; }
  /// True when every orientation of the kept history is the present one: every point then
  /// feels the present air.
  bool steady() const { return steps_since_change_ >= capacity_ - 1; }
  /// How many orientations are kept (the present one included): at_lag() reads 0 to this - 1.
  int capacity() const { return capacity_; }
  /// Steps back whose orientation reaches a point r_m from s (0: the present), at most the
  /// history's span; with the formation, the lag less ln 2 tau(r). `carry`: phi (top of file).
  int lag_steps(double r_m, double carry = 1.0) const;
  /// Steps back of the newest orientation whose air has reached floor point p_W: the smallest
  /// k with lag_steps(|p_W - s_k|, carry) <= k (the history's span when none has).
  int reached_steps(const Eigen::Vector2d& p_W, double carry = 1.0) const;
  /// True when the front is carried by the old air (the lag is on and a weight is not 0).
  bool carried() const {
    return enabled() && (params_.front_co_flow > 0.0 || params_.front_counter_flow > 0.0);
  }
  /// phi for a straight path of length `length_m` from s: `along` holds the old air's component
  /// along the path (m/s) at n equal segments' midpoints. 1 when the front is not carried.
  double carry_factor(const double* along, int n, double length_m) const;
  /// The front's speed in still air r from s (m/s): 1 / the lag's slope (never above 1000;
  /// infinite when the lag is off).
  double front_speed_mps(double r_m) const;
  /// True when the air forms over time (a formation is in use and the lag is on).
  bool forms() const { return formation_ != nullptr && enabled(); }
  /// With the formation, what is left after one step of a departure from the reached air at r
  /// from s: exp(-dt / tau(r)) (tau scaled by formation_time_scale); without it 0 (the reached
  /// air is felt at once).
  double formation_decay(double r_m) const;
  /// The effective orientation `steps` steps ago (0: the present), clamped to the history.
  const NozzleOrientation& at_lag(int steps) const;
  /// Its stagnation point (m, world frame).
  const Eigen::Vector2d& s_at_lag(int steps) const;

 private:
  AirTransportParameters params_;
  const CfdStartup* startup_;          // the lag's source when set, else r / front_speed_mps
  const WallJetFormation* formation_;  // set when params.formation and startup_ are
  double timestep_s_;
  int capacity_;  // orientations kept: max_lag_s / dt + 1
  // The lag (s) at r with phi = carry, with the formation's shortening.
  double lag_s(double r_m, double carry = 1.0) const;
  // The still-air lag (s) at r, without the formation's shortening.
  double still_lag_s(double r_m) const;
  // The reach table for phi nearest carry (its level: round(8 log2 carry), within +-kCarryLevels).
  const double* reach2_for(double carry) const;
  // The formation's time (s) at r: the pulses' tau scaled.
  double formation_time_s(double r_m) const;
  std::vector<NozzleOrientation> ring_;
  std::vector<Eigen::Vector2d> s_ring_;  // each orientation's stagnation point
  // reach2_[level * capacity_ + k]: the squared distance within which air k steps old has
  // arrived with phi = 2^((level - kCarryLevels) / 8) (infinite when every distance has); one
  // level (phi = 1) when the front is not carried.
  static constexpr int kCarryLevels = 16;  // phi from 1/4 to 4
  std::vector<double> reach2_;
  int levels_ = 1;
  // 1 / the still-air front's speed (s/m) on a 5 mm grid from s (empty when the lag is off).
  std::vector<double> pace_;
  // The box around every kept stagnation point: no orientation reaches a point p sooner than
  // the first k whose reach exceeds p's distance from it.
  Eigen::Vector2d s_min_, s_max_;
  int newest_ = 0;              // index of the present orientation in ring_
  int64_t steps_since_change_;  // steps since the orientation last changed
};

}  // namespace airtwin
