// `airtwin run` end to end: the files it writes (summary.json with the issue's keys, the
// trajectory-CSV log, decisions.csv, plans.csv, nozzle.csv), consistent with one another, and one
// clear line for bad input. (The controller, the loop and whole runs are tested in tests/controller
// and tests/rigs.)

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/units.h"
#include "models/air_field.h"
#include "models/nozzle_geometry.h"
#include "models/nozzle_log.h"
#include "models/trajectory_data.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

const std::string kScenes = std::string(AIRTWIN_SOURCE_DIR) + "/scenes/";

// An extended_model.json with the paper's tracer coefficients, the default nozzle response and
// `extensions` (a JSON object's members).
void write_extended_model(const std::string& path, const std::string& extensions) {
  std::ofstream(path) << R"({"format": "airtwin-extended-model", "version": 1,
      "objects": {"tracer": {"xi1": -2.66, "xi2": 4.26, "xi3": -8.53}},
      "nozzle_response": {"max_speed_radps": 7, "max_acceleration_radps2": 30,
                          "transit_delay_s": 0.2},
      "extensions": {)" + extensions +
                             "}}";
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(RunCli, LineWritesSummaryLogAndDecisions) {
  const std::string d = scratch_dir("run_line");
  const auto r = run_airtwin("run " + kScenes + "line.yaml --seed 2 --quiet --out " + d);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(d + "/summary.json"));
  for (const char* key :
       {"scenario", "seed", "success", "completion_time_s", "path_error_cm",
        "max_pairwise_distance_cm", "objects_in_zone", "n_objects", "decisions", "decision_ms"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["scenario"], "line");
  EXPECT_EQ(j["seed"], 2);
  EXPECT_EQ(j["n_objects"], 1);
  EXPECT_EQ(j["perception"], "truth");
  ASSERT_TRUE(j["success"].get<bool>());
  // The log is a trajectory CSV the project reads back: one object, a row per 40 Hz frame up to
  // the end of the run.
  const TrajectorySet log = read_trajectory_csv(d + "/log.csv");
  ASSERT_EQ(log.trajectories.size(), 1u);
  EXPECT_EQ(log.trajectories[0].group, "line");
  EXPECT_NEAR(log.trajectories[0].samples.back().t_s, j["end_time_s"].get<double>(), 1e-6);
  // One decisions.csv row per decision after the header.
  EXPECT_EQ(count_lines(slurp(d + "/decisions.csv")), 1 + j["decisions"].get<int>());
  // plans.csv: one row per object per decision; in fast mode the perceived position is the
  // truth's at that time (log.csv), and the object was seen.
  std::istringstream plans(slurp(d + "/plans.csv"));
  std::string row;
  std::getline(plans, row);
  EXPECT_EQ(row, "t,id,type,seen,x,y,vx,vy,end_x,end_y");
  int n_rows = 0;
  const auto& truth = log.trajectories[0].samples;
  while (std::getline(plans, row)) {
    ++n_rows;
    std::vector<std::string> f;
    std::istringstream cells(row);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    ASSERT_EQ(f.size(), 10u) << row;
    EXPECT_EQ(f[1], "t1");
    EXPECT_EQ(f[2], "tracer");
    EXPECT_EQ(f[3], "1");
    const double t = std::stod(f[0]);
    const auto at = std::min_element(truth.begin(), truth.end(), [&](const auto& a, const auto& b) {
      return std::fabs(a.t_s - t) < std::fabs(b.t_s - t);
    });
    ASSERT_NEAR(at->t_s, t, 1e-6) << row;
    EXPECT_NEAR(std::stod(f[4]), at->p_W.x(), 2e-6) << row;
    EXPECT_NEAR(std::stod(f[5]), at->p_W.y(), 2e-6) << row;
  }
  EXPECT_EQ(n_rows, j["decisions"].get<int>());
  EXPECT_NE(r.out.find("line seed 2: success"), std::string::npos) << r.out;

  // nozzle.csv, the nozzle log `trajectories --nozzle` reads: a row at each decision that changed
  // the command (decisions.csv), the command in force at every decision the one it chose, and at
  // every other frame of log.csv the one log.csv recorded. (The frame at a decision's instant was
  // taken before the command was sent: log.csv holds the previous command there.)
  const NozzleLog nozzle = read_nozzle_log(d + "/nozzle.csv");
  ASSERT_GE(nozzle.commands.size(), 2u);
  EXPECT_EQ(nozzle.commands.front().t_s, truth.front().t_s);
  std::istringstream decisions(slurp(d + "/decisions.csv"));
  std::getline(decisions, row);
  EXPECT_EQ(row,
            "t,reference_index,ref_x,ref_y,s_x,s_y,pan_deg,tilt_deg,cost,iterations,converged,"
            "sweep,rescue,n_observed,decision_ms");
  std::vector<double> decision_times;
  while (std::getline(decisions, row)) {
    std::vector<std::string> f;
    std::istringstream cells(row);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    ASSERT_EQ(f.size(), 15u) << row;
    const double t = std::stod(f[0]);
    decision_times.push_back(t);
    const long i = nozzle.index_at(t);
    ASSERT_GE(i, 0) << row;
    EXPECT_NEAR(rad_to_deg(nozzle.commands[i].nozzle.pan_rad), std::stod(f[6]), 1e-9) << row;
    EXPECT_NEAR(rad_to_deg(nozzle.commands[i].nozzle.tilt_rad), std::stod(f[7]), 1e-9) << row;
  }
  for (const NozzleCommand& c : nozzle.commands) {
    EXPECT_NE(std::find(decision_times.begin(), decision_times.end(), c.t_s), decision_times.end())
        << c.t_s;
  }
  int compared = 0;
  for (const TrajectorySample& s : truth) {
    const double t = std::stod(std::to_string(s.t_s));  // as the files print it, 6 decimals
    if (std::find(decision_times.begin(), decision_times.end(), t) != decision_times.end()) {
      continue;
    }
    const NozzleCommand& c = nozzle.commands[nozzle.index_at(s.t_s)];
    EXPECT_NEAR(c.nozzle.pan_rad, s.nozzle.pan_rad, deg_to_rad(2e-6)) << s.t_s;
    EXPECT_NEAR(c.nozzle.tilt_rad, s.nozzle.tilt_rad, deg_to_rad(2e-6)) << s.t_s;
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

// With --vision the run writes what its camera pipeline detected (detections.csv, at the
// detection rate); joined with nozzle.csv by `trajectories`, it gives the run's log.csv back: the
// twin's positions within the detection's few millimetres, the command in force at every frame
// but those at a decision's instant (taken before the command was sent).
// A tracer 1.3 m out, to be pushed toward the nozzle's foot: every s on its ray lies beyond it,
// 0.3-0.5 m upstream at tilts near 50 deg, where the CFD's air (1.2 m/s at 42 cm upstream of s
// at 35 deg, docs/twin.md) stays below the 2 m/s that starts a tracer. Nothing moves, and the
// run says it stalled rather than ran out of time.
TEST(RunCli, ATracerUpstreamOfEveryPushStallsAndTheRunSaysSo) {
  const std::string d = scratch_dir("run_stalled");
  std::string text = slurp(kScenes + "line.yaml");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"x: -0.26, y: 0.25}", "x: 0.0, y: 1.3}"},
           {"path: [[-0.26, 0.25], [0.26, 0.25]]", "path: [[0.0, 1.3], [0.0, 0.8]]"},
           {"time_limit_s: 120", "time_limit_s: 8"}}) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  std::ofstream(d + "/upstream.yaml") << text;
  const auto r = run_airtwin("run " + d + "/upstream.yaml --seed 1 --quiet --out " + d + "/run");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("FAILED (time limit 8 s; stalled: no object moved more than 1 cm after"),
            std::string::npos)
      << r.out;
  const auto j = nlohmann::json::parse(slurp(d + "/run/summary.json"));
  EXPECT_FALSE(j["success"].get<bool>());
  EXPECT_GE(j["end_time_s"].get<double>() - j["still_since_s"].get<double>(), 5.0);
  // The log agrees: the tracer ends within 1 cm of where it was at still_since_s.
  const TrajectorySet log = read_trajectory_csv(d + "/run/log.csv");
  const auto& samples = log.trajectories.at(0).samples;
  const auto at = std::find_if(samples.begin(), samples.end(), [&](const TrajectorySample& x) {
    return x.t_s >= j["still_since_s"].get<double>() - 1e-9;
  });
  ASSERT_NE(at, samples.end());
  EXPECT_LE((samples.back().p_W - at->p_W).norm(), 0.01);
}

