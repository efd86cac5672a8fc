// Savitzky-Golay smoothing against its defining properties: polynomials up to the degree pass
// unchanged (interior and ends), and white noise's variance at the centre drops by the classical
// factor 3(3m^2 + 3m - 1) / ((2m-1)(2m+1)(2m+3)).

#include "models/savitzky_golay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "common/errors.h"

namespace airtwin {
namespace {

TEST(SavitzkyGolay, CubicsPassUnchangedEverywhere) {
  std::vector<double> x(30);
  for (size_t i = 0; i < x.size(); ++i) {
    const double t = 0.025 * i;
    x[i] = 0.3 - 1.2 * t + 4.0 * t * t - 2.5 * t * t * t;
  }
  const std::vector<double> y = savitzky_golay(x, 4, 3);
  ASSERT_EQ(y.size(), x.size());
  for (size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(y[i], x[i], 1e-12) << i;
}

TEST(SavitzkyGolay, AQuarticIsNotACubic) {
  // The smoother really fits a cubic: a quartic's centre value moves by the known amount
  // (-sum of w_j j^4 over the window is not zero), so the test above cannot pass by identity.
  std::vector<double> x(9);
  for (int i = 0; i < 9; ++i) x[i] = std::pow(i - 4, 4);
  const double centre = savitzky_golay(x, 4, 3)[4];
  EXPECT_GT(std::abs(centre - x[4]), 1.0);
  const std::vector<double> w = savitzky_golay_weights(9, 4, 3);
  double expected = 0;
  for (int j = 0; j < 9; ++j) expected += w[j] * std::pow(j - 4, 4);
  EXPECT_NEAR(centre, expected, 1e-9);
  // The classical 9-point quadratic/cubic weights: (-21, 14, 39, 54, 59, 54, 39, 14, -21) / 231.
  const double classical[9] = {-21, 14, 39, 54, 59, 54, 39, 14, -21};
  for (int j = 0; j < 9; ++j) EXPECT_NEAR(w[j], classical[j] / 231.0, 1e-12);
}

TEST(SavitzkyGolay, WhiteNoiseVarianceDropsByTheClassicalFactor) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> x(200000);
  for (double& xi : x) xi = noise(rng);
  const std::vector<double> y = savitzky_golay(x, 4, 3);
  double sum2 = 0;
  for (size_t i = 4; i + 4 < y.size(); ++i) sum2 += y[i] * y[i];
  const double variance = sum2 / (y.size() - 8);
  const double m = 4,
               factor = 3 * (3 * m * m + 3 * m - 1) / ((2 * m - 1) * (2 * m + 1) * (2 * m + 3));
  EXPECT_NEAR(factor, 59.0 / 231.0, 1e-12);
  EXPECT_NEAR(variance, factor, 0.01);  // standard error of the estimate ~0.0015
}

TEST(SavitzkyGolay, ShortSeriesAndEdgeCases) {
  const std::vector<double> two = {1.0, 3.0};
  const std::vector<double> line = savitzky_golay(two, 4, 3);  // a line through two points
  EXPECT_NEAR(line[0], 1.0, 1e-12);
  EXPECT_NEAR(line[1], 3.0, 1e-12);
  const std::vector<double> x = {1.0, 2.0, 4.0};
  EXPECT_EQ(savitzky_golay(x, 0, 3), x);                  // no window: unchanged
  const std::vector<double> q = savitzky_golay(x, 4, 1);  // straight line through three points
  EXPECT_NEAR(q[0], 5.0 / 6.0, 1e-12);
  EXPECT_NEAR(q[2], 23.0 / 6.0, 1e-12);
  EXPECT_TRUE(savitzky_golay(std::vector<double>{}, 4, 3).empty());
  EXPECT_THROW(savitzky_golay(x, -1, 3), InputError);
  EXPECT_THROW(savitzky_golay(x, 4, -2), InputError);
}

}  // namespace
}  // namespace airtwin
