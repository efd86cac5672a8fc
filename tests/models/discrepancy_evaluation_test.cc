// The evaluator's kept results against predictions made afresh: a repeat is answered with the
// very figures a new evaluator computes, and nothing that changes a prediction (the extensions,
// one type's own effect, the windows, the fidelity) or what was asked (the residuals) is taken
// for a repeat.

#include "models/discrepancy_evaluation.h"

#include <gtest/gtest.h>

#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "models/air_field.h"
#include "models/discrepancy_windows.h"
#include "models/object_dynamics.h"
#include "tests/support/appendix_d_trials.h"

namespace airtwin::discrepancy_detail {
namespace {

class EvaluatorTest : public ::testing::Test {
 protected:
  EvaluatorTest()
      : field_(AirFieldModel::with_constructed_table()),
        set_(testing::appendix_d_trials(
            field_, 12, 7, testing::extended_model_plant(field_, truth(), kTracerDynamics))),
        ws_(make_windows(set_, objects_, DiscrepancyOptions{})),
        all_(ws_.windows.size()) {
    std::iota(all_.begin(), all_.end(), size_t{0});
  }
  // A push near s that the nominal model lacks: the windows' figures depend on the extensions.
  static ModelExtensions truth() {
    ModelExtensions x;
    x.push_strength_mps2 = 4.0;
    x.push_length_m = 0.2;
    return x;
  }
  Evaluator evaluator() const { return Evaluator(field_, ws_, 1e-3, 8e-3); }

  const AirFieldModel field_;
  // The windows point into it (their coefficients and type).
  const std::map<std::string, ObjectDynamics> objects_ = {{"tracer", kTracerDynamics}};
  const TrajectorySet set_;
  const WindowSet ws_;
  std::vector<size_t> all_;
};

void expect_same(const std::vector<WindowScore>& a, const std::vector<WindowScore>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].path_error, b[i].path_error) << "window " << i;
    EXPECT_EQ(a[i].predicted_travel_m, b[i].predicted_travel_m) << "window " << i;
    EXPECT_TRUE(a[i].end_pct == b[i].end_pct ||
                (std::isnan(a[i].end_pct) && std::isnan(b[i].end_pct)))
        << "window " << i;
  }
}

bool any_differs(const std::vector<WindowScore>& a, const std::vector<WindowScore>& b) {
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].path_error != b[i].path_error) return true;
  }
  return false;
}

TEST_F(EvaluatorTest, ARepeatIsAnsweredWithTheFiguresAFreshPredictionGives) {
  ASSERT_GE(ws_.windows.size(), 12u);
  const ModelExtensions nominal;
  ModelExtensions scaled;
  scaled.field_scale = 1.1;
  const Evaluator ev = evaluator();
  std::vector<WindowScore> first, other, repeat;
  Eigen::VectorXd first_res, repeat_res;
  ev.evaluate(nominal, all_, &first, &first_res);
  ev.evaluate(scaled, all_, &other, nullptr);
  ev.evaluate(nominal, all_, &repeat, &repeat_res);
  EXPECT_EQ(ev.evaluations_predicted(), 2u);
  EXPECT_EQ(ev.repeats_answered(), 1u);
  // The other extensions predict otherwise, so an answer taken from them would show.
  EXPECT_TRUE(any_differs(first, other));
  expect_same(repeat, first);
  ASSERT_EQ(repeat_res.size(), first_res.size());
  EXPECT_TRUE(repeat_res == first_res);

  // And the figures are those a new evaluator predicts.
  std::vector<WindowScore> fresh;
  Eigen::VectorXd fresh_res;
  evaluator().evaluate(nominal, all_, &fresh, &fresh_res);
  expect_same(repeat, fresh);
  EXPECT_TRUE(repeat_res == fresh_res);
}

