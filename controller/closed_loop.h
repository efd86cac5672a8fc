#pragma once
// The closed loop of section V-A: observe the objects, update the task, let CEM choose the next
// stagnation point, aim the nozzle, let the air act for Delta T plus the rig's delay, repeat
// until the task is done or its time is up. The loop knows the rig only through controller/rig.h.
//
// Objects are remembered by id: one the perception misses for a while keeps its last position
// (at rest) in the plan and the task, as a person watching the rig would assume, until it has
// been unseen for `forget_after_s` (a tracker that lost an object in a merge gives it a new id
// when it reappears; the old id must not haunt the task).

#include <Eigen/Core>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/random_stream.h"
#include "controller/cem_planner.h"
#include "controller/rig.h"
#include "controller/task.h"
#include "models/air_field.h"
#include "models/object_dynamics.h"

namespace airtwin {

/// What one decision did (for logs and the run summary).
struct DecisionRecord {
  double t_s = 0.0;            ///< rig time of the observation it used
  size_t reference_index = 0;  ///< current path reference (0 for zone tasks)
  Eigen::Vector2d reference_W = Eigen::Vector2d::Zero();  ///< the anchor's reference (m)
  PlanResult plan;
  double decision_ms = 0.0;  ///< wall-clock time of the CEM decision
  int n_observed = 0;        ///< objects in the observation
  int n_known = 0;           ///< objects planned for (observed or remembered)
  /// The objects planned for, in the order of plan.predicted_end_W: as perceived (a remembered
  /// one at its last position, at rest), and whether it was in this observation.
  std::vector<ObservedObject> objects;
  std::vector<char> seen;
};

class Controller {
 public:
  /// `dynamics_by_type`: eq. (8) coefficients per object type (an observed type without an entry
  /// is an InputError at the first decision). `model` must outlive the controller.
  /// With `extended`, the planner predicts with an extended model (controller/cem_planner.h)
  /// and knows each new command follows the previous one.
  Controller(const AirFieldModel& model, const CemParameters& cem, const TaskSpec& task,
             std::map<std::string, ObjectDynamics> dynamics_by_type, uint64_t seed,
             double forget_after_s = 3.0, std::optional<ExtendedPlanning> extended = std::nullopt);

  /// Takes an observation: remembers the objects, updates the task; returns true when done.
  bool observe(const Observation& observation);
  /// Tells the controller the command the nozzle rests at before its first decision (extended
  /// planning predicts the change from it; the default is none: already at the new command).
  void assume_nozzle(const NozzleOrientation& command) { last_command_ = command; }
  /// The next decision from what is known (call after observe() returned false).
  DecisionRecord decide(double pan_hint_rad);

  const TaskProgress& progress() const { return progress_; }
  /// The objects known now, by id (last seen position, velocity, type).
  const std::map<std::string, ObservedObject>& known() const { return known_; }

 private:
  CemPlanner planner_;
  TaskProgress progress_;
  std::map<std::string, ObjectDynamics> dynamics_;
  RandomStream rng_;
  std::map<std::string, ObservedObject> known_;
  std::map<std::string, double> last_seen_s_;
  double forget_after_s_;
  double last_t_s_ = 0.0;
  int last_observed_ = 0;
  std::optional<NozzleOrientation> last_command_;
};

struct LoopOptions {
  /// After each aim the rig waits this long (s) before observing again: Delta T plus the servos'
  /// travel and the field's delay.
  double hold_s = 1.8;
  /// The run stops, unsuccessful, when rig time reaches this (s).
  double time_limit_s = 300.0;
};

struct LoopResult {
  bool success = false;
  std::optional<double> completion_time_s;  ///< rig time when the task was seen done
  double end_time_s = 0.0;                  ///< rig time when the loop stopped
  int objects_seen_at_end = 0;              ///< objects in the last observation
  std::vector<DecisionRecord> decisions;
};

/// Runs the loop on `rig` until the task is done or time runs out. `on_decision` (optional) is
/// called after each aim. Errors of the rig or the controller propagate.
LoopResult run_closed_loop(Rig& rig, Controller& controller, const LoopOptions& options,
                           const std::function<void(const DecisionRecord&)>& on_decision = {});

}  // namespace airtwin
