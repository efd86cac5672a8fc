#pragma once
// How long the wall jet takes to form at a point, from the CFD of short pulses (data/cfd/
// pulse<MS>ms_tilt00_d40.json, scripts/cfd/startup.py, docs/cfd.md "Short pulses"): the rig's
// jet at tilt 0 opened for MS milliseconds over a still floor, axisymmetric transient RANS.
//
// A point beside a sweeping jet receives its air only while the footprint passes, ~0.1 s. The
// pulses say a jet held that briefly does not build its wall jet: the radial air's peak at 4 mm
// is 53 % of the steady air 0.11 m from s after 100 ms, 37 % at 0.41 m; 93 % and 70 % after
// 200 ms. The twin takes this as a first-order formation: at distance r from s the air a point
// feels relaxes toward the air of the orientation that reaches it (sim/air_transport.h) with a
// time constant tau(r), so a pulse of length T peaks at 1 - exp(-T / tau(r)). tau is fitted to
// the pulses at each probe distance: ~0.1 s within 0.3 m of s, 0.16 s at 0.41 m, growing
// farther out where the pulse's air thins on its way.
//
// What a first-order formation leaves out (docs/cfd.md): the head of a pulse held 0.4 s
// overshoots the steady air by ~10 % near s, and a short pulse's air arrives later than a
// continuous jet's front.

#include <string>
#include <vector>

namespace airtwin {

/// One pulse case: its length and, at each floor distance its air reached before the run
/// ended, the peak radial air at the lowest height as a fraction of the steady jet's there.
struct CfdPulse {
  double pulse_s = 0.0;               ///< the valve's command: open at 0, closing from pulse_s
  double valve_s = 0.0;               ///< the valve's opening and closing time (linear in speed)
  std::vector<double> r_m;            ///< increasing distances from s (m)
  std::vector<double> peak_fraction;  ///< peak / steady at each (> 0)

  /// The pulse's length in the steady jet's momentum: the ramps' speed is linear, so each
  /// delivers a third of its time's momentum (pulse_s - valve_s / 3).
  double effective_s() const { return pulse_s - valve_s / 3.0; }

  /// Reads a pulse's converted JSON (scripts/cfd/startup.py convert). Probes are kept at the
  /// lowest height, outward from s until the first whose peak came at the run's end (the
  /// pulse's air still arriving there, and so beyond). InputError naming the file and the
  /// field when a field is missing or not a finite number, or no probe is kept.
  static CfdPulse read(const std::string& path);
};

class WallJetFormation {
 public:
  /// The formation time at each distance any pulse reached, fitted by least squares of
  /// 1 - exp(-T / tau) against min(1, peak_fraction) over the pulses there (a golden-section
  /// search in log tau over [0.01, 10] s). InputError when `pulses` is empty.
  static WallJetFormation fit(const std::vector<CfdPulse>& pulses);
  /// Every pulse<MS>ms_tilt00_d40.json in `dir` (none: an empty optional is the caller's).
  static std::vector<CfdPulse> read_pulses(const std::string& dir);
  /// From the figures: formation times tau_s (s, > 0) at increasing distances r_m (m, > 0).
  /// InputError naming the value otherwise.
  WallJetFormation(std::vector<double> r_m, std::vector<double> tau_s);

  const std::vector<double>& r_m() const { return r_m_; }
  const std::vector<double>& tau_s() const { return tau_s_; }
  /// tau at distance r from s (s): linear between the fitted distances, the nearest end's
  /// beyond them.
  double time_s(double r_m) const;
  /// The peak of a pulse of effective length T (s) at distance r: 1 - exp(-T / tau(r)).
  double pulse_peak_fraction(double pulse_s, double r_m) const;

 private:
  std::vector<double> r_m_, tau_s_;
};

}  // namespace airtwin