TEST_F(EvaluatorTest, WhatChangesAPredictionOrWhatIsAskedIsNotARepeat) {
  const ModelExtensions nominal;
  const Evaluator ev = evaluator();
  std::vector<WindowScore> base, s;
  Eigen::VectorXd res;
  ev.evaluate(nominal, all_, &base, nullptr);
  size_t predicted = 1;

  // Other windows.
  std::vector<size_t> fewer(all_.begin(), all_.end() - 1);
  ev.evaluate(nominal, fewer, &s, nullptr);
  EXPECT_EQ(ev.evaluations_predicted(), ++predicted);
  ASSERT_EQ(s.size(), fewer.size());

  // The screening step.
  ev.evaluate(nominal, all_, &s, nullptr, Fidelity::kScreen);
  EXPECT_EQ(ev.evaluations_predicted(), ++predicted);
  EXPECT_TRUE(any_differs(s, base));

  // An object's effect: shared, then a type's own at two sizes.
  ModelExtensions shared = nominal;
  shared.object.lift_s2_per_m2 = 0.05;
  std::vector<WindowScore> lifted;
  ev.evaluate(shared, all_, &lifted, nullptr);
  EXPECT_EQ(ev.evaluations_predicted(), ++predicted);
  EXPECT_TRUE(any_differs(lifted, base));
  ModelExtensions own = nominal;
  own.object_by_type["tracer"].lift_s2_per_m2 = 0.05;
  ev.evaluate(own, all_, &s, nullptr);
  EXPECT_EQ(ev.evaluations_predicted(), ++predicted);
  expect_same(s, lifted);  // the type's own, felt by its objects as the shared one
  own.object_by_type["tracer"].lift_s2_per_m2 = 0.1;
  ev.evaluate(own, all_, &s, nullptr);
  EXPECT_EQ(ev.evaluations_predicted(), ++predicted);
  EXPECT_TRUE(any_differs(s, lifted));

  // Residuals asked where the kept result has none: predicted, then kept with them.
  ev.evaluate(nominal, all_, &s, &res);
  EXPECT_EQ(ev.evaluations_predicted(), ++predicted);
  EXPECT_EQ(res.size(), static_cast<Eigen::Index>(ev.residual_count(all_)));
  expect_same(s, base);
  ev.evaluate(nominal, all_, &s, nullptr);
  ev.evaluate(nominal, all_, &s, &res);
  EXPECT_EQ(ev.evaluations_predicted(), predicted);
  EXPECT_EQ(ev.repeats_answered(), 2u);
}

// A bootstrap's resample names windows several times: each is predicted as alone, on every
// thread, and again once the windows' orientations are kept (the second evaluation under the same
// delay and offset makes them).
TEST_F(EvaluatorTest, AResampleNamingWindowsTwiceIsPredictedAsEachAlone) {
  // The list twice over: a window's two entries fall to different threads.
  std::vector<size_t> twice = all_;
  twice.insert(twice.end(), all_.begin(), all_.end());
  std::vector<WindowScore> alone;
  evaluator().evaluate(ModelExtensions{}, all_, &alone, nullptr);
  const Evaluator ev = evaluator();
  for (double scale : {1.0, 1.05, 1.1}) {  // other extensions: predicted each time
    ModelExtensions x;
    x.field_scale = scale;
    std::vector<WindowScore> s, expected;
    evaluator().evaluate(x, all_, &expected, nullptr);
    ev.evaluate(x, twice, &s, nullptr);
    ASSERT_EQ(s.size(), twice.size());
    for (size_t k = 0; k < twice.size(); ++k) {
      EXPECT_EQ(s[k].path_error, expected[k % all_.size()].path_error)
          << "scale " << scale << ", entry " << k;
    }
    if (scale == 1.0) expect_same({s.begin(), s.begin() + all_.size()}, alone);
  }
  EXPECT_EQ(ev.evaluations_predicted(), 3u);
}

TEST_F(EvaluatorTest, KeepsAtMostItsBoundOfResults) {
  const Evaluator ev = evaluator();
  std::vector<WindowScore> s;
  const std::vector<size_t> one = {0};
  auto scaled = [](size_t i) {
    ModelExtensions x;
    x.field_scale = 1.0 + 0.001 * static_cast<double>(i);
    return x;
  };
  for (size_t i = 0; i <= Evaluator::kMemoEntries; ++i) {
    ev.evaluate(scaled(i), one, &s, nullptr, Fidelity::kScreen);
  }
  EXPECT_EQ(ev.evaluations_predicted(), Evaluator::kMemoEntries + 1);
  // The latest is kept, the first no longer.
  ev.evaluate(scaled(Evaluator::kMemoEntries), one, &s, nullptr, Fidelity::kScreen);
  EXPECT_EQ(ev.repeats_answered(), 1u);
  ev.evaluate(scaled(0), one, &s, nullptr, Fidelity::kScreen);
  EXPECT_EQ(ev.evaluations_predicted(), Evaluator::kMemoEntries + 2);
}

}  // namespace
}  // namespace airtwin::discrepancy_detail
