// `airtwin trajectories` end to end: the documented path from a camera to a model. The twin
// renders tracers blown by the jet, `calibrate` and `detect` read the frames as a rig's camera,
// `trajectories` joins the tracks with the render's nozzle log, and `identify` on the result is
// compared with `identify` on the twin's own positions of the same frames (truth.csv, turned into
// a trajectory CSV here, without the command under test). Then the report of what is dropped,
// the trials, and one clear line for every bad input.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "common/csv.h"
#include "common/units.h"
#include "models/trajectory_data.h"
#include "tests/app/cli_runner.h"

namespace airtwin {
namespace {

using testing::count_lines;
using testing::run_airtwin;
using testing::scratch_dir;

void write_file(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// Twelve tracers on two rings (15 and 28 cm) around (centre_x, centre_y), by default the
// stagnation point (0.3, 0) of pan 0, tilt 12.09 deg (`airtwin aim --stagnation 0.3,0`), where
// the jet blows them outward.
std::string ring_scenario(double centre_x = 0.3, double centre_y = 0.0) {
  std::string objects;
  int k = 0;
  for (const auto& [radius_m, offset_deg] : {std::pair{0.15, 0.0}, std::pair{0.28, 30.0}}) {
    for (int i = 0; i < 6; ++i) {
      const double a = deg_to_rad(offset_deg + 60.0 * i);
      char line[128];
      std::snprintf(line, sizeof line, "  - {id: t%d, type: tracer, x: %.3f, y: %.3f}\n", ++k,
                    centre_x + radius_m * std::cos(a), centre_y + radius_m * std::sin(a));
      objects += line;
    }
  }
  return "name: ring\nobjects:\n" + objects +
         "task:\n  kind: aggregation\n  zone: {centre: [0, 0], diameter_m: 0.37}\n"
         "  time_limit_s: 10\n";
}

nlohmann::json read_json(const std::string& path) {
  return nlohmann::json::parse(read_text_file(path));
}

// The camera's path: `calibrate` from the checkerboard views in `calibration`, `detect` on the
// frames in `frames` as on a rig's, `trajectories` joining the tracks with `nozzle` (and
// `flags`) into DIR/data.csv. Returns what `trajectories` did; a failed step before it fails the
// test and is returned instead.
testing::CliResult camera_to_trajectories(const std::string& d, const std::string& calibration,
                                          const std::string& frames, const std::string& nozzle,
                                          const std::string& flags) {
  const auto calib = run_airtwin("calibrate " + calibration + " --out " + d + "/calib.yaml");
  EXPECT_EQ(calib.exit_code, 0) << calib.err;
  if (calib.exit_code != 0) return calib;
  const auto detect = run_airtwin("detect " + frames + " --calib " + d +
                                  "/calib.yaml --quiet --out " + d + "/detections.csv");
  EXPECT_EQ(detect.exit_code, 0) << detect.err;
  if (detect.exit_code != 0) return detect;
  return run_airtwin("trajectories " + d + "/detections.csv --nozzle " + nozzle +
                     " --object tracer" + flags + " --out " + d + "/data.csv");
}

// `identify` (the paper's method and library) on DIR/data.csv, the camera's trajectories, and on
// DIR/truth_data.csv, the twin's positions of the same frames: eq. (8) from each, every
// coefficient of the camera's within 5 % of the truth's.
void expect_camera_model_near_truth(const std::string& d, const std::string& label) {
  for (const char* f : {"data", "truth_data"}) {
    const auto r = run_airtwin("identify " + d + "/" + f + ".csv --out " + d + "/" + f + ".json");
    ASSERT_EQ(r.exit_code, 0) << f << ": " << r.err;
  }
  const nlohmann::json measured = read_json(d + "/data.json")["eq8"];
  const nlohmann::json reference_model = read_json(d + "/truth_data.json")["eq8"];
  ASSERT_FALSE(measured.is_null());
  ASSERT_FALSE(reference_model.is_null());
  for (const char* xi : {"xi1", "xi2", "xi3"}) {
    const double m = measured[xi].get<double>(), t = reference_model[xi].get<double>();
    std::printf("%s, %s: camera %.4f, truth %.4f, %.2f %%\n", label.c_str(), xi, m, t,
                100.0 * std::abs(m / t - 1));
    EXPECT_LE(std::abs(m / t - 1), 0.05)
        << label << ", " << xi << ": camera " << m << ", truth " << t;
  }
}

TEST(TrajectoriesCli, CameraToModelAgreesWithTheTwinsTruth) {
  const std::string d = scratch_dir("trajectories_e2e");
  write_file(d + "/ring.yaml", ring_scenario());
  const std::string pan = "0", tilt = "12.09";
  // The mirror twin: the camera's chain is checked against the model its objects follow.
  const auto render = run_airtwin(
      "render " + d + "/ring.yaml --air model --drag eq8 --frames 80 --noise low --pan " + pan +
      " --tilt " + tilt + " --seed 1 --quiet --out " + d + "/r");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  // The render's nozzle log: its one command, from the first frame on.
  EXPECT_EQ(read_text_file(d + "/r/nozzle.csv"),
            "t,pan_deg,tilt_deg\n0.000000,0.000000,12.090000\n");
  // The camera from the render's checkerboard views, then detection as on a rig's frames.
  const auto join =
      camera_to_trajectories(d, d + "/r/calibration", d + "/r/frames", d + "/r/nozzle.csv", "");
  ASSERT_EQ(join.exit_code, 0) << join.err;
  EXPECT_EQ(join.err, "");
  EXPECT_NE(join.out.find("in 12 tracks, 1 nozzle commands"), std::string::npos) << join.out;

  // The reference: the twin's positions of the same frames with the render's command.
  const CsvTable truth = CsvTable::read_file(
      d + "/r/truth.csv", {"frame", "t", "id", "object", "x", "y"}, {"x_px", "y_px"});
  std::string reference = "traj,object,t,x,y,pan_deg,tilt_deg\n";
  for (size_t row = 0; row < truth.rows(); ++row) {
    reference += truth.text(row, "id") + "," + truth.text(row, "object") + "," +
                 truth.text(row, "t") + "," + truth.text(row, "x") + "," + truth.text(row, "y") +
                 "," + pan + "," + tilt + "\n";
  }
  write_file(d + "/truth_data.csv", reference);
  ASSERT_EQ(truth.rows(), 12u * 80u);

  // The detections keep nearly every object-frame, as tracks of the twin's objects.
  const TrajectorySet data = read_trajectory_csv(d + "/data.csv");
  size_t rows = 0;
  for (const Trajectory& t : data.trajectories) {
    rows += t.samples.size();
    EXPECT_EQ(t.object, "tracer");
    for (const TrajectorySample& s : t.samples) {
      EXPECT_NEAR(rad_to_deg(s.nozzle.tilt_rad), 12.09, 1e-9);
    }
  }
  EXPECT_GE(rows, 12u * 80u * 95 / 100);

  // identify on both, the paper's method and library: eq. (8) from each, within 5 %.
  expect_camera_model_near_truth(d, "one command");
}

// Appendix D trials cut from one camera recording: three trials one after the other, each a
// ring of twelve tracers at rest around the trial's stagnation point with the jet settled at the
// trial's command (pan 0 / tilt 12.09 deg, s (0.3, 0); tilt 0, s (0, 0); pan 180 / tilt 12.09,
// s (-0.3, 0)), 1.5 s at 40 Hz each. The twin renders each trial; their frames, numbered on, are
// the recording, and the log of the three commands (at 0, 1.5 and 3 s) its nozzle log. `detect`
// reads the recording as one, `trajectories --trials` cuts it into trials, and `identify` on the
// result is compared with `identify` on the twin's positions of the same trials (the renders'
// truth.csv with each trial's command, written here without the command under test). A command
// period given to the wrong frames would put a trial under another tilt's air and move the
// coefficients by far more than 5 %. Measured: within 0.05 % (docs/identification.md).
TEST(TrajectoriesCli, AppendixDTrialsFromACameraAgreeWithTheTwinsTruth) {
  const std::string d = scratch_dir("trajectories_trials_e2e");
  struct Trial {
    double centre_x, centre_y;
    const char *pan, *tilt;
  };
  const std::vector<Trial> trials = {
      {0.3, 0.0, "0", "12.09"}, {0.0, 0.0, "0", "0"}, {-0.3, 0.0, "180", "12.09"}};
  const int frames = 60;  // per trial
  std::filesystem::create_directories(d + "/recording");
  std::string nozzle = "t,pan_deg,tilt_deg\n";
  std::string reference = "traj,object,t,x,y,pan_deg,tilt_deg\n";
  for (size_t i = 0; i < trials.size(); ++i) {
    const Trial& trial = trials[i];
    const std::string dir = d + "/trial" + std::to_string(i);
    write_file(dir + ".yaml", ring_scenario(trial.centre_x, trial.centre_y));
    // The camera's calibration views once, from the first trial's render.
    const auto render = run_airtwin(
        "render " + dir + ".yaml --air model --drag eq8 --frames " + std::to_string(frames) +
        " --noise low --pan " + trial.pan + " --tilt " + trial.tilt + " --seed " +
        std::to_string(i + 1) + (i == 0 ? "" : " --calibration-views 0") + " --quiet --out " + dir);
    ASSERT_EQ(render.exit_code, 0) << render.err;
    // The recording: this trial's frames after the previous trials' frames.
    const int first = static_cast<int>(i) * frames;
    for (int f = 0; f < frames; ++f) {
      char from[64], to[64];
      std::snprintf(from, sizeof from, "/frames/frame_%06d.png", f);
      std::snprintf(to, sizeof to, "/recording/frame_%06d.png", first + f);
      std::filesystem::copy_file(dir + from, d + to);
    }
    const double t0_s = first / 40.0;
    nozzle += std::to_string(t0_s) + "," + trial.pan + "," + trial.tilt + "\n";
    // The reference: the twin's positions in this trial, on the recording's clock.
    const CsvTable truth = CsvTable::read_file(
        dir + "/truth.csv", {"frame", "t", "id", "object", "x", "y"}, {"x_px", "y_px"});
    ASSERT_EQ(truth.rows(), 12u * frames);
    for (size_t row = 0; row < truth.rows(); ++row) {
      reference += std::to_string(i) + "." + truth.text(row, "id") + "," +
                   truth.text(row, "object") + "," + std::to_string(t0_s + truth.number(row, "t")) +
                   "," + truth.text(row, "x") + "," + truth.text(row, "y") + "," + trial.pan + "," +
                   trial.tilt + "\n";
    }
  }
  write_file(d + "/nozzle.csv", nozzle);
  write_file(d + "/truth_data.csv", reference);

  // The camera: calibrated from the checkerboard views, then detection on the whole recording.
  const auto join = camera_to_trajectories(d, d + "/trial0/calibration", d + "/recording",
                                           d + "/nozzle.csv", " --trials");
  ASSERT_EQ(join.exit_code, 0) << join.err;
  EXPECT_NE(join.out.find("3 nozzle commands (3 periods)"), std::string::npos) << join.out;
  EXPECT_NE(join.out.find("(one per trial)"), std::string::npos) << join.out;

  // Every trajectory lies in one trial and has that trial's command; nearly every object-frame
  // is kept.
  const TrajectorySet data = read_trajectory_csv(d + "/data.csv");
  size_t rows = 0;
  for (const Trajectory& t : data.trajectories) {
    rows += t.samples.size();
    const size_t trial = static_cast<size_t>(t.samples.front().t_s * 40.0 / frames + 1e-6);
    ASSERT_LT(trial, trials.size()) << t.id;
    for (const TrajectorySample& s : t.samples) {
      EXPECT_EQ(static_cast<size_t>(s.t_s * 40.0 / frames + 1e-6), trial) << t.id;
      EXPECT_NEAR(rad_to_deg(s.nozzle.pan_rad), std::stod(trials[trial].pan), 1e-9) << t.id;
      EXPECT_NEAR(rad_to_deg(s.nozzle.tilt_rad), std::stod(trials[trial].tilt), 1e-9) << t.id;
    }
  }
  EXPECT_GE(rows, 3u * 12u * frames * 95 / 100);

  // identify on both: eq. (8) from each, within 5 %.
  expect_camera_model_near_truth(d, "trials");
}

const std::string kHeader = "frame,t,id,object,x,y,x_px,y_px\n";

// Frames [first, last] of an object at (x0 + v (f - first) / 40, y), skipping `missing`.
std::string track(int first, int last, const std::string& id, const std::string& object, double x0,
                  double y, double v, int missing = -1) {
  std::string out;
  for (int f = first; f <= last; ++f) {
    if (f == missing) continue;
    char line[160];
    std::snprintf(line, sizeof line, "%d,%.6f,%s,%s,%.6f,%.6f,1.0,1.0\n", f, f / 40.0, id.c_str(),
                  object.c_str(), x0 + v * (f - first) / 40.0, y);
    out += line;
  }
  return out;
}

// Rows of separate tracks merged frame by frame (each track's text is in frame order).
std::string interleave(const std::vector<std::string>& tracks) {
  std::map<int, std::string> by_frame;
  for (const std::string& t : tracks) {
    std::istringstream in(t);
    for (std::string line; std::getline(in, line);) {
      by_frame[std::stoi(line.substr(0, line.find(',')))] += line + "\n";
    }
  }
  std::string out = kHeader;
  for (const auto& [f, rows] : by_frame) out += rows;
  return out;
}

TEST(TrajectoriesCli, CutsTrialsAndReportsWhatItDrops) {
  const std::string d = scratch_dir("trajectories_trials");
  // Track 1 lives through three commands; 2 jumps 15.5 cm at frame 30; 3 is short; 4 is cotton;
  // 5 misses frame 50.
  std::string jumper =
      track(0, 29, "2", "tracer", -0.5, 0.2, 0.2) + track(30, 60, "2", "tracer", -0.2, 0.2, 0.2);
  write_file(d + "/det.csv", interleave({track(0, 79, "1", "tracer", 0.2, 0.1, 0.4), jumper,
                                         track(10, 14, "3", "tracer", 0.5, 0.5, 0.1),
                                         track(0, 79, "4", "cotton", -0.4, -0.4, 0.1),
                                         track(20, 79, "5", "tracer", 0.0, -0.6, 0.3, 50)}));
  write_file(d + "/nozzle.csv", "t,pan_deg,tilt_deg\n-2,-90,50\n0.5,10,22.5\n1.25,45,0\n");
  const auto r = run_airtwin("trajectories " + d + "/det.csv --nozzle " + d +
                             "/nozzle.csv --object tracer --trials --out " + d + "/out/data.csv");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out,
            "trajectories: 285 detections in 5 tracks, 3 nozzle commands (3 periods)\n"
            "  not tracer: 1 tracks (80 rows)\n"
            "  dropped, a step faster than 3 m/s: 1 tracks (2); the first: track 2, 6.20 m/s into "
            "frame 30\n"
            "  dropped, shorter than 10 frames: 1 tracks, 5 rows (3)\n"
            "  cut: 1 at missed frames, 2 at command changes\n"
            "  wrote 5 trajectories (one per trial), 139 rows, to " +
                d + "/out/data.csv\n");
  // Track 1: frames 0-19 (-90, 50), 20-49 (10, 22.5), 50-79 (45, 0); track 5: 20-49, then
  // 51-79 after the missed frame (the cut at the change, frame 50, falls in the gap).
  const TrajectorySet set = read_trajectory_csv(d + "/out/data.csv");
  const std::vector<std::tuple<std::string, size_t, double, double>> expected = {
      {"1.1", 20, -90, 50},
      {"1.2", 30, 10, 22.5},
      {"1.3", 30, 45, 0},
      {"5.1", 30, 10, 22.5},
      {"5.2", 29, 45, 0}};
  ASSERT_EQ(set.trajectories.size(), 5u) << read_text_file(d + "/out/data.csv");
  for (size_t i = 0; i < expected.size(); ++i) {
    const auto& [id, n, pan, tilt] = expected[i];
    const Trajectory& t = set.trajectories[i];
    EXPECT_EQ(t.id, id);
    EXPECT_EQ(t.samples.size(), n) << id;
    for (const TrajectorySample& s : t.samples) {
      EXPECT_NEAR(rad_to_deg(s.nozzle.pan_rad), pan, 1e-9) << id;
      EXPECT_NEAR(rad_to_deg(s.nozzle.tilt_rad), tilt, 1e-9) << id;
    }
  }
}

void expect_error(const std::string& args, int code, const std::string& fragment) {
  const auto r = run_airtwin(args);
  EXPECT_EQ(r.exit_code, code) << args << "\nstderr: " << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\nstderr: " << r.err;
  EXPECT_EQ(r.out, "") << args;
}

TEST(TrajectoriesCli, BadInputIsOneClearLine) {
  const std::string d = scratch_dir("trajectories_bad");
  const std::string good = interleave({track(0, 40, "1", "tracer", 0.2, 0.1, 0.4)});
  write_file(d + "/det.csv", good);
  write_file(d + "/nozzle.csv", "t,pan_deg,tilt_deg\n0,10,20\n");
  const std::string nozzle = " --nozzle " + d + "/nozzle.csv --out " + d + "/o.csv";
  auto with = [&](const std::string& name, const std::string& text) {
    write_file(d + "/" + name, text);
    return d + "/" + name;
  };
  // Detections: unsorted, a repeated time, a reused id, NaN, a missing column.
  expect_error("trajectories " +
                   with("unsorted.csv", kHeader + track(1, 1, "1", "tracer", 0, 0, 0) +
                                            track(0, 0, "1", "tracer", 0, 0, 0)) +
                   nozzle,
               1, "unsorted.csv:3: column 'frame': expected frames in order, got 0 after frame 1");
  expect_error("trajectories " +
                   with("repeated.csv", kHeader + "0,0,1,tracer,0,0,1,1\n1,0,1,tracer,0,0,1,1\n") +
                   nozzle,
               1, "repeated.csv:3: column 't': expected a time after frame 0's 0.000000 s");
  expect_error("trajectories " +
                   with("reused.csv", interleave({track(0, 10, "1", "tracer", 0, 0, 0.1),
                                                  track(11, 30, "2", "tracer", 0, 0.03, 0.1),
                                                  track(20, 30, "1", "tracer", 0.5, 0.5, 0)})) +
                   nozzle,
               1, "reused.csv:23: column 'id': track '1' reappears in frame 20 after 9 frames");
  expect_error("trajectories " + with("nan.csv", kHeader + "0,0,1,tracer,0,NaN,1,1\n") + nozzle, 1,
               "nan.csv:2: column 'y': expected a finite number, got 'NaN'");
  expect_error("trajectories " + with("nocol.csv", "frame,t,id,x,y\n0,0,1,0,0\n") + nozzle, 1,
               "nocol.csv: missing column 'object'");
  // The nozzle log: starting after the first frame, a repeated time, not a number.
  const std::string det = "trajectories " + d + "/det.csv --out " + d + "/o.csv --nozzle ";
  expect_error(det + with("late.csv", "t,pan_deg,tilt_deg\n0.1,10,20\n"), 1,
               "late.csv:2: column 't': the first command is at 0.100000 s, after the "
               "recording's first frame");
  expect_error(det + with("twice.csv", "t,pan_deg,tilt_deg\n0,10,20\n0,10,30\n"), 1,
               "twice.csv:3: column 't': expected a time after line 2's 0 s");
  expect_error(det + with("word.csv", "t,pan_deg,tilt_deg\n0,ten,20\n"), 1,
               "word.csv:2: column 'pan_deg': expected a finite number, got 'ten'");
  expect_error(det + d + "/none.csv", 1, "none.csv: cannot open file");
  // Nothing left: a clear error, no file.
  expect_error(det + d + "/nozzle.csv --min-frames 50", 1, "no trajectory left to write");
  // Flags: usage errors naming the flag.
  expect_error(det + d + "/nozzle.csv --min-frames 1", 2, "--min-frames: expected");
  expect_error(det + d + "/nozzle.csv --max-speed -1", 2, "--max-speed: expected");
  expect_error(det + d + "/nozzle.csv --max-missed -1", 2, "--max-missed: expected");
  expect_error(det + d + "/nozzle.csv --object pebble", 2, "--object: unknown object type");
  expect_error("trajectories " + d + "/det.csv --out " + d + "/o.csv", 2, "--nozzle is required");
  EXPECT_FALSE(std::filesystem::exists(d + "/o.csv"));
}

}  // namespace
}  // namespace airtwin
