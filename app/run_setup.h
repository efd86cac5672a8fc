#pragma once
// What `run`, `view` and `batch` share: the flags that set up a closed-loop run besides the
// scenario and the seed (field table, identified models, twin effects, a user's MJCF scene,
// vision), their checks, and their translation into ScenarioRunOptions (runs/scenario_run.h).

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "app/cli_common.h"
#include "models/air_field.h"
#include "runs/scenario_run.h"
#include "scenes/scenario.h"
#include "vision/calibrated_camera.h"

namespace airtwin::cli {

struct RunSetupFlags {
  std::string table;
  std::vector<std::string> models;
  std::vector<std::string> effects;
  std::string mjcf;  ///< a user's MJCF scene ("": the twin builds it)
  bool vision = false;
  std::string calib;
  double vision_rate_hz = 10.0;
  std::string noise = "none";
  /// --vary-physics: none, documented or a spread (sim/physics_variation.h).
  std::string vary_physics = "none";
  AirFlags air;
};

/// Adds --table, --model, --effect, --air, --cfd, --mjcf, --vary-physics, --vision, --calib,
/// --vision-rate and --noise to `sub`.
/// `calib_default` completes --calib's help: what happens without it.
void add_run_setup_flags(CLI::App* sub, RunSetupFlags& flags, const std::string& calib_default);

/// Throws UsageError naming the flag: vision-only flags without --vision, an unknown --noise, a
/// --vision-rate that does not divide the camera's 40 Hz, a malformed --effect or
/// --vary-physics, --vary-physics with --mjcf (a user's scene keeps its own masses and
/// friction). Reads no file.
void check_run_setup_flags(const RunSetupFlags& flags);

/// --vary-physics's variation; UsageError naming the flag and the text when malformed.
PhysicsVariation physics_variation_of(const RunSetupFlags& flags);

/// The dynamics the controller plans with, unless --model names others: in the physical twin (CFD
/// air, physical drag) the dynamics identified in it and extended by the discrepancy analysis of
/// its closed-loop logs (models/data/twin/extended_model.json, scripts/fit_twin_models.sh),
/// otherwise the paper's eq. (8) (none).
std::vector<std::string> controller_models(const RunSetupFlags& flags);

/// The controller's field model (and the model air's, with --air model): --table's, or the
/// default one fitted to the CFD (field_model_or_default). Throws InputError for a bad file.
AirFieldModel field_model_of(const RunSetupFlags& flags);

/// The run options the flags set (the seed is left 0): the twin's air and effects, the dynamics of
/// controller_models' files, the vision pipeline's rate, noise and blur (the camera is
/// vision_camera_of's).
/// Throws InputError for an unreadable model or one that names no object type.
ScenarioRunOptions run_options_of(const RunSetupFlags& flags);

/// With --mjcf: checks that the file is a scene the twin can simulate `scenario` in (load_scene,
/// sim/scene_builder.h), so that a bad one fails before anything runs or opens. Throws InputError
/// "<file>: <element>: <what is wrong>; expected ..." for the first thing missing.
void check_user_scene(const RunSetupFlags& flags, const Scenario& scenario,
                      const ScenarioRunOptions& options);

/// With --vision: --calib's camera, or the twin's camera calibrated as a user calibrates the rig's
/// (checkerboard views rendered into `dir`/calibration with `seed` and the flags' noise and blur,
/// the result written to `dir`/calib.yaml, which appears complete or not at all). Throws InputError
/// for a bad --calib file.
CalibratedCamera vision_camera_of(const RunSetupFlags& flags, const ScenarioRunOptions& options,
                                  const std::string& dir, uint64_t seed);

}  // namespace airtwin::cli
