// The jet's start-up timings: the lag's interpolation against its definition on a small inline
// table; on the shipped start-up, the reader's transit and arrivals against the probes' own time
// series (data/cfd/startup_tilt00_d40_floor.csv and _axis.csv, every 0.05 s) timed here a second
// way; bad files.

#include "models/cfd_startup.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/errors.h"
#include "tests/support/scratch_dir.h"

namespace airtwin {
namespace {

TEST(CfdStartup, LagIsArrivalLessTransitLinearBetweenSamples) {
  const CfdStartup s(0.25, {0.1, 0.3, 0.5}, {0.30, 0.45, 0.75});
  EXPECT_DOUBLE_EQ(s.wall_jet_lag_s(0.1), 0.05);
  EXPECT_DOUBLE_EQ(s.wall_jet_lag_s(0.3), 0.20);
  EXPECT_NEAR(s.wall_jet_lag_s(0.2), 0.125, 1e-12);   // between samples
  EXPECT_NEAR(s.wall_jet_lag_s(0.05), 0.025, 1e-12);  // from 0 at s to the first
  EXPECT_NEAR(s.wall_jet_lag_s(0.7), 0.80, 1e-12);    // past the last: the last interval's speed
  EXPECT_EQ(s.wall_jet_lag_s(0.0), 0.0);
  EXPECT_EQ(s.wall_jet_lag_s(-1.0), 0.0);
}

// The first time a series reaches `level`, linear between samples (a second implementation of
// the converter's timing).
double first_reach(const std::vector<std::pair<double, double>>& series, double level) {
  for (size_t i = 1; i < series.size(); ++i) {
    if (series[i].second >= level) {
      const auto& [t0, y0] = series[i - 1];
      const auto& [t1, y1] = series[i];
      return t0 + (level - y0) / (y1 - y0) * (t1 - t0);
    }
  }
  return NAN;
}

// Columns t, a key column and a value column of the start-up's CSVs: key -> time series.
std::map<double, std::vector<std::pair<double, double>>> read_series(const std::string& path,
                                                                     int key_col, int value_col,
                                                                     int filter_col,
                                                                     double filter_value) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::string line;
  std::getline(in, line);
  std::map<double, std::vector<std::pair<double, double>>> out;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    if (filter_col >= 0 && std::abs(v[filter_col] - filter_value) > 1e-6) continue;
    out[v[key_col]].emplace_back(v[0], v[value_col]);
  }
  return out;
}

TEST(CfdStartup, ShippedTimingsMatchTheProbesTimedAgain) {
  const std::string dir = AIRTWIN_SOURCE_DIR "/data/cfd/";
  const CfdStartup s = CfdStartup::read(dir + "startup_tilt00_d40.json");
  // The axis (t, z, downward speed): the head at the lowest probe, half its last second's mean.
  const auto axis = read_series(dir + "startup_tilt00_d40_axis.csv", 1, 2, -1, 0.0);
  const auto& low = axis.begin()->second;
  double final_down = 0.0;
  int n = 0;
  for (const auto& [t, y] : low) {
    if (t >= 9.0) final_down += y, ++n;
  }
  final_down /= n;
  // CSV samples every 0.05 s against the probes' 0.02 s: the two timings agree within a sample.
  EXPECT_NEAR(s.transit_s(), first_reach(low, 0.5 * final_down), 0.05);
  EXPECT_NEAR(s.transit_s(), 0.27, 0.01);  // docs/cfd.md
  // The floor (t, height, r, ur, ...) at 4 mm.
  const auto floor = read_series(dir + "startup_tilt00_d40_floor.csv", 2, 3, 1, 0.004);
  for (double r : {0.21, 0.41, 0.61, 1.01}) {
    const auto it = floor.lower_bound(r - 1e-6);
    ASSERT_NE(it, floor.end());
    double final_ur = 0.0;
    int m = 0;
    for (const auto& [t, y] : it->second) {
      if (t >= 9.0) final_ur += y, ++m;
    }
    final_ur /= m;
    const double arrival = first_reach(it->second, 0.5 * final_ur);
    EXPECT_NEAR(s.transit_s() + s.wall_jet_lag_s(r), arrival, 0.05) << "r = " << r;
  }
  // The front slows with its air: the lag grows faster than linearly with r.
  EXPECT_GT(s.wall_jet_lag_s(1.0) / 1.0, 2.0 * s.wall_jet_lag_s(0.4) / 0.4);
}

TEST(CfdStartup, BadFilesAreOneClearError) {
  const std::string dir = testing::fresh_scratch_dir("cfd_startup");
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    const std::string path = dir + "/s.json";
    std::ofstream(path) << text;
    try {
      CfdStartup::read(path);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << what;
    }
  };
  expect_error("{", "not JSON");
  expect_error("{}", "figures");
  expect_error(R"({"figures": {"axis": [], "floor": []}})", "figures.axis");
  const std::string axis = R"("axis": [{"z_m": 0.05, "arrival_s": 0.27}])";
  expect_error(R"({"figures": {)" + axis + R"(, "floor": [{"height_m": 0.004, "r_m": 0.1}]}})",
               "at least two");
  expect_error(R"({"figures": {)" + axis +
                   R"(, "floor": [{"height_m": 0.004, "r_m": 0.1, "arrival_s": 0.2},
                                  {"height_m": 0.004, "r_m": 0.2, "arrival_s": 0.3}]}})",
               "at or after the transit");
  expect_error(R"({"figures": {)" + axis +
                   R"(, "floor": [{"height_m": 0.004, "r_m": "x", "arrival_s": 0.3}]}})",
               "figures.floor[0]: field 'r_m'");
  EXPECT_THROW(CfdStartup::read(dir + "/missing.json"), InputError);
}

}  // namespace
}  // namespace airtwin
