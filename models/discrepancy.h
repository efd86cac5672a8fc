#pragma once
// What the model gets wrong in measured data, why, and what fixing it gains (`airtwin
// discrepancy`). Given trajectories (Appendix D recordings or the log of a closed-loop run):
//
// 1. Windows. Each trajectory is cut into windows of at most window_s (a 2 s Appendix D trial is
//    one window; a closed-loop log many). A window is predicted from its first observed state
//    (position and velocity from a quadratic through its first 5 frames) under the recorded
//    command history, so a prediction never runs longer than a window.
// 2. Baseline. The nominal model: the field table, the eq. (8) coefficients and the nozzle's
//    response (servo travel and transit, models/nozzle_response.h), integrated as eqs. (8)-(9)
//    (models/extended_predictor.h with every extension off). Per window: the path error (RMS of
//    the position error over the window's frames, divided by the window's scale, its measured path
//    length but at least 5 cm) and the end error in percent of that scale (so an object that
//    stayed put while the model moved it 30 cm counts 600 %, and every model is scored on the same
//    windows with the same denominators). Residuals are split into the component along the radial
//    direction from s and across it, and binned against distance from s, alpha, time since the
//    command changed, speed and floor position.
// 3. Diagnosis. The trajectories are split (seeded) into a training and a held-out part. Each
//    extension of the catalogue (models/model_extensions.h) is fitted on the training windows by
//    nonlinear least squares on the normalised position errors (a grid over its fit range ranked
//    at a coarse screening step, a compass search, then Levenberg-Marquardt from Eigen's
//    unsupported module; docs/discrepancy.md), and scored on the held-out windows. It counts as
//    a cause when all three hold:
//      - delta BIC <= -10 on the training windows (n = windows, SSE of the normalised errors);
//      - the one-sided Wilcoxon signed-rank test of the held-out per-window path errors
//        (nominal minus extended) gives p < alpha / (number of candidates) (Bonferroni);
//      - the held-out median path error (over windows where something moved or was predicted
//        to) falls by at least min_gain (an effect, not noise:
//        turbulence adds scatter that no extension removes, so nothing passes on data without a
//        cause);
//      - the fitted size exceeds the extension's negligible size (models/model_extensions.h).
//    Among the causes of a round the one the training windows support best (the lowest delta
//    BIC) is added.
//    Selection is forward: the best cause is added, the remaining extensions are refitted on top
//    of it and tested against it, and so on, up to max_found; then backward: each cause found is
//    tested against the model of the others refitted without it, and one the others make
//    redundant is dropped. Effects can mask each other (each alone fails the held-out test):
//    when a round finds no cause, the candidate the training windows support best among those
//    that pass every test but the size of their held-out gain enters provisionally, and stays only
//    if the next round finds a cause on top of it, the backward check keeps it, and the causes
//    together beat the model before it on the held-out windows. Last, each cause is exchanged for
//    the rivals that passed in its round, the later causes in the model: a cause that only mimicked
//    another gives way when that lowers the held-out cost. A rival the held-out windows cannot
//    tell from a cause found (the cause's path errors not lower by the signed-rank test at
//    alpha) is reported beside it: either explains the data, and the training windows' BIC
//    made the choice. Every fit, and the base of every round,
//    carries an ordinary static friction (static / kinetic in [1, 1.3]) as a nuisance: eq. (8)'s
//    start condition ignores it, and left out it bends the parameters of any cause that changes
//    which objects start (a slope, a push, a nozzle offset). It is reported and left out of the
//    extended model.
// 4. Extension. The causes found, with their fitted parameters, make the extended model
//    (models/extended_model.h); its held-out end MAPE against the baseline's is the gain.
// 5. What is left. The extended model's residual accelerations are smoothed over each group of
//    features (place on the floor, place relative to s, time since the command) by a
//    kernel smoother fitted on the training windows; when the best group's correction removes a
//    significant part of the held-out residual, the report says `unexplained` and where
//    (models/discrepancy_correction.h): the data hold something outside the catalogue.
//
// What cannot be decided is stated, not guessed: too few windows, windows too short, a response
// delay without any command change recorded, a single tilt (the tilt dependence is not checked).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "models/air_field.h"
#include "models/extended_model.h"
#include "models/trajectory_data.h"

