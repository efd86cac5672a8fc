#include "app/run_setup.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/cli_common.h"
#include "common/errors.h"
#include "models/field_model_file.h"
#include "sim/effects.h"
#include "sim/scene_builder.h"

namespace airtwin::cli {

void add_run_setup_flags(CLI::App* sub, RunSetupFlags& f, const std::string& calib_default) {
  sub->add_option(
      "--table", f.table,
      std::string("The controller's air model (and with --air model the twin's): a\n"
                  "coefficient table CSV or a field-model JSON (eq. (2)'s a1, a2 and a\n"
                  "table); ") +
          kDefaultFieldModelHelp);
  sub->add_option("--model", f.models,
                  "model.json from 'airtwin identify' or extended_model.json from 'airtwin\n"
                  "discrepancy' (repeatable, one per object type): the dynamics the controller\n"
                  "plans with (default: in the physical twin, CFD air and physical drag, the\n"
                  "models fitted to it, models/data/twin/extended_model.json, with\n"
                  "--no-air-turbulence-swept models/data/twin_lagrangian/; otherwise the paper's\n"
                  "eq. (8))");
  sub->add_option("--effect", f.effects,
                  "Switch on a physical effect in the twin, NAME:k=v,... (repeatable)");
  add_air_flags(sub, f.air);
  sub->add_option("--mjcf", f.mjcf,
                  "Simulate this MJCF scene (e.g. `airtwin scene`'s scene.xml, edited) instead of\n"
                  "building it; the scenario still gives the task and the objects (docs/twin.md)");
  sub->add_option(
         "--vary-physics", f.vary_physics,
         "Each object gets its own physics, drawn from the seed: 'documented' (every\n"
         "parameter uniform over the range docs/twin.md gives for its type) or a spread F\n"
         "in (0, 0.5] (within +-F of its type's value); mass, C_D, mu_k, mu_s/mu_k, C_L")
      ->capture_default_str();
  sub->add_flag(
      "--vision", f.vision,
      "The controller sees through the detection pipeline on rendered frames (calibrated\n"
      "camera, detection, tracking) instead of the twin's truth");
  sub->add_option(
      "--calib", f.calib,
      "With --vision: the camera model (calib.yaml from 'airtwin calibrate'); default:\n" +
          calib_default);
  sub->add_option("--vision-rate", f.vision_rate_hz,
                  "With --vision: frames detected per simulated second (divides 40)")
      ->capture_default_str();
  sub->add_option("--noise", f.noise, "With --vision: sensor noise none | low | high")
      ->capture_default_str();
}

void check_run_setup_flags(const RunSetupFlags& f) {
  if (!f.vision && (!f.calib.empty() || f.noise != "none" || f.vision_rate_hz != 10.0)) {
    throw UsageError("--calib, --noise and --vision-rate need --vision");
  }
  parse_noise(f.noise);
  const double frames_per_detection = 40.0 / f.vision_rate_hz;
  if (!(f.vision_rate_hz > 0.0 && frames_per_detection <= 40.0 &&
        std::fabs(frames_per_detection - std::round(frames_per_detection)) < 1e-9)) {
    throw UsageError("--vision-rate must divide the camera's 40 Hz (40, 20, 10, 8, 5, ...)");
  }
  TwinParameters scratch;
  apply_effect_flags(f.effects, &scratch);
  check_air_flags(f.air);
  if (physics_variation_of(f).active() && !f.mjcf.empty()) {
    throw UsageError(
        "--vary-physics needs the scene the twin builds: a --mjcf scene keeps its "
        "own masses and friction");
  }
}

PhysicsVariation physics_variation_of(const RunSetupFlags& f) {
  return parse_vary_physics(f.vary_physics);
}

std::vector<std::string> controller_models(const RunSetupFlags& f) {
  if (!f.models.empty()) return f.models;
  return default_controller_models(f.air.air == "cfd", f.air.drag == "physical",
                                   !f.air.no_turbulence_swept);
}

AirFieldModel field_model_of(const RunSetupFlags& f) { return field_model_or_default(f.table); }

ScenarioRunOptions run_options_of(const RunSetupFlags& f) {
  ScenarioRunOptions options;
  // The twin's physics: its air, with the effects switched on.
  apply_air_flags(f.air, &options.twin);
  apply_effect_flags(f.effects, &options.twin);
  options.twin.scene_file = f.mjcf;
  options.physics_variation = physics_variation_of(f);
  // The dynamics the controller plans with, per object type (and an extended model's
  // extensions).
  const std::vector<std::string> models = controller_models(f);
  if (!models.empty()) plan_with_model_files(models, field_model_of(f), &options);
  // The vision pipeline's sensor and rate.
  if (f.vision) {
    const NoiseLevel noise = parse_noise(f.noise);
    options.vision.rate_hz = f.vision_rate_hz;
    options.vision.noise_sigma_grey = noise.noise_sigma_grey;
    options.vision.blur_sigma_px = noise.blur_sigma_px;
  }
  return options;
}

void check_user_scene(const RunSetupFlags& f, const Scenario& scenario,
                      const ScenarioRunOptions& options) {
  if (!f.mjcf.empty()) load_scene(f.mjcf, scenario.scene, options.twin.scene);
}

CalibratedCamera vision_camera_of(const RunSetupFlags& f, const ScenarioRunOptions& options,
                                  const std::string& dir, uint64_t seed) {
  if (!f.calib.empty()) return CalibratedCamera::read(f.calib);
  const CalibratedCamera camera =
      calibrate_twin_camera(dir + "/calibration", options.twin.scene, seed,
                            options.vision.noise_sigma_grey, options.vision.blur_sigma_px);
  camera.write(dir + "/calib.yaml");  // whole or not at all
  return camera;
}

}  // namespace airtwin::cli
