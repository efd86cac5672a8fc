#include "controller/closed_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "common/errors.h"

namespace airtwin {
namespace {

std::map<std::string, double> thresholds_of(const std::map<std::string, ObjectDynamics>& by_type) {
  std::map<std::string, double> out;
  for (const auto& [type, xi] : by_type) out[type] = xi.threshold_air_speed();
  return out;
}

}  // namespace

Controller::Controller(const AirFieldModel& model, const CemParameters& cem, const TaskSpec& task,
                       std::map<std::string, ObjectDynamics> dynamics_by_type, uint64_t seed,
                       double forget_after_s, std::optional<ExtendedPlanning> extended)
    : planner_(model, cem, FastPredictor::Options{}, std::move(extended)),
      progress_(resolve_sorting_stages(task, thresholds_of(dynamics_by_type))),
      dynamics_(std::move(dynamics_by_type)),
      rng_(seed, RandomPurpose::kController, 0),
      forget_after_s_(forget_after_s) {
  if (!(forget_after_s > 0.0)) throw InputError("controller: forget_after_s must be > 0");
}

bool Controller::observe(const Observation& observation) {
  for (const auto& o : observation.objects) {
    if (!o.p_W.allFinite() || !o.v_W.allFinite()) {
      throw InputError("controller: object '" + o.id + "' observed at a non-finite position");
    }
    known_[o.id] = o;
    last_seen_s_[o.id] = observation.t_s;
  }
  // Remembered objects not seen now are taken as at rest where last seen, and forgotten after
  // forget_after_s.
  for (auto it = known_.begin(); it != known_.end();) {
    const double unseen_s = observation.t_s - last_seen_s_[it->first];
    if (unseen_s > forget_after_s_) {
      last_seen_s_.erase(it->first);
      it = known_.erase(it);
      continue;
    }
    if (unseen_s > 0.0) it->second.v_W.setZero();
    ++it;
  }
  last_t_s_ = observation.t_s;
  last_observed_ = static_cast<int>(observation.objects.size());
  std::vector<Eigen::Vector2d> p;
  std::vector<std::string> types;
  for (const auto& [id, o] : known_) {
    p.push_back(o.p_W);
    types.push_back(o.type);
  }
  return progress_.update(p, types, observation.t_s, observation.out_of_view);
}

PlanningProblem DecisionInputs::problem(double pan_hint_rad) const {
  PlanningProblem problem;
  problem.positions_W = positions_W;
  problem.velocities_W = velocities_W;
  problem.dynamics = dynamics;
  problem.types = types;
  problem.references_W = references_W;
  problem.weights = shaping.weights;
  problem.reach_m = shaping.reach_m;
  problem.pan_hint_rad = pan_hint_rad;
  return problem;
}

DecisionInputs Controller::inputs() const {
  if (known_.empty()) throw InputError("controller: no objects observed");
  DecisionInputs in;
  for (const auto& [id, o] : known_) {
    const auto it = dynamics_.find(o.type);
    if (it == dynamics_.end()) {
      throw InputError("controller: no dynamics for object type '" + o.type + "' (object '" + id +
                       "')");
    }
    in.ids.push_back(id);
    in.types.push_back(o.type);
    in.positions_W.push_back(o.p_W);
    in.velocities_W.push_back(o.v_W);
    in.dynamics.push_back(it->second);
    in.seen.push_back(last_seen_s_.at(id) == last_t_s_ ? 1 : 0);
  }
  in.references_W = progress_.references(in.types);
  in.shaping = progress_.cost_shaping(in.positions_W, in.types);
  return in;
}

DecisionRecord Controller::decide(double pan_hint_rad) {
  const DecisionInputs in = inputs();
  const std::vector<Eigen::Vector2d>& p = in.positions_W;
  const std::vector<Eigen::Vector2d>& r = in.references_W;
  DecisionRecord record;
  for (const std::string& id : in.ids) record.objects.push_back(known_.at(id));
  record.seen = in.seen;
  PlanningProblem problem = in.problem(pan_hint_rad);
  problem.nozzle_now = last_command_;

  const auto start = std::chrono::steady_clock::now();
  record.plan = planner_.plan(problem, rng_);
  record.decision_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  last_command_ = record.plan.orientation;
  record.t_s = last_t_s_;
  record.reference_index = progress_.reference_index();
  // The reference of the object farthest from its own: the one the line search anchors on.
  double farthest = -1.0;
  for (size_t j = 0; j < p.size(); ++j) {
    const double d = (p[j] - r[j]).norm();
    if (d > farthest) {
      farthest = d;
      record.reference_W = r[j];
    }
  }
  record.n_observed = last_observed_;
  record.n_known = static_cast<int>(p.size());
  return record;
}

ClosedLoop::ClosedLoop(Rig& rig, Controller& controller, const LoopOptions& options)
    : rig_(rig), controller_(controller), options_(options) {
  if (!(std::isfinite(options.hold_s) && options.hold_s > 0.0)) {
    throw InputError("loop: the hold time must be a positive number of seconds");
  }
  if (!(std::isfinite(options.time_limit_s) && options.time_limit_s > 0.0)) {
    throw InputError("loop: the time limit must be a positive number of seconds");
  }
  if (!(std::isfinite(options.latency_s) && options.latency_s >= 0.0)) {
    throw InputError("loop: the latency must be a number of seconds >= 0");
  }
  observe();
}

void ClosedLoop::observe() {
  observation_ = rig_.observe();
  result_.objects_seen_at_end = static_cast<int>(observation_.objects.size());
  if (controller_.observe(observation_)) {
    result_.success = true;
    result_.completion_time_s = controller_.progress().done_time_s();
  } else if (controller_.known().empty()) {
    // Blown out of the camera's view or lost in merges, and forgotten: a failed run, not an
    // error of the input.
    result_.lost_every_object = true;
  }
  time_up_ = rig_.time() >= options_.time_limit_s;
}

const DecisionRecord& ClosedLoop::command(DecisionRecord record) {
  command(record.plan.orientation);
  result_.decisions.push_back(std::move(record));
  return result_.decisions.back();
}

void ClosedLoop::command(const NozzleOrientation& target) {
  AIRTWIN_DEMAND(!finished());
  // The decision's time: the objects move on under the previous command.
  const double latency = std::min(options_.latency_s, options_.time_limit_s - rig_.time());
  if (latency > 0.0) rig_.wait(latency);
  rig_.aim(target);
  controller_.assume_nozzle(target);
  pan_rad_ = target.pan_rad;
}

void ClosedLoop::hold() {
  AIRTWIN_DEMAND(!finished());
  // Never wait past the time limit: the last observation falls on it (at once when the
  // latency reached it).
  const double hold = std::min(options_.hold_s, options_.time_limit_s - rig_.time());
  if (hold > 0.0) rig_.wait(hold);
  observe();
}

const LoopResult& ClosedLoop::result() {
  result_.end_time_s = rig_.time();
  return result_;
}

LoopResult run_closed_loop(Rig& rig, Controller& controller, const LoopOptions& options,
                           const std::function<void(const DecisionRecord&)>& on_decision) {
  ClosedLoop loop(rig, controller, options);
  while (!loop.finished()) {
    const DecisionRecord& record = loop.command(loop.decide());
    if (on_decision) on_decision(record);
    loop.hold();
  }
  return loop.result();
}

}  // namespace airtwin