namespace airtwin {

struct DiscrepancyOptions {
  double holdout_fraction = 0.3;  ///< of the trajectories, for scoring (0.1-0.9)
  std::uint64_t seed = 1;         ///< the split
  double window_s = 3.0;          ///< longest prediction (s)
  double min_window_s = 0.5;      ///< shorter windows are not used
  int residual_stride = 2;        ///< frames between the samples of the error
  double alpha = 0.05;            ///< family-wise significance level
  double max_delta_bic = -10.0;   ///< a cause needs delta BIC at most this
  double min_gain = 0.15;         ///< and this relative reduction of the held-out path error
  int max_found = 3;
  /// The held-out gain of the nonparametric correction that marks the residual as structured.
  double min_unexplained_gain = 0.03;
  size_t min_windows = 20;         ///< fewer usable windows: nothing can be decided
  size_t min_heldout_windows = 8;  ///< fewer held-out windows: nothing can be decided
  int max_iterations = 40;         ///< Levenberg-Marquardt iterations per fit
  double predictor_step_s = 1e-3;
  /// The step at which the fits' grids are ranked before their best points are scored at
  /// predictor_step_s (docs/discrepancy.md); predictor_step_s itself: no screening.
  double screen_step_s = 8e-3;
  NozzleResponseParameters nozzle;  ///< the nominal response
  /// Where the nozzle was before each trajectory's first sample, when the data do not record it:
  /// Appendix D recordings without a lead-in re-aim from an idle orientation at their first
  /// sample (`airtwin collect`'s is pan -90, tilt 50 deg). The servos then travel from it at the
  /// first sample, as the model's timeline has them. Unset: the first recorded command held
  /// before.
  std::optional<NozzleOrientation> prior_command;
  /// The experiment each trajectory comes from, by trajectory id (ids not listed: the unnamed
  /// one). Given several, a cause's held-out size (path-error gain, end MAPE) may be shown by one
  /// experiment's windows alone (its own signed-rank p below the corrected level over the
  /// experiments' count), the pooled windows still passing the signed-rank test and keeping their
  /// end MAPE: objects launched to coast in still air show their friction beyond the air, which
  /// closed-loop logs hold in few windows (docs/discrepancy.md).
  std::map<std::string, std::string> experiment_of;
  /// Called with one line per stage (progress for people); optional.
  std::function<void(const std::string&)> progress;

