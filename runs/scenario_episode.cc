#include "runs/scenario_episode.h"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "models/nozzle_geometry.h"
#include "rigs/twin_rig.h"
#include "sim/physics_variation.h"

namespace airtwin {
namespace {

// How long an object the perception misses stays in the plan (controller/closed_loop.h).
constexpr double kForgetAfter = 3.0;

// The observation a rig would give before anything moved: the scenario's start positions.
Observation start_observation(const Scenario& scenario) {
  Observation o;
  for (const ObjectSpec& spec : scenario.scene.objects) {
    ObservedObject obj;
    obj.id = spec.id;
    obj.type = spec.type;
    obj.p_W = spec.p_W;
    o.objects.push_back(obj);
  }
  return o;
}

const Scenario& with_objects(const Scenario& scenario) {
  if (scenario.scene.objects.empty()) {
    throw InputError(scenario.source + ": the scenario has no objects");
  }
  return scenario;
}

// The twin's parameters: the options', the nozzle resting where the controller would first aim
// (a plan from the start positions, with its own random stream) and the jet running, so that the
// rig is ready when the run begins.
TwinParameters start_parameters(const Scenario& scenario, const AirFieldModel& planning,
                                const ScenarioRunOptions& options) {
  TwinParameters params = options.twin;
  Controller first(planning, scenario.controller, scenario.task, options.dynamics,
                   options.seed ^ 0x5EEDF00Dull, kForgetAfter, options.planning_extensions);
  first.observe(start_observation(scenario));
  params.initial_orientation = first.decide(0.0).plan.orientation;
  params.jet_on_at_start = true;
  return params;
}

// The twin's objects: the scenario's, each drawn its own physics when the options vary them.
SceneSpec objects_of_run(const Scenario& scenario, const ScenarioRunOptions& options) {
  SceneSpec scene = scenario.scene;
  vary_object_physics(options.physics_variation, options.twin.scene, options.seed, &scene);
  return scene;
}

LoopOptions loop_options_of(const Scenario& scenario) {
  LoopOptions o;
  o.hold_s = scenario.controller.horizon_s + scenario.loop.settle_s;
  o.time_limit_s = scenario.task.time_limit_s;
  o.latency_s = scenario.loop.latency_s;
  return o;
}

}  // namespace

struct ScenarioEpisode::Impl {
  Impl(const Scenario& scenario_in, const AirFieldModel& field_model,
       const ScenarioRunOptions& options_in)
      : scenario(with_objects(scenario_in)),
        options(options_in),
        // The field the controller plans with: the twin's, or the one the options give.
        planning(options.planning_field ? *options.planning_field : field_model),
        params(start_parameters(scenario, planning, options)),
        scene(objects_of_run(scenario, options)),
        twin(scene, params, field_model, options.seed),
        metrics(scenario.task),
        controller(planning, scenario.controller, scenario.task, options.dynamics, options.seed,
                   kForgetAfter, options.planning_extensions),
        loop_options(loop_options_of(scenario)) {
    controller.set_planner_threads(options.planner_threads);
    twin.settle_jet();
    run.scenario = scenario.name;
    run.seed = options.seed;
    run.n_objects = static_cast<int>(scenario.scene.objects.size());
    if (options.physics_variation.active()) {
      run.physics_variation = options.physics_variation.to_string();
      for (const ObjectSpec& o : scene.objects) {
        run.object_physics.push_back(
            {o.id, object_physics_to_string(*o.physics, parse_object_type(o.type, o.id))});
      }
    }

    // The perception: the twin's truth, or the detection pipeline on its rendered frames.
    Perception* perception = &truth;
    if (options.vision_camera) {
      VisionPerceptionOptions vo = options.vision;
      vo.seed = options.seed;
      vision = std::make_unique<VisionPerception>(*options.vision_camera, vo);
      perception = vision.get();
      run.perception = "vision";
    }
    rig = std::make_unique<TwinRig>(twin, *perception);
    controller.assume_nozzle(params.initial_orientation);

    // The log: one trajectory per object, a row per camera frame, the commanded orientation.
    run.log.has_group = true;
    for (size_t i = 0; i < twin.object_count(); ++i) {
      Trajectory t;
      t.id = twin.object(i).id;
      t.object = object_type_name(twin.object(i).type);
      t.group = scenario.name;
      run.log.trajectories.push_back(std::move(t));
      types.push_back(object_type_name(twin.object(i).type));
    }
    rig->add_frame_observer([this](const Twin& tw, int64_t frame) {
      const std::vector<ObjectMotion> motion = tw.object_states();
      std::vector<Eigen::Vector2d> p(motion.size());
      for (size_t i = 0; i < motion.size(); ++i) {
        p[i] = motion[i].p_W;
        TrajectorySample s;
        s.t_s = tw.time();
        s.p_W = p[i];
        s.nozzle = tw.commanded_orientation();
        run.log.trajectories[i].samples.push_back(s);
      }
      metrics.add_frame(tw.time(), p, types);
      if (options.on_frame) options.on_frame(tw, frame, decisions_so_far);
    });

    // The nozzle log: the start command, then each command as it is sent.
    record_command(&run.nozzle_log, twin.time(), twin.commanded_orientation());
    loop.emplace(*rig, controller, loop_options);
  }

  void check_running() const {
    if (loop->finished()) {
      throw InputError("episode " + scenario.name +
                       ": finished (task done or time limit reached); start a new one");
    }
  }

