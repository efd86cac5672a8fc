#pragma once
// The physical twin as `airtwin run` builds it by default, for tests that run scenarios in it
// (header-only; the tests that include it link airtwin_runs): the shipped CFD's air with the wall
// jet's lag and formation at their defaults, physical drag with the calibrated parameters
// (sim/scene_spec.cc; docs/twin.md), and the controller's models fitted to that twin
// (models/data/cfd_fitted_field_model.json, models/data/twin/, scripts/fit_twin_models.sh).

#include <memory>

#include "models/cfd_field.h"
#include "models/field_model_file.h"
#include "runs/scenario_run.h"
#include "tests/support/shipped_cfd.h"

namespace airtwin::testing {

/// The twin: CFD air, every object type on physical drag with its default parameters.
inline TwinParameters physical_twin() {
  TwinParameters p;
  p.cfd_air = shipped_cfd();
  p.scene.tracer.use_physical_drag();
  p.scene.cotton.use_physical_drag();
  return p;
}

/// The controller's field model in CFD air: eq. (2) and the table fitted to the CFD.
inline AirFieldModel cfd_fitted_field() {
  return read_air_field_model(AIRTWIN_SOURCE_DIR "/models/data/cfd_fitted_field_model.json");
}

/// Run options in the physical twin, planning with the shipped models of it.
inline ScenarioRunOptions physical_twin_run_options(const AirFieldModel& field) {
  ScenarioRunOptions options;
  options.twin = physical_twin();
  plan_with_model_files({AIRTWIN_SOURCE_DIR "/models/data/twin/extended_model.json"}, field,
                        &options);
  return options;
}

}  // namespace airtwin::testing