TEST(RunCli, VisionRunGivesDetectionsAndNozzleLogThatTrajectoriesJoins) {
  const std::string d = scratch_dir("run_vision_pair");
  std::string text = slurp(kScenes + "line.yaml");
  text.replace(text.find("time_limit_s: 120"), 17, "time_limit_s: 8");
  std::ofstream(d + "/line_short.yaml") << text;
  const auto r =
      run_airtwin("run " + d + "/line_short.yaml --seed 2 --vision --quiet --out " + d + "/run");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("nozzle.csv, detections.csv"), std::string::npos) << r.out;
  // The vision tracker coasts 10 processed frames at 10 Hz: --max-missed 10.
  const auto join = run_airtwin("trajectories " + d + "/run/detections.csv --nozzle " + d +
                                "/run/nozzle.csv --max-missed 10 --out " + d + "/data.csv");
  ASSERT_EQ(join.exit_code, 0) << join.err;
  EXPECT_NE(join.out.find("in 1 tracks"), std::string::npos) << join.out;
  const TrajectorySet data = read_trajectory_csv(d + "/data.csv");
  const TrajectorySet log = read_trajectory_csv(d + "/run/log.csv");
  const NozzleLog nozzle = read_nozzle_log(d + "/run/nozzle.csv");
  ASSERT_EQ(data.trajectories.size(), 1u);
  ASSERT_EQ(log.trajectories.size(), 1u);
  const auto& truth = log.trajectories[0].samples;
  const auto& seen = data.trajectories[0].samples;
  // Every processed frame (10 Hz over 8 s) was detected.
  EXPECT_EQ(seen.size(), 81u);
  int compared = 0;
  for (const TrajectorySample& s : seen) {
    const auto at = std::min_element(truth.begin(), truth.end(), [&](const auto& a, const auto& b) {
      return std::fabs(a.t_s - s.t_s) < std::fabs(b.t_s - s.t_s);
    });
    ASSERT_NEAR(at->t_s, s.t_s, 1e-9);
    EXPECT_LT((at->p_W - s.p_W).norm(), 0.003) << s.t_s;
    const bool decision_instant =
        std::any_of(nozzle.commands.begin(), nozzle.commands.end(),
                    [&](const NozzleCommand& c) { return c.t_s == s.t_s; });
    if (decision_instant) continue;
    EXPECT_NEAR(s.nozzle.pan_rad, at->nozzle.pan_rad, deg_to_rad(2e-6)) << s.t_s;
    EXPECT_NEAR(s.nozzle.tilt_rad, at->nozzle.tilt_rad, deg_to_rad(2e-6)) << s.t_s;
    ++compared;
  }
  EXPECT_GT(compared, 70);
}

