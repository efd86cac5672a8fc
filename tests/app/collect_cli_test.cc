// `airtwin collect` end to end: the trajectory CSV it writes, same seed same bytes, effects, the
// collection through the camera (--vision), and one clear line for bad flags. (The physics is
// tested in tests/sim, the camera's collection in tests/runs.)

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "common/csv.h"
#include "models/trajectory_data.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

void expect_usage_error(const std::string& args, const std::string& fragment) {
  const auto r = run_airtwin(args);
  EXPECT_EQ(r.exit_code, 2) << args << "\nstderr: " << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\nstderr: " << r.err;
}

TEST(CollectCli, WritesTheTrajectoryCsvSameSeedSameBytes) {
  const std::string d = scratch_dir("collect");
  // The mirror first (the model's air, eq. (8) drag); the default twin is the physical one.
  const std::string quick = "collect --per-tilt 2 --wait 0.5 --quiet --seed 4 ";
  const std::string mirror = quick + testing::mirror_flags();
  const auto r = run_airtwin(mirror + "--out " + d + "/a/data.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("collected 4 tracer trajectories"), std::string::npos) << r.out;
  const TrajectorySet set = read_trajectory_csv(d + "/a/data.csv");
  ASSERT_EQ(set.trajectories.size(), 4u);
  for (const Trajectory& tr : set.trajectories) EXPECT_EQ(tr.samples.size(), 81u);
  ASSERT_EQ(run_airtwin(mirror + "--threads 2 --out " + d + "/b.csv").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/a/data.csv"), read_text_file(d + "/b.csv"));
  // Without --quiet, progress goes to stderr as plain lines when it is not a terminal.
  const auto loud = run_airtwin("collect --per-tilt 2 --wait 0.5 --seed 4" +
                                testing::mirror_flags() + "--out " + d + "/l.csv");
  ASSERT_EQ(loud.exit_code, 0) << loud.err;
  EXPECT_NE(loud.err.find("collect 4/4 trials"), std::string::npos) << loud.err;
  EXPECT_EQ(loud.err.find('\r'), std::string::npos) << loud.err;
  EXPECT_EQ(read_text_file(d + "/a/data.csv"), read_text_file(d + "/l.csv"));
  // An effect changes what the twin does, and the run says which.
  const auto e = run_airtwin(mirror + "--effect field_scale:factor=1.5 --out " + d + "/c.csv");
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_NE(e.out.find("field_scale:factor=1.5"), std::string::npos) << e.out;
  EXPECT_NE(read_text_file(d + "/a/data.csv"), read_text_file(d + "/c.csv"));
  // The CFD's air: other trajectories than the model's, the same for the same seed, and said.
  const auto cfd = run_airtwin(quick + "--air cfd --drag eq8 --out " + d + "/cfd.csv");
  ASSERT_EQ(cfd.exit_code, 0) << cfd.err;
  EXPECT_NE(cfd.out.find("cfd air"), std::string::npos) << cfd.out;
  ASSERT_EQ(run_airtwin(quick + "--air cfd --drag eq8 --out " + d + "/cfd2.csv").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/cfd.csv"), read_text_file(d + "/cfd2.csv"));
  EXPECT_NE(read_text_file(d + "/a/data.csv"), read_text_file(d + "/cfd.csv"));
  // Physical drag in the CFD's air: other trajectories again.
  const auto phys = run_airtwin(quick + "--air cfd --drag physical --out " + d + "/phys.csv");
  ASSERT_EQ(phys.exit_code, 0) << phys.err;
  EXPECT_NE(read_text_file(d + "/cfd.csv"), read_text_file(d + "/phys.csv"));
  // ... which is the default twin.
  ASSERT_EQ(run_airtwin(quick + "--out " + d + "/default.csv").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/phys.csv"), read_text_file(d + "/default.csv"));
  // Its physical parameters set from the command line change the trajectories too.
  const auto heavy = run_airtwin(quick + "--air cfd --drag physical --object-physics " +
                                 "tracer:mass_g=0.176,mu_k=0.5 --out " + d + "/heavy.csv");
  ASSERT_EQ(heavy.exit_code, 0) << heavy.err;
  EXPECT_NE(read_text_file(d + "/phys.csv"), read_text_file(d + "/heavy.csv"));
  // Objects that differ: each trial's own object, recorded beside the data, the same for the
  // same seed; no record without the variation.
  const std::string varied = quick + "--vary-physics 0.2 --out " + d;
  const auto v = run_airtwin(varied + "/varied.csv");
  ASSERT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("varied_objects.csv"), std::string::npos) << v.out;
  ASSERT_EQ(run_airtwin(varied + "/varied2.csv").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/varied.csv"), read_text_file(d + "/varied2.csv"));
  EXPECT_EQ(read_text_file(d + "/varied_objects.csv"), read_text_file(d + "/varied2_objects.csv"));
  EXPECT_NE(read_text_file(d + "/phys.csv"), read_text_file(d + "/varied.csv"));
  const CsvTable objects = CsvTable::read_file(
      d + "/varied_objects.csv", {"traj", "mass_g", "cd", "area_cm2", "mu_k", "mu_s_ratio", "cl"});
  ASSERT_EQ(objects.rows(), 4u);
  for (size_t i = 0; i < objects.rows(); ++i) {
    EXPECT_EQ(objects.text(i, "traj"), std::to_string(i));
    EXPECT_NEAR(objects.number(i, "mu_k"), 0.45, 0.2 * 0.45 + 1e-9);  // the tracer's 0.45 +-20 %
    EXPECT_EQ(objects.number(i, "area_cm2"), objects.number(0, "area_cm2"));  // the geometry
  }
  EXPECT_NE(objects.number(0, "mu_k"), objects.number(1, "mu_k"));
  EXPECT_FALSE(std::filesystem::exists(d + "/phys_objects.csv"));
  // The turbulence swept past the objects is the default's; the Lagrangian time alone another
  // twin, the same for the same seed.
  ASSERT_EQ(run_airtwin(quick + "--air-turbulence-swept --out " + d + "/swept.csv").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/phys.csv"), read_text_file(d + "/swept.csv"));
  const std::string lagrangian = quick + "--no-air-turbulence-swept --out " + d;
  ASSERT_EQ(run_airtwin(lagrangian + "/lagrangian.csv").exit_code, 0);
  ASSERT_EQ(run_airtwin(lagrangian + "/lagrangian2.csv").exit_code, 0);
  EXPECT_EQ(read_text_file(d + "/lagrangian.csv"), read_text_file(d + "/lagrangian2.csv"));
  EXPECT_NE(read_text_file(d + "/phys.csv"), read_text_file(d + "/lagrangian.csv"));
}

TEST(CollectCli, TheImplicitIntegratorSurvivesTheTumbleThatStopsEuler) {
  // A tracer that a strong push near s sets tumbling (trial 26 of this collection): under
  // explicit Euler at 2.5 ms its spin grows until the runaway check stops the run; MuJoCo's
  // implicit integrator completes it.
  const std::string d = scratch_dir("collect_integrator");
  const std::string args = "collect --object tracer --per-tilt 50 --lead-in 0.5 --quiet --seed 3" +
                           testing::mirror_flags() +
                           "--effect pressure_gradient:strength=25,length=0.2145 ";
  const auto euler = run_airtwin(args + "--out " + d + "/euler.csv");
  EXPECT_NE(euler.exit_code, 0);
  EXPECT_NE(euler.err.find("object '26' moves faster than 100 m/s"), std::string::npos)
      << euler.err;
  const auto implicit = run_airtwin(args + "--integrator implicit --out " + d + "/implicit.csv");
  ASSERT_EQ(implicit.exit_code, 0) << implicit.err;
  EXPECT_EQ(read_trajectory_csv(d + "/implicit.csv").trajectories.size(), 100u);
  // A bad name is one usage line.
  const auto bad = run_airtwin("collect --per-tilt 2 --integrator rk4 --out " + d + "/bad.csv");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--integrator: expected euler or implicit, got 'rk4'"), std::string::npos)
      << bad.err;
}

TEST(CollectCli, VisionRecordsThroughTheCalibratedCamera) {
  const std::string d = scratch_dir("collect_vision");
  const auto r = run_airtwin(
      "collect --vision --noise low --per-tilt 1 --record 0.5 --quiet --seed 4 --truth-out " + d +
      "/truth.csv --out " + d + "/v/data.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The camera calibrated first from rendered checkerboard views, beside the output.
  EXPECT_NE(r.out.find("calibrated the camera"), std::string::npos) << r.out;
  EXPECT_NE(read_text_file(d + "/v/data_calib.yaml").find("1024"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(d + "/v/data_calibration/view_00.png"));
  // What was kept and dropped, and the camera's error, in one stated line.
  EXPECT_NE(r.out.find("camera: kept 2 of 2 trials, dropped 0 (0 not found at the start, 0 lost, "
                       "0 left the view); camera against truth over 42 positions"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("collected 2 tracer trajectories"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("through the camera"), std::string::npos) << r.out;
  // The camera's positions differ from the twin's truth of the same frames by less than 3 mm.
  const TrajectorySet camera = read_trajectory_csv(d + "/v/data.csv");
  const TrajectorySet truth = read_trajectory_csv(d + "/truth.csv");
  ASSERT_EQ(camera.trajectories.size(), 2u);
  ASSERT_EQ(truth.trajectories.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(camera.trajectories[i].samples.size(), 21u);
    ASSERT_EQ(truth.trajectories[i].samples.size(), 21u);
    for (size_t k = 0; k < 21; ++k) {
      EXPECT_LT(
          (camera.trajectories[i].samples[k].p_W - truth.trajectories[i].samples[k].p_W).norm(),
          3e-3);
    }
  }
  // The truth file is the plain collection's positions of the same trials.
  ASSERT_EQ(
      run_airtwin("collect --per-tilt 1 --record 0.5 --quiet --seed 4 --out " + d + "/plain.csv")
          .exit_code,
      0);
  EXPECT_EQ(read_text_file(d + "/truth.csv"), read_text_file(d + "/plain.csv"));
}

TEST(CollectCli, BadFlagsAreOneClearLine) {
  expect_usage_error("collect --object pebble --out x.csv", "--object");
  expect_usage_error("collect --vary-physics 0.9 --out x.csv", "--vary-physics: expected none");
  expect_usage_error("collect --tilts 70 --out x.csv", "--tilts");
  expect_usage_error("collect --tilts 0,abc --out x.csv", "--tilts");
  expect_usage_error("collect --per-tilt 0 --out x.csv", "--per-tilt");
  expect_usage_error("collect --wait -1 --out x.csv", "--wait");
  expect_usage_error("collect --protocol dropped --out x.csv",
                     "--protocol: expected one of reaim, placed, mixed, launched, got 'dropped'");
  expect_usage_error("collect --protocol placed --lead-in 0.5 --out x.csv",
                     "--lead-in: placed trials are recorded from their start");
  expect_usage_error("collect --launch-speed 1,2 --out x.csv",
                     "--launch-speed needs --protocol launched");
  expect_usage_error("collect --protocol launched --launch-speed 2,1 --out x.csv",
                     "--launch-speed: expected speeds 0 < min <= max <= 5 m/s, got 2, 1");
  expect_usage_error("collect --protocol launched --launch-speed 1 --out x.csv", "--launch-speed");
  expect_usage_error("collect --protocol launched --release-after 0.5 --out x.csv",
                     "--release-after: launched trials run under the idle nozzle throughout");
  expect_usage_error("collect --effect warp --out x.csv",
                     "--effect: effect 'warp': unknown effect 'warp'");
  expect_usage_error("collect --effect stiction:ratio=0.5 --out x.csv", "stiction.ratio");
  expect_usage_error("collect", "--out");
  expect_usage_error("collect --air wind --out x.csv", "--air: expected cfd or model, got 'wind'");
  expect_usage_error("collect --air model --cfd data --out x.csv", "--cfd needs --air cfd");
  expect_usage_error("collect --drag glue --out x.csv", "--drag: expected eq8 or physical");
  expect_usage_error(
      "collect --air cfd --no-air-formation --air-formation-time-scale 1 --out x.csv",
      "--air-formation-time-scale needs the formation (drop --no-air-formation)");
  expect_usage_error("collect --air model --air-formation-time-scale 1 --out x.csv",
                     "--air-formation-time-scale needs --air cfd");
  expect_usage_error("collect --air cfd --air-formation --no-air-formation --out x.csv",
                     "excludes");
  expect_usage_error("collect --air cfd --air-formation --air-formation-time-scale 11 --out x.csv",
                     "--air-formation-time-scale: expected (0, 10]");
  expect_usage_error("collect --air model --air-front-co-flow 0 --out x.csv",
                     "--air-front-co-flow and --air-front-counter-flow need --air cfd");
  expect_usage_error("collect --air cfd --air-front-counter-flow 2.5 --out x.csv",
                     "--air-front-counter-flow: expected [0, 2]");
  expect_usage_error("collect --air model --air-turbulence-swept --out x.csv",
                     "--air-turbulence-swept needs --air cfd");
  expect_usage_error("collect --air-turbulence-swept --no-air-turbulence-swept --out x.csv",
                     "excludes");
  expect_usage_error("collect --air cfd --table t.csv --out x.csv", "--table needs --air model");
  expect_usage_error("collect --drag eq8 --object-physics tracer:mu_k=0.4 --out x.csv",
                     "--object-physics: object physics 'tracer:mu_k=0.4': tracer.mu_k belongs to "
                     "the physical drag law");
  expect_usage_error("collect --drag physical --object-physics tracer:cd=9 --out x.csv",
                     "tracer.cd must be a number in [0.05, 3], got '9'");
  // A folder without CFD cases: an input error naming it.
  const auto r = run_airtwin("collect --air cfd --cfd " + scratch_dir("no_cfd") + " --out x.csv");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no CFD case"), std::string::npos) << r.err;
  expect_usage_error("collect --calib c.yaml --out x.csv",
                     "--calib, --noise and --truth-out need --vision");
  expect_usage_error("collect --noise low --out x.csv", "need --vision");
  expect_usage_error("collect --vision --noise loud --out x.csv",
                     "--noise: expected none, low or high, got 'loud'");
  const auto no_calib = run_airtwin("collect --vision --calib " + scratch_dir("no_calib") +
                                    "/missing.yaml --out " + scratch_dir("no_calib") + "/x.csv");
  EXPECT_EQ(no_calib.exit_code, 1) << no_calib.err;
  EXPECT_EQ(count_lines(no_calib.err), 1) << no_calib.err;
  EXPECT_NE(no_calib.err.find("missing.yaml"), std::string::npos) << no_calib.err;
  expect_usage_error("calibrate-dynamics --iterations 0 --out x.json", "--iterations");
  expect_usage_error("calibrate-dynamics --target 1,2 --out x.json", "--target");
  expect_usage_error("calibrate-dynamics --drag eq8 --search cd=0.3:1:3 --out x.json",
                     "--search needs --drag physical");
  expect_usage_error("calibrate-dynamics --drag physical --search cd=0.3:1 --out x.json",
                     "--search: expected KEY=MIN:MAX:N or KEY=VALUE");
  expect_usage_error("calibrate-dynamics --drag physical --search cd=0.01:1:3 --out x.json",
                     "--search: axis 1 (cd): window [0.01, 1] is not inside [0.05, 3]");
  expect_usage_error("calibrate-dynamics --drag physical --search cd=0.3:1:3,5 --out x.json",
                     "--search: expected");
  expect_usage_error("calibrate-dynamics --drag eq8 --held-out-seeds 3 --out x.json",
                     "--held-out-seeds needs --drag physical");
  expect_usage_error("calibrate-dynamics --drag physical --held-out-seeds -1 --out x.json",
                     "--held-out-seeds");
  expect_usage_error("calibrate-dynamics --drag physical --held-out-first-seed 7 --out x.json",
                     "--held-out-first-seed needs --held-out-seeds N");
  expect_usage_error(
      "calibrate-dynamics --drag physical --seed 5 --held-out-seeds 3 --held-out-first-seed 4 "
      "--out x.json",
      "--held-out-seeds: seeds 4-6 hold the calibration's --seed 5");
}

// The held-out check end to end: the record of each collection, equal to what a calibration at
// that seed records for the same point, and the summary of them.
TEST(CollectCli, CalibrationCheckedOnHeldOutSeeds) {
  const std::string d = scratch_dir("calibrate_held_out");
  const std::string quick =
      "calibrate-dynamics --object tracer --air model --drag physical --per-tilt 6 --tilts 0 "
      "--search cd=0.6 --search mu_k=0.3 ";
  const auto r = run_airtwin(quick + "--seed 5 --held-out-seeds 2 --out " + d + "/cal.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("held out, 2 collections: the air term lost in "), std::string::npos)
      << r.out;
  const nlohmann::json j = nlohmann::json::parse(read_text_file(d + "/cal.json"));
  const nlohmann::json& h = j.at("held_out");
  ASSERT_EQ(h.at("seeds").get<int>(), 2);
  ASSERT_EQ(h.at("checks").size(), 2u);
  int lost = 0;
  for (int k = 0; k < 2; ++k) {
    const nlohmann::json& c = h.at("checks")[static_cast<size_t>(k)];
    EXPECT_EQ(c.at("seed").get<int>(), 6 + k);
    lost += c.at("air_term_kept").get<bool>() ? 0 : 1;
    if (k > 0) continue;
    // The same point calibrated at that seed: its own record of it.
    const std::string own = d + "/own" + std::to_string(6 + k) + ".json";
    const auto o = run_airtwin(quick + "--seed " + std::to_string(6 + k) + " --out " + own);
    ASSERT_EQ(o.exit_code, 0) << o.err;
    const nlohmann::json p = nlohmann::json::parse(read_text_file(own)).at("points")[0];
    EXPECT_EQ(c.at("identified_eq8_form"), p.at("identified_eq8_form")) << 6 + k;
    EXPECT_EQ(c.at("end_position_mape_by_tilt"), p.at("end_position_mape_by_tilt")) << 6 + k;
    EXPECT_EQ(c.at("full_library_terms"), p.at("full_library_terms")) << 6 + k;
    EXPECT_EQ(c.at("repeatability_pct"),
              nlohmann::json::parse(read_text_file(own)).at("best_repeatability_pct"))
        << 6 + k;
  }
  const nlohmann::json& s = h.at("summary");
  EXPECT_EQ(s.at("air_term_lost").get<int>(), lost);
  if (lost < 2) {
    EXPECT_LE(s.at("worst_relative_error").at("min").get<double>(),
              s.at("worst_relative_error").at("median").get<double>());
    EXPECT_LE(s.at("worst_relative_error").at("median").get<double>(),
              s.at("worst_relative_error").at("max").get<double>());
  }
}

}  // namespace
}  // namespace airtwin
