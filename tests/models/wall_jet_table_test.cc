// The constructed default table: reproducible from its generator, and meeting the physical
// constraints it was built from (docs/field_model.md).

#include "models/wall_jet_table.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"

namespace airtwin {
namespace {

// Peak of a profile by dense search (independent of the closed form used to build it).
double search_peak(const FieldCoefficients& c, double* r_at = nullptr) {
  double best = 0, r_best = 0;
  for (double r = 0; r <= 2.0; r += 1e-4) {
    if (c.speed(r) > best) best = c.speed(r), r_best = r;
  }
  if (r_at) *r_at = r_best;
  return best;
}

TEST(WallJetTable, ShippedDefaultTableIsExactlyTheGeneratorOutput) {
  const std::string shipped =
      read_text_file(std::string(AIRTWIN_SOURCE_DIR) + "/models/data/constructed_field_table.csv");
  EXPECT_EQ(construct_wall_jet_table(WallJetDesign{}).to_csv(), shipped)
      << "regenerate with: airtwin maketable --out models/data/constructed_field_table.csv";
}

TEST(WallJetTable, ObliqueMomentumShareConservesMomentum) {
  // Hasson & Peck's sheet: the shares average to exactly 1 over all directions, for any tilt
  // (the integral of 1 / (1 - a cos b)^2 over a turn is 2 pi / (1 - a^2)^1.5).
  for (double tilt : {0.0, 10.0, 22.5, 45.0, 60.0}) {
    double sum = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) sum += oblique_momentum_share(deg_to_rad(tilt), 2 * kPi * i / n);
    EXPECT_NEAR(sum / n, 1.0, 1e-9) << "tilt " << tilt;
  }
  EXPECT_DOUBLE_EQ(oblique_momentum_share(0.0, 1.234), 1.0);
}

TEST(WallJetTable, ProfileFromShapePeaksWhereAsked) {
  const FieldCoefficients c = profile_from_shape(3.0, 0.15, 0.8);
  double r_peak;
  EXPECT_NEAR(search_peak(c, &r_peak), 3.0, 1e-6);
  EXPECT_NEAR(r_peak, 0.15, 2e-4);
  EXPECT_NEAR(c.b2, -0.8, 1e-15);
  EXPECT_THROW(profile_from_shape(3.0, 0.5, 2.5), InputError);  // k r_p >= 1: no peak
}

TEST(WallJetTable, MeetsThePapersConstraints) {
  const FieldTable t = construct_wall_jet_table(WallJetDesign{});
  // Largest peak over all tilts and directions: the paper's 3.4 m/s.
  double global_peak = 0;
  for (size_t i = 0; i < t.n_tilts(); ++i)
    for (int a = 0; a < 360; a += 5) global_peak = std::max(global_peak, search_peak(t.at(i, a)));
  EXPECT_NEAR(global_peak, 3.4, 1e-3);
  // The normal jet keeps tracers moving (v_air > 8.53 / 4.26 = 2.0 m/s) out to 0.6 m, all round.
  for (int a = 0; a < 360; ++a) {
    EXPECT_NEAR(t.at(0, a).speed(0.6), 2.2, 1e-6);
    EXPECT_GT(t.at(0, a).speed(0.58), 8.53 / 4.26);
  }
  // Tilted jets: stronger downstream (alpha 0) than upstream (alpha 180) at every radius.
  for (size_t i = 1; i < t.n_tilts(); ++i)
    for (double r = 0.05; r < 1.5; r += 0.05) EXPECT_GT(t.at(i, 0).speed(r), t.at(i, 180).speed(r));
  // Weaker at larger tilt: the direction-averaged peak falls with tilt.
  double mean_peak[3] = {0, 0, 0};
  for (size_t i = 0; i < 3; ++i) {
    for (int a = 0; a < 360; a += 3) mean_peak[i] += search_peak(t.at(i, a)) / 120.0;
  }
  EXPECT_GT(mean_peak[0], mean_peak[1]);
  EXPECT_GT(mean_peak[1], mean_peak[2]);
  // Speeds are positive away from s everywhere on the 2 x 2 m workspace (b1 > 0, b3 < b2 < 0).
  for (size_t i = 0; i < 3; ++i) {
    for (int a = 0; a < 360; ++a) {
      EXPECT_GT(t.at(i, a).b1, 0);
      EXPECT_LT(t.at(i, a).b3, t.at(i, a).b2);
      EXPECT_LT(t.at(i, a).b2, 0);
    }
  }
}

TEST(WallJetTable, RejectsMeaninglessDesigns) {
  WallJetDesign d;
  d.tilts_deg = {0, 45};
  EXPECT_THROW(construct_wall_jet_table(d), InputError);
  d = WallJetDesign{};
  d.reach_speed_mps = 5.0;  // above the peak
  EXPECT_THROW(construct_wall_jet_table(d), InputError);
  d = WallJetDesign{};
  d.peak_radius_m = -0.1;
  EXPECT_THROW(construct_wall_jet_table(d), InputError);
}

}  // namespace
}  // namespace airtwin
