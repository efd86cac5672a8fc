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

/// What a decision plans with: the objects known now (in id order), their references and
/// eq. (10)'s shaping (controller/task.h). problem() views it for the planner.
struct DecisionInputs {
  std::vector<std::string> ids, types;
  std::vector<Eigen::Vector2d> positions_W, velocities_W, references_W;  ///< m, m/s, m
  std::vector<ObjectDynamics> dynamics;
  std::vector<char> seen;  ///< in the last observation (else remembered, at rest)
  CostShaping shaping;
  /// A view of these vectors (valid while this lives) with the pan hint (rad).
  PlanningProblem problem(double pan_hint_rad) const;
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
  /// What the next decision plans with. Throws InputError when no object is known or one's type
  /// has no dynamics.
  DecisionInputs inputs() const;
  const CemPlanner& planner() const { return planner_; }
  /// Threads that predict each decision's candidates (CemPlanner::set_threads).
  void set_planner_threads(int threads) { planner_.set_threads(threads); }
  /// The command the nozzle rests at (the last decision's or assume_nozzle's), if known.
  const std::optional<NozzleOrientation>& nozzle_command() const { return last_command_; }

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
  /// From an observation to the aim it leads to (s): the camera's frame, the detection and the
  /// decision's own computing on a real rig. The objects move on under the previous command
  /// meanwhile; the controller plans from the observation, as the paper's does. 0: the aim
  /// follows at once.
  double latency_s = 0.0;
};

struct LoopResult {
  bool success = false;
  std::optional<double> completion_time_s;  ///< rig time when the task was seen done
  double end_time_s = 0.0;                  ///< rig time when the loop stopped
  int objects_seen_at_end = 0;              ///< objects in the last observation
  /// The loop stopped early, unsuccessful: the perception had lost every object and the
  /// controller had forgotten them all, so there was nothing left to plan for.
  bool lost_every_object = false;
  std::vector<DecisionRecord> decisions;
};

/// The loop one turn at a time, for a caller that chooses some commands itself (the Python
/// environment): observe and update the task (at construction and after each hold()), then a
/// command, then hold(). run_closed_loop below is this with every command the controller's.
class ClosedLoop {
 public:
  /// `rig` and `controller` must outlive the loop. Throws InputError for a hold time or a time
  /// limit that is not a positive number of seconds. Takes the first observation.
  ClosedLoop(Rig& rig, Controller& controller, const LoopOptions& options);

  /// The task is done, rig time has reached the time limit, or no object is known any more (the
  /// perception lost them all): no more commands.
  bool finished() const { return result_.success || time_up_ || result_.lost_every_object; }
  /// The controller's next decision from what is known (its random stream advances).
  DecisionRecord decide() { return controller_.decide(pan_rad_); }
  /// Aims the rig at the decision's orientation, `latency_s` after the observation it used, and
  /// keeps the record (result().decisions).
  const DecisionRecord& command(DecisionRecord record);
  /// Aims the rig at an orientation the controller did not choose (rad), `latency_s` after the
  /// last observation (never past the time limit); the controller is told
  /// the nozzle's command (extended planning predicts from it) and the next decision's pan hint
  /// is its pan. No record is kept.
  void command(const NozzleOrientation& target);
  /// Lets the air act for the hold time (never past the time limit), observes, updates the task.
  void hold();

  /// The pan (rad) the next decision's aim starts from: the last command's (0 before any).
  double pan_hint_rad() const { return pan_rad_; }
  /// The last observation.
  const Observation& observation() const { return observation_; }
  /// The loop so far (end_time_s: rig time now).
  const LoopResult& result();

 private:
  void observe();

  Rig& rig_;
  Controller& controller_;
  LoopOptions options_;
  Observation observation_;
  LoopResult result_;
  bool time_up_ = false;
  double pan_rad_ = 0.0;
};

/// Runs the loop on `rig` until the task is done, time runs out or every object is lost.
/// `on_decision` (optional) is called after each aim. Errors of the rig or the controller
/// propagate.
LoopResult run_closed_loop(Rig& rig, Controller& controller, const LoopOptions& options,
                           const std::function<void(const DecisionRecord&)>& on_decision = {});

}  // namespace airtwin
