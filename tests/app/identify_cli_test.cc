// `airtwin identify` end to end: model.json from trajectories and from a speed series, identical
// bytes for identical runs, and one clear error line for every kind of bad input.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/csv.h"
#include "models/air_field.h"
#include "models/trajectory_data.h"
#include "tests/app/cli_runner.h"
#include "tests/support/synthetic_trajectories.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

void expect_failure(const std::string& args, int code, const std::string& fragment) {
  const auto r = run_airtwin(args);
  EXPECT_EQ(r.exit_code, code) << args << "\nstderr: " << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\nstderr: " << r.err;
}

class IdentifyCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(scratch_dir("identify"));
    // The default field model, which identify reads vair from unless --table names another.
    const AirFieldModel model = AirFieldModel::fitted_to_cfd();
    TrajectorySet set = testing::make_ray_trajectories(model, -2.66, 4.26, -8.53, 40, 21, "tracer");
    write(*dir_ + "/tracer.csv", trajectory_csv(set));
    const TrajectorySet cotton =
        testing::make_ray_trajectories(model, -4.25, 3.46, -4.12, 40, 22, "cotton");
    for (Trajectory tr : cotton.trajectories) {
      tr.id = "c" + tr.id;
      set.trajectories.push_back(tr);
    }
    write(*dir_ + "/mixed.csv", trajectory_csv(set));
    write(*dir_ + "/series.csv",
          testing::make_speed_series_csv(model, -4.25, 3.46, -4.12, 40, 23, 0.0));
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string* dir_;
};
std::string* IdentifyCli::dir_ = nullptr;

