// MATLAB's makima: reference values from shared physics notes (computed with MATLAB's definition).

#include "models/makima.h"

#include <gtest/gtest.h>

#include <cmath>

namespace airtwin {
namespace {

TEST(Makima, MatchesMatlabReferenceValues) {
  const std::vector<double> x = {0, 22.5, 45};
  const Makima rising(x, {1, 2, 4});
  EXPECT_NEAR(rising(11.25), 1.3844, 5e-5);
  EXPECT_NEAR(rising(33.75), 2.8679, 5e-5);
  const Makima bump(x, {0, 1, 0});
  EXPECT_NEAR(bump(11.25), 0.6875, 5e-5);
}

TEST(Makima, InterpolatesNodesAndIsCloseToButNotTheParabola) {
  const std::vector<double> x = {0, 22.5, 45};
  const Makima m(x, {1, 2, 4});
  EXPECT_DOUBLE_EQ(m(0), 1);
  EXPECT_DOUBLE_EQ(m(22.5), 2);
  EXPECT_DOUBLE_EQ(m(45), 4);
  // The interpolating parabola through the nodes: 1 + x/45 + x^2/1012.5 at 11.25 is 1.375.
  EXPECT_GT(std::abs(m(11.25) - 1.375), 1e-3);
  EXPECT_LT(std::abs(m(11.25) - 1.375), 0.05);
}

TEST(Makima, ReproducesStraightLinesExactly) {
  // Any makima variant must reproduce linear data (all slopes equal).
  const std::vector<double> x = {0, 1, 3, 4, 7};
  std::vector<double> y;
  for (double xi : x) y.push_back(2.5 * xi - 1);
  const Makima m(x, y);
  for (double q = 0; q <= 7; q += 0.37) EXPECT_NEAR(m(q), 2.5 * q - 1, 1e-12);
}

TEST(Makima, ClampsOutsideTheNodes) {
  const Makima m({0, 22.5, 45}, {1, 2, 4});
  EXPECT_DOUBLE_EQ(m(-10), 1);
  EXPECT_DOUBLE_EQ(m(90), 4);
}

TEST(Makima, TwoNodesIsLinear) {
  const Makima m({0, 10}, {3, 5});
  EXPECT_NEAR(m(2.5), 3.5, 1e-12);
}

TEST(Makima, FlatStretchesStayFlatNoOvershoot) {
  // Akima's point: no overshoot next to a flat stretch; makima's added |delta sum| terms keep
  // the flat region exactly flat. (Only interior intervals: at the ends the quadratic
  // extrapolation of the slopes may legitimately bend the last interval.)
  const Makima m({0, 1, 2, 3, 4, 5, 6}, {0, 0, 0, 1, 1, 1, 1});
  for (double q = 0; q <= 2; q += 0.1) EXPECT_NEAR(m(q), 0.0, 1e-15);
  for (double q = 3; q <= 5; q += 0.1) EXPECT_NEAR(m(q), 1.0, 1e-15);
  for (double q = 2; q <= 3; q += 0.05) {
    EXPECT_GE(m(q), -1e-12);
    EXPECT_LE(m(q), 1 + 1e-12);
  }
}

TEST(Makima, ContinuousFirstDerivativeAtNodes) {
  const Makima m({0, 1, 2.5, 3, 5}, {0.3, -1, 2, 2.2, 0});
  for (double node : {1.0, 2.5, 3.0}) {
    const double h = 1e-6;
    const double left = (m(node) - m(node - h)) / h;
    const double right = (m(node + h) - m(node)) / h;
    EXPECT_NEAR(left, right, 1e-4) << "at node " << node;
  }
}

}  // namespace
}  // namespace airtwin