  /// Throws FieldError naming the field ("discrepancy.window_s") when a value is out of range.
  void validate() const;
};

/// One candidate's fit and score.
struct CandidateResult {
  std::string name;
  std::vector<double> params;  ///< typed, catalogue order
  double train_sse = 0.0;
  double delta_bic = 0.0;           ///< training, against the round's base (negative: better)
  double p_value = 1.0;             ///< held-out, one-sided Wilcoxon signed-rank
  double heldout_path_error = 0.0;  ///< median normalised path error (1 = one scale)
  double heldout_end_mape = 0.0;    ///< percent
  double gain = 0.0;                ///< 1 - held-out path error / the base's
  double heldout_cost = 0.0;        ///< the robust cost over the held-out windows
  bool relevant = false;            ///< larger than the extension's negligible size
  bool end_mape_improves = false;   ///< held-out end MAPE not above the round's base
  bool significant = false;
  /// The experiment whose held-out windows alone showed the size, when the pooled ones did not
  /// ("" otherwise), and its gain.
  std::string shown_by;
  double shown_gain = 0.0;
  /// Of bootstrap resamples of the windows, the fraction in which the decision rule adds this
  /// candidate in its round (its fit held; models/discrepancy_uncertainty.h).
  double selection_frequency = 0.0;
  int fit_evaluations = 0;         ///< windows-set predictions at the full step
  int fit_screen_evaluations = 0;  ///< and at the screening step (the grid's ranking)
};

/// One step of the backward check of the forward selection: the model with the found causes
/// against the same model without `name` (the others refitted without it), by the rule the cause
/// entered by.
struct BackwardCheck {
  std::string name;
  std::vector<std::string> others;  ///< the causes kept in the model without it
  double delta_bic = 0.0;           ///< training, with it minus without it
  double p_value = 1.0;             ///< held-out, one-sided Wilcoxon signed-rank
  double gain = 0.0;                ///< 1 - held-out path error with it / without it
  bool end_mape_improves = false;
  bool kept = false;     ///< significant: the data need it beside the others
  std::string shown_by;  ///< as CandidateResult's
};

/// One step of the exchange check: a cause found (`removed`) replaced by a rival that passed in
/// the same round (`added`), the selection refitted; kept when the held-out cost falls and the
/// backward check keeps every cause.
struct Exchange {
  std::string removed, added;
  double cost_before = 0.0, cost_after = 0.0;  ///< the robust cost over the held-out windows
  bool accepted = false;
};

/// A candidate that passed the rule in the round where a cause was chosen (by its lower delta
/// BIC), and that the held-out windows cannot tell from that cause: either explains the data.
struct Rival {
  std::string cause, rival;
  std::vector<double> params;  ///< the rival's fit in that round, typed, catalogue order
  double p_value = 1.0;  ///< one-sided signed-rank: the cause's held-out path errors the lower
  double cause_delta_bic = 0.0, rival_delta_bic = 0.0;  ///< training, against the round's base
  double cause_gain = 0.0, rival_gain = 0.0;            ///< held-out path error gain
};

/// A bin of residuals (cm): the mean along the radial direction from s, across it (positive
/// counter-clockwise) and of the error's length.
struct ResidualBin {
  double lo = 0.0, hi = 0.0;
  size_t n = 0;
  double radial_cm = 0.0, tangential_cm = 0.0, norm_cm = 0.0;
};

/// One residual sample of the baseline (for plots and bins).
struct ResidualSample {
  double distance_m = 0.0;      ///< from the stagnation point the field follows
  double alpha_deg = 0.0;       ///< direction from s, from downstream, in (-180, 180]
  double since_change_s = 0.0;  ///< since the command last changed
  double speed_mps = 0.0;       ///< measured speed
  Eigen::Vector2d p_W = Eigen::Vector2d::Zero();
  double radial_m = 0.0, tangential_m = 0.0;  ///< prediction minus measurement
};

/// What the model with the causes found still gets wrong, seen as a residual acceleration (the
/// measured one minus the model's, each from a local quadratic through 5 samples, the model
/// started from the measured state) smoothed over one group of features: a nonparametric
/// correction (models/discrepancy_correction.h). Components along the radial direction from s and
/// across it (counter-clockwise), m/s^2, on a regular grid of the feature (1-D: ny = 1).
struct ResidualCorrection {
  std::string feature;            ///< "position_from_s", "floor_position" or "time_since_command"
  std::string unit;               ///< of the feature axes: "m" or "s"
  double bandwidth = 0.0;         ///< the Gaussian kernel's width, in `unit`
  double cv_gain = 0.0;           ///< training windows, cross-validated: 1 - loss with / without it
  double heldout_gain = 0.0;      ///< held-out windows: 1 - loss with / without it
  double p_value = 1.0;           ///< held-out, one-sided sign-flip test over windows
  double heldout_rms_mps2 = 0.0;  ///< the correction's RMS over the held-out samples
  double x0 = 0.0, y0 = 0.0, step = 0.0;  ///< the grid: first cell's centre and pitch
  int nx = 0, ny = 1;
  std::vector<double> radial, across;  ///< the correction, nx * ny, row-major in y
  std::vector<double> weight;          ///< the smoothed sample count behind each cell
  /// Where the correction is largest (with support from the data), for people.
  std::string where;
};

/// A 95 % bootstrap interval of a fitted parameter.
/// The other route of the forward selection (at most one): from the first round in which a
/// cause was found while the decision could have gone another way - a lead the training windows
/// support better failed only the size of its held-out gain or end MAPE, or another cause passed
/// too - that candidate takes the cause's place (a lead provisionally) and the selection runs
/// on. The other route's causes are reported when
/// they keep that candidate and their held-out path errors are significantly the lower ones.
struct AlternativeRoute {
  int round = 0;             ///< 1-based
  std::string lead;          ///< the candidate that took the found cause's place
  bool provisional = false;  ///< a lead (provisional), or another cause that passed
  std::vector<std::string> found_first, found_other;
  double cost_first = 0.0, cost_other = 0.0;  ///< the robust cost over the held-out windows
  /// One-sided signed rank over the held-out windows: the other route's path errors the lower.
  double p_value = 1.0;
  bool taken = false;  ///< the other route's causes are reported
};

/// Two candidates fitted together, tried when a round finds no cause and no lead: effects can
/// cancel so that no single one is supported (a shorter delay beside a stronger field and a
/// slope). A pair that passes the rule with both parameter counts enters as two causes.
struct PairEntry {
  int round = 0;  ///< 1-based
  std::string first, second;
  double delta_bic = 0.0;  ///< training, against the round's base
  double p_value = 1.0;    ///< held-out, one-sided Wilcoxon signed-rank
  double gain = 0.0;       ///< 1 - held-out path error / the base's
  bool end_mape_improves = false;
  bool significant = false;
};

struct ParameterRange {
  double lo = NAN, hi = NAN;
  double resolution = NAN;  ///< the fit's finest step: the interval is never narrower
};

struct DiscrepancyReport {
  std::string source;
  size_t n_trajectories = 0, n_windows = 0, n_train_windows = 0, n_heldout_windows = 0;
  size_t n_mape_windows = 0;      ///< held-out windows in the MAPE
  std::vector<double> tilts_deg;  ///< distinct tilts seen
  bool decidable = false;
  std::vector<std::string> notes;  ///< what could not be decided and why

