// Accuracy of the identification against the true coefficients on noisy and spiked speed series,
// beside two second methods (issue 25): robust E-SINDy (the product's default) against ordinary
// least squares on eq. (8)'s three terms (an independent Eigen solve written here) and plain
// STLSQ (the product's `--method stlsq`).
//
// Data: 100 tracers under eq. (8) with the paper's coefficients (dv/dt = -2.66 v + 4.26 vair -
// 8.53), integrated finely along rays (tests/support/synthetic_trajectories.h), as one speed series
// that goes through the product's preprocessing (the rest threshold from the noise estimate, the
// Savitzky-Golay smoothing of each run, as `identify --series` does). Two kinds of 5 % noise on v:
// multiplicative (sigma = 5 % of each sample) and additive (sigma = 5 % of the RMS speed of the
// moving samples, ~1.7 cm/s; signed near rest). Spikes: +-5 sigma added to the regressor v_k of
// 5 % of the regression rows (the target v_{k+1} left as it is), after the preprocessing.
//
// Error measure: the worst relative error of the three coefficients, max_i |xi_i / xi_i,true - 1|,
// against the true ones (not against another fit).
//
// Tolerances: calibrated on seeds 1-30 (DISABLED_CalibrationTable prints them; run it with
// --gtest_also_run_disabled_tests), asserted on seeds 31-33, which the calibration did not see.
// docs/identification.md, "Measured", has the calibration's figures.

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "models/sindy.h"
#include "models/speed_pairs.h"
#include "models/speed_series.h"
#include "tests/support/synthetic_trajectories.h"

