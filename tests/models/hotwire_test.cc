// The simulated hot-wire campaign (Appendix A): the static law against its defining properties,
// the one-minute mean in turbulence against the analytic mean speed of a Gaussian velocity (the
// 3-D Rice / noncentral chi mean) within the sampling error of the simulated minute, and the
// campaign on the shipped CFD: bit-identical reruns, independence of thread count and of the other
// tilts, another seed other values, the vertical air near s, bad input.

#include "models/hotwire.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/cfd_field.h"
#include "models/field_grid.h"

namespace airtwin {
namespace {

// E|X| for X ~ N(mu, sigma^2 I_3), |mu| = m > 0: the mean of a noncentral chi with 3 degrees of
// freedom, sigma sqrt(2/pi) exp(-m^2 / 2 sigma^2) + (m + sigma^2 / m) erf(m / (sigma sqrt 2)).
double rice3_mean(double m, double sigma) {
  return sigma * std::sqrt(2.0 / kPi) * std::exp(-m * m / (2 * sigma * sigma)) +
         (m + sigma * sigma / m) * std::erf(m / (sigma * std::sqrt(2.0)));
}

// The air of a point: mean velocity u, turbulence of standard deviation sigma per component, and
// epsilon such that the Lagrangian time (the Eulerian one at zero mean speed) is t_lagrangian.
HotWireAir turbulent_air(const Eigen::Vector3d& u, double sigma, double t_lagrangian) {
  HotWireAir air;
  air.u_W = u;
  air.k = 1.5 * sigma * sigma;
  air.epsilon = 4.0 * air.k / (3.0 * 2.1 * t_lagrangian);
  return air;
}

// The mean of `runs` one-minute readings (each on its own stream) against the Rice mean, within
// 4 standard errors of the simulated minutes: a run averages N samples of a process whose
// correlation between samples dt apart is at most rho = exp(-dt / T_E) (the speed of an
// Ornstein-Uhlenbeck vector decorrelates no slower than its components), so its variance is at
// most Var|X| / N (1 + rho) / (1 - rho).
void expect_rice_mean(const Eigen::Vector3d& u, double sigma, const HotWireSpec& spec,
                      uint64_t seed) {
  const HotWireAir air = turbulent_air(u, sigma, 0.05);
  const double m = u.norm(), mean = rice3_mean(m, sigma);
  const double variance = m * m + 3 * sigma * sigma - mean * mean;
  const double t_e = eulerian_integral_time_s(m, air.k, air.epsilon);
  const double dt = 1.0 / spec.sample_rate_hz;
  const double n = spec.averaging_time_s * spec.sample_rate_hz;
  const double rho = std::exp(-dt / t_e);
  const int runs = 12;
  const double se = std::sqrt(variance / n * (1 + rho) / (1 - rho) / runs);
  double sum = 0.0;
  for (int r = 0; r < runs; ++r) {
    RandomStream rng(seed, RandomPurpose::kMeasurement, r);
    sum += simulate_hotwire_mean_mps(air, spec, rng);
  }
  const double simulated = sum / runs;
  EXPECT_NEAR(simulated, mean, 4 * se) << "|U| " << m << " sigma " << sigma;
  // The test can tell: the turbulence lifts the mean reading above |U| by many standard errors.
  EXPECT_GT(mean - m, 8 * se) << "|U| " << m << " sigma " << sigma;
}

TEST(HotWireStaticLaw, ExactInTheCalibratedRangeAFreeConvectionFloorBelow) {
  const HotWireSpec spec;  // U0 = 0.1 m/s
  for (double v : {0.2, 0.35, 1.0, 3.4, 20.0}) EXPECT_EQ(hotwire_static_reading_mps(v, spec), v);
  // Still air reads U0; below 2 U0 it overreads, by less as the speed grows.
  EXPECT_EQ(hotwire_static_reading_mps(0.0, spec), 0.1);
  double previous_excess = INFINITY;
  for (double v : {0.0, 0.05, 0.1, 0.15, 0.19}) {
    const double excess = hotwire_static_reading_mps(v, spec) - v;
    EXPECT_GT(excess, 0.0) << v;
    EXPECT_LT(excess, previous_excess) << v;
    previous_excess = excess;
  }
  // Continuous with a continuous slope where the floor meets the identity (2 U0).
  const double h = 1e-6;
  EXPECT_NEAR(hotwire_static_reading_mps(0.2 - h, spec), 0.2 - h, 1e-11);
  EXPECT_NEAR(
      (hotwire_static_reading_mps(0.2, spec) - hotwire_static_reading_mps(0.2 - h, spec)) / h, 1.0,
      1e-5);
  // U0 = 0: the identity everywhere.
  HotWireSpec ideal;
  ideal.detection_limit_mps = 0.0;
  EXPECT_EQ(hotwire_static_reading_mps(0.0, ideal), 0.0);
  EXPECT_EQ(hotwire_static_reading_mps(0.013, ideal), 0.013);
}

TEST(HotWireMean, WithoutTurbulenceReadsTheThreeDimensionalSpeedExactly) {
  const HotWireSpec spec;
  RandomStream rng(7, RandomPurpose::kMeasurement, 1);
  HotWireAir air;
  air.u_W = {1.2, -0.5, -0.9};  // |U| = 1.5833, well above the limit; vertical part included
  EXPECT_DOUBLE_EQ(simulate_hotwire_mean_mps(air, spec, rng), air.u_W.norm());
  // Turbulence far too weak to matter: every step, the response and the average run.
  air.k = 1e-30;
  air.epsilon = 1e-3;
  EXPECT_NEAR(simulate_hotwire_mean_mps(air, spec, rng), air.u_W.norm(), 1e-12);
}

TEST(HotWireMean, InTurbulenceMatchesTheMeanSpeedOfAGaussianVelocity) {
  HotWireSpec ideal;
  ideal.detection_limit_mps = 0.0;
  // Strong turbulence on weak mean air (as near s) and moderate turbulence on a wall jet.
  expect_rice_mean({0.2, 0.0, -0.25}, 0.5, ideal, 11);
  expect_rice_mean({1.5, 0.4, 0.0}, 0.6, ideal, 12);
  // The free-convection floor changes nothing where |U + u'| never comes near 2 U0.
  expect_rice_mean({2.0, -1.0, 0.3}, 0.3, HotWireSpec{}, 13);
}

TEST(HotWireMean, EulerianIntegralTimeLimits) {
  const double k = 0.3, epsilon = 2.0;
  EXPECT_DOUBLE_EQ(eulerian_integral_time_s(0.0, k, epsilon), 4 * k / (3 * 2.1 * epsilon));
  const double sweep = 0.43 * std::pow(k, 1.5) / epsilon / 1e4;
  EXPECT_NEAR(eulerian_integral_time_s(1e4, k, epsilon) / sweep, 1.0, 1e-4);
}

TEST(HotWireMean, BadInputIsOneClearError) {
  RandomStream rng(1, RandomPurpose::kMeasurement, 1);
  HotWireAir air;
  air.u_W = {1, 0, 0};
  air.k = -0.1;
  try {
    simulate_hotwire_mean_mps(air, HotWireSpec{}, rng);
    FAIL() << "negative k accepted";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "hotwire.k");
    EXPECT_NE(std::string(e.what()).find("got -0.1"), std::string::npos) << e.what();
  }
  HotWireSpec spec;
  spec.sample_rate_hz = 0.0;
  try {
    spec.validate();
    FAIL() << "sample rate 0 accepted";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "hotwire.sample_rate_hz");
    EXPECT_NE(std::string(e.what()).find("got 0"), std::string::npos) << e.what();
  }
  air.k = 0.1;
  air.u_W = {NAN, 0, 0};
  EXPECT_THROW(simulate_hotwire_mean_mps(air, HotWireSpec{}, rng), FieldError);
}

