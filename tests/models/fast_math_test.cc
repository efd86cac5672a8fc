// The field kernel's branch-free atan2 and exp against the C library's, over their whole use.

#include "models/fast_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace airtwin {
namespace {

TEST(FastMath, Atan2MatchesLibmEverywhere) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<double> scale(-30, 30);
  double worst = 0;
  for (int i = 0; i < 2'000'000; ++i) {
    const double s = std::exp2(scale(rng));
    const double x = u(rng) * s, y = u(rng) * s;
    worst = std::max(worst, std::abs(fast_atan2(y, x) - std::atan2(y, x)));
  }
  EXPECT_LT(worst, 2e-15);  // a few ulp of pi
}

TEST(FastMath, Atan2Axes) {
  const double pi = 3.141592653589793;
  EXPECT_EQ(fast_atan2(0.0, 0.0), 0.0);
  EXPECT_EQ(fast_atan2(0.0, 1.0), 0.0);
  EXPECT_NEAR(fast_atan2(1.0, 0.0), pi / 2, 1e-16);
  EXPECT_NEAR(fast_atan2(-1.0, 0.0), -pi / 2, 1e-16);
  EXPECT_NEAR(fast_atan2(0.0, -1.0), pi, 1e-15);
  EXPECT_NEAR(fast_atan2(1.0, 1.0), pi / 4, 1e-16);
  EXPECT_NEAR(fast_atan2(-1.0, -1.0), -3 * pi / 4, 1e-15);
  // Both sides of the tan(pi/8) switch of the range reduction.
  const double t8 = std::tan(pi / 8);
  for (double t : {std::nextafter(t8, 0.0), t8, std::nextafter(t8, 1.0)})
    EXPECT_NEAR(fast_atan2(t, 1.0), std::atan(t), 1e-16);
}

TEST(FastMath, ExpRelativeErrorOverTheFieldsRange) {
  // The field evaluates exp(b r) with b r in about [-100, 1]; cover [-700, 700].
  double worst = 0;
  for (int i = 0; i <= 1'400'000; ++i) {
    const double x = -700.0 + i * 1e-3;
    worst = std::max(worst, std::abs(fast_exp(x) / std::exp(x) - 1.0));
  }
  EXPECT_LT(worst, 1e-15);
  EXPECT_EQ(fast_exp(0.0), 1.0);
  EXPECT_GT(fast_exp(-1e6), 0.0);  // clamped, no underflow to garbage
  EXPECT_TRUE(std::isfinite(fast_exp(1e6)));
}

TEST(FastMath, EstrinExpMatchesLibmAndHorner) {
  double worst = 0, worst_vs_horner = 0;
  for (int i = 0; i <= 1'400'000; ++i) {
    const double x = -700.0 + i * 1e-3;
    worst = std::max(worst, std::abs(fast_exp_estrin(x) / std::exp(x) - 1.0));
    worst_vs_horner = std::max(worst_vs_horner, std::abs(fast_exp_estrin(x) / fast_exp(x) - 1.0));
  }
  EXPECT_LT(worst, 1e-15);
  EXPECT_LT(worst_vs_horner, 1e-15);
  EXPECT_EQ(fast_exp_estrin(0.0), 1.0);
  EXPECT_TRUE(std::isfinite(fast_exp_estrin(1e6)));
}

}  // namespace
}  // namespace airtwin