TEST_F(IdentifyCli, TrajectoriesToModelJson) {
  const std::string& d = *dir_;
  const auto r = run_airtwin("identify " + d + "/tracer.csv --out " + d + "/out/model.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("end-position MAPE"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(read_text_file(d + "/out/model.json"));
  EXPECT_EQ(j["object"], "tracer");
  EXPECT_EQ(j["method"], "robust-esindy");
  ASSERT_EQ(j["terms"].size(), 10u);
  EXPECT_EQ(j["terms"][9], "vair^3");
  EXPECT_NEAR(j["coefficients"][1].get<double>(), -2.66, 0.005 * 2.66);
  EXPECT_NEAR(j["coefficients"][2].get<double>(), 4.26, 0.005 * 4.26);
  EXPECT_NEAR(j["coefficients"][0].get<double>(), -8.53, 0.005 * 8.53);
  for (int k = 3; k < 10; ++k) EXPECT_EQ(j["coefficients"][k].get<double>(), 0.0);
  EXPECT_LT(j["end_position_mape"].get<double>(), 1.0);
  EXPECT_GT(j["r2"].get<double>(), 0.99);
  EXPECT_GT(j["n_samples"].get<int>(), 0);
  EXPECT_GT(j["n_dropped"].get<int>(), 0);

  // Same data, same seed: the same bytes. Another seed: other bootstraps.
  ASSERT_EQ(run_airtwin("identify " + d + "/tracer.csv --out " + d + "/again.json").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/out/model.json"), read_text_file(d + "/again.json"));
  ASSERT_EQ(
      run_airtwin("identify " + d + "/tracer.csv --seed 9 --out " + d + "/seed9.json").exit_code,
      0);
  const auto j9 = nlohmann::json::parse(read_text_file(d + "/seed9.json"));
  EXPECT_EQ(j9["seed"], 9);

  // The same file twice, as two sessions: every trajectory twice, the same model within the
  // bootstraps' scatter, and the source names both.
  ASSERT_EQ(
      run_airtwin("identify " + d + "/tracer.csv " + d + "/tracer.csv --out " + d + "/twice.json")
          .exit_code,
      0);
  const auto j2 = nlohmann::json::parse(read_text_file(d + "/twice.json"));
  EXPECT_EQ(j2["source"].get<std::string>().rfind("2 files, ", 0), 0u) << j2["source"];
  for (int k : {0, 1, 2}) {
    EXPECT_NEAR(j2["coefficients"][k].get<double>(), j["coefficients"][k].get<double>(),
                0.01 * std::abs(j["coefficients"][k].get<double>()))
        << k;
  }
}

TEST_F(IdentifyCli, ObjectChoiceInAMixedFileAndSpeedSeries) {
  const std::string& d = *dir_;
  expect_failure("identify " + d + "/mixed.csv --out " + d + "/m.json", 2, "--object");
  const auto r = run_airtwin("identify " + d + "/mixed.csv --object cotton --method stlsq --out " +
                             d + "/cotton.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text_file(d + "/cotton.json"));
  EXPECT_EQ(j["object"], "cotton");
  EXPECT_EQ(j["method"], "stlsq");
  EXPECT_NEAR(j["coefficients"][1].get<double>(), -4.25, 0.005 * 4.25);

  const auto s = run_airtwin("identify --series " + d + "/series.csv --out " + d + "/s.json");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto js = nlohmann::json::parse(read_text_file(d + "/s.json"));
  EXPECT_TRUE(js["object"].is_null());
  EXPECT_TRUE(js["end_position_mape"].is_null());  // a series has no positions
  EXPECT_NEAR(js["coefficients"][2].get<double>(), 3.46, 0.005 * 3.46);
  EXPECT_EQ(js["n_negative_speeds"], 0);

  // Measured speeds near rest are negative now and then: data, counted and reported.
  std::string text = read_text_file(d + "/series.csv");
  const std::string rest = ",0.000000,";  // a resting sample "t,0.000000,vair"
  const size_t last = text.rfind(rest);
  ASSERT_NE(last, std::string::npos);
  text.replace(last, rest.size(), ",-0.004000,");
  write(d + "/signed.csv", text);
  const auto n = run_airtwin("identify --series " + d + "/signed.csv --out " + d + "/n.json");
  ASSERT_EQ(n.exit_code, 0) << n.err;
  EXPECT_NE(n.out.find("1 negative v"), std::string::npos) << n.out;
  EXPECT_EQ(nlohmann::json::parse(read_text_file(d + "/n.json"))["n_negative_speeds"], 1);
}

TEST_F(IdentifyCli, BadInputIsOneClearLine) {
  const std::string& d = *dir_;
  expect_failure("identify --out " + d + "/x.json", 2, "neither");
  expect_failure("identify " + d + "/tracer.csv --series " + d + "/series.csv --out x.json", 2,
                 "both");
  expect_failure("identify " + d + "/tracer.csv", 2, "--out");
  expect_failure("identify " + d + "/tracer.csv --method lasso --out x.json", 2, "--method");
  expect_failure("identify " + d + "/tracer.csv --lambda nan --out x.json", 2, "--lambda");
  expect_failure("identify " + d + "/tracer.csv --bootstraps 0 --out x.json", 2, "--bootstraps");
  expect_failure("identify " + d + "/tracer.csv --terms 1,vair --out x.json", 2, "must include v");
  expect_failure("identify " + d + "/tracer.csv --terms 1,v,w --out x.json", 2, "unknown term 'w'");
  expect_failure("identify " + d + "/missing.csv --out x.json", 1, "missing.csv");
  expect_failure("identify " + d + "/tracer.csv " + d + "/gone.csv --out x.json", 1, "gone.csv");
  expect_failure("identify " + d + "/tracer.csv --object pebble --out x.json", 1, "pebble");
  write(d + "/bad.csv",
        "traj,object,t,x,y,pan_deg,tilt_deg\n1,tracer,0,0.1,0.2,0,0\n"
        "1,tracer,0.025,inf,0.2,0,0\n");
  expect_failure("identify " + d + "/bad.csv --out x.json", 1, "bad.csv:3: column 'x'");
  write(d + "/few.csv",
        "traj,object,t,x,y,pan_deg,tilt_deg\n1,tracer,0,0.1,0.2,0,0\n"
        "1,tracer,0.025,0.11,0.2,0,0\n1,tracer,0.05,0.13,0.2,0,0\n"
        "1,tracer,0.075,0.16,0.2,0,0\n1,tracer,0.1,0.2,0.2,0,0\n");
  expect_failure("identify " + d + "/few.csv --out x.json", 1, "usable speed pairs");
  write(d + "/binary.csv", std::string("\x7f"
                                       "ELF\x01\x00\x00",
                                       7));
  expect_failure("identify " + d + "/binary.csv --out x.json", 1, "binary.csv");
  expect_failure("identify --series " + d + "/tracer.csv --out x.json", 1, "tracer.csv");
}

}  // namespace
}  // namespace airtwin
