#pragma once
// A hot-wire campaign simulated from the jet's CFD, as the paper's Appendix A measured it: a
// degreeC UAS150 (an omnidirectional thermal anemometer) at the points of an 11 x 11 grid over the
// 2 x 2 m workspace, 1.5 cm above the floor, each reading a one-minute mean. The result is the
// measured grid `airtwin fitfield` fuses with the CFD (Appendix C, docs/field_fitting.md).
//
// What the instrument sees at a point (docs/cfd.md, "The analytic model fitted to the CFD"):
//  - the full 3-D air velocity U + u': U the CFD's mean (horizontal and vertical; the vertical part
//    is large near the stagnation point s, where the jet comes down) and u' isotropic turbulence
//    of variance 2k/3 per component, each component a stationary Ornstein-Uhlenbeck process with
//    the Eulerian integral time of a fixed probe (eulerian_integral_time_s);
//  - an omnidirectional sensor reads the magnitude |U + u'| through its static law
//    (hotwire_static_reading_mps): exact in its calibrated range, a free-convection floor U0 below
//    it, where it overreads (the paper, section III-B: "may overestimate low air velocities near
//    its lower detection limit (~10 cm/s)");
//  - a first-order response (time constant tau) on that reading, sampled at the instrument's rate,
//    the samples averaged over one minute after the response has settled;
//  - a calibration gain error (the maker's accuracy, as a fraction of the reading), one per
//    campaign: the same probe measured every point.
// Randomness comes from explicit seeds only (RandomStream); a point's numbers depend on the seed,
// its tilt and its index, never on the order points are simulated in or on the thread count.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "common/random_stream.h"
#include "models/cfd_field.h"
#include "models/field_grid.h"

namespace airtwin {

/// The instrument (degreeC UAS150 as the paper used it; sources and assumptions in docs/cfd.md).
struct HotWireSpec {
  /// U0 (m/s): the reading in still air, the free-convection floor of the static law; the paper's
  /// "lower detection limit (~10 cm/s)". 0 makes the law the identity.
  double detection_limit_mps = 0.1;
  /// The calibration's accuracy as a fraction of the reading, read as a 2-sigma bound: the
  /// campaign's gain is 1 + e, e ~ N(0, (accuracy / 2)^2) drawn once. 0: an exact calibration.
  double accuracy_fraction = 0.05;
  double time_constant_s = 1.0;    ///< tau (s) of the first-order response; 0: instantaneous
  double sample_rate_hz = 10.0;    ///< samples of the response per second (Hz)
  double averaging_time_s = 60.0;  ///< the averaging window per point (s)
  /// The simulation's finest time step (s): the turbulence and the response are stepped at
  /// min(T_E, tau) / 4 but no finer than this (the exact Ornstein-Uhlenbeck update keeps the
  /// turbulence's statistics at any step; a coarser step changes the reading's variance, not its
  /// mean).
  double min_step_s = 1e-3;

