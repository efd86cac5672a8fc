#pragma once
// The twin's and the controller's set-up as Python callers give them, for Twin, the runs and the
// environment alike. The twin's: the options
// `airtwin run` and the other commands take as --air, --cfd, --drag, --object-physics, --effect,
// --mjcf, --air-formation / --no-air-formation, --air-formation-time-scale, --integrator,
// --air-front-co-flow, --air-front-counter-flow and --air-turbulence-swept / --no-...,
// validated by the libraries
// that own them, so a bad value raises ValueError with the library's message (the field or the
// effect named, never a flag).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "models/air_field.h"
#include "models/cfd_field.h"
#include "scenes/scenario.h"
#include "sim/twin.h"

namespace airtwin::python {

struct TwinSetup {
  /// "cfd" (the jet's CFD, the default as the CLI's) or "model" (the analytical field).
  std::string air = "cfd";
  /// The CFD cases for air "cfd"; null: the shipped data/cfd, read once per process.
  std::shared_ptr<const CfdField> cfd;
  std::string drag = "physical";            ///< physical | eq8 (sim/object_physics.h)
  std::vector<std::string> object_physics;  ///< "TYPE:key=value,..." in order, after drag
  std::vector<std::string> effects;         ///< "NAME[:key=value,...]" (sim/effects.h)
  std::string mjcf;                         ///< a user's MJCF scene; "": built
  /// The wall jet's formation in the CFD's air (sim/air_transport.h): unset, on where the cases
  /// have the start-up and pulses; true asks for it (--air-formation: an error where they have
  /// not); false switches it off (--no-air-formation).
  std::optional<bool> air_formation;
  /// The formation's times: the pulses' times this (--air-formation-time-scale).
  double air_formation_time_scale = AirTransportParameters{}.formation_time_scale;
  /// MuJoCo's integrator for the built scene: "euler" | "implicit" (--integrator).
  std::string integrator = "euler";
  /// The new wall jet's front carried by the old air in the CFD's air (sim/air_transport.h):
  /// the shares of the old air's component along its path that speed it up where it flows its
  /// way and slow it down where it flows against it (--air-front-co-flow,
  /// --air-front-counter-flow; both 0: the front of still air).
  double air_front_co_flow = AirTransportParameters{}.front_co_flow;
  double air_front_counter_flow = AirTransportParameters{}.front_counter_flow;
  /// In the CFD's air, the eddies each object feels swept past it by the air relative to it
  /// (AirForceParameters::turbulence_swept): unset, on in the CFD's air; true asks for them
  /// (--air-turbulence-swept: an error in the model's air); false, T_L alone
  /// (--no-air-turbulence-swept).
  std::optional<bool> air_turbulence_swept;
};

/// What the controller plans with, as `--table` and `--model` set it: the field model (the twin's
/// analytical air too) and the model files.
struct ControllerSetup {
  std::string table;                ///< "": the default model, fitted to the CFD
  std::vector<std::string> models;  ///< empty: default_controller_models of the twin
};

/// The model files the controller plans with: its own, or those fitted to the twin `setup` builds
/// (runs/scenario_run.h default_controller_models, as the CLI's).
std::vector<std::string> controller_models(const ControllerSetup& controller,
                                           const TwinSetup& setup);

/// The controller's field model: `table`'s, or the default one fitted to the CFD. Throws
/// InputError for a bad file.
AirFieldModel controller_field_model(const ControllerSetup& controller);

/// The twin's parameters the set-up selects, checked against `scenario` (a user's MJCF must
/// provide what the twin needs for its objects, sim/scene_builder.h). Throws InputError
/// (FieldError for `air` and `drag`) naming the value that cannot be used.
TwinParameters twin_parameters(const TwinSetup& setup, const Scenario& scenario);

}  // namespace airtwin::python
