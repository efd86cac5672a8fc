#pragma once
// The result of `airtwin identify`: an identified object model and how it was obtained, and its
// file, model.json (docs/data_formats.md), which later commands read back (`--model`).
//
// Fixed keys, in this order: object, method, terms (the ten library names), coefficients
// (continuous time, per term, dv/dt in m/s^2), discrete_coefficients (v_{k+1} at the data's dt),
// inclusion_probability, r2, end_position_mape (percent; null when it cannot be computed, e.g. a
// speed series has no positions), n_samples, n_dropped; then the details: eq8 ({xi1, xi2, xi3}
// when only the terms 1, v, vair are active, else null), r2_change, end_position_mape_by_tilt,
// end_position_by_sector, n_mape_trajectories, n_mape_excluded, n_pairs, n_trajectories,
// n_glitches_repaired, n_short_trajectories, n_off_radial, n_transient, transient_s, dt_s, lambda,
// library, bootstraps, seed, smoothing_half_window, position_noise_m, positions_smoothed,
// stationary_speed_mps, source.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "models/object_dynamics.h"
#include "models/sindy.h"
#include "models/trajectory_replay.h"

namespace airtwin {

struct IdentifiedModel {
  using Coefficients = Eigen::Matrix<double, kSindyTerms, 1>;

  std::string object;  ///< object type; empty when unknown (a speed series without --object)
  std::string method;  ///< sindy_method_name()
  Coefficients coefficients = Coefficients::Zero();  ///< continuous time
  Coefficients discrete = Coefficients::Zero();
  Coefficients inclusion = Coefficients::Zero();
  double r2 = 0.0;         ///< of v_{k+1}, the regression of eq. (6) (the paper's figure)
  double r2_change = 0.0;  ///< of v_{k+1} - v_k (stricter)
  std::optional<double> end_position_mape_pct;
  std::map<double, double> end_position_mape_by_tilt_pct;  ///< tilt (deg) -> MAPE (%)
  /// Tilt (deg) -> the end-position figures by placement sector (models/trajectory_replay.h):
  /// where around s the model errs. Written, not read back.
  std::map<double, std::array<SectorFigures, kPlacementSectors>> end_position_by_sector;
  size_t n_samples = 0, n_dropped = 0, n_pairs = 0, n_trajectories = 0;
  size_t n_glitches_repaired = 0, n_short_trajectories = 0;
  size_t n_off_radial = 0, n_transient = 0;  ///< moving samples not used (docs/identification.md)
  double transient_s = 0.0;                  ///< the --skip-transient setting
  size_t n_mape_trajectories = 0, n_mape_excluded = 0;
  /// Tilt (deg, the first sample's, to 1e-3) -> {trajectories whose last position is at least
  /// ReplayOptions::min_travel_m from their first, all trajectories}: which placements the air set
  /// in motion (Appendix D placed its objects where "air velocity is sufficient to set the
  /// objects in motion"). Trajectory data only.
  std::map<double, std::pair<size_t, size_t>> moved_by_tilt;
  double dt_s = 0.0;
  double lambda = 0.0;
  /// The library terms the regression was allowed (SindyOptions::terms); all ten by default.
  std::vector<std::string> library{kTermNames.begin(), kTermNames.end()};
  int bootstraps = 0;
  std::uint64_t seed = 0;
  int smoothing_half_window = 0;
  double position_noise_m = 0.0;      ///< estimated detection noise per axis (trajectory data)
  bool positions_smoothed = false;    ///< positions smoothed before differencing
  double stationary_speed_mps = 0.0;  ///< the rest threshold used
  double speed_noise_mps = 0.0;       ///< estimated noise of a speed series' v (0: trajectories)
  size_t n_negative_speeds = 0;       ///< a speed series' negative v (measured near rest)
  std::string source;                 ///< the data file

  /// Whether only the terms of eq. (8) (1, v, vair) are active.
  bool is_eq8() const;
  /// The eq. (8) coefficients {xi1 = v, xi2 = vair, xi3 = 1}. Throws InputError naming the extra
  /// terms when the model is not of that form.
  ObjectDynamics eq8() const;
  /// Why the model is not of the form of eq. (8) (its extra terms), or "" when it is.
  std::string eq8_note() const;
};

/// The model.json text (2-space indented, keys in the documented order, ends with a newline).
std::string identified_model_json(const IdentifiedModel& model);

/// Reads a model.json back. Every problem (not JSON, missing key, wrong term names or count,
/// non-finite coefficient) is an InputError naming the file and the key.
IdentifiedModel parse_identified_model_json(const std::string& text, const std::string& source);
IdentifiedModel read_identified_model(const std::string& path);

}  // namespace airtwin
