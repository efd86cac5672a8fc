// The speed-series CSV of `airtwin identify --series`: what it accepts and how it refuses.

#include "models/speed_series.h"

#include <gtest/gtest.h>

#include "common/errors.h"

namespace airtwin {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_speed_series_csv(text, "s.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SpeedSeries, ReadsAUniformSeriesInAnyColumnOrder) {
  const SpeedSeries s = parse_speed_series_csv(
      "vair,t,v\n# comment\n2.5,0.000,0.0\n2.4,0.025,0.1\n2.3,0.050,0.2\n", "s.csv");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s.dt_s, 0.025, 1e-15);
  EXPECT_EQ(s.v_mps[2], 0.2);
  EXPECT_EQ(s.vair_mps[0], 2.5);
}

TEST(SpeedSeries, NegativeMeasuredSpeedsAreCountedNotRefused) {
  const SpeedSeries s =
      parse_speed_series_csv("t,v,vair\n0,0.01,2\n0.025,-0.02,2\n0.05,-0.01,-0.1\n", "s.csv");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s.v_mps[1], -0.02);
  EXPECT_EQ(s.n_negative_v, 2u);
  EXPECT_EQ(s.n_negative_vair, 1u);
}

TEST(SpeedSeries, BadFilesGetOneClearError) {
  EXPECT_NE(error_of("t,v\n0,1\n1,1\n2,1\n").find("vair"), std::string::npos);
  EXPECT_NE(error_of("t,v,vair\n0,1,1\n0.025,nan,1\n0.05,1,1\n").find("s.csv:3: column 'v'"),
            std::string::npos);
  EXPECT_NE(error_of("t,v,vair\n0,1,1\n0.025,1,1\n0.025,1,1\n").find("time must increase"),
            std::string::npos);
  EXPECT_NE(error_of("t,v,vair\n0,1,1\n0.025,1,1\n0.05,1,1\n0.1,1,1\n0.125,1,1\n")
                .find("s.csv:5: column 't': the series must be uniformly sampled"),
            std::string::npos);
  EXPECT_NE(error_of("t,v,vair\n0,1,1\n0.025,1,1\n").find("at least 3 rows"), std::string::npos);
  EXPECT_NE(error_of("t,v,vair,extra\n0,1,1,1\n").find("extra"), std::string::npos);
  EXPECT_THROW(read_speed_series_csv("/nonexistent/series.csv"), InputError);
}

}  // namespace
}  // namespace airtwin
