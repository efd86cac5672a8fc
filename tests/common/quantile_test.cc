// Quantiles by linear interpolation between order statistics (numpy's default).

#include "common/quantile.h"

#include <gtest/gtest.h>

namespace airtwin {
namespace {

TEST(Quantile, AgreesWithTheDefinitionAndNumpy) {
  // numpy.quantile([1, 2, 3, 4], [0, 0.25, 0.5, 0.9, 1]) = [1, 1.75, 2.5, 3.7, 4].
  const std::vector<double> v = {4, 1, 3, 2};
  EXPECT_DOUBLE_EQ(quantile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.25), 1.75);
  EXPECT_DOUBLE_EQ(quantile(v, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile(v, 0.9), 3.7);
  EXPECT_DOUBLE_EQ(quantile(v, 1.0), 4.0);
  // An odd count's median is the middle value; one value is every quantile.
  EXPECT_DOUBLE_EQ(quantile({5, 1, 3}, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(quantile({7}, 0.9), 7.0);
}

}  // namespace
}  // namespace airtwin
