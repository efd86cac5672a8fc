// The decision rule against its definition on hand-made per-window figures: delta BIC from the
// summed training costs, the signed-rank test on the held-out differences (with differences under
// 1 mm as ties), the gain of the median path error, the end MAPE's veto and the relevance flag.

#include "models/discrepancy_decision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "models/discrepancy_statistics.h"

namespace airtwin::discrepancy_detail {
namespace {

struct Case {
  WindowFigures base, candidate;
  std::vector<double> scale_m;
  std::vector<char> informative;
};

// 12 held-out windows (scale 10 cm) where the candidate halves the base's path error, 20
// training windows where it cuts each cost from 1 to 0.25.
Case better_everywhere() {
  Case c;
  for (int i = 0; i < 20; ++i) {
    c.base.train_cost.push_back(1.0);
    c.candidate.train_cost.push_back(0.25);
  }
  for (int i = 0; i < 12; ++i) {
    c.base.held.push_back(WindowScore{0.2 + 0.01 * i, 40.0});
    c.candidate.held.push_back(WindowScore{0.1 + 0.005 * i, 20.0});
    c.scale_m.push_back(0.1);
    c.informative.push_back(1);
  }
  return c;
}

TEST(DiscrepancyDecision, ReadsEachCriterionAsDefined) {
  const Case c = better_everywhere();
  const DecisionWindows w = all_windows(20, 12, c.scale_m, c.informative);
  const DecisionRule rule;  // p < 0.05, delta BIC <= -10, gain >= 15 %
  const Decision d = decide(c.base, c.candidate, 2, true, w, rule);
  EXPECT_NEAR(d.delta_bic, bic(5.0, 20, 2) - bic(20.0, 20, 0), 1e-12);
  std::vector<double> diff;
  for (int i = 0; i < 12; ++i)
    diff.push_back(c.base.held[i].path_error - c.candidate.held[i].path_error);
  EXPECT_NEAR(d.p_value, wilcoxon_greater(diff), 1e-15);
  // Medians of 12: the mean of the 6th and 7th.
  EXPECT_NEAR(d.path_error, 0.5 * (0.125 + 0.13), 1e-12);
  EXPECT_NEAR(d.gain, 1.0 - d.path_error / (0.5 * (0.25 + 0.26)), 1e-12);
  EXPECT_NEAR(d.end_mape, 20.0, 1e-12);
  EXPECT_TRUE(d.end_mape_improves);
  EXPECT_TRUE(d.significant);
  // Each criterion alone vetoes.
  EXPECT_FALSE(decide(c.base, c.candidate, 2, false, w, rule).significant);  // negligible size
  DecisionRule strict = rule;
  strict.min_gain = 0.6;
  EXPECT_FALSE(decide(c.base, c.candidate, 2, true, w, strict).significant);
  strict = rule;
  strict.p_threshold = d.p_value;  // p must be below it
  EXPECT_FALSE(decide(c.base, c.candidate, 2, true, w, strict).significant);
  strict = rule;
  strict.max_delta_bic = d.delta_bic - 1.0;
  EXPECT_FALSE(decide(c.base, c.candidate, 2, true, w, strict).significant);
  Case worse_end = c;
  for (WindowScore& s : worse_end.candidate.held) s.end_pct = 41.0;  // base: 40 %
  const Decision e = decide(worse_end.base, worse_end.candidate, 2, true, w, rule);
  EXPECT_FALSE(e.end_mape_improves);
  EXPECT_FALSE(e.significant);
}

// Two experiments: 40 held-out windows ("logs") where the candidate changes the path error by
// 2 % (0.4-0.5 mm, ties) and 12 ("coast", windows 40-51) where it halves it. The pooled median
// moves 6 %: no cause by the pooled windows alone. Named as experiments, the coast's windows show
// the size (gain 50 %, the same p as the pooled windows' since the logs' are ties, below 0.05 /
// 2), the pooled ones pass the test and keep their end MAPE: a cause, shown by the coast. Each
// condition of that route vetoes on its own.
TEST(DiscrepancyDecision, OneExperimentMayShowTheSizeThePooledWindowsDoNot) {
  Case c;
  for (int i = 0; i < 20; ++i) {
    c.base.train_cost.push_back(1.0);
    c.candidate.train_cost.push_back(0.25);
  }
  std::vector<int> experiment;
  for (int i = 0; i < 52; ++i) {
    const bool coast = i >= 40;
    const double e = coast ? 0.2 + 0.01 * (i - 40) : 0.2 + 0.001 * i;
    c.base.held.push_back(WindowScore{e, 40.0});
    c.candidate.held.push_back(WindowScore{coast ? 0.5 * e : 0.98 * e, coast ? 20.0 : 40.0});
    c.scale_m.push_back(0.1);
    c.informative.push_back(1);
    experiment.push_back(coast ? 1 : 0);
  }
  const std::vector<std::string> names = {"logs", "coast"};
  const DecisionWindows w = all_windows(20, 52, c.scale_m, c.informative);
  DecisionRule rule;
  const Decision pooled = decide(c.base, c.candidate, 1, true, w, rule);
  EXPECT_LT(pooled.gain, 0.15);
  std::vector<double> coast_diff;
  for (int i = 40; i < 52; ++i)
    coast_diff.push_back(c.base.held[i].path_error - c.candidate.held[i].path_error);
  const double p = wilcoxon_greater(coast_diff);
  EXPECT_NEAR(pooled.p_value, p, 1e-15);  // the 40 ties drop out
  EXPECT_LT(p, 0.025);
  EXPECT_FALSE(pooled.significant);
  EXPECT_EQ(pooled.shown_by, -1);

  rule.held_experiment = &experiment;
  rule.experiment_count = 2;
  rule.experiment_names = &names;
  const Decision d = decide(c.base, c.candidate, 1, true, w, rule);
  EXPECT_TRUE(d.significant);
  EXPECT_EQ(d.shown_by, 1);
  EXPECT_EQ(shown_by_name(d, rule), "coast");
  EXPECT_NEAR(d.shown_gain, 0.5, 1e-12);
  EXPECT_NEAR(d.gain, pooled.gain, 1e-15);  // the pooled figures are reported as they are

  // The coast's p must be below the level over the experiments' count.
  DecisionRule strict = rule;
  strict.p_threshold = 1.5 * p;  // the pooled p passes, the coast's against 0.75 p fails
  EXPECT_FALSE(decide(c.base, c.candidate, 1, true, w, strict).significant);
  strict.p_threshold = 2.5 * p;
  EXPECT_TRUE(decide(c.base, c.candidate, 1, true, w, strict).significant);
  // Too few windows in the experiment.
  strict = rule;
  strict.min_experiment_windows = 13;
  EXPECT_FALSE(decide(c.base, c.candidate, 1, true, w, strict).significant);
  // The pooled end MAPE must not grow, nor the experiment's own.
  Case worse = c;
  for (int i = 0; i < 40; ++i) worse.candidate.held[i].end_pct = 50.0;  // pooled 43.1 > 40 %
  EXPECT_FALSE(decide(worse.base, worse.candidate, 1, true, w, rule).significant);
  // Not without the training's support, nor below the negligible size.
  strict = rule;
  strict.max_delta_bic = pooled.delta_bic - 1.0;
  EXPECT_FALSE(decide(c.base, c.candidate, 1, true, w, strict).significant);
  EXPECT_FALSE(decide(c.base, c.candidate, 1, false, w, rule).significant);
}

TEST(DiscrepancyDecision, ARivalIsToldApartOnlyByLowerHeldOutErrors) {
  const Case c = better_everywhere();
  const DecisionWindows w = all_windows(20, 12, c.scale_m, c.informative);
  // The candidate's held-out errors are lower in every window: it beats the base as a rival, by
  // the same test the rule reads (base minus candidate, one-sided), and the base does not beat it.
  std::vector<double> diff;
  for (int i = 0; i < 12; ++i)
    diff.push_back(c.base.held[i].path_error - c.candidate.held[i].path_error);
  EXPECT_NEAR(p_chosen_beats_rival(c.candidate, c.base, w), wilcoxon_greater(diff), 1e-15);
  EXPECT_LT(p_chosen_beats_rival(c.candidate, c.base, w), 0.05);
  EXPECT_GT(p_chosen_beats_rival(c.base, c.candidate, w), 0.95);
  // Two models with the same held-out errors (the training costs aside): all ties, nothing tells
  // them apart.
  WindowFigures twin = c.candidate;
  for (double& t : twin.train_cost) t *= 0.5;
  EXPECT_GE(p_chosen_beats_rival(twin, c.candidate, w), 0.5);
  EXPECT_GE(p_chosen_beats_rival(c.candidate, twin, w), 0.5);
}

TEST(DiscrepancyDecision, DifferencesUnderAMillimetreAreTies) {
  Case c = better_everywhere();
  // Scale 5 mm: every difference (0.1-0.155 scales, 0.5-0.8 mm) is under 1 mm: all ties,
  // nothing to test.
  for (double& s : c.scale_m) s = 0.005;
  const DecisionWindows w = all_windows(20, 12, c.scale_m, c.informative);
  const Decision d = decide(c.base, c.candidate, 2, true, w, DecisionRule{});
  EXPECT_EQ(d.p_value, 1.0);
  EXPECT_FALSE(d.significant);
}

// The joint check of causes found on top of a provisional one: the causes added since the
// selection before it, their parameters summed, and the rule read on the two selections. Two
// extensions that only trade off against each other fit the training windows better but leave
// every held-out window as it was: taken out, with a note naming both.
TEST(DiscrepancyDecision, CausesFoundTogetherMustBeatTheModelWithoutThem) {
  const Case c = better_everywhere();
  const DecisionWindows w = all_windows(20, 12, c.scale_m, c.informative);
  const DecisionRule rule;
  const std::vector<std::string> before = {"floor_slope"};
  const std::vector<std::string> after = {"floor_slope", "response_delay", "field_scale"};
  const auto count = [](const std::string& name) { return name == "floor_slope" ? 2 : 1; };
  const JointCheck kept = check_jointly(c.base, before, c.candidate, after, count, w, rule);
  EXPECT_EQ(kept.added, (std::vector<std::string>{"response_delay", "field_scale"}));
  EXPECT_EQ(kept.k, 2);
  const Decision d = decide(c.base, c.candidate, 2, true, w, rule);
  EXPECT_EQ(kept.decision.p_value, d.p_value);
  EXPECT_EQ(kept.decision.delta_bic, d.delta_bic);
  EXPECT_TRUE(kept.kept());

  WindowFigures trading = c.candidate;
  trading.held = c.base.held;  // the training cost falls; nothing held out changes
  const JointCheck out = check_jointly(c.base, before, trading, after, count, w, rule);
  EXPECT_FALSE(out.kept());
  EXPECT_EQ(out.decision.p_value, 1.0);  // every held-out difference is 0: all ties
  EXPECT_EQ(out.rejection_note(),
            "response_delay, field_scale together did not beat the model without them on the "
            "held-out windows (p 1.0000): taken out again.");
  // Better held-out figures that are not better enough (a gain under 15 %) are taken out too.
  WindowFigures slight = c.base;
  slight.train_cost = c.candidate.train_cost;
  for (WindowScore& s : slight.held) s.path_error *= 0.9;
  const JointCheck small = check_jointly(c.base, before, slight, after, count, w, rule);
  EXPECT_LT(small.decision.p_value, rule.p_threshold);
  EXPECT_NEAR(small.decision.gain, 0.1, 1e-12);
  EXPECT_FALSE(small.kept());
}

TEST(DiscrepancyDecision, ResamplesReadTheWindowsTheyPick) {
  // A resample that picks one window twelve times reads that window alone.
  const Case c = better_everywhere();
  DecisionWindows w = all_windows(20, 12, c.scale_m, c.informative);
  w.held.assign(12, 3);
  const Decision d = decide(c.base, c.candidate, 2, true, w, DecisionRule{});
  EXPECT_NEAR(d.path_error, c.candidate.held[3].path_error, 1e-15);
  EXPECT_NEAR(d.cost, 12.0 * robust_cost(c.candidate.held[3].path_error), 1e-12);
}

}  // namespace
}  // namespace airtwin::discrepancy_detail
