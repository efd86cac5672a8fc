// The discrepancy analysis's statistics against values computed independently (the normal
// approximation of the signed-rank statistic with continuity and tie corrections, as SciPy's
// wilcoxon(alternative="greater", correction=True, method="approx") gives 0.0295 for 1..5).

#include "models/discrepancy_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

namespace airtwin::discrepancy_detail {
namespace {

TEST(Wilcoxon, OneSidedPValues) {
  EXPECT_NEAR(wilcoxon_greater({1, 2, 3, 4, 5}), 0.02952911454526837, 1e-12);
  // Ties (0.5 three times, -0.2 twice) and a zero, dropped.
  EXPECT_NEAR(wilcoxon_greater({0.5, -0.2, 0.5, 1.5, -0.7, 2.0, 0.5, 0.0, 3.1, -0.2}),
              0.06094287200823181, 1e-12);
  EXPECT_NEAR(wilcoxon_greater({-1, -2, -3}), 0.9693155854302989, 1e-12);
  // Nothing left to test.
  EXPECT_EQ(wilcoxon_greater({}), 1.0);
  EXPECT_EQ(wilcoxon_greater({0.0, 0.0, NAN}), 1.0);
}

// The exact one-sided p of the sign-flip test: the fraction of all 2^n sign assignments whose sum
// reaches the observed one.
double exact_sign_flip(const std::vector<double>& d) {
  const double observed = std::accumulate(d.begin(), d.end(), 0.0);
  int reach = 0;
  const int n = static_cast<int>(d.size());
  for (int mask = 0; mask < (1 << n); ++mask) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += (mask >> i & 1) ? -d[i] : d[i];
    if (sum >= observed - 1e-12) ++reach;
  }
  return static_cast<double>(reach) / (1 << n);
}

TEST(SignFlip, AgreesWithTheExactEnumeration) {
  const std::vector<std::vector<double>> cases = {
      {1, 2, 3, 4, 5},  // all positive: only itself reaches it, 1/32
      {0.5, -0.2, 0.5, 1.5, -0.7, 2.0, 0.5, 0.0, 3.1, -0.2},
      {-1, -2, -3},  // the sum is the least: every assignment reaches it
      // Four windows carry a large gain, twelve lose a little (exact p 0.062; the signed-rank
      // test's p is 0.55: the ranks of the many small losses outweigh the four).
      {4.0, 5.0, 6.0, 5.5, -0.3, -0.25, -0.2, -0.35, 0.1, -0.15, 0.05, -0.3, -0.2, -0.1, 0.15,
       -0.25}};
  for (const std::vector<double>& d : cases) {
    const double exact = exact_sign_flip(d);
    const int resamples = 19999;
    const double p = sign_flip_greater(d, resamples, 7);
    // The Monte Carlo estimate's binomial standard deviation, and the observed assignment counted
    // once among resamples + 1.
    const double sd = std::sqrt(exact * (1.0 - exact) / resamples);
    EXPECT_NEAR(p, exact, 4.0 * sd + 1.0 / (resamples + 1)) << "exact " << exact;
  }
  // Seeded: the same seed, the same p.
  EXPECT_EQ(sign_flip_greater(cases[1], 999, 3), sign_flip_greater(cases[1], 999, 3));
  EXPECT_EQ(sign_flip_greater({}, 999, 3), 1.0);
  // Where a few windows carry the effect, the sum sees what the ranks hide.
  EXPECT_NEAR(exact_sign_flip(cases[3]), 0.062164306640625, 1e-12);  // 4074 of 65536
  EXPECT_GT(wilcoxon_greater(cases[3]), 0.5);
}

TEST(Bic, IsTheGaussianCriterion) {
  // n log(SSE / n) + k log(n).
  EXPECT_NEAR(bic(2.0, 10, 3), 10 * std::log(0.2) + 3 * std::log(10.0), 1e-12);
  // More parameters cost log(n) each; a perfect fit stays finite.
  EXPECT_NEAR(bic(2.0, 10, 4) - bic(2.0, 10, 3), std::log(10.0), 1e-12);
  EXPECT_TRUE(std::isfinite(bic(0.0, 10, 1)));
}

}  // namespace
}  // namespace airtwin::discrepancy_detail
