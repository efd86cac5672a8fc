#pragma once
// The discrepancy analysis's decision rule (models/discrepancy.h, step 3): whether a candidate,
// fitted on top of a round's base, is a cause, read from each model's per-window figures. One
// home for the rule, used on the windows as they are and on resamples of them (the bootstrap of
// models/discrepancy_uncertainty.h). Internal to the analysis.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "models/discrepancy_evaluation.h"

namespace airtwin::discrepancy_detail {

// One model's figures per window: the robust cost of each training window and the scores of the
// held-out ones.
struct WindowFigures {
  std::vector<double> train_cost;
  std::vector<WindowScore> held;
};

// The thresholds of the rule.
struct DecisionRule {
  double p_threshold = 0.05;     // alpha / number of candidates
  double max_delta_bic = -10.0;  // training
  double min_gain = 0.15;        // relative drop of the held-out median path error
  // The experiments the data come from (DiscrepancyOptions::experiment_of): each held-out window's
  // experiment index (indexed as WindowFigures::held), and their count. One experiment (or
  // none given): the rule on the pooled windows alone.
  const std::vector<int>* held_experiment = nullptr;
  int experiment_count = 1;
  const std::vector<std::string>* experiment_names = nullptr;  // by index
  // An experiment needs this many held-out windows to show a cause's size on its own.
  size_t min_experiment_windows = 8;
};

// What the rule reads and decides.
struct Decision {
  double delta_bic = 0.0;   // candidate minus base, training
  double p_value = 1.0;     // one-sided Wilcoxon signed-rank on the held-out path errors
  double path_error = 0.0;  // the candidate's held-out median path error (informative windows)
  double end_mape = 0.0;    // the candidate's held-out end MAPE, percent
  double gain = 0.0;        // 1 - path_error / the base's
  double cost = 0.0;        // the candidate's robust cost over the held-out windows
  bool end_mape_improves = false;
  bool significant = false;
  // The experiment whose held-out windows showed the size (gain and end MAPE) when the pooled
  // windows did not; -1: the pooled windows (or none).
  int shown_by = -1;
  double shown_gain = 0.0;  // that experiment's gain
};

// The held-out and training windows the rule reads: indices into WindowFigures' vectors (repeats
// allowed, for resamples), with each held-out window's scale (m) and whether it is informative
// (something moved or was predicted to).
struct DecisionWindows {
  std::vector<size_t> train, held;
  const std::vector<double>* held_scale_m = nullptr;
  const std::vector<char>* informative = nullptr;
};

// The rule: delta BIC <= max_delta_bic with k the candidate's parameter count, p below the
// threshold (held-out differences below kResolvedDifference_m count as ties at zero), gain >=
// min_gain, the end MAPE not above the base's, and `relevant` (larger than negligible). With
// several experiments the size (gain and end MAPE) may instead be shown by one of them on its
// own held-out windows, its signed-rank p below the threshold over the experiments' count: a
// protocol made to isolate a cause (objects coasting in still air) is not outvoted by data in
// which the cause is a small part; the pooled p and the pooled end MAPE still decide.
Decision decide(const WindowFigures& base, const WindowFigures& candidate, int k, bool relevant,
                const DecisionWindows& windows, const DecisionRule& rule);

// The name of the experiment that showed a decision's size; "" for the pooled windows.
std::string shown_by_name(const Decision& d, const DecisionRule& rule);

// Whether the held-out windows tell a chosen cause from a rival that passed the rule in the same
// round: the p-value of the one-sided signed-rank test that the chosen model's held-out path
// errors are lower than the rival's (differences under kResolvedDifference_m are ties, as in
// `decide`). At or above the analysis's alpha the data cannot tell the two apart.
double p_chosen_beats_rival(const WindowFigures& chosen, const WindowFigures& rival,
                            const DecisionWindows& windows);

// Every window once, in order: the decision on the data as they are.
DecisionWindows all_windows(size_t n_train, size_t n_held, const std::vector<double>& held_scale_m,
                            const std::vector<char>& informative);

// The causes found on top of a provisional one (models/discrepancy.cc), together against the
// selection before the provisional one: two spurious extensions can each make up for the other,
// so that each is "needed" beside the other while together they explain nothing.
struct JointCheck {
  std::vector<std::string> added;  // the causes `after` has and `before` had not, in order
  int k = 0;                       // their parameters, together
  Decision decision;               // the rule, `after` against `before`, relevance granted
  bool kept() const { return decision.significant; }
  // The report's note when they are taken out again: their names and the p-value.
  std::string rejection_note() const;
};
JointCheck check_jointly(const WindowFigures& before, const std::vector<std::string>& before_causes,
                         const WindowFigures& after, const std::vector<std::string>& after_causes,
                         const std::function<int(const std::string&)>& parameter_count,
                         const DecisionWindows& windows, const DecisionRule& rule);

}  // namespace airtwin::discrepancy_detail
