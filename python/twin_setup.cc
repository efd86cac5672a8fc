#include "python/twin_setup.h"

#include <mutex>

#include "common/errors.h"
#include "models/field_model_file.h"
#include "runs/scenario_run.h"
#include "sim/effects.h"
#include "sim/object_physics.h"
#include "sim/scene_builder.h"

namespace airtwin::python {
namespace {

// The shipped CFD cases, read at the first use (a few seconds) and shared by every twin.
std::shared_ptr<const CfdField> shipped_cfd() {
  static std::mutex mutex;
  static std::shared_ptr<const CfdField> cfd;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!cfd) cfd = std::make_shared<const CfdField>(CfdField::read_dir(AIRTWIN_CFD_DIR));
  return cfd;
}

}  // namespace

std::vector<std::string> controller_models(const ControllerSetup& controller,
                                           const TwinSetup& setup) {
  if (!controller.models.empty()) return controller.models;
  return default_controller_models(setup.air == "cfd", setup.drag == "physical",
                                   setup.air_turbulence_swept.value_or(true));
}

AirFieldModel controller_field_model(const ControllerSetup& controller) {
  return controller.table.empty() ? AirFieldModel::fitted_to_cfd()
                                  : read_air_field_model(controller.table);
}

TwinParameters twin_parameters(const TwinSetup& setup, const Scenario& scenario) {
  TwinParameters params;
  // The air: the model's or the CFD's.
  if (setup.air == "cfd") {
    params.cfd_air = setup.cfd ? setup.cfd : shipped_cfd();
  } else if (setup.air == "model") {
    if (setup.cfd) throw FieldError("cfd", "CFD cases need air 'cfd'");
  } else {
    throw FieldError("air", "expected cfd or model, got '" + setup.air + "'");
  }
  // The formation: on where the CFD's cases can form the air unless switched off.
  const bool default_scale =
      setup.air_formation_time_scale == AirTransportParameters{}.formation_time_scale;
  if (setup.air_formation.value_or(false)) {
    if (!params.cfd_air) throw FieldError("air_formation", "needs the CFD's air (air 'cfd')");
    if (!params.cfd_air->forms_air()) {
      throw FieldError("air_formation",
                       std::string("the CFD cases lack ") + CfdField::kFormationData);
    }
  }
  params.air_transport.formation = setup.air_formation.value_or(true);
  if (!default_scale) {
    if (!params.cfd_air || !params.air_transport.formation) {
      throw FieldError("air_formation_time_scale",
                       "needs the formation (the CFD's air, air_formation not False)");
    }
    params.air_transport.formation_time_scale = setup.air_formation_time_scale;
    params.air_transport.validate();
  }
  const AirTransportParameters transport_defaults;
  if (setup.air_front_co_flow != transport_defaults.front_co_flow ||
      setup.air_front_counter_flow != transport_defaults.front_counter_flow) {
    if (!params.cfd_air) {
      throw FieldError("air_front_co_flow", "the carried front needs the CFD's air (air 'cfd')");
    }
    params.air_transport.front_co_flow = setup.air_front_co_flow;
    params.air_transport.front_counter_flow = setup.air_front_counter_flow;
    try {
      params.air_transport.validate();
    } catch (const FieldError& e) {
      // The Python argument's name, not the library's field.
      const bool co = e.field() == "air_transport.front_co_flow";
      if (!co && e.field() != "air_transport.front_counter_flow") throw;
      throw FieldError(co ? "air_front_co_flow" : "air_front_counter_flow", e.detail());
    }
  }
  if (setup.air_turbulence_swept.value_or(false) && !params.cfd_air) {
    throw FieldError("air_turbulence_swept", "needs the CFD's air (air 'cfd')");
  }
  params.air.turbulence_swept = setup.air_turbulence_swept.value_or(true);
  if (setup.integrator != "euler" && setup.integrator != "implicit") {
    throw FieldError("integrator", "expected euler or implicit, got '" + setup.integrator + "'");
  }
  params.scene.implicit_integrator = setup.integrator == "implicit";
  // The objects' drag law, then their physical parameters, then the effects.
  apply_drag_law(setup.drag, &params.scene);
  for (const std::string& text : setup.object_physics) apply_object_physics(text, &params.scene);
  std::vector<Effect> effects;
  for (const std::string& text : setup.effects) effects.push_back(parse_effect(text));
  apply_effects(effects, &params);
  // A user's scene: checked before any twin is built from it.
  params.scene_file = setup.mjcf;
  if (!setup.mjcf.empty()) load_scene(setup.mjcf, scenario.scene, params.scene);
  return params;
}

}  // namespace airtwin::python
