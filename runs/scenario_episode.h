#pragma once
// A scenario's closed-loop run one turn at a time: the run of runs/scenario_run.h opened up so
// that a caller may choose commands itself (the Python environment, python/airtwin/env.py), in
// the same twin, perception, task bookkeeping and log. run_scenario is this episode with every
// command the controller's, so an episode whose commands are the controller's decisions is
// that run to the last bit.
//
// Built as run_scenario builds its run: the nozzle at rest where the controller would first aim
// (a plan from the start positions, with its own random stream), the jet settled, the
// perception (truth, or the detection pipeline with options.vision_camera), the controller
// (controller/closed_loop.h: its memory of objects and the task's references), the judge's
// figures from the twin's truth every camera frame, the trajectory log and the nozzle log.

#include <memory>

#include "controller/closed_loop.h"
#include "runs/scenario_run.h"

namespace airtwin {

class ScenarioEpisode {
 public:
  /// `scenario` and `field_model` must outlive the episode. Throws InputError for unusable
  /// inputs, SimulationError when the twin fails.
  ScenarioEpisode(const Scenario& scenario, const AirFieldModel& field_model,
                  const ScenarioRunOptions& options);
  ~ScenarioEpisode();
  ScenarioEpisode(const ScenarioEpisode&) = delete;
  ScenarioEpisode& operator=(const ScenarioEpisode&) = delete;

  /// The task is done (as the controller sees it) or the time limit is reached.
  bool finished() const;
  /// The controller's next decision (CEM on what it knows; its random stream advances).
  DecisionRecord decide();
  /// One turn with the controller's decision: aim, record it, hold, observe. Throws InputError
  /// when the episode is finished.
  void step(DecisionRecord decision);
  /// One turn with a command of the caller's (rad): aim, hold, observe. Throws InputError for an
  /// orientation outside the servos' range or when the episode is finished.
  void step(const NozzleOrientation& command);
  /// One turn with the stagnation point s (m) the caller chooses: the nozzle aimed at it
  /// (eqs. 1-2 inverted, from the pan the controller's aim would start from); an s beyond the
  /// nozzle's reach is brought in along its ray to 0.999 of the farthest reachable radius, as the
  /// planner holds an infeasible s, and costs J_P. Throws InputError for a non-finite s or when
  /// finished.
  void step_at(const Eigen::Vector2d& s_W);

  /// eq. (10) of the last turn on the positions the objects reached (CemPlanner::outcome_cost):
  /// the known objects' distances to the references in force when the turn began, with the
  /// task's weights and reaches, or J_P when its s was within delta_min of an object or out of
  /// reach. An object the perception forgot during the turn counts where it was. 0 before the
  /// first turn.
  double last_cost() const;
  /// The stagnation point of the last turn's command (m).
  const Eigen::Vector2d& last_stagnation_point() const;

  /// The last observation (what the perception reports).
  const Observation& observation() const;
  const Controller& controller() const;
  const Twin& twin() const;
  /// Rig time (s).
  double time() const;
  /// The run so far, with the judge's figures as of now (what run_scenario returns at the end).
  ScenarioRunResult result() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace airtwin