  // One turn: the command (the decision's, kept in the record, or the caller's), the nozzle log,
  // the progress display, the hold; then eq. (10) on where the known objects got to.
  void turn(const NozzleOrientation& command, const Eigen::Vector2d& s_W,
            std::optional<DecisionRecord> decision) {
    check_running();
    const DecisionInputs before = controller.inputs();
    if (decision) {
      const DecisionRecord& d = loop->command(std::move(*decision));
      if (options.on_frame) decisions_so_far.push_back(d);
    } else {
      loop->command(command);
    }
    record_command(&run.nozzle_log, rig->time(), twin.commanded_orientation());
    if (options.on_progress) options.on_progress(rig->time(), loop_options.time_limit_s);
    loop->hold();
    std::vector<Eigen::Vector2d> end_W = before.positions_W;
    for (size_t j = 0; j < end_W.size(); ++j) {
      const auto it = controller.known().find(before.ids[j]);
      if (it != controller.known().end()) end_W[j] = it->second.p_W;
    }
    last_s_W = s_W;
    last_cost = controller.planner().outcome_cost(before.problem(command.pan_rad), s_W, end_W);
  }

  const Scenario& scenario;
  ScenarioRunOptions options;
  const AirFieldModel& planning;
  TwinParameters params;
  SceneSpec scene;  // the scenario's objects, each with its own physics when they vary
  Twin twin;
  TruthPerception truth;
  std::unique_ptr<VisionPerception> vision;
  std::unique_ptr<TwinRig> rig;
  RunMetrics metrics;
  Controller controller;
  LoopOptions loop_options;
  std::optional<ClosedLoop> loop;
  ScenarioRunResult run;  // the log and the nozzle log so far
  std::vector<std::string> types;
  std::vector<DecisionRecord> decisions_so_far;  // for the frame callback, during the run
  double last_cost = 0.0;
  Eigen::Vector2d last_s_W = Eigen::Vector2d::Zero();
};

ScenarioEpisode::ScenarioEpisode(const Scenario& scenario, const AirFieldModel& field_model,
                                 const ScenarioRunOptions& options)
    : impl_(std::make_unique<Impl>(scenario, field_model, options)) {}

ScenarioEpisode::~ScenarioEpisode() = default;

bool ScenarioEpisode::finished() const { return impl_->loop->finished(); }

DecisionRecord ScenarioEpisode::decide() {
  impl_->check_running();
  return impl_->loop->decide();
}

void ScenarioEpisode::step(DecisionRecord decision) {
  const NozzleOrientation command = decision.plan.orientation;
  const Eigen::Vector2d s_W = decision.plan.stagnation_W;
  impl_->turn(command, s_W, std::move(decision));
}

void ScenarioEpisode::step(const NozzleOrientation& command) {
  impl_->turn(command, stagnation_point(impl_->planning.geometry(), command), std::nullopt);
}

void ScenarioEpisode::step_at(const Eigen::Vector2d& s_W) {
  if (!s_W.allFinite()) throw InputError("episode: the stagnation point must be finite");
  const NozzleGeometry& geometry = impl_->planning.geometry();
  const double pan_hint = impl_->loop->pan_hint_rad();
  AimResult aim = aim_at_stagnation(geometry, s_W, pan_hint);
  if (!aim.reachable()) {
    // Beyond reach: along its ray to where the nozzle can put it (J_P all the same).
    const double r_max = 0.999 * max_stagnation_radius(geometry);
    const Eigen::Vector2d held =
        s_W.norm() > r_max ? Eigen::Vector2d(s_W * (r_max / s_W.norm())) : s_W;
    aim = aim_at_stagnation(geometry, held, pan_hint);
    if (!aim.reachable()) {
      throw InputError("episode: stagnation point (" + std::to_string(s_W.x()) + ", " +
                       std::to_string(s_W.y()) + ") m: " + aim.unreachable_reason);
    }
  }
  impl_->turn(*aim.orientation, s_W, std::nullopt);
}

double ScenarioEpisode::last_cost() const { return impl_->last_cost; }
const Eigen::Vector2d& ScenarioEpisode::last_stagnation_point() const { return impl_->last_s_W; }

const Observation& ScenarioEpisode::observation() const { return impl_->loop->observation(); }
const Controller& ScenarioEpisode::controller() const { return impl_->controller; }
const Twin& ScenarioEpisode::twin() const { return impl_->twin; }
double ScenarioEpisode::time() const { return impl_->rig->time(); }

ScenarioRunResult ScenarioEpisode::result() const {
  ScenarioRunResult result = impl_->run;
  result.loop = impl_->loop->result();
  if (impl_->vision) {
    const VisionPerception& vision = *impl_->vision;
    result.vision_frames = vision.frames_processed();
    result.vision_frame_ms = vision.mean_frame_ms();
    result.vision_counters = vision.counters();
    result.vision_duplicates = vision.duplicates();
    result.vision_detections_csv = vision.detections_csv();
  }
  const RunMetrics& metrics = impl_->metrics;
  result.path_error_m = metrics.path_error();
  result.max_pairwise_distance_m = metrics.max_pairwise_distance_m();
  result.objects_in_zone = metrics.objects_in_zone();
  result.still_since_s = metrics.still_since_s();
  result.success = run_verdict(impl_->scenario.task.kind, result.loop.success,
                               result.objects_in_zone, result.n_objects);
  double sum = 0.0;
  for (const auto& d : result.loop.decisions) {
    sum += d.decision_ms;
    result.decision_ms_max = std::max(result.decision_ms_max, d.decision_ms);
  }
  if (!result.loop.decisions.empty()) {
    result.decision_ms_mean = sum / static_cast<double>(result.loop.decisions.size());
  }
  return result;
}

}  // namespace airtwin