  double baseline_end_mape = 0.0;      ///< held-out, percent
  double baseline_end_mape_all = 0.0;  ///< every window, percent
  double baseline_path_error = 0.0;    ///< held-out mean normalised path error
  double baseline_path_error_cm_mean = 0.0, baseline_path_error_cm_max = 0.0;  ///< every window
  std::vector<ResidualSample> residuals;
  std::map<std::string, std::vector<ResidualBin>> residual_bins;  ///< by quantity

  std::vector<CandidateResult> candidates;           ///< round 1: each extension alone
  std::vector<std::vector<CandidateResult>> rounds;  ///< every round of the forward selection
  /// Per round, the fraction of bootstrap resamples in which no candidate would be added.
  std::vector<double> none_frequency;
  /// The backward check after the forward selection (two or more causes found): every check
  /// made, in order; a cause not kept was dropped from `found`.
  std::vector<BackwardCheck> backward;
  /// The exchange check after the backward check (two or more causes found).
  std::vector<Exchange> exchanges;
  /// The found causes' rivals the held-out windows cannot tell from them (p at or above alpha).
  std::vector<Rival> rivals;
  /// Candidates that entered provisionally (no cause in their round, but the training windows'
  /// support): effects can mask each other until one is modelled (docs/discrepancy.md).
  std::vector<std::string> provisional;
  /// The pairs tried (PairEntry).
  std::vector<PairEntry> pairs;
  /// The other route, when one was followed (models/discrepancy.h, AlternativeRoute).
  std::vector<AlternativeRoute> alternative;
  /// With a provisional entry followed by a cause: the held-out p of the causes from then on
  /// against the selection before them (NaN when no such check was made).
  double joint_p_value = NAN;
  std::vector<std::string> found;  ///< in the order they were added, after the backward check
  /// Causes the rule selected against the nominal model with the ordinary static friction fitted
  /// (its reference), withdrawn because the extended model as written (without that friction)
  /// is worse on a held-out figure than the nominal model: never a cause beside a worse figure.
  std::vector<std::string> withdrawn;
  ModelExtensions extensions;  ///< fitted jointly over the found causes
  /// Per found cause, a 95 % bootstrap interval of each typed parameter (catalogue order).
  std::map<std::string, std::vector<ParameterRange>> intervals;
  /// The ordinary static friction (static / kinetic, within 1 + negligible_size("stiction"))
  /// that the fits carry as a nuisance, as the causes found leave it (not a cause, not in
  /// `extensions`); NaN when stiction is a cause.
  double nuisance_static_friction_ratio = 1.0;
  double extended_end_mape = 0.0;  ///< held-out, percent
  double extended_path_error = 0.0;
  double gain_pct = 0.0;  ///< 100 (1 - extended / baseline) of the held-out end MAPE

  /// Step 5: the residual the causes found leave, corrected nonparametrically over each feature
  /// group (its best bandwidth by cross-validation on the training windows).
  std::vector<ResidualCorrection> corrections;
  int chosen_correction = -1;  ///< the group with the best cross-validated gain (-1: none)
  /// Samples with an acceleration estimate where the measurement or the model moves.
  size_t n_acceleration_samples = 0;
  /// Their median residual acceleration (m/s^2, radial from s and across it), taken out before
  /// the corrections, which are judged against this constant.
  double median_residual_radial = 0.0, median_residual_across = 0.0;
  /// The chosen correction removes a significant part of the held-out residual (p < alpha, gain
  /// >= min_unexplained_gain) and is not negligible (RMS >= 0.1 m/s^2): something the catalogue
  /// does not name is in the data.
  bool unexplained = false;
};

/// Runs the analysis. `objects` gives eq. (8) coefficients per object type; every type in `set`
/// must be there (InputError naming the type otherwise).
DiscrepancyReport analyse_discrepancy(const TrajectorySet& set, const AirFieldModel& field,
                                      const std::map<std::string, ObjectDynamics>& objects,
                                      const DiscrepancyOptions& options);

/// report.json: baseline_end_mape, found, candidates [{name, params {key: value}, heldout_end_mape,
/// delta_bic, p_value, ...}], extended_end_mape, gain_pct, then the details.
std::string discrepancy_report_json(const DiscrepancyReport& report);
/// correction.csv: the chosen correction's grid (feature x, y, radial, across, weight); only the
/// header when none was chosen.
std::string discrepancy_correction_csv(const DiscrepancyReport& report);
/// report.md: what is wrong, where, why, what was added, what it gained; for people.
std::string discrepancy_report_markdown(const DiscrepancyReport& report);

}  // namespace airtwin
