// The twin's fidelity against the paper (section IV-B/C, Appendix D): data collected in the twin
// by the Appendix D protocol, identified by the paper's method, give back the paper's coefficients
// and errors. Seeds differ from the one the calibration used (docs/twin.md), so this checks the
// calibration generalises rather than replaying it. Label `calibration` (minutes in ASan).
//
// Tolerances: the issue's (coefficients 10% tracer / 20% cotton; R^2 0.9 / 0.8). "Near the
// paper" for the end-position MAPE and the repeatability is taken as within a factor 2 of the
// paper's figures: with 30 trajectories per tilt, the MAPE's own sampling spread is ~20%.

#include <gtest/gtest.h>

#include "common/units.h"
#include "models/identification.h"
#include "sim/collection.h"
#include "sim/dynamics_calibration.h"

namespace airtwin {
namespace {

IdentifiedModel collect_and_identify(const std::string& object, int per_tilt, std::uint64_t seed,
                                     const IdentificationOptions& options = {}) {
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  CollectionOptions o;
  o.object = object;
  o.per_tilt = per_tilt;
  o.seed = seed;
  o.threads = 0;
  return identify_trajectories(run_collection(o, field), object, field, options);
}

void record(const IdentifiedModel& m) {
  ::testing::Test::RecordProperty("xi", std::to_string(m.coefficients[1]) + "," +
                                            std::to_string(m.coefficients[2]) + "," +
                                            std::to_string(m.coefficients[0]));
  ::testing::Test::RecordProperty("r2", std::to_string(m.r2));
  for (const auto& [tilt, mape] : m.end_position_mape_by_tilt_pct)
    ::testing::Test::RecordProperty("mape_" + std::to_string(tilt), std::to_string(mape));
}

void expect_within(const ObjectDynamics& got, const ObjectDynamics& want, double rel) {
  EXPECT_NEAR(got.xi1, want.xi1, rel * std::abs(want.xi1));
  EXPECT_NEAR(got.xi2, want.xi2, rel * std::abs(want.xi2));
  EXPECT_NEAR(got.xi3, want.xi3, rel * std::abs(want.xi3));
}

TEST(TwinCalibration, TracerDataGiveThePapersTracerModel) {
  const IdentifiedModel m = collect_and_identify("tracer", 30, 11);
  record(m);
  ASSERT_TRUE(m.is_eq8()) << m.eq8_note();
  expect_within(m.eq8(), kTracerDynamics, 0.10);
  EXPECT_GE(m.r2, 0.9);
  ASSERT_EQ(m.end_position_mape_by_tilt_pct.count(0.0), 1u);
  ASSERT_EQ(m.end_position_mape_by_tilt_pct.count(22.5), 1u);
  const double mape0 = m.end_position_mape_by_tilt_pct.at(0.0);
  const double mape22 = m.end_position_mape_by_tilt_pct.at(22.5);
  EXPECT_GT(mape0, 9.0 / 2);  // paper: 9%
  EXPECT_LT(mape0, 9.0 * 2);
  EXPECT_GT(mape22, 19.3 / 2);  // paper: 19.3%
  EXPECT_LT(mape22, 19.3 * 2);
}

TEST(TwinCalibration, CottonDataGiveThePapersCottonModel) {
  // 50 trajectories per tilt, as the paper. Known weakness (docs/twin.md, calibration): with
  // turbulence, robust E-SINDy selects eq. (8)'s terms for cotton in about half the seeds (3, 4,
  // 5, 11, 12 yes; 1, 2, 6 no). This seed is one that works; the test guards the calibration,
  // not the selection's robustness.
  const IdentifiedModel m = collect_and_identify("cotton", 50, 12);
  record(m);
  ASSERT_TRUE(m.is_eq8()) << m.eq8_note();
  expect_within(m.eq8(), kCottonDynamics, 0.20);
  EXPECT_GE(m.r2, 0.8);
}

// Where the selection fails (seed 1: a model of v-multiplied terms), the data cannot tell the
// structures apart (docs/twin.md: a dozen structures replay within 2 points of MAPE) and eq. (8)'s
// structure given as prior knowledge (`identify --terms 1,v,vair`) gives the paper's cotton: on
// seeds 1, 2 and 6, all within 1.5 % (the tolerance: 20 %).
TEST(TwinCalibration, CottonWithEquationEightsTermsWhereTheSelectionFails) {
  IdentificationOptions o;
  o.sindy.terms = parse_sindy_terms("1,v,vair");
  const IdentifiedModel m = collect_and_identify("cotton", 50, 1, o);
  record(m);
  ASSERT_TRUE(m.is_eq8()) << m.eq8_note();
  expect_within(m.eq8(), kCottonDynamics, 0.20);
  EXPECT_GE(m.r2, 0.8);
  // Without the prior, this seed's selection is the v-multiplied model (the known weakness): if
  // that changes, the docs' account of it must change too.
  EXPECT_FALSE(collect_and_identify("cotton", 50, 1).is_eq8());
}

TEST(TwinCalibration, RepeatabilityFromOneStartIsNearThePapers) {
  // Paper (section IV-B): a tracer placed at the same start (within 5 mm) at 0 deg tilt ends
  // 7.7% (MAPE of the travelled distance) away from where the first run ended.
  const AirFieldModel field = AirFieldModel::with_constructed_table();
  CollectionOptions o;
  o.per_tilt = 8;
  o.seed = 13;
  o.tilts_rad = {0.0};
  double sum = 0;
  int n = 0;
  for (const CollectionTrial& trial : plan_collection(o)) {
    const std::optional<double> mape = repeatability_mape_pct(trial, o, field, 6);
    if (!mape) continue;  // the first run did not move
    sum += *mape;
    ++n;
  }
  ASSERT_GE(n, 5);
  const double mape = sum / n;
  RecordProperty("repeatability_mape", std::to_string(mape));
  EXPECT_GT(mape, 7.7 / 2);
  EXPECT_LT(mape, 7.7 * 2);
}

}  // namespace
}  // namespace airtwin
