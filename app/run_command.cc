// airtwin run: one closed-loop run of a scenario in the twin (runs/scenario_run.h). Writes
// DIR/summary.json, DIR/log.csv (the trajectory CSV, nozzle commands included),
// DIR/decisions.csv, DIR/plans.csv and DIR/nozzle.csv (the commands sent to the nozzle).

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "app/run_setup.h"
#include "common/errors.h"
#include "controller/cem_planner.h"
#include "runs/run_video.h"
#include "runs/scenario_run.h"
#include "scenes/scenario.h"

namespace airtwin::cli {
namespace {

struct RunArgs {
  std::string scenario;
  std::string out;
  RunSetupFlags setup;
  std::string video;
  int video_stride = 1;
  uint64_t seed = 0;
  int planner_threads = 1;
  bool quiet = false;
};

void run_run(const RunArgs& a) {
  // Flags first: nothing is read or written for a run that cannot start.
  if (a.video_stride < 1) throw UsageError("--video-stride must be >= 1");
  check_run_setup_flags(a.setup);
  const Scenario scenario = read_scenario(a.scenario);
  const AirFieldModel field = field_model_of(a.setup);
  ScenarioRunOptions options = run_options_of(a.setup);
  options.seed = a.seed;
  if (a.planner_threads < 1 || a.planner_threads > CemPlanner::kMaxThreads) {
    throw UsageError("--planner-threads must be in [1, " + std::to_string(CemPlanner::kMaxThreads) +
                     "]");
  }
  options.planner_threads = a.planner_threads;
  check_user_scene(a.setup, scenario, options);
  std::unique_ptr<Progress> progress;
  const int limit = static_cast<int>(scenario.task.time_limit_s);
  if (!a.quiet)
    progress = std::make_unique<Progress>("run " + scenario.name, "s", std::max(1, limit));
  options.on_progress = [&](double t, double) {
    if (progress) progress->update(std::min(limit, static_cast<int>(t)));
  };

  std::filesystem::create_directories(a.out);
  if (a.setup.vision) {
    // Without --calib, the twin's camera is calibrated with the run's seed: DIR/calibration and
    // DIR/calib.yaml.
    options.vision_camera = vision_camera_of(a.setup, options, a.out, a.seed);
  }
  std::unique_ptr<RunVideo> video;
  if (!a.video.empty()) {
    ensure_parent_dir(a.video);
    video = std::make_unique<RunVideo>(
        a.video, scenario.task, scenario.name + " seed " + std::to_string(a.seed), a.video_stride);
    options.on_frame = [&](const Twin& twin, int64_t frame,
                           const std::vector<DecisionRecord>& decisions) {
      video->on_frame(twin, frame, decisions);
    };
  }
  const ScenarioRunResult result = run_scenario(scenario, field, options);
  if (progress) progress->finish();
  if (video) {
    const VideoSummary v = video->close();
    std::printf("video %s: %lld frames, %.1f s at %.0fx the simulation's speed\n", v.path.c_str(),
                static_cast<long long>(v.frames_written), v.video_seconds,
                static_cast<double>(a.video_stride));
  }
  write_text_file(a.out + "/summary.json", run_summary_json(result, scenario.task.time_limit_s));
  write_text_file(a.out + "/log.csv", trajectory_csv(result.log));
  write_text_file(a.out + "/decisions.csv", decisions_csv(result));
  write_text_file(a.out + "/plans.csv", plans_csv(result));
  write_text_file(a.out + "/nozzle.csv", nozzle_log_csv(result.nozzle_log));
  if (a.setup.vision) write_text_file(a.out + "/detections.csv", result.vision_detections_csv);

  std::printf("%s seed %llu: %s", scenario.name.c_str(), static_cast<unsigned long long>(a.seed),
              result.success ? "success" : "FAILED");
  if (result.loop.success && !result.success) {
    std::printf(
        " (the controller saw the task done; in the twin's truth only %d of %d are in"
        " their zones)",
        result.objects_in_zone, result.n_objects);
  }
  if (result.success && result.loop.completion_time_s) {
    std::printf(" in %.1f s", *result.loop.completion_time_s);
  } else if (result.loop.lost_every_object) {
    std::printf(" (at %.1f s the perception had lost every object)", result.loop.end_time_s);
  } else if (!result.loop.success) {
    std::printf(" (time limit %.0f s", scenario.task.time_limit_s);
    if (run_stalled(result.success, result.loop.end_time_s, result.still_since_s)) {
      std::printf("; stalled: no object moved more than 1 cm after %.1f s", result.still_since_s);
    }
    if (result.loop.objects_seen_at_end < result.n_objects) {
      std::printf("; the perception saw %d of the %d objects at the end",
                  result.loop.objects_seen_at_end, result.n_objects);
    }
    std::printf(")");
  }
  if (result.path_error_m.count > 0) {
    std::printf(", path error mean %.2f cm, max %.2f cm", 100.0 * result.path_error_m.mean,
                100.0 * result.path_error_m.max);
  }
  std::printf(", %d/%d objects in zone, max pairwise %.1f cm, %zu decisions (%.2f ms mean)\n",
              result.objects_in_zone, result.n_objects, 100.0 * result.max_pairwise_distance_m,
              result.loop.decisions.size(), result.decision_ms_mean);
  std::printf("wrote %s/summary.json, log.csv, decisions.csv, plans.csv, nozzle.csv%s\n",
              a.out.c_str(), a.setup.vision ? ", detections.csv" : "");
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* sub = app.add_subcommand(
      "run",
      "Run a scenario in closed loop in the MuJoCo twin: the CEM controller of section V (eq. 10)\n"
      "plans on the field model and the identified dynamics, aims the twin's nozzle, waits\n"
      "Delta T plus the settle time, observes, repeats until the task is done or time is up.\n"
      "Writes DIR/summary.json, DIR/log.csv (trajectory CSV), DIR/decisions.csv,\n"
      "DIR/plans.csv (what each decision perceived and predicted, per object) and\n"
      "DIR/nozzle.csv (the commands sent to the nozzle, t,pan_deg,tilt_deg); with --vision\n"
      "DIR/detections.csv (what the camera pipeline detected, as `detect` writes it).\n"
      "Scenarios: scenes/*.yaml (docs/scenario_schema.md).");
  sub->add_option("scenario", args->scenario, "Scenario file (YAML)")->required();
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->add_option("--seed", args->seed, "Seed of the twin and the controller")
      ->capture_default_str();
  sub->add_option("--video", args->video,
                  "Write the top camera with the overlay as H.264 MP4 (1024x1024, 40 fps) and a\n"
                  "sidecar FILE.mp4.json");
  sub->add_option("--video-stride", args->video_stride,
                  "Keep every k-th camera frame in the video (it then plays k times faster)")
      ->capture_default_str();
  add_run_setup_flags(sub, args->setup,
                      "calibrate the twin's camera into DIR/calibration and DIR/calib.yaml");
  sub->add_option("--planner-threads", args->planner_threads,
                  "Threads that predict each decision's candidates: the same run for any number,\n"
                  "each decision sooner on a machine with the cores (decisions.csv's decision_ms)")
      ->capture_default_str();
  sub->add_flag("--quiet", args->quiet, "No progress display");
  sub->callback([args] { run_run(*args); });
}

}  // namespace airtwin::cli
