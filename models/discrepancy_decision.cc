#include "models/discrepancy_decision.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "models/discrepancy_report.h"
#include "models/discrepancy_statistics.h"
#include "models/discrepancy_windows.h"

namespace airtwin::discrepancy_detail {

Decision decide(const WindowFigures& base, const WindowFigures& candidate, int k, bool relevant,
                const DecisionWindows& w, const DecisionRule& rule) {
  Decision d;
  double base_sse = 0.0, cand_sse = 0.0;
  for (size_t i : w.train) {
    base_sse += base.train_cost[i];
    cand_sse += candidate.train_cost[i];
  }
  d.delta_bic = bic(cand_sse, w.train.size(), k) - bic(base_sse, w.train.size(), 0);
  // Differences of the RMS path error below what the data resolve are ties at zero: they say
  // nothing either way, and an effect that acts only in part of the floor (a push near s) would
  // otherwise drown in the noise of the windows it does not touch.
  std::vector<double> diff(w.held.size());
  std::vector<WindowScore> b, c;
  std::vector<char> informative;
  b.reserve(w.held.size());
  c.reserve(w.held.size());
  for (size_t j = 0; j < w.held.size(); ++j) {
    const size_t i = w.held[j];
    const double e = base.held[i].path_error - candidate.held[i].path_error;
    diff[j] = std::abs(e * (*w.held_scale_m)[i]) < kResolvedDifference_m ? 0.0 : e;
    b.push_back(base.held[i]);
    c.push_back(candidate.held[i]);
    informative.push_back((*w.informative)[i]);
  }
  d.p_value = wilcoxon_greater(diff);
  d.path_error = mean_path_error(c, informative);
  d.end_mape = end_mape(c);
  d.gain = 1.0 - d.path_error / mean_path_error(b, informative);
  d.cost = sum_squares(c);
  // Never a cause beside a worse held-out figure: the end-position MAPE must not grow either.
  d.end_mape_improves = !(d.end_mape > end_mape(b));
  const bool held_out_better = d.p_value < rule.p_threshold && d.end_mape_improves;
  d.significant =
      d.delta_bic <= rule.max_delta_bic && held_out_better && d.gain >= rule.min_gain && relevant;
  if (d.significant || rule.experiment_count < 2 || rule.held_experiment == nullptr ||
      !(d.delta_bic <= rule.max_delta_bic && held_out_better && relevant)) {
    return d;
  }
  // The size shown by one experiment on its own: the same test and figures on its windows.
  for (int g = 0; g < rule.experiment_count; ++g) {
    std::vector<double> diff_g;
    std::vector<WindowScore> b_g, c_g;
    std::vector<char> informative_g;
    for (size_t j = 0; j < w.held.size(); ++j) {
      const size_t i = w.held[j];
      if ((*rule.held_experiment)[i] != g) continue;
      diff_g.push_back(diff[j]);
      b_g.push_back(b[j]);
      c_g.push_back(c[j]);
      informative_g.push_back(informative[j]);
    }
    if (diff_g.size() < rule.min_experiment_windows) continue;
    const double gain_g =
        1.0 - mean_path_error(c_g, informative_g) / mean_path_error(b_g, informative_g);
    if (wilcoxon_greater(diff_g) < rule.p_threshold / rule.experiment_count &&
        gain_g >= rule.min_gain && !(end_mape(c_g) > end_mape(b_g)) &&
        (d.shown_by < 0 || gain_g > d.shown_gain)) {
      d.shown_by = g;
      d.shown_gain = gain_g;
    }
  }
  d.significant = d.shown_by >= 0;
  return d;
}

std::string shown_by_name(const Decision& d, const DecisionRule& rule) {
  if (d.shown_by < 0 || rule.experiment_names == nullptr) return "";
  return (*rule.experiment_names)[static_cast<size_t>(d.shown_by)];
}

double p_chosen_beats_rival(const WindowFigures& chosen, const WindowFigures& rival,
                            const DecisionWindows& windows) {
  // The rival as the base and the chosen cause as the candidate: the test that the candidate's
  // path errors are the lower ones. The rule's thresholds play no part in the p-value.
  return decide(rival, chosen, 0, true, windows, DecisionRule{}).p_value;
}

DecisionWindows all_windows(size_t n_train, size_t n_held, const std::vector<double>& held_scale_m,
                            const std::vector<char>& informative) {
  DecisionWindows w;
  w.train.resize(n_train);
  std::iota(w.train.begin(), w.train.end(), 0);
  w.held.resize(n_held);
  std::iota(w.held.begin(), w.held.end(), 0);
  w.held_scale_m = &held_scale_m;
  w.informative = &informative;
  return w;
}

JointCheck check_jointly(const WindowFigures& before, const std::vector<std::string>& before_causes,
                         const WindowFigures& after, const std::vector<std::string>& after_causes,
                         const std::function<int(const std::string&)>& parameter_count,
                         const DecisionWindows& windows, const DecisionRule& rule) {
  JointCheck j;
  for (const std::string& name : after_causes) {
    if (std::find(before_causes.begin(), before_causes.end(), name) == before_causes.end()) {
      j.added.push_back(name);
      j.k += parameter_count(name);
    }
  }
  j.decision = decide(before, after, j.k, true, windows, rule);
  return j;
}

std::string JointCheck::rejection_note() const {
  std::string names;
  for (const std::string& name : added) names += (names.empty() ? "" : ", ") + name;
  return names + " together did not beat the model without them on the held-out windows (p " +
         fixed(decision.p_value, 4) + "): taken out again.";
}

}  // namespace airtwin::discrepancy_detail
