// trim_blanks and format_number against hand-written expectations.

#include "common/text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace airtwin {
namespace {

TEST(Text, TrimBlanksTakesSpacesTabsAndCarriageReturnsOffBothEnds) {
  EXPECT_EQ(trim_blanks("  a b\t\r"), "a b");
  EXPECT_EQ(trim_blanks("\t x=1 "), "x=1");
  EXPECT_EQ(trim_blanks(" \t\r "), "");
  EXPECT_EQ(trim_blanks(""), "");
  EXPECT_EQ(trim_blanks("a\nb"), "a\nb");  // inner characters stay
}

TEST(Text, FormatNumberKeepsNineDigitsAndReadsBack) {
  EXPECT_EQ(format_number(0.16), "0.16");
  EXPECT_EQ(format_number(-2.5e-7), "-2.5e-07");
  EXPECT_EQ(format_number(11.780972450961727), "11.7809725");
  for (double x : {3.14159265358979, 1e-12, 123456789.0, -0.001}) {
    EXPECT_NEAR(std::strtod(format_number(x).c_str(), nullptr), x, 5e-9 * std::abs(x));
  }
}

}  // namespace
}  // namespace airtwin