  /// Throws FieldError naming the field ("hotwire.sample_rate_hz") when a value is out of range:
  /// detection_limit_mps in [0, 10], accuracy_fraction in [0, 0.5], time_constant_s in [0, 60],
  /// sample_rate_hz in [0.01, 1e4], averaging_time_s in [1 / sample_rate_hz, 3600], min_step_s in
  /// [1e-6, 1 / sample_rate_hz]; NaN and infinity nowhere.
  void validate() const;
};

/// The mean air and its turbulence at one point, as the CFD gives them.
struct HotWireAir {
  Eigen::Vector3d u_W = Eigen::Vector3d::Zero();  ///< mean velocity (m/s), z up
  double k = 0.0;                                 ///< turbulence kinetic energy (m^2/s^2), >= 0
  double epsilon = 0.0;                           ///< its dissipation rate (m^2/s^3), > 0 if k > 0
};

/// The static law: what the instrument shows in steady air of speed `speed_mps` (m/s, >= 0).
/// Calibrated in forced convection, it reads the speed exactly from 2 U0 up; below, free convection
/// from the heated sensor keeps the heat loss from falling with the speed and the reading flattens
/// to U0 in still air: U0 + speed^2 / (4 U0), the parabola that meets the identity at 2 U0 with
/// the same slope. U0 = spec.detection_limit_mps (the identity when 0). Negative or NaN speed:
/// FieldError naming "hotwire.speed_mps".
double hotwire_static_reading_mps(double speed_mps, const HotWireSpec& spec);

/// The Eulerian integral time (s) of the velocity at a fixed probe: swept_integral_time_s
/// (models/turbulence_time.h) with the Lagrangian time T_L = 4 k / (3 C0 epsilon) (C0 = 2.1) and
/// the sweep speed |U| = `mean_speed_mps` (m/s). k and epsilon > 0, else FieldError naming
/// "hotwire.k" or "hotwire.epsilon".
double eulerian_integral_time_s(double mean_speed_mps, double k, double epsilon);

/// The one-minute mean reading (m/s) of the instrument at one point, without the calibration gain
/// (gain 1): the static law of |U + u'| through the first-order response, sampled and averaged
/// over spec.averaging_time_s after a settling time of 5 max(tau, T_E). With k = 0 it is the
/// static law of |U| exactly. Draws from `rng` only. FieldError for an invalid spec or air (a
/// non-finite velocity "hotwire.u_W", k < 0 "hotwire.k", epsilon <= 0 with k > 0
/// "hotwire.epsilon").
double simulate_hotwire_mean_mps(const HotWireAir& air, const HotWireSpec& spec, RandomStream& rng);

/// Where and when the campaign measures.
struct HotWireCampaign {
  std::vector<double> tilts_rad;  ///< tilts measured (rad), each in the CFD's tilt range
  double pan_rad = 0.0;           ///< pan of every measurement (rad)
  /// Measurement points (m, world frame). Default: the paper's 11 x 11 grid over 2 x 2 m.
  std::vector<Eigen::Vector2d> points_W = square_grid(2.0, 11);
  double height_m = 0.015;  ///< sensor height above the floor (m)
  uint64_t seed = 1;        ///< the campaign's seed: the turbulence and the calibration gain
  int threads = 1;          ///< points simulated concurrently (results do not depend on it)

  /// n x n points equally spaced over a square of side `side_m` (m) centred on the origin, row by
  /// row (y outer, x inner, both increasing). n >= 2, side > 0, else FieldError naming
  /// "hotwire.points" or "hotwire.side_m".
  static std::vector<Eigen::Vector2d> square_grid(double side_m, int n);

  /// FieldError naming the field: no tilt or a tilt outside [0, 90) deg ("hotwire.tilts"), a
  /// duplicated tilt, no point or a non-finite one ("hotwire.points"), height outside (0, 0.1] m
  /// ("hotwire.height_m"), |pan| > 2 pi ("hotwire.pan_rad"), threads < 1 ("hotwire.threads").
  void validate() const;
};

/// A simulated campaign: the grid file's samples and what went into them.
struct HotWireResult {
  FieldGrid grid;     ///< kMeasured; speed = the mean reading, rows by tilt then point
  double gain = 1.0;  ///< the calibration gain applied to every reading
  /// Per sample (same order): the CFD's mean air speed in the floor plane, |(ux, uy)|, and in
  /// 3-D, |(ux, uy, uz)| (m/s): what eq. (3) models and what the instrument's mean flow is.
  std::vector<double> cfd_horizontal_speed_mps, cfd_speed_3d_mps;
};

/// Simulates the campaign on the CFD air (CfdField, the mean velocity with its vertical part, k
/// and epsilon at the sensor's height). `source` names the grid in later messages. FieldError for
/// an invalid campaign or spec; InputError naming the tilt when it is outside the CFD's range.
/// Deterministic: the same inputs give the same samples bit for bit.
HotWireResult simulate_hotwire_campaign(const CfdField& cfd, const HotWireCampaign& campaign,
                                        const HotWireSpec& spec, const std::string& source);

}  // namespace airtwin