// A small campaign on the shipped CFD (mesh 1, 20 mm inlet, tilts 0-60 deg).
class HotWireCampaignTest : public ::testing::Test {
 protected:
  static const CfdField& cfd() {
    static const CfdField field = CfdField::read_dir(std::string(AIRTWIN_SOURCE_DIR) + "/data/cfd");
    return field;
  }
  static HotWireCampaign campaign(uint64_t seed) {
    HotWireCampaign c;
    c.tilts_rad = {0.0, deg_to_rad(22.5)};
    c.points_W = HotWireCampaign::square_grid(1.0, 3);
    c.seed = seed;
    return c;
  }
  static HotWireSpec quick_spec() {
    HotWireSpec s;
    s.averaging_time_s = 10.0;
    return s;
  }
};

TEST_F(HotWireCampaignTest, SameSeedSameBytesAnyThreadsOtherSeedOtherValues) {
  const HotWireResult a = simulate_hotwire_campaign(cfd(), campaign(5), quick_spec(), "a.csv");
  const HotWireResult b = simulate_hotwire_campaign(cfd(), campaign(5), quick_spec(), "a.csv");
  ASSERT_EQ(a.grid.samples.size(), 18u);
  EXPECT_EQ(field_grid_to_csv(a.grid), field_grid_to_csv(b.grid));
  HotWireCampaign two_threads = campaign(5);
  two_threads.threads = 2;
  EXPECT_EQ(
      field_grid_to_csv(simulate_hotwire_campaign(cfd(), two_threads, quick_spec(), "a.csv").grid),
      field_grid_to_csv(a.grid));
  // One tilt alone reads what it read beside the other.
  HotWireCampaign alone = campaign(5);
  alone.tilts_rad = {deg_to_rad(22.5)};
  const HotWireResult c = simulate_hotwire_campaign(cfd(), alone, quick_spec(), "a.csv");
  for (size_t i = 0; i < 9; ++i)
    EXPECT_EQ(c.grid.samples[i].speed_mps, a.grid.samples[9 + i].speed_mps);
  // Another seed: another gain and other turbulence at every point.
  const HotWireResult d = simulate_hotwire_campaign(cfd(), campaign(6), quick_spec(), "a.csv");
  EXPECT_NE(d.gain, a.gain);
  for (size_t i = 0; i < a.grid.samples.size(); ++i) {
    EXPECT_NE(d.grid.samples[i].speed_mps, a.grid.samples[i].speed_mps) << i;
    EXPECT_EQ(d.grid.samples[i].p_W, a.grid.samples[i].p_W);
  }
}

