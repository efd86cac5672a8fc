#pragma once
// A scenario: one YAML file (scenes/*.yaml, schema in docs/scenario_schema.md) that says which
// objects start where, which task the controller has, and the controller's parameters. It is the
// per-run description; the fixed physics (sim::SceneParameters) and the field model are not in it.
//
//   name: octagon
//   description: Four tracers along an octagon (Fig. 7a, Table I row 4)
//   objects:
//     - {id: t1, type: tracer, x: 0.25, y: -0.03}
//   task:
//     kind: path                 # path | aggregation | sorting
//     path: [[0.25, 0.0], ...]   # m
//     references: vertices       # vertices | spaced
//     spacing_m: 0.10
//     switch_distance_m: 0.063
//     time_limit_s: 400
//     # aggregation: zone: {centre: [x, y], diameter_m: 0.37}
//     # sorting:     zones: {tracer: {centre: [..], diameter_m: 0.21}, cotton: {...}}
//   controller:                  # every key optional; defaults by search (cem_planner.h)
//     search: line               # line | plane (default: plane for sorting, else line)
//     horizon_s: 1.5
//     ...
//   loop:
//     settle_s: 0.3              # extra wait after each aim, beyond horizon_s
//     latency_s: 0               # from an observation to its aim (camera, decision)
//
// Every key is checked: an unknown key, a wrong type, a missing required field or a value out of
// range is one InputError naming the file, the line and the key path (e.g. `task.zone.diameter_m`).

#include <string>

#include "controller/cem_planner.h"
#include "controller/task.h"
#include "sim/scene_spec.h"

namespace airtwin {

/// How the closed loop paces itself around the controller.
struct LoopParameters {
  /// After each aim the rig waits horizon_s + settle_s (s) before the next decision: the servos'
  /// travel and the field's delay (the paper: "time lags ... determined by Delta T and a time
  /// delay").
  double settle_s = 0.3;
  /// From each observation to the aim it leads to (s): what a rig's camera, detection and
  /// decision take, while the objects move on under the previous command. 0 by default: the
  /// twin's decision takes no rig time.
  double latency_s = 0.0;
};

struct Scenario {
  std::string name;         ///< `name`, default: the file's stem
  std::string description;  ///< free text, may be empty
  std::string source;       ///< the file it was read from (for messages)
  SceneSpec scene;          ///< the objects (scene.source = source)
  TaskSpec task;
  CemParameters controller;
  LoopParameters loop;
};

/// Reads and validates a scenario file. Throws InputError as described above, or when the file
/// cannot be read.
Scenario read_scenario(const std::string& path);
/// The same from text; `source` names it in messages.
Scenario parse_scenario(const std::string& yaml_text, const std::string& source);

}  // namespace airtwin
