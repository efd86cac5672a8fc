// Selection frequencies over bootstrap resamples, on hand-made per-window figures: a candidate
// better in every window is chosen in every resample, one equal to the base in none, and of two
// passing causes the one the training windows support best (the lower delta BIC), also when the
// other has the lower held-out cost; the same seed gives the same frequencies.
// (The parameter intervals need predictions: tests/models/discrepancy_test.cc.)

#include "models/discrepancy_uncertainty.h"

#include <gtest/gtest.h>

namespace airtwin::discrepancy_detail {
namespace {

// `factor` scales the base's path errors and costs (1: the base itself).
WindowFigures figures(double factor) {
  WindowFigures f;
  for (int i = 0; i < 30; ++i) f.train_cost.push_back(factor * factor * (1.0 + 0.1 * (i % 7)));
  for (int i = 0; i < 15; ++i)
    f.held.push_back(WindowScore{factor * (0.2 + 0.02 * i), factor * 40.0});
  return f;
}

TEST(DiscrepancyUncertainty, SelectionFrequenciesFollowTheRule) {
  const WindowFigures base = figures(1.0), same = figures(1.0), half = figures(0.5),
                      third = figures(0.33);
  const std::vector<double> scale(15, 0.1);
  const std::vector<char> informative(15, 1);
  const DecisionRule rule;
  // Alone: the better candidate in every resample; the base's copy never.
  std::vector<double> f = selection_frequencies(base, {{&half, 1, true}, {&same, 1, true}}, scale,
                                                informative, rule, 4, 0);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0], 1.0);
  EXPECT_EQ(f[1], 0.0);
  EXPECT_EQ(f[2], 0.0);
  // Two causes: the lower delta BIC wins every time.
  f = selection_frequencies(base, {{&half, 1, true}, {&third, 1, true}}, scale, informative, rule,
                            4, 0);
  EXPECT_EQ(f[0], 0.0);
  EXPECT_EQ(f[1], 1.0);
  // The training's figures and the held-out ones disagree: the training's delta BIC decides,
  // though the other candidate's held-out cost is lower.
  WindowFigures train_better = third, held_better = half;
  train_better.held = half.held;
  held_better.held = third.held;
  f = selection_frequencies(base, {{&train_better, 1, true}, {&held_better, 1, true}}, scale,
                            informative, rule, 4, 0);
  EXPECT_EQ(f[0], 1.0);
  EXPECT_EQ(f[1], 0.0);
  // Nothing better than the base: none.
  f = selection_frequencies(base, {{&same, 1, true}}, scale, informative, rule, 4, 0);
  EXPECT_EQ(f[1], 1.0);
  // A negligible candidate is never added.
  f = selection_frequencies(base, {{&half, 1, false}}, scale, informative, rule, 4, 0);
  EXPECT_EQ(f[1], 1.0);
}

TEST(DiscrepancyUncertainty, ABorderlineCandidateIsChosenInSomeResamples) {
  // Better in 10 of 15 held-out windows, a little worse in 5 (p = 0.006 on the windows as they
  // are, against a threshold of 0.01): the signed-rank p moves with the resample.
  const WindowFigures base = figures(1.0);
  WindowFigures mixed = figures(0.7);
  for (int i = 10; i < 15; ++i) mixed.held[i].path_error = 1.1 * base.held[i].path_error;
  const std::vector<double> scale(15, 0.1);
  const std::vector<char> informative(15, 1);
  DecisionRule rule;
  rule.min_gain = 0.0;
  rule.p_threshold = 0.01;
  const std::vector<double> a =
      selection_frequencies(base, {{&mixed, 1, true}}, scale, informative, rule, 9, 0);
  EXPECT_GT(a[0], 0.05);
  EXPECT_LT(a[0], 0.95);
  EXPECT_NEAR(a[0] + a[1], 1.0, 1e-12);
  // Same seed and round, same frequencies; another round draws other resamples.
  EXPECT_EQ(selection_frequencies(base, {{&mixed, 1, true}}, scale, informative, rule, 9, 0), a);
  EXPECT_NE(selection_frequencies(base, {{&mixed, 1, true}}, scale, informative, rule, 9, 1), a);
}

}  // namespace
}  // namespace airtwin::discrepancy_detail