TEST_F(HotWireCampaignTest, ReadsTheVerticalAirAtTheStagnationPointAndTheFloorFarAway) {
  HotWireSpec exact = quick_spec();
  exact.accuracy_fraction = 0.0;
  const HotWireResult r = simulate_hotwire_campaign(cfd(), campaign(3), exact, "a.csv");
  EXPECT_EQ(r.gain, 1.0);
  // Tilt 0, the centre point is s: almost no horizontal air, the jet coming down.
  const size_t centre = 4;
  EXPECT_LT(r.cfd_horizontal_speed_mps[centre], 0.2);
  EXPECT_GT(r.cfd_speed_3d_mps[centre], 3 * r.cfd_horizontal_speed_mps[centre]);
  EXPECT_GT(r.grid.samples[centre].speed_mps, 3 * r.cfd_horizontal_speed_mps[centre]);
  // Every reading at least the still-air floor and at least about the mean 3-D speed.
  for (size_t i = 0; i < r.grid.samples.size(); ++i) {
    EXPECT_GE(r.grid.samples[i].speed_mps, exact.detection_limit_mps) << i;
    EXPECT_GT(r.grid.samples[i].speed_mps, 0.97 * r.cfd_speed_3d_mps[i]) << i;
  }
}

TEST_F(HotWireCampaignTest, BadCampaignIsOneClearError) {
  HotWireCampaign c = campaign(1);
  c.tilts_rad = {deg_to_rad(75.0)};  // beyond the CFD's 60 deg
  try {
    simulate_hotwire_campaign(cfd(), c, quick_spec(), "a.csv");
    FAIL() << "tilt beyond the CFD accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("75"), std::string::npos) << e.what();
  }
  c = campaign(1);
  c.tilts_rad = {0.0, 0.0};
  try {
    simulate_hotwire_campaign(cfd(), c, quick_spec(), "a.csv");
    FAIL() << "duplicated tilt accepted";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "hotwire.tilts");
  }
  c = campaign(1);
  c.height_m = 0.0;
  EXPECT_THROW(simulate_hotwire_campaign(cfd(), c, quick_spec(), "a.csv"), FieldError);
  EXPECT_THROW(HotWireCampaign::square_grid(2.0, 1), FieldError);
}

}  // namespace
}  // namespace airtwin
