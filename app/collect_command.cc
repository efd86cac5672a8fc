// airtwin collect: the Appendix D protocol in the twin (sim/collection.h), positions from the
// twin's truth or, with --vision, through the rendered camera and the detection pipeline
// (runs/camera_collection.h). Writes the trajectory CSV that `airtwin identify` and
// `airtwin discrepancy` read.

#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "common/csv.h"
#include "common/errors.h"
#include "common/units.h"
#include "models/field_model_file.h"
#include "rigs/vision_perception.h"
#include "runs/camera_collection.h"
#include "sim/collection.h"
#include "sim/effects.h"

namespace airtwin::cli {
namespace {

struct CollectArgs {
  std::string tilts = "0,22.5";
  std::string table;
  std::string out;
  bool quiet = false;
  std::vector<std::string> effects;
  AirFlags air;
  CollectionOptions options;
  bool vision = false;
  std::string calib;
  std::string noise = "none";
  std::string truth_out;
  std::string protocol = "reaim";
  std::string launch_speed = "0.5,2.5";
  std::string vary_physics = "none";
};

// Where --vary-physics's record of each trial's object goes: <out stem>_objects.csv.
std::string objects_path(const std::string& out) {
  const std::filesystem::path p(out);
  return ((p.parent_path() / p.stem()).string() + "_objects.csv");
}

// The camera model of --vision: --calib's, or the twin's camera calibrated from rendered
// checkerboard views as `run --vision` does, the views into <out stem>_calibration/ and the model
// into <out stem>_calib.yaml beside the output.
CalibratedCamera collection_camera(const CollectArgs& a, const NoiseLevel& noise) {
  if (!a.calib.empty()) return CalibratedCamera::read(a.calib);
  const std::filesystem::path out(a.out);
  const std::string stem = (out.parent_path() / out.stem()).string();
  const CalibratedCamera camera =
      calibrate_twin_camera(stem + "_calibration", a.options.twin.scene, a.options.seed,
                            noise.noise_sigma_grey, noise.blur_sigma_px);
  camera.write(stem + "_calib.yaml");
  std::printf("calibrated the camera from rendered checkerboard views: RMS %.3f px, %s\n",
              camera.rms_reprojection_px, (stem + "_calib.yaml").c_str());
  return camera;
}

// --vision: the trials through the camera; prints what was kept and dropped, and the camera's
// error against the twin's truth.
TrajectorySet collect_through_camera(const CollectArgs& a, const AirFieldModel& field,
                                     const std::function<void(int, int)>& progress) {
  const NoiseLevel noise = parse_noise(a.noise);
  CameraCollectionOptions co;
  co.collection = a.options;
  co.noise_sigma_grey = noise.noise_sigma_grey;
  co.blur_sigma_px = noise.blur_sigma_px;
  const CalibratedCamera camera = collection_camera(a, noise);
  const CameraCollectionResult r = run_camera_collection(co, field, camera, progress);
  if (!a.truth_out.empty()) write_text_file(a.truth_out, trajectory_csv(r.truth));
  std::printf(
      "camera: kept %d of %d trials, dropped %d (%d not found at the start, %d lost, %d left the "
      "view); camera against truth over %lld positions: RMS %.2f mm, max %.2f mm\n",
      r.kept, r.planned, r.dropped(), r.not_found_at_start, r.lost, r.left_view,
      static_cast<long long>(r.positions), 1e3 * r.rms_error_m, 1e3 * r.max_error_m);
  return r.camera;
}

void run_collect(CollectArgs a) {
  CollectionOptions& o = a.options;
  o.tilts_rad = parse_degree_list(a.tilts, "--tilts");
  if (!a.table.empty() && a.air.air != "model") throw UsageError("--table needs --air model");
  if (!a.vision && (!a.calib.empty() || a.noise != "none" || !a.truth_out.empty())) {
    throw UsageError("--calib, --noise and --truth-out need --vision");
  }
  parse_noise(a.noise);
  with_flags(kCollectionFlags, [&] { o.protocol = parse_collection_protocol(a.protocol); });
  if (a.launch_speed != CollectArgs().launch_speed && o.protocol != CollectionProtocol::kLaunched) {
    throw UsageError("--launch-speed needs --protocol launched");
  }
  const Eigen::Vector2d launch = parse_xy(a.launch_speed, "--launch-speed");
  o.min_launch_speed_mps = launch.x();
  o.max_launch_speed_mps = launch.y();
  o.physics_variation = parse_vary_physics(a.vary_physics);
  apply_air_flags(a.air, &o.twin);
  const std::vector<Effect> effects = apply_effect_flags(a.effects, &o.twin);
  with_flags(kCollectionFlags, [&] { o.validate(); });
  const AirFieldModel field = field_model_or_default(a.table);
  ensure_parent_dir(a.out);
  const int total = static_cast<int>(o.tilts_rad.size()) * o.per_tilt;
  std::unique_ptr<Progress> progress;
  if (!a.quiet) progress = std::make_unique<Progress>("collect", "trials", total);
  if (!a.truth_out.empty()) ensure_parent_dir(a.truth_out);
  const auto report = [&](int done, int) {
    if (progress) progress->update(done);
  };
  const TrajectorySet set =
      a.vision ? collect_through_camera(a, field, report) : run_collection(o, field, report);
  if (progress) progress->finish();
  write_text_file(a.out, trajectory_csv(set));
  if (o.physics_variation.active()) {
    write_text_file(objects_path(a.out), collection_objects_csv(o));
  }
  std::string effect_list;
  for (const Effect& e : effects)
    effect_list += (effect_list.empty() ? "" : " ") + effect_to_string(e);
  std::printf(
      "collected %d %s trajectories (%d per tilt, protocol %s, seed %llu, %s air%s%s%s) "
      "into %s\n",
      static_cast<int>(set.trajectories.size()), o.object.c_str(), o.per_tilt,
      collection_protocol_name(o.protocol), static_cast<unsigned long long>(o.seed),
      a.air.air.c_str(), effects.empty() ? "" : ", effects ", effect_list.c_str(),
      a.vision ? ", through the camera" : "", a.out.c_str());
  if (o.physics_variation.active()) {
    std::printf("each trial's object (--vary-physics %s) in %s\n",
                o.physics_variation.to_string().c_str(), objects_path(a.out).c_str());
  }
}

}  // namespace

void add_collect_command(CLI::App& app) {
  auto args = std::make_shared<CollectArgs>();
  CLI::App* sub = app.add_subcommand(
      "collect",
      "Run the data collection of Appendix D in the MuJoCo twin: per trial an object is placed\n"
      "20-58 cm from the trial's stagnation point with the nozzle idle (pan -90, tilt 50 deg),\n"
      "the jet runs 8 s, the nozzle turns to the trial's orientation (random pan, given tilt) and\n"
      "the object is recorded 2 s at 40 Hz. Writes the trajectory CSV\n"
      "(traj,object,t,x,y,pan_deg,tilt_deg) that 'airtwin identify' reads. docs/twin.md.");
  CollectionOptions& o = args->options;
  sub->add_option("--object", o.object, "tracer | cotton")->capture_default_str();
  sub->add_option("--tilts", args->tilts, "Comma-separated tilts (deg)")->capture_default_str();
  sub->add_option("--per-tilt", o.per_tilt, "Trials per tilt")->capture_default_str();
  sub->add_option("--seed", o.seed, "Seed of the plan and of each trial's twin")
      ->capture_default_str();
  sub->add_option("--wait", o.wait_s, "Seconds the jet runs at idle before the re-aim")
      ->capture_default_str();
  sub->add_option("--record", o.record_s, "Seconds recorded after the re-aim")
      ->capture_default_str();
  sub->add_option(
         "--lead-in", o.lead_in_s,
         "Seconds recorded before the re-aim, at the idle command (t < 0): the data then\n"
         "show the command change, which 'airtwin discrepancy' needs to tell a response delay")
      ->capture_default_str();
  sub->add_option(
         "--protocol", args->protocol,
         "How each trial starts: reaim (Appendix D: the nozzle turns from idle at t = 0),\n"
         "placed (the object is released at t = 0 into the trial's steady air: the nozzle\n"
         "never moves, no lead-in), mixed (trials alternate, even re-aimed, odd placed):\n"
         "starts from rest where a late response of the nozzle plays no part, or launched\n"
         "(the object slides off at t = 0 under the idle nozzle and coasts to rest, as from a\n"
         "chute: its friction beyond the air, with no air term at work)")
      ->capture_default_str();
  sub->add_option("--release-after", o.release_s,
                  "Seconds into the record at which the nozzle turns back to idle, so that the\n"
                  "object coasts from its speed in still air (recorded with the idle command);\n"
                  "0: never, as Appendix D")
      ->capture_default_str();
  sub->add_option("--launch-speed", args->launch_speed,
                  "With --protocol launched: MIN,MAX (m/s), the launch speeds' uniform range")
      ->capture_default_str();
  o.threads = 0;  // every core by default: the result does not depend on the thread count
  sub->add_option("--threads", o.threads, "Twins in parallel (0: one per core)")
      ->capture_default_str();
  add_air_flags(sub, args->air);
  sub->add_option(
      "--table", args->table,
      std::string("With --air model: the twin's air model (a coefficient table CSV or a\n"
                  "field-model JSON); ") +
          kDefaultFieldModelHelp);
  sub->add_option("--out", args->out, "Output trajectory CSV")->required();
  sub->add_option("--vary-physics", args->vary_physics,
                  "Each trial's object its own physics, drawn from the trial's seed: 'documented'\n"
                  "or a spread F in (0, 0.5] (as run's); written to <out stem>_objects.csv")
      ->capture_default_str();
  sub->add_option("--effect", args->effects,
                  "Switch on a physical effect the nominal model lacks, NAME or "
                  "NAME:key=value,...; repeatable. Effects:\n" +
                      effect_help());
  sub->add_flag("--vision", args->vision,
                "Record each trial through the twin's rendered top camera and the detection\n"
                "pipeline (calibrated camera, detection, tracking) instead of the twin's truth;\n"
                "trials whose object is not followed over the record are dropped and counted");
  sub->add_option(
      "--calib", args->calib,
      "With --vision: the camera model (calib.yaml from 'airtwin calibrate'); default:\n"
      "the twin's camera calibrated from rendered checkerboard views, written beside\n"
      "--out as <stem>_calib.yaml (views in <stem>_calibration/)");
  sub->add_option("--noise", args->noise, "With --vision: sensor noise none | low | high")
      ->capture_default_str();
  sub->add_option("--truth-out", args->truth_out,
                  "With --vision: also write the twin's positions of the kept trials' frames");
  sub->add_flag("--quiet", args->quiet, "No progress on stderr");
  sub->callback([args] { run_collect(*args); });
}

}  // namespace airtwin::cli
