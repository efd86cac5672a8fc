#pragma once
// From trajectories to the speed pairs SINDy regresses on (Appendix D), with a defence against
// detection glitches.
//
// Steps, per trajectory:
//  1. Glitch repair. A wrong position in one frame corrupts two consecutive central-difference
//     speeds and puts the outlier in the regressors, where bisquare weighting cannot help (the
//     leverage is high). Positions are therefore checked before differencing: each frame is
//     compared with a quadratic in time through its neighbours within +-3 frames, chosen by least
//     median of squares among all 3-frame subsets, so one or two glitched neighbours cannot spoil
//     it; smooth motion follows such a quadratic to well under a millimetre at 40 Hz, a glitch of
//     1-3 cm does not. Threshold: max(glitch_floor_m, 6 x the trajectory's robust scale of the
//     misfit). Flagged frames are replaced by the quadratic's value. Every repair is counted.
//  2. Detection noise. The positions' noise (per axis) is estimated over the whole data set from
//     fourth differences (robust: median absolute value). When it exceeds a floor (0.02 mm),
//     each trajectory's x and y are smoothed by Savitzky-Golay (the window of step 5) first.
//     The rest threshold of step 4 is raised to 3.5 x the speed noise this leaves, so that a
//     resting object's jitter is not taken for motion.
//  2b. Speeds by central differences, v_k = |p_{k+1} - p_{k-1}| / (2 dt) (Appendix D).
//  3. Air speed at p_k from the field model under the nozzle command in force at frame k.
//  4. Stationary samples dropped (speed below the threshold: dry friction is discontinuous at zero
//     speed), counted in n_dropped; so are samples moving more than 30 deg off the radial
//     direction from s (eq. 9 does not describe them: the jet was still sweeping toward the
//     recorded orientation), counted in n_off_radial; and, when asked (transient_s), samples
//     too soon after a command change, counted in n_transient. What remains splits into runs of
//     consecutive moving samples.
//  5. Each run's speeds smoothed on their own by Savitzky-Golay (models/savitzky_golay.h: cubic
//     over +-4 samples by default), against the errors-in-variables bias of noisy speeds in the
//     regressors. Pairs (k, k+1) inside a run whose smoothed speeds are both above the threshold.
// The same steps 4-5 apply to a speed series (`airtwin identify --series`).
// All trajectories must share one frame interval (within 1%); the data set's dt is their median.

#include <string>

#include "models/air_field.h"
#include "models/sindy.h"
#include "models/speed_series.h"
#include "models/trajectory_data.h"

namespace airtwin {

struct SpeedPairOptions {
  bool repair_glitches = true;
  double glitch_floor_m = 0.008;        ///< smallest position jump taken for a glitch
  double stationary_speed_mps = 0.005;  ///< speeds below this count as at rest (at least)
  /// Positions are smoothed (same Savitzky-Golay window) before differencing when the estimated
  /// detection noise exceeds this; noise-free data are left exactly as measured.
  double position_noise_floor_m = 2e-5;
  /// Samples moving more than this away from the radial direction from s (eq. 9) are not used:
  /// the air there is not the recorded command's (the jet sweeping over the floor while the
  /// servos turn, section IV: "transient effects resulting from the jet changing direction").
  /// pi switches the check off.
  double max_direction_error_rad = 0.5235987755982988;  // 30 deg
  /// Samples within this time (s) after a command change, or after a trajectory's first frame,
  /// are not used: the servos are still turning and the field still sweeping toward the recorded
  /// command. 0 (the paper's preprocessing) uses everything; see docs/identification.md.
  double transient_s = 0.0;
  int smoothing_half_window = 4;  ///< Savitzky-Golay half window (samples); 0: none
  int smoothing_order = 3;        ///< Savitzky-Golay polynomial degree
};

struct SpeedPairReport {
  size_t n_trajectories = 0;
  size_t n_frames = 0;
  size_t n_samples = 0;     ///< speed samples computed (interior frames)
  size_t n_pairs = 0;       ///< pairs kept for regression
  size_t n_dropped = 0;     ///< speed samples dropped as stationary (raw or after smoothing)
  size_t n_off_radial = 0;  ///< moving samples dropped as not radial from s (step 4)
  size_t n_transient = 0;   ///< moving samples dropped as within transient_s of a command change
  size_t n_glitches_repaired = 0;
  size_t n_short_trajectories = 0;    ///< fewer than 4 frames: no pair possible
  double position_noise_m = 0.0;      ///< estimated detection noise (m, per axis; trajectories)
  bool positions_smoothed = false;    ///< whether positions were smoothed before differencing
  double stationary_speed_mps = 0.0;  ///< the rest threshold used (option or 3.5 x speed noise)
  /// Speed series: the estimated noise of v (m/s), 1.4826 median |fourth difference| / sqrt(70),
  /// (0 below 24 samples), and how many v were negative (measured speeds of objects at rest).
  double speed_noise_mps = 0.0;
  size_t n_negative_speeds = 0;
};

/// Builds the regression pairs for trajectories of one object type. Throws InputError when the
/// frame interval differs between or within trajectories by more than 1%.
SpeedPairs speed_pairs_from_trajectories(const TrajectorySet& set, const AirFieldModel& field,
                                         const SpeedPairOptions& options, SpeedPairReport* report);

/// Builds the regression pairs of one speed series (steps 4-5 above).
SpeedPairs speed_pairs_from_series(const SpeedSeries& series, const SpeedPairOptions& options,
                                   SpeedPairReport* report);

/// Repairs position glitches of one trajectory in place (step 1 above); returns the repaired
/// frame indices, in increasing order.
std::vector<size_t> repair_position_glitches(std::vector<TrajectorySample>* samples,
                                             double floor_m);

}  // namespace airtwin
