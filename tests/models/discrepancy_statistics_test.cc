// The discrepancy analysis's statistics against values computed independently (the normal
// approximation of the signed-rank statistic with continuity and tie corrections, as SciPy's
// wilcoxon(alternative="greater", correction=True, method="approx") gives 0.0295 for 1..5).

#include "models/discrepancy_statistics.h"

#include <gtest/gtest.h>

#include <cmath>

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

TEST(Bic, IsTheGaussianCriterion) {
  // n log(SSE / n) + k log(n).
  EXPECT_NEAR(bic(2.0, 10, 3), 10 * std::log(0.2) + 3 * std::log(10.0), 1e-12);
  // More parameters cost log(n) each; a perfect fit stays finite.
  EXPECT_NEAR(bic(2.0, 10, 4) - bic(2.0, 10, 3), std::log(10.0), 1e-12);
  EXPECT_TRUE(std::isfinite(bic(0.0, 10, 1)));
}

}  // namespace
}  // namespace airtwin::discrepancy_detail