namespace airtwin {
namespace {

constexpr double kXi1 = -2.66, kXi2 = 4.26, kXi3 = -8.53;  // v, vair, 1 (tracer, eq. 8)

struct Eq8 {
  double xi1 = 0, xi2 = 0, xi3 = 0;
};

Eq8 eq8_of(const SindyResult& r) { return {r.continuous[1], r.continuous[2], r.continuous[0]}; }

double worst_relative_error(const Eq8& e) {
  return std::max(
      {std::abs(e.xi1 / kXi1 - 1), std::abs(e.xi2 / kXi2 - 1), std::abs(e.xi3 / kXi3 - 1)});
}

// The largest coefficient of a term eq. (8) does not have.
double largest_spurious(const SindyResult& r) {
  return r.continuous.tail(kSindyTerms - 3).cwiseAbs().maxCoeff();
}

// Ordinary least squares of v_{k+1} on (1, v_k, (va_k + va_{k+1}) / 2), then the exact flow of the
// linear ODE dv/dt = xi1 v + xi2 va + xi3 over dt with va held at the step's mean:
// v_{k+1} = e^{xi1 dt} v_k + (e^{xi1 dt} - 1) / xi1 (xi2 va + xi3). Independent of models/sindy.cc.
Eq8 ordinary_least_squares(const SpeedPairs& d) {
  Eigen::MatrixXd X(d.v.size(), 3);
  X.col(0).setOnes();
  X.col(1) = d.v;
  X.col(2) = 0.5 * (d.va + d.va_next);
  const Eigen::Vector3d b = X.colPivHouseholderQr().solve(d.v_next);
  const double xi1 = std::log(b[1]) / d.dt_s;
  const double gain = (b[1] - 1) / xi1;
  return {xi1, b[2] / gain, b[0] / gain};
}

enum class Noise { kMultiplicative, kAdditive };

// The noisy series' regression pairs (the product's preprocessing) and the same pairs with spikes
// of +-5 sigma in the regressor v_k of 5 % of the rows (rows and signs drawn from `seed`). For the
// calibration table also the pairs of the noisy series with such spikes in 5 % of its moving
// samples, before the preprocessing.
struct NoisyPairs {
  SpeedPairs noisy, spiked, series_spiked;
  size_t n_spikes = 0;
};

NoisyPairs make_noisy_pairs(std::uint64_t seed, Noise kind, int smoothing_half_window = 4) {
  const SpeedSeries clean =
      parse_speed_series_csv(testing::make_speed_series_csv(AirFieldModel::with_constructed_table(),
                                                            kXi1, kXi2, kXi3, 100, seed, 0.0),
                             "clean.csv");
  double sum_squares = 0;
  size_t moving = 0;
  for (double v : clean.v_mps) {
    if (v > 0) sum_squares += v * v, ++moving;
  }
  const double rms_mps = std::sqrt(sum_squares / static_cast<double>(moving));
  // Noise on every sample of the series.
  std::mt19937_64 rng(1000 + seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  SpeedSeries series = clean;
  for (double& v : series.v_mps) {
    v += (kind == Noise::kMultiplicative ? 0.05 * v : 0.05 * rms_mps) * gauss(rng);
  }
  SpeedPairOptions options;
  options.smoothing_half_window = smoothing_half_window;
  NoisyPairs out;
  out.noisy = speed_pairs_from_series(series, options, nullptr);
  // Spikes: 5 % of the rows, each +-5 sigma of the noise at that sample.
  out.spiked = out.noisy;
  std::vector<Eigen::Index> rows(static_cast<size_t>(out.noisy.v.size()));
  std::iota(rows.begin(), rows.end(), Eigen::Index{0});
  std::shuffle(rows.begin(), rows.end(), rng);
  out.n_spikes = rows.size() / 20;
  std::bernoulli_distribution positive(0.5);
  for (size_t i = 0; i < out.n_spikes; ++i) {
    double& v = out.spiked.v[rows[i]];
    const double sigma = kind == Noise::kMultiplicative ? 0.05 * v : 0.05 * rms_mps;
    v += (positive(rng) ? 5 : -5) * sigma;
  }
  SpeedSeries spiked_series = series;
  for (size_t k = 0; k < series.size(); ++k) {
    if (clean.v_mps[k] > 0 && rng() % 20 == 0) {
      const double sigma = kind == Noise::kMultiplicative ? 0.05 * clean.v_mps[k] : 0.05 * rms_mps;
      spiked_series.v_mps[k] += (positive(rng) ? 5 : -5) * sigma;
    }
  }
  out.series_spiked = speed_pairs_from_series(spiked_series, options, nullptr);
  return out;
}

SindyResult fit(const SpeedPairs& d, SindyMethod method) {
  SindyOptions o;
  o.method = method;
  return identify_sindy(d, o);
}

const char* noise_name(Noise kind) {
  return kind == Noise::kMultiplicative ? "multiplicative" : "additive";
}

// The baseline first: on noise-free data the independent OLS recovers the truth (so what it gets
// wrong later is the data's doing), and on spiked data it is the same solve as the product's
// STLSQ restricted to eq. (8)'s terms with lambda 0 (which converts to continuous time its own
// way, by a Levenberg-Marquardt fit of the one-step flow).
TEST(SindyRobustness, IndependentLeastSquaresIsACorrectBaseline) {
  const SpeedSeries clean =
      parse_speed_series_csv(testing::make_speed_series_csv(AirFieldModel::with_constructed_table(),
                                                            kXi1, kXi2, kXi3, 100, 31, 0.0),
                             "clean.csv");
  const SpeedPairs d = speed_pairs_from_series(clean, SpeedPairOptions{}, nullptr);
  EXPECT_LT(worst_relative_error(ordinary_least_squares(d)), 0.002);

  const NoisyPairs n = make_noisy_pairs(31, Noise::kAdditive);
  SindyOptions o;
  o.method = SindyMethod::kStlsq;
  o.terms = parse_sindy_terms("1,v,vair");
  o.lambda = 0.0;
  const Eq8 product = eq8_of(identify_sindy(n.spiked, o));
  const Eq8 independent = ordinary_least_squares(n.spiked);
  EXPECT_NEAR(independent.xi1, product.xi1, 0.005 * std::abs(product.xi1));
  EXPECT_NEAR(independent.xi2, product.xi2, 0.005 * std::abs(product.xi2));
  EXPECT_NEAR(independent.xi3, product.xi3, 0.005 * std::abs(product.xi3));
}

// 5 % noise: robust E-SINDy within 4 % of every true coefficient, exactly eq. (8)'s terms.
// Calibration (seeds 1-30): worst 2.7 % (multiplicative), 2.0 % (additive).
TEST(SindyRobustness, FivePercentNoiseRobustEsindyWithinFourPercent) {
  for (Noise kind : {Noise::kMultiplicative, Noise::kAdditive}) {
    for (std::uint64_t seed : {31, 32, 33}) {
      SCOPED_TRACE(std::string(noise_name(kind)) + " seed " + std::to_string(seed));
      const NoisyPairs n = make_noisy_pairs(seed, kind);
      ASSERT_GT(n.noisy.size(), 3000u);
      const SindyResult r = fit(n.noisy, SindyMethod::kRobustEsindy);
      const double error = worst_relative_error(eq8_of(r));
      std::printf("5 %% %s noise, seed %d: robust E-SINDy %.4f\n", noise_name(kind),
                  static_cast<int>(seed), error);
      EXPECT_LE(error, 0.04);
      EXPECT_EQ(largest_spurious(r), 0.0);
    }
  }
}

// Spikes of +-5 sigma in 5 % of the regressor rows: robust E-SINDy within 10 %, exactly eq. (8)'s
// terms; OLS on the three terms and plain STLSQ on the library clearly worse: more than 6 % off
// and more than three times robust E-SINDy's error. Calibration (seeds 1-30, multiplicative /
// additive): robust E-SINDy at most 3.0 % / 2.2 %; OLS 9.6-27 % / 13-23 %, at least 5.7 / 8.7
// times robust E-SINDy's error; plain STLSQ 11 % - 27 (median 3.0) / 18 % - 19 (median 2.1),
// keeping spurious terms up to 50 / 47, at least 8.4 / 12 times robust E-SINDy's error.
TEST(SindyRobustness, SpikesInFivePercentOfTheRegressorsRobustEsindyWithinTenPercent) {
  for (Noise kind : {Noise::kMultiplicative, Noise::kAdditive}) {
    for (std::uint64_t seed : {31, 32, 33}) {
      SCOPED_TRACE(std::string(noise_name(kind)) + " seed " + std::to_string(seed));
      const NoisyPairs n = make_noisy_pairs(seed, kind);
      ASSERT_EQ(n.n_spikes, n.spiked.size() / 20);
      const SindyResult robust = fit(n.spiked, SindyMethod::kRobustEsindy);
      const double robust_error = worst_relative_error(eq8_of(robust));
      const double ols_error = worst_relative_error(ordinary_least_squares(n.spiked));
      const SindyResult stlsq = fit(n.spiked, SindyMethod::kStlsq);
      const double stlsq_error = worst_relative_error(eq8_of(stlsq));
      std::printf(
          "5 %% %s noise + spikes, seed %d: robust E-SINDy %.4f, OLS %.4f, STLSQ %.4f (largest "
          "spurious term %.2f)\n",
          noise_name(kind), static_cast<int>(seed), robust_error, ols_error, stlsq_error,
          largest_spurious(stlsq));
      EXPECT_LE(robust_error, 0.10);
      EXPECT_EQ(largest_spurious(robust), 0.0);
      EXPECT_GT(ols_error, 0.06);
      EXPECT_GT(ols_error, 3 * robust_error);
      EXPECT_GT(stlsq_error, 0.06);
      EXPECT_GT(stlsq_error, 3 * robust_error);
    }
  }
}

// The figures of docs/identification.md ("Measured") and of the tolerances above: seeds 1-30.
// Also without the smoothing (errors in variables) and with the spikes put into the series
// before the preprocessing, where the smoothing spreads each over nine samples.
TEST(SindyRobustness, DISABLED_CalibrationTable) {
  std::printf("seed,noise,case,robust_esindy,robust_spurious,ols,stlsq,stlsq_spurious\n");
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    for (Noise kind : {Noise::kMultiplicative, Noise::kAdditive}) {
      const NoisyPairs n = make_noisy_pairs(seed, kind);
      const NoisyPairs raw = make_noisy_pairs(seed, kind, 0);
      for (const auto& [name, d] : {std::pair{"noise", &n.noisy}, std::pair{"spikes", &n.spiked},
                                    std::pair{"noise_unsmoothed", &raw.noisy},
                                    std::pair{"series_spikes", &n.series_spiked}}) {
        const SindyResult robust = fit(*d, SindyMethod::kRobustEsindy);
        const SindyResult stlsq = fit(*d, SindyMethod::kStlsq);
        std::printf("%d,%s,%s,%.4f,%.2f,%.4f,%.4f,%.2f\n", static_cast<int>(seed), noise_name(kind),
                    name, worst_relative_error(eq8_of(robust)), largest_spurious(robust),
                    worst_relative_error(ordinary_least_squares(*d)),
                    worst_relative_error(eq8_of(stlsq)), largest_spurious(stlsq));
      }
    }
  }
}

}  // namespace
}  // namespace airtwin