// The planner's threads change when each decision is ready, not what it decides: the same
// files but the decisions' wall-clock times.
TEST(RunCli, PlannerThreadsGiveTheSameRun) {
  const std::string d = scratch_dir("run_threads");
  for (const char* threads : {"1", "3"}) {
    const auto r = run_airtwin("run " + kScenes + "line.yaml --seed 2 --quiet --planner-threads " +
                               threads + " --out " + d + "/t" + threads);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  for (const char* file : {"/log.csv", "/plans.csv", "/nozzle.csv"}) {
    EXPECT_EQ(slurp(d + "/t1" + file), slurp(d + "/t3" + file)) << file;
  }
}

TEST(RunCli, BadInputIsOneClearLine) {
  const std::string d = scratch_dir("run_bad");
  const auto missing = run_airtwin("run " + d + "/none.yaml --out " + d + "/o");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(count_lines(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("none.yaml"), std::string::npos);

  std::ofstream(d + "/bad.yaml") << "name: x\nobjects: []\ntask: {kind: path, time_limit_s: 10}\n";
  const auto bad = run_airtwin("run " + d + "/bad.yaml --out " + d + "/o");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_EQ(count_lines(bad.err), 1) << bad.err;

  const std::string line = "run " + kScenes + "line.yaml --out " + d + "/o ";
  for (const std::string flags :
       {"--video-stride 0", "--noise low", "--vision --noise medium", "--vision --vision-rate 7",
        "--calib c.yaml", "--vary-physics 0.7", "--vary-physics lots",
        "--vary-physics 0.1 --mjcf scene.xml", "--planner-threads 0"}) {
    const auto r = run_airtwin(line + flags);
    EXPECT_EQ(r.exit_code, 2) << flags;
    EXPECT_EQ(count_lines(r.err), 1) << flags << ": " << r.err;
    if (flags.rfind("--vary", 0) == 0) {
      EXPECT_NE(r.err.find("--vary-physics"), std::string::npos) << r.err;
    }
  }
  // Flags are checked before anything is written.
  EXPECT_FALSE(std::ifstream(d + "/o/summary.json").good());

  // An extended model with a value out of its extension's range is one line naming it.
  write_extended_model(d + "/ext.json", R"("floor_slope": {"angle_deg": 95, "direction_deg": 0})");
  const auto ext = run_airtwin(line + "--model " + d + "/ext.json");
  EXPECT_EQ(ext.exit_code, 1);
  EXPECT_EQ(count_lines(ext.err), 1) << ext.err;
  EXPECT_NE(ext.err.find("floor_slope"), std::string::npos) << ext.err;
}

// The closed loop's gain from an extended model: the twin's servos are off by (8, 4) deg. The
// controller planning with the nominal model aims wrong and does not finish the line; with an
// extended model that carries the offset it commands the aim minus the offset (checked on every
// decision against eqs. (1)-(2) inverted) and finishes.
TEST(RunCli, ExtendedModelCompensatesTheNozzleOffset) {
  const std::string d = scratch_dir("run_extended");
  write_extended_model(d + "/ext.json", R"("nozzle_offset": {"pan_deg": 8, "tilt_deg": 4})");
  // In the mirror twin, where the offset is the only thing the nominal model lacks.
  const std::string line = "run " + kScenes + "line.yaml --seed 2 --quiet" +
                           testing::mirror_flags() + "--effect nozzle_offset:pan_deg=8,tilt_deg=4 ";
  const auto nominal = run_airtwin(line + "--out " + d + "/nominal");
  ASSERT_EQ(nominal.exit_code, 0) << nominal.err;
  const auto extended = run_airtwin(line + "--model " + d + "/ext.json --out " + d + "/extended");
  ASSERT_EQ(extended.exit_code, 0) << extended.err;
  const auto jn = nlohmann::json::parse(slurp(d + "/nominal/summary.json"));
  const auto je = nlohmann::json::parse(slurp(d + "/extended/summary.json"));
  EXPECT_FALSE(jn["success"].get<bool>());
  EXPECT_TRUE(je["success"].get<bool>());

  // decisions.csv: t,reference_index,ref_x,ref_y,s_x,s_y,pan_deg,tilt_deg,...
  std::istringstream rows(slurp(d + "/extended/decisions.csv"));
  std::string row;
  std::getline(rows, row);
  const AirFieldModel model = AirFieldModel::with_constructed_table();
  int checked = 0;
  double pan_hint = 0.0;
  while (std::getline(rows, row)) {
    std::vector<double> v;
    std::istringstream cells(row);
    for (std::string cell; std::getline(cells, cell, ',');) v.push_back(std::stod(cell));
    ASSERT_GE(v.size(), 8u) << row;
    const AimResult aim = aim_at_stagnation(model.geometry(), {v[4], v[5]}, pan_hint);
    ASSERT_TRUE(aim.reachable()) << row;
    // The CSV carries 6 decimals of s (1 um) and of the angles.
    EXPECT_NEAR(v[6], rad_to_deg(wrap_angle(aim.orientation->pan_rad - deg_to_rad(8.0))), 1e-3)
        << row;
    EXPECT_NEAR(v[7], rad_to_deg(aim.orientation->tilt_rad) - 4.0, 1e-3) << row;
    pan_hint = deg_to_rad(v[6]);
    ++checked;
  }
  EXPECT_EQ(checked, je["decisions"].get<int>());
}

}  // namespace
}  // namespace airtwin
