// airtwin run: one closed-loop run of a scenario in the twin (rigs/scenario_run.h). Writes
// DIR/summary.json, DIR/log.csv (the trajectory CSV, nozzle commands included) and
// DIR/decisions.csv.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "common/errors.h"
#include "models/identified_model.h"
#include "rigs/run_video.h"
#include "rigs/scenario_run.h"
#include "scenes/scenario.h"
#include "sim/effects.h"

namespace airtwin::cli {
namespace {

struct RunArgs {
  std::string scenario;
  std::string out;
  std::string table;
  std::vector<std::string> models;
  std::vector<std::string> effects;
  std::string video;
  int video_stride = 1;
  bool vision = false;
  std::string calib;
  double vision_rate_hz = 10.0;
  std::string noise = "none";
  uint64_t seed = 0;
  bool quiet = false;
};

void run_run(const RunArgs& a) {
  // Flags first: nothing is read or written for a run that cannot start.
  if (a.video_stride < 1) throw UsageError("--video-stride must be >= 1");
  if (!a.vision && (!a.calib.empty() || a.noise != "none" || a.vision_rate_hz != 10.0)) {
    throw UsageError("--calib, --noise and --vision-rate need --vision");
  }
  const NoiseLevel noise = parse_noise(a.noise);
  const double frames_per_detection = 40.0 / a.vision_rate_hz;
  if (!(a.vision_rate_hz > 0.0 && frames_per_detection <= 40.0 &&
        std::fabs(frames_per_detection - std::round(frames_per_detection)) < 1e-9)) {
    throw UsageError("--vision-rate must divide the camera's 40 Hz (40, 20, 10, 8, 5, ...)");
  }
  const Scenario scenario = read_scenario(a.scenario);
  const AirFieldModel field = a.table.empty()
                                  ? AirFieldModel::with_default_table()
                                  : AirFieldModel(NozzleGeometry{}, FieldTable::load_csv(a.table));
  ScenarioRunOptions options;
  options.seed = a.seed;
  std::vector<Effect> effects;
  for (const std::string& text : a.effects) effects.push_back(parse_effect(text));
  apply_effects(effects, &options.twin);
  for (const std::string& path : a.models) {
    const IdentifiedModel model = read_identified_model(path);
    if (model.object.empty()) {
      throw InputError(path + ": the model names no object type (identify it with --object)");
    }
    options.dynamics[model.object] = model.eq8();
  }
  std::unique_ptr<Progress> progress;
  const int limit = static_cast<int>(scenario.task.time_limit_s);
  if (!a.quiet) progress = std::make_unique<Progress>("run " + scenario.name, "s", std::max(1, limit));
  options.on_progress = [&](double t, double) {
    if (progress) progress->update(std::min(limit, static_cast<int>(t)));
  };

  std::filesystem::create_directories(a.out);
  if (a.vision) {
    const double sigma = noise.noise_sigma_grey, blur = noise.blur_sigma_px;
    options.vision.rate_hz = a.vision_rate_hz;
    options.vision.noise_sigma_grey = sigma;
    options.vision.blur_sigma_px = blur;
    if (!a.calib.empty()) {
      options.vision_camera = CalibratedCamera::read(a.calib);
    } else {
      // Calibrate the twin's camera as a user calibrates the rig's: frames of a checkerboard on
      // the floor, kept in DIR/calibration with the result in DIR/calib.yaml.
      options.vision_camera = calibrate_twin_camera(a.out + "/calibration", options.twin.scene,
                                                    a.seed, sigma, blur);
      options.vision_camera->write(a.out + "/calib.yaml");
    }
  }
  std::unique_ptr<RunVideo> video;
  if (!a.video.empty()) {
    ensure_parent_dir(a.video);
    video = std::make_unique<RunVideo>(a.video, scenario.task,
                                       scenario.name + " seed " + std::to_string(a.seed),
                                       a.video_stride);
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

  std::printf("%s seed %llu: %s", scenario.name.c_str(),
              static_cast<unsigned long long>(a.seed), result.loop.success ? "success" : "FAILED");
  if (result.loop.completion_time_s) {
    std::printf(" in %.1f s", *result.loop.completion_time_s);
  } else {
    std::printf(" (time limit %.0f s)", scenario.task.time_limit_s);
  }
  if (result.path_error_m.count > 0) {
    std::printf(", path error mean %.2f cm, max %.2f cm", 100.0 * result.path_error_m.mean,
                100.0 * result.path_error_m.max);
  }
  std::printf(", %d/%d objects in zone, max pairwise %.1f cm, %zu decisions (%.2f ms mean)\n",
              result.objects_in_zone, result.n_objects, 100.0 * result.max_pairwise_distance_m,
              result.loop.decisions.size(), result.decision_ms_mean);
  std::printf("wrote %s/summary.json, log.csv, decisions.csv\n", a.out.c_str());
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* sub = app.add_subcommand(
      "run",
      "Run a scenario in closed loop in the MuJoCo twin: the CEM controller of section V (eq. 10)\n"
      "plans on the field model and the identified dynamics, aims the twin's nozzle, waits\n"
      "Delta T plus the settle time, observes, repeats until the task is done or time is up.\n"
      "Writes DIR/summary.json, DIR/log.csv (trajectory CSV) and DIR/decisions.csv.\n"
      "Scenarios: scenes/*.yaml (docs/scenario_schema.md).");
  sub->add_option("scenario", args->scenario, "Scenario file (YAML)")->required();
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->add_option("--seed", args->seed, "Seed of the twin and the controller")
      ->capture_default_str();
  sub->add_option("--table", args->table, "Field coefficient table (default: built in)");
  sub->add_option("--model", args->models,
                  "model.json from 'airtwin identify' (repeatable, one per object type): the\n"
                  "dynamics the controller plans with instead of the paper's eq. (8)");
  sub->add_option("--effect", args->effects,
                  "Switch on a physical effect in the twin, NAME:k=v,... (repeatable)");
  sub->add_option("--video", args->video,
                  "Write the top camera with the overlay as H.264 MP4 (1024x1024, 40 fps) and a\n"
                  "sidecar FILE.mp4.json");
  sub->add_option("--video-stride", args->video_stride,
                  "Keep every k-th camera frame in the video (it then plays k times faster)")
      ->capture_default_str();
  sub->add_flag("--vision", args->vision,
               "The controller sees through the detection pipeline on rendered frames (calibrated\n"
               "camera, detection, tracking) instead of the twin's truth");
  sub->add_option("--calib", args->calib,
                  "With --vision: the camera model (calib.yaml from 'airtwin calibrate'); default:\n"
                  "calibrate the twin's camera into DIR/calibration and DIR/calib.yaml");
  sub->add_option("--vision-rate", args->vision_rate_hz,
                  "With --vision: frames detected per simulated second (divides 40)")
      ->capture_default_str();
  sub->add_option("--noise", args->noise, "With --vision: sensor noise none | low | high")
      ->capture_default_str();
  sub->add_flag("--quiet", args->quiet, "No progress display");
  sub->callback([args] { run_run(*args); });
}

}  // namespace airtwin::cli
