// The discrepancy analysis on data made by the extended model itself (models/extended_predictor.h
// as the plant, no noise): the truth is known exactly, so the fitted cause and the ordinary
// static friction the fits carry as a nuisance can be held to tight bounds. The end-to-end tests
// on twin data are in tests/app/discrepancy_cli_test.cc.

#include "models/discrepancy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "common/errors.h"
#include "common/units.h"
#include "models/extended_predictor.h"
#include "tests/support/appendix_d_trials.h"

namespace airtwin {
namespace {

// Appendix D trials (tests/support/appendix_d_trials.h) moved by the extended model with `truth`.
TrajectorySet appendix_d_data(const AirFieldModel& field, const ModelExtensions& truth, int trials,
                              std::uint64_t seed) {
  return testing::appendix_d_trials(field, trials, seed,
                                    testing::extended_model_plant(field, truth, kTracerDynamics));
}

std::string describe_extension_params(const CandidateResult& c) {
  std::string text;
  for (double p : c.params) {
    char v[32];
    std::snprintf(v, sizeof(v), "%.3f ", p);
    text += v;
  }
  return text;
}

// The first round's candidates, for failure messages.
std::string candidates(const DiscrepancyReport& r) {
  std::string text;
  for (const CandidateResult& c : r.candidates) {
    char line[160];
    std::snprintf(line, sizeof(line), "%s: %s gain %.3f dBIC %.1f p %.3g%s\n", c.name.c_str(),
                  describe_extension_params(c).c_str(), c.gain, c.delta_bic, c.p_value,
                  c.significant ? " cause" : "");
    text += line;
  }
  return text;
}

// `screen_step_s` 0: the options' default screening step; else that step (the analysis's own 1 ms
// turns the screening off).
DiscrepancyReport analyse(const AirFieldModel& field, const TrajectorySet& set,
                          double screen_step_s = 0.0) {
  DiscrepancyOptions o;
  o.seed = 3;
  if (screen_step_s > 0.0) o.screen_step_s = screen_step_s;
  return analyse_discrepancy(set, field, {{"tracer", kTracerDynamics}}, o);
}

// A 4 deg slope toward 40 deg under static friction 1.2 times kinetic: the slope is found and
// recovered, the nuisance reads 1.2, and the extended model carries the slope alone. (With the
// candidates' grids at ratio 1 only, this slope was not found at all: 4.4 deg toward -64 deg.)
TEST(Discrepancy, SlopeUnderOrdinaryStaticFrictionIsRecovered) {
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  ModelExtensions truth;
  truth.slope_rad = deg_to_rad(4.0);
  truth.slope_direction_rad = deg_to_rad(40.0);
  truth.static_friction_ratio = 1.2;
  const DiscrepancyReport r = analyse(field, appendix_d_data(field, truth, 60, 7));
  ASSERT_TRUE(r.decidable);
  ASSERT_EQ(r.found, std::vector<std::string>{"floor_slope"}) << candidates(r);
  EXPECT_NEAR(rad_to_deg(r.extensions.slope_rad), 4.0, 0.12);  // 3 %
  EXPECT_NEAR(rad_to_deg(r.extensions.slope_direction_rad), 40.0, 2.0);
  EXPECT_NEAR(r.nuisance_static_friction_ratio, 1.2, 0.025 + 1e-9);  // one grid step
  EXPECT_EQ(r.extensions.static_friction_ratio, 1.0);                // the nuisance is not a cause
  // Firm: chosen in (nearly) every resample of the windows, and its 95 % intervals hold the fit
  // and reach the truth to within their resolution (the refits' finest compass step, 1/16 of the
  // grid's 2 deg pitch in each component: 0.125 deg). Exact data: only the windows' draw spreads
  // them; the fit's own bias (the slope trades off against the nuisance) is not theirs to cover.
  for (const CandidateResult& c : r.candidates) {
    if (c.name == "floor_slope") {
      EXPECT_GE(c.selection_frequency, 0.95);
    }
  }
  const double resolution = 0.125;
  ASSERT_EQ(r.intervals.count("floor_slope"), 1u);
  const std::vector<ParameterRange>& iv = r.intervals.at("floor_slope");
  ASSERT_EQ(iv.size(), 2u);
  const double angle = rad_to_deg(r.extensions.slope_rad);
  const double direction = rad_to_deg(r.extensions.slope_direction_rad);
  std::printf("slope %.3f deg [%.3f, %.3f] toward %.2f deg [%.2f, %.2f]\n", angle, iv[0].lo,
              iv[0].hi, direction, iv[1].lo, iv[1].hi);
  EXPECT_LE(iv[0].lo, angle);
  EXPECT_GE(iv[0].hi, angle);
  EXPECT_LE(iv[0].lo, 4.0 + resolution);
  EXPECT_GE(iv[0].hi, 4.0 - resolution);
  EXPECT_LT(iv[0].hi - iv[0].lo, 1.0);  // informative: narrower than a quarter of the slope
  EXPECT_LE(iv[1].lo, 40.0);
  EXPECT_GE(iv[1].hi, 40.0);
  // (The extended model's MAPE is not asserted here: it leaves the nuisance out, and on exact
  // data a slope alone starts some objects that static friction 1.2 holds. On twin data the
  // hidden-effect tests assert the gain.)

  // The grids ranked at the screening step only choose where the fits start: without screening
  // (every prediction at 1 ms) the same cause, parameters and nuisance to well within the bounds
  // above.
  const DiscrepancyReport full = analyse(field, appendix_d_data(field, truth, 60, 7), 1e-3);
  ASSERT_EQ(full.found, r.found) << candidates(full);
  EXPECT_NEAR(rad_to_deg(full.extensions.slope_rad), rad_to_deg(r.extensions.slope_rad), 0.03);
  EXPECT_NEAR(rad_to_deg(full.extensions.slope_direction_rad),
              rad_to_deg(r.extensions.slope_direction_rad), 0.5);
  EXPECT_EQ(full.nuisance_static_friction_ratio, r.nuisance_static_friction_ratio);
  for (size_t i = 0; i < r.candidates.size(); ++i) {
    EXPECT_EQ(full.candidates[i].significant, r.candidates[i].significant) << r.candidates[i].name;
    EXPECT_GT(full.candidates[i].fit_evaluations, 0);
    EXPECT_GT(r.candidates[i].fit_screen_evaluations, 0);
  }
}

TEST(Discrepancy, OptionsNameTheFieldOutOfRange) {
  DiscrepancyOptions o;
  o.screen_step_s = 0.5e-3;  // finer than the analysis's own step
  try {
    o.validate();
    FAIL() << "a screening step below predictor_step_s was accepted";
  } catch (const FieldError& e) {
    EXPECT_NE(std::string(e.what()).find("discrepancy.screen_step_s"), std::string::npos)
        << e.what();
  }
  o = DiscrepancyOptions{};
  o.predictor_step_s = 0.0;
  EXPECT_THROW(o.validate(), FieldError);
  o = DiscrepancyOptions{};
  o.window_s = 0.1;
  EXPECT_THROW(o.validate(), FieldError);
}

// The same plant with kinetic = static friction and no slope: nothing is found and the nuisance
// stays at 1 (the grid's smallest ratio wins ties: objects that start under both make no
// difference).
TEST(Discrepancy, NominalDataFindNothing) {
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  const DiscrepancyReport r = analyse(field, appendix_d_data(field, ModelExtensions{}, 60, 8));
  ASSERT_TRUE(r.decidable);
  EXPECT_TRUE(r.found.empty()) << candidates(r);
  EXPECT_EQ(r.nuisance_static_friction_ratio, 1.0);
  EXPECT_NEAR(r.baseline_end_mape, 0.0, 1.0);  // the plant is the model, up to the start fit
  ASSERT_EQ(r.none_frequency.size(), 1u);
  EXPECT_GE(r.none_frequency[0], 0.95);  // and no resample of the windows says otherwise
  EXPECT_TRUE(r.intervals.empty());
  // Model-made data leave only what the acceleration estimator itself leaves (the model restarts
  // from the local quadratic's state, not the true one): systematic but far below what counts.
  EXPECT_FALSE(r.unexplained);
  EXPECT_LT(std::abs(r.median_residual_radial), 0.05);
  for (const ResidualCorrection& c : r.corrections) EXPECT_LT(c.heldout_rms_mps2, 0.05);
}

}  // namespace
}  // namespace airtwin
