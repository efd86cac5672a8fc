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

DecisionRecord Controller::decide(double pan_hint_rad) {
  if (known_.empty()) throw InputError("controller: no objects observed");
  std::vector<Eigen::Vector2d> p, v;
  std::vector<std::string> types;
  std::vector<ObjectDynamics> xi;
  DecisionRecord record;
  for (const auto& [id, o] : known_) {
    const auto it = dynamics_.find(o.type);
    if (it == dynamics_.end()) {
      throw InputError("controller: no dynamics for object type '" + o.type + "' (object '" + id +
                       "')");
    }
    p.push_back(o.p_W);
    v.push_back(o.v_W);
    types.push_back(o.type);
    xi.push_back(it->second);
    record.objects.push_back(o);
    record.seen.push_back(last_seen_s_.at(id) == last_t_s_ ? 1 : 0);
  }
  const std::vector<Eigen::Vector2d> r = progress_.references(types);
  PlanningProblem problem;
  problem.positions_W = p;
  problem.velocities_W = v;
  problem.dynamics = xi;
  problem.references_W = r;
  const CostShaping shaping = progress_.cost_shaping(p, types);
  problem.weights = shaping.weights;
  problem.reach_m = shaping.reach_m;
  problem.pan_hint_rad = pan_hint_rad;
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

LoopResult run_closed_loop(Rig& rig, Controller& controller, const LoopOptions& options,
                           const std::function<void(const DecisionRecord&)>& on_decision) {
  if (!(std::isfinite(options.hold_s) && options.hold_s > 0.0)) {
    throw InputError("loop: the hold time must be a positive number of seconds");
  }
  if (!(std::isfinite(options.time_limit_s) && options.time_limit_s > 0.0)) {
    throw InputError("loop: the time limit must be a positive number of seconds");
  }
  LoopResult result;
  double pan = 0.0;
  while (true) {
    const Observation observation = rig.observe();
    result.objects_seen_at_end = static_cast<int>(observation.objects.size());
    if (controller.observe(observation)) {
      result.success = true;
      result.completion_time_s = controller.progress().done_time_s();
      break;
    }
    if (rig.time() >= options.time_limit_s) break;
    DecisionRecord record = controller.decide(pan);
    rig.aim(record.plan.orientation);
    pan = record.plan.orientation.pan_rad;
    if (on_decision) on_decision(record);
    result.decisions.push_back(std::move(record));
    // Never wait past the time limit: the last observation falls on it.
    rig.wait(std::min(options.hold_s, options.time_limit_s - rig.time()));
  }
  result.end_time_s = rig.time();
  return result;
}

}  // namespace airtwin
