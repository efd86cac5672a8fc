#pragma once
// How long the jet's air takes to reach the floor, from the CFD of its start-up (data/cfd/
// startup_tilt00_d40.json, scripts/cfd/startup.py, docs/cfd.md "The jet's start-up"): a transient
// axisymmetric RANS of the rig's jet switched on over a still floor at tilt 0.
//
// Two times come out of it. The free jet's transit: the jet's head reaches 5 cm above the floor
// (half its final downward speed there) 0.27 s after the valve opens. The wall jet's arrival at
// distance r from s: the radial air at the lowest sampled height (4 mm, nearest the objects'
// centres) reaches half its final value at 0.28 s at 0.11 m, 0.44 s at 0.41 m, 1.32 s at 1.01 m.
// Their difference is the wall jet's transport lag after the free jet has landed, which the twin
// uses after each re-aim (sim/air_transport.h). The CFD of the jet's stop (stop_tilt00_d40) shows
// the old air falling to half at about the time the new arrives (docs/cfd.md, "The jet's stop"),
// which is where the twin switches from the one to the other.

#include <string>
#include <vector>

namespace airtwin {

class CfdStartup {
 public:
  /// Reads the start-up's converted JSON (scripts/cfd/startup.py convert). InputError naming the
  /// file and the field when a field is missing or not a finite number, the axis has no arrival
  /// near the floor, or the floor has fewer than two arrivals at the lowest height.
  static CfdStartup read(const std::string& path);
  /// From the figures themselves: the transit (s) and the arrival times (s) at increasing
  /// distances r (m) from s, each at or after the transit. InputError naming the value otherwise.
  CfdStartup(double transit_s, std::vector<double> r_m, std::vector<double> arrival_s);

  /// The free jet's transit from the nozzle to the floor (s).
  double transit_s() const { return transit_s_; }
  /// Distances from s (m) and the wall jet's arrival there after the valve opened (s).
  const std::vector<double>& r_m() const { return r_m_; }
  const std::vector<double>& arrival_s() const { return arrival_s_; }
  /// The wall jet's lag at distance r from s after the free jet lands (s): arrival - transit,
  /// linear between the samples, from 0 at s to the first, and past the last at the last
  /// interval's speed; never negative.
  double wall_jet_lag_s(double r_m) const;

 private:
  double transit_s_ = 0.0;
  std::vector<double> r_m_, arrival_s_;
};

}  // namespace airtwin
