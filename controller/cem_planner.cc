#include "controller/cem_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "common/errors.h"
#include "common/parallel_for.h"
#include "controller/task.h"

namespace airtwin {

CemParameters CemParameters::line_defaults() { return CemParameters{}; }

CemParameters CemParameters::plane_defaults() {
  CemParameters p;
  p.search = CemSearch::kPlane;
  p.variance0_m2 = 31.3e-4;
  p.samples = 100;
  p.elite = 10;
  p.max_iterations = 5;
  p.converged_variance_m2 = 0.5e-4;
  return p;
}

void CemParameters::validate(const std::string& source) const {
  auto positive = [&](double value, const char* name) {
    if (!(std::isfinite(value) && value > 0.0)) {
      throw InputError(source + ": controller." + name + " must be a positive number");
    }
  };
  positive(horizon_s, "horizon_s");
  positive(penalty, "penalty");
  positive(variance0_m2, "variance0_m2");
  positive(converged_variance_m2, "converged_variance_m2");
  if (!(std::isfinite(min_distance_m) && min_distance_m >= 0.0)) {
    throw InputError(source + ": controller.min_distance_m must be a number >= 0");
  }
  if (!std::isfinite(mean0_m)) {
    throw InputError(source + ": controller.mean0_m must be finite");
  }
  if (horizon_s > 60.0) {
    throw InputError(source + ": controller.horizon_s must be at most 60 s");
  }
  if (samples < 1 || samples > 100000) {
    throw InputError(source + ": controller.samples must be in [1, 100000]");
  }
  if (elite < 1 || elite > samples) {
    throw InputError(source + ": controller.elite must be in [1, samples]");
  }
  if (max_iterations < 1 || max_iterations > 1000) {
    throw InputError(source + ": controller.max_iterations must be in [1, 1000]");
  }
  if (!(std::isfinite(scan_step_m) && scan_step_m >= 0.0)) {
    throw InputError(source + ": controller.scan_step_m must be a number >= 0");
  }
  if (scan_step_m > 0.0 && scan_step_m < 0.01) {
    throw InputError(source + ": controller.scan_step_m must be at least 0.01 m (or 0: no scan)");
  }
  if (!(std::isfinite(sweep_clearance_m) && sweep_clearance_m >= 0.0)) {
    throw InputError(source + ": controller.sweep_clearance_m must be a number >= 0");
  }
  if (predict_transition || sweep_clearance_m > 0.0) transition.validate();
}

CemPlanner::CemPlanner(const AirFieldModel& model, const CemParameters& params,
                       const FastPredictor::Options& predictor_options,
                       std::optional<ExtendedPlanning> extended)
    : model_(model), params_(params), predictor_(predictor_options), extended_(extended) {
  params_.validate("controller");
  if (extended_) {
    extended_->extensions.validate();
    extended_->response.validate();
    extended_predictor_.emplace(model_, extended_->step_s);
  }
}

namespace {

// With the re-aim predicted, how many of the scan's cheapest points under the paper's prediction
// are ranked again with the re-aim (see plan()).
constexpr size_t kScanShortlist = 10;
// A line search whose feasible samples' costs all lie within this (m) moved nothing it could
// rank: 1 mm, a tenth of the paper's smallest path error (Table I: 0.67 cm).
constexpr double kBlindSpread_m = 1e-3;
// A blind line search's rescue may not predict the group spreading by more than this (m).
constexpr double kSpreadTolerance_m = 1e-3;

// Per-decision scratch: the predictor's output and the start states, reused over candidates.
struct Scratch {
  std::vector<ObjectState> start;
  Prediction prediction;
  // Extended planning.
  std::vector<WindowStart> window_start;
  std::vector<ObjectExtensions> object_ext;  // each object its type's (worked out at the first)
  bool object_ext_ready = false;
  std::vector<Eigen::Vector2d> end_W;
  // Transition: the sweep's schedule, and what every candidate of one decision shares (worked
  // out at the first): the objects' states as the transit under the command in force ends.
  OrientationSchedule schedule;
  bool transit_ready = false;
  std::vector<ObjectState> start_now;      // at the decision, along the rays of the air now
  std::vector<ObjectState> after_transit;  // a transit later (start_now when there is none)
};

// The sweep of a re-aim from `from` to `to` (predict_transition, see cem_planner.h), timed from
// when the air on the floor starts to follow the servos (a transit after the command): the
// servos' closed-form rest-to-rest moves, cut into kSweepStep pieces that each hold the
// orientation at their middle, then `to`. Returns when `to` holds (0: no move, and `schedule`
// is `to` throughout). Pieces of 100 ms held at their middles: accuracy against CVODE on the
// continuous sweep in docs/controller.md, the variant they replaced in docs/decisions.md.
constexpr double kSweepStep = 0.1;
double transition_schedule(const NozzleResponseParameters& r, const NozzleOrientation& from,
                           const NozzleOrientation& to, OrientationSchedule& schedule) {
  schedule.clear();
  const ServoMove pan(from.pan_rad, to.pan_rad, r.max_speed_radps, r.max_acceleration_radps2);
  const ServoMove tilt(from.tilt_rad, to.tilt_rad, r.max_speed_radps, r.max_acceleration_radps2);
  const double sweep_s = std::max(pan.duration_s(), tilt.duration_s());
  const int pieces = static_cast<int>(std::ceil(sweep_s / kSweepStep));
  for (int k = 0; k < pieces; ++k) {
    const double mid = (k + 0.5) * kSweepStep;
    schedule.push_back({k * kSweepStep, {pan.angle(mid), tilt.angle(mid)}});
  }
  schedule.push_back({pieces * kSweepStep, to});
  return pieces * kSweepStep;
}

// The transition's shared part (see Scratch): each object's speed along its ray from the
// present s carries over (eq. 9 under the air that blows now), and the transit is predicted
// once under the command in force.
void prepare_transit(const AirFieldModel& model, const FastPredictor& fast,
                     const CemParameters& params, const PlanningProblem& pr, Scratch& scratch) {
  const size_t m = pr.positions_W.size();
  const OrientedRays now = model.rays_at(*pr.nozzle_now);
  const Eigen::Vector2d& s_now = now.stagnation_point();
  scratch.start_now.resize(m);
  for (size_t j = 0; j < m; ++j) {
    const Eigen::Vector2d d = pr.positions_W[j] - s_now;
    const double n = d.norm();
    scratch.start_now[j].p_W = pr.positions_W[j];
    scratch.start_now[j].v = n > 0.0 ? std::max(0.0, pr.velocities_W[j].dot(d / n)) : 0.0;
  }
  scratch.after_transit = scratch.start_now;
  if (params.transition.transit_delay_s > 0.0) {
    PredictionOptions options;
    options.horizon_s = params.transition.transit_delay_s;
    fast.predict(now, pr.dynamics, scratch.start_now, options, scratch.prediction);
    scratch.after_transit = scratch.prediction.end;
  }
  scratch.transit_ready = true;
}

// The command that puts the air where `aim` would with the servos' offset compensated: the
// servos turn to command + offset (the rig takes tilts from 0 up; pan wraps). The tilt is held
// within [0, tilt_max_rad], the range the nozzle is commanded in.
NozzleOrientation compensated_command(const NozzleOrientation& aim, const ModelExtensions& ext,
                                      double tilt_max_rad) {
  NozzleOrientation c;
  c.pan_rad = wrap_angle(aim.pan_rad - ext.pan_offset_rad);
  c.tilt_rad = std::clamp(aim.tilt_rad - ext.tilt_offset_rad, 0.0, tilt_max_rad);
  return c;
}

// Whether the compensated command of `aim` lies within the commanded tilt range: a stagnation
// point beyond it (a tilt offset of -3 deg asks 63 deg for the aim of 60) is one the nozzle
// cannot produce.
bool compensation_reachable(const NozzleOrientation& aim, const ModelExtensions& ext,
                            double tilt_max_rad) {
  return aim.tilt_rad - ext.tilt_offset_rad <= tilt_max_rad;
}

// The end positions under the extended model for the command `command`, issued now.
void predict_extended(const ExtendedPlanning& ext, const ExtendedPredictor& predictor,
                      const CemParameters& params, const PlanningProblem& pr,
                      const NozzleOrientation& command, Scratch& scratch) {
  const size_t m = pr.positions_W.size();
  // Until the new field has acted for Delta T: the transit, any extra delay and the transport
  // lag to the farthest object come first.
  double lag_s = 0.0;
  if (ext.extensions.transport_pace_s_per_m > 0.0) {
    NozzleOrientation felt = command;
    felt.pan_rad += ext.extensions.pan_offset_rad;
    felt.tilt_rad += ext.extensions.tilt_offset_rad;
    const Eigen::Vector2d s_new = stagnation_point(predictor.field().geometry(), felt);
    double farthest = 0.0;
    for (const Eigen::Vector2d& p : pr.positions_W)
      farthest = std::max(farthest, (p - s_new).norm());
    lag_s = std::min(ext.extensions.transport_pace_s_per_m * farthest, kMaxTransportLagS);
  }
  const double t_end =
      params.horizon_s + ext.response.transit_delay_s + ext.extensions.extra_delay_s + lag_s;
  std::vector<TimedCommand> commands;
  if (pr.nozzle_now) commands.push_back({-1.0, *pr.nozzle_now});
  commands.push_back({0.0, command});
  const NozzleTimeline timeline(ext.response, commands, t_end);
  scratch.window_start.resize(m);
  for (size_t j = 0; j < m; ++j) {
    scratch.window_start[j] = WindowStart{0.0, pr.positions_W[j], pr.velocities_W[j]};
  }
  scratch.end_W.resize(m);
  // Each object its type's own effects, when the model has effects per type: the same for every
  // candidate of the decision.
  if (!scratch.object_ext_ready) {
    scratch.object_ext.clear();
    if (!ext.extensions.object_by_type.empty()) {
      if (pr.types.size() != m) {
        throw InputError(
            "controller: the extended model has effects per object type, the objects no types");
      }
      for (const std::string& type : pr.types)
        scratch.object_ext.push_back(ext.extensions.object_for(type));
    }
    scratch.object_ext_ready = true;
  }
  predictor.predict_ends(pr.dynamics, ext.extensions, scratch.object_ext, timeline,
                         scratch.window_start, t_end, scratch.end_W);
}

void check_problem(const PlanningProblem& pr) {
  const size_t m = pr.positions_W.size();
  if (m == 0) throw InputError("controller: no objects to plan for");
  if (pr.velocities_W.size() != m || pr.dynamics.size() != m || pr.references_W.size() != m) {
    throw InputError("controller: positions, velocities, dynamics and references differ in size");
  }
  if (!pr.types.empty() && pr.types.size() != m) {
    throw InputError("controller: positions and object types differ in size");
  }
  if ((!pr.weights.empty() && pr.weights.size() != m) ||
      (!pr.reach_m.empty() && pr.reach_m.size() != m)) {
    throw InputError("controller: weights or reaches given for some objects only");
  }
  for (size_t j = 0; j < pr.weights.size(); ++j) {
    if (!(std::isfinite(pr.weights[j]) && pr.weights[j] >= 0.0)) {
      throw InputError("controller: object " + std::to_string(j) +
                       " has a weight that is not a finite number >= 0");
    }
  }
  for (size_t j = 0; j < pr.reach_m.size(); ++j) {
    if (!(pr.reach_m[j] > 0.0)) {
      throw InputError("controller: object " + std::to_string(j) + " has a reach that is not > 0");
    }
  }
  for (size_t j = 0; j < m; ++j) {
    if (!pr.positions_W[j].allFinite() || !pr.velocities_W[j].allFinite() ||
        !pr.references_W[j].allFinite()) {
      throw InputError("controller: object " + std::to_string(j) +
                       " has a non-finite position, velocity or reference");
    }
  }
  if (pr.anchor >= static_cast<int>(m)) {
    throw InputError("controller: anchor object " + std::to_string(pr.anchor) + " out of range");
  }
}

// eq. (10)'s sum over the predicted ends, with the problem's weights and reaches (see the top of
// cem_planner.h).
double end_cost(const PlanningProblem& pr, std::span<const Eigen::Vector2d> end_W) {
  double sum = 0.0;
  for (size_t j = 0; j < end_W.size(); ++j) {
    const double w = pr.weights.empty() ? 1.0 : pr.weights[j];
    sum += w * (end_W[j] - pr.references_W[j]).norm();
    if (!pr.reach_m.empty()) {
      sum += kOutOfReachCost * std::max(0.0, end_W[j].norm() - pr.reach_m[j]);
    }
  }
  return sum;
}

// The stopping rule (section V-A): the elites' spread below converged_variance_m2, the variance
// along the line or, in the plane, the covariance's Frobenius norm. Otherwise the search stops
// after max_iterations.
bool cem_converged(const CemParameters& p, const Eigen::Matrix2d& sigma) {
  const double spread = p.search == CemSearch::kLine ? sigma(0, 0) : sigma.norm();
  return spread < p.converged_variance_m2;
}

// The planner's predictors: the fast one of eqs. (8)-(9), or the extended model's.
struct Predictors {
  const FastPredictor& fast;
  const ExtendedPlanning* extended = nullptr;
  const ExtendedPredictor* extended_predictor = nullptr;
};

// Sweep clearance (see cem_planner.h): whether s comes within `clearance` of an object while the
// servos turn from `from` to `to`. `offset` is added to the servos' orientation to get the one the
// air follows (an extended model's nozzle_offset; zero otherwise).
// The pieces' length (s): s moves at most ~12 cm in one (7 rad/s at 1.65 m), its chord at most
// 1 mm off the arc.
constexpr double kSweepCheckStep = 0.01;
bool sweep_passes_objects(const NozzleGeometry& g, const NozzleResponseParameters& servos,
                          const NozzleOrientation& from, const NozzleOrientation& to,
                          const NozzleOrientation& offset, std::span<const Eigen::Vector2d> p_W,
                          double clearance) {
  const ServoMove pan(from.pan_rad, to.pan_rad, servos.max_speed_radps,
                      servos.max_acceleration_radps2);
  const ServoMove tilt(from.tilt_rad, to.tilt_rad, servos.max_speed_radps,
                       servos.max_acceleration_radps2);
  const double duration = std::max(pan.duration_s(), tilt.duration_s());
  auto s_at = [&](double t) {
    const NozzleOrientation o{pan.angle(t) + offset.pan_rad,
                              std::max(0.0, tilt.angle(t) + offset.tilt_rad)};
    return stagnation_point(g, o);
  };
  // How fast s can cross the floor (m/s), to skip the pieces it cannot bring near an object.
  // s = R(rho) [cos pan, sin pan] with rho = h tan(tilt) and R = rho - a1 rho^a2 (eqs. 1-2), the
  // tilt between its ends: |ds/dt| <= |R| |pan'| + |dR/drho| h / cos^2(tilt) |tilt'|, each factor
  // at its largest over the move. Skipping changes no piece: those checked are the same chords.
  const double tilt_hi = std::max(0.0, std::max(from.tilt_rad, to.tilt_rad) + offset.tilt_rad);
  double pan_term = 0.0, tilt_term = 0.0;
  const bool bounded = tilt_hi < 1.5;  // 86 deg: beyond, no useful bound
  if (bounded) {
    const double rho_hi = g.height_m * std::tan(tilt_hi);
    const double cos_hi = std::cos(tilt_hi);
    pan_term = pan.peak_speed() * (rho_hi + g.a1 * std::pow(rho_hi, g.a2));
    tilt_term = tilt.peak_speed() * (1.0 + g.a1 * g.a2 * std::pow(rho_hi, g.a2 - 1.0)) *
                g.height_m / (cos_hi * cos_hi);
  }
  auto nearest = [&](const Eigen::Vector2d& q) {
    double d = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d& p : p_W) d = std::min(d, (p - q).norm());
    return d;
  };
  Eigen::Vector2d a = s_at(0.0);
  const int pieces = static_cast<int>(std::ceil(duration / kSweepCheckStep));
  for (int k = 1; k <= pieces;) {
    if (bounded) {
      // Every chord ending by t_safe lies within v (t_safe - t) of a = s(t): none can come
      // within the clearance of an object farther than that from a (a 1 % margin on v).
      const double t = (k - 1) * kSweepCheckStep;
      const double v = 1.01 * ((t < pan.duration_s() ? pan_term : 0.0) +
                               (t < tilt.duration_s() ? tilt_term : 0.0));
      const double room = nearest(a) - clearance;
      if (room > 0.0 && v > 0.0) {
        const int last_safe = static_cast<int>(std::floor((t + room / v) / kSweepCheckStep));
        if (last_safe >= pieces) return false;
        if (last_safe >= k) {
          k = last_safe + 1;
          a = s_at(std::min(duration, last_safe * kSweepCheckStep));
          continue;
        }
      }
    }
    const Eigen::Vector2d b = s_at(std::min(duration, k * kSweepCheckStep));
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    for (const Eigen::Vector2d& p : p_W) {
      const double u = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      if ((a + u * ab - p).norm() < clearance) return true;
    }
    a = b;
    ++k;
  }
  return false;
}

// eq. (10)'s penalty: s not finite, an object starting within delta_min of s (where motion is
// most stochastic), or a stagnation point the nozzle cannot produce (no better than one too close
// to an object). Otherwise the orientation that puts s there.
std::optional<NozzleOrientation> unpenalised_aim(const AirFieldModel& model,
                                                 const CemParameters& params,
                                                 const PlanningProblem& pr,
                                                 const Eigen::Vector2d& s_W) {
  if (!s_W.allFinite()) return std::nullopt;
  for (const Eigen::Vector2d& p_W : pr.positions_W) {
    if ((p_W - s_W).norm() < params.min_distance_m) return std::nullopt;
  }
  const AimResult aim = aim_at_stagnation(model.geometry(), s_W, pr.pan_hint_rad);
  if (!aim.reachable()) return std::nullopt;
  return *aim.orientation;
}

// Whether the re-aim to `command` (the servos' target) sweeps s within the sweep clearance of an
// object (see cem_planner.h): a candidate it blocks costs J_P.
bool sweep_blocks(const AirFieldModel& model, const Predictors& predictors,
                  const CemParameters& params, const PlanningProblem& pr,
                  const NozzleOrientation& command) {
  if (!(params.sweep_clearance_m > 0.0 && pr.nozzle_now)) return false;
  if (predictors.extended != nullptr) {
    const ModelExtensions& ext = predictors.extended->extensions;
    return sweep_passes_objects(model.geometry(), predictors.extended->response, *pr.nozzle_now,
                                command, {ext.pan_offset_rad, ext.tilt_offset_rad}, pr.positions_W,
                                params.sweep_clearance_m);
  }
  return sweep_passes_objects(model.geometry(), params.transition, *pr.nozzle_now, command, {},
                              pr.positions_W, params.sweep_clearance_m);
}

// The cost of candidate s, eq. (10): the penalty when an object starts within delta_min of s,
// the nozzle cannot produce s or (with `check_sweep`) the re-aim's sweep blocks it, else
// end_cost() of the predicted ends (in scratch.end_W). `orientation` receives the command.
double evaluate(const AirFieldModel& model, const Predictors& predictors,
                const CemParameters& params, const PlanningProblem& pr, const Eigen::Vector2d& s_W,
                Scratch& scratch, NozzleOrientation* orientation, bool* feasible,
                bool check_sweep = true) {
  *feasible = false;
  const size_t m = pr.positions_W.size();
  const std::optional<NozzleOrientation> aim = unpenalised_aim(model, params, pr, s_W);
  if (!aim) return params.penalty;
  if (predictors.extended != nullptr) {
    const ModelExtensions& ext = predictors.extended->extensions;
    const double tilt_max = model.geometry().tilt_max_rad;
    if (!compensation_reachable(*aim, ext, tilt_max)) return params.penalty;
    const NozzleOrientation command = compensated_command(*aim, ext, tilt_max);
    if (check_sweep && sweep_blocks(model, predictors, params, pr, command)) {
      return params.penalty;
    }
    if (orientation != nullptr) *orientation = command;
    predict_extended(*predictors.extended, *predictors.extended_predictor, params, pr, command,
                     scratch);
    *feasible = true;
    return end_cost(pr, scratch.end_W);
  }
  if (check_sweep && sweep_blocks(model, predictors, params, pr, *aim)) return params.penalty;
  if (orientation != nullptr) *orientation = *aim;
  if (params.predict_transition && pr.nozzle_now) {
    if (!scratch.transit_ready) prepare_transit(model, predictors.fast, params, pr, scratch);
    const double sweep_s =
        transition_schedule(params.transition, *pr.nozzle_now, *aim, scratch.schedule);
    PredictionOptions options;
    options.horizon_s = sweep_s + params.horizon_s;
    // No move, no transit to wait for: Delta T under the air now, from the decision on.
    predictors.fast.predict(model, scratch.schedule, pr.dynamics,
                            sweep_s > 0.0 ? scratch.after_transit : scratch.start_now, options,
                            scratch.prediction);
    scratch.end_W.resize(m);
    for (size_t j = 0; j < m; ++j) scratch.end_W[j] = scratch.prediction.end[j].p_W;
    *feasible = true;
    return end_cost(pr, scratch.end_W);
  }
  // The fast predictor follows each object's ray: the field's rays are all it needs.
  const OrientedRays field = model.rays_at(*aim);
  // eq. (9): each object moves radially away from s; its present speed along that ray carries
  // over (eq. 8's state), a speed toward s does not.
  scratch.start.resize(m);
  const Eigen::Vector2d s_eff = field.stagnation_point();
  for (size_t j = 0; j < m; ++j) {
    const Eigen::Vector2d d = pr.positions_W[j] - s_eff;
    const double n = d.norm();
    const double v_radial = n > 0.0 ? pr.velocities_W[j].dot(d / n) : 0.0;
    scratch.start[j].p_W = pr.positions_W[j];
    scratch.start[j].v = std::max(0.0, v_radial);
  }
  PredictionOptions options;
  options.horizon_s = params.horizon_s;
  predictors.fast.predict(field, pr.dynamics, scratch.start, options, scratch.prediction);
  scratch.end_W.resize(m);
  for (size_t j = 0; j < m; ++j) scratch.end_W[j] = scratch.prediction.end[j].p_W;
  *feasible = true;
  return end_cost(pr, scratch.end_W);
}

Predictors predictors_of(const FastPredictor& fast, const std::optional<ExtendedPlanning>& ext,
                         const std::optional<ExtendedPredictor>& ext_predictor) {
  return Predictors{fast, ext ? &*ext : nullptr, ext_predictor ? &*ext_predictor : nullptr};
}

}  // namespace

double CemPlanner::cost(const PlanningProblem& problem, const Eigen::Vector2d& s_W,
                        std::vector<Eigen::Vector2d>* end_W) const {
  check_problem(problem);
  const Predictors preds = predictors_of(predictor_, extended_, extended_predictor_);
  Scratch scratch;
  bool feasible = false;
  const double j = evaluate(model_, preds, params_, problem, s_W, scratch, nullptr, &feasible);
  if (end_W != nullptr) {
    end_W->clear();
    if (feasible) {
      *end_W = scratch.end_W;
    } else {
      end_W->assign(problem.positions_W.begin(), problem.positions_W.end());
    }
  }
  return j;
}

double CemPlanner::outcome_cost(const PlanningProblem& problem, const Eigen::Vector2d& s_W,
                                std::span<const Eigen::Vector2d> end_W) const {
  check_problem(problem);
  if (end_W.size() != problem.positions_W.size()) {
    throw InputError("controller: " + std::to_string(end_W.size()) + " end positions for " +
                     std::to_string(problem.positions_W.size()) + " objects");
  }
  if (!unpenalised_aim(model_, params_, problem, s_W)) return params_.penalty;
  return end_cost(problem, end_W);
}

PlanResult CemPlanner::plan(const PlanningProblem& problem, RandomStream& rng) const {
  check_problem(problem);
  PlanResult result = plan_with(params_, problem, rng);
  if (params_.sweep_clearance_m > 0.0 && problem.nozzle_now && result.cost >= params_.penalty) {
    // The clearance blocks every candidate (see cem_planner.h): the paper's decision.
    CemParameters paper = params_;
    paper.sweep_clearance_m = 0.0;
    result = plan_with(paper, problem, rng);
    // Blocked only when the paper's search finds a push: with none (every s too near an object
    // or out of reach) the clearance changed nothing.
    result.sweep_blocked = result.cost < params_.penalty;
  }
  return result;
}

void CemPlanner::set_threads(int threads) {
  if (threads < 1 || threads > kMaxThreads) {
    throw InputError("controller: planner threads must be in [1, " + std::to_string(kMaxThreads) +
                     "], got " + std::to_string(threads));
  }
  threads_ = threads;
}

PlanResult CemPlanner::plan_with(const CemParameters& p, const PlanningProblem& problem,
                                 RandomStream& rng) const {
  const Predictors preds = predictors_of(predictor_, extended_, extended_predictor_);
  const size_t m = problem.positions_W.size();
  const int n = p.samples;
  const int n_elite = p.elite;
  Scratch scratch;
  PlanResult result;

  // The search space. Line: s = p_a + x e with e the unit vector from the anchor's reference to
  // the anchor (pushing "away from the reference point"), x ~ N(mu, Sigma). Plane: s ~ N(mu,
  // Sigma).
  size_t anchor = 0;
  Eigen::Vector2d e = Eigen::Vector2d::UnitX();
  if (p.search == CemSearch::kLine) {
    if (problem.anchor >= 0) {
      anchor = static_cast<size_t>(problem.anchor);
    } else {
      double farthest = -1.0;
      for (size_t j = 0; j < m; ++j) {
        const double d = (problem.positions_W[j] - problem.references_W[j]).norm();
        if (d > farthest) {
          farthest = d;
          anchor = j;
        }
      }
    }
    const Eigen::Vector2d away = problem.positions_W[anchor] - problem.references_W[anchor];
    if (away.norm() > 1e-9) e = away.normalized();
  }
  auto to_point = [&](const Eigen::Vector2d& z) -> Eigen::Vector2d {
    return p.search == CemSearch::kLine ? Eigen::Vector2d(problem.positions_W[anchor] + z.x() * e)
                                        : z;
  };

  // The scan (see cem_planner.h): eq. (10) on every point of a grid of stagnation points over
  // the reachable disc; returns the cheapest feasible point and its cost (infinite cost: none
  // feasible).
  // With `keep_spread`, a point whose predicted ends lie farther apart than the objects do now
  // does not count (the blind line search's rescue, see cem_planner.h).
  const double spread_now = max_pairwise_distance(problem.positions_W);
  auto spreads = [&](bool keep_spread, const std::vector<Eigen::Vector2d>& end_W) {
    return keep_spread && max_pairwise_distance(end_W) > spread_now + kSpreadTolerance_m;
  };
  // eq. (10) for each of `points` under `params`, with its command and whether its predicted
  // ends spread (see `spreads`). On several threads each run of candidates has its own scratch
  // (the transit shared by a decision's candidates is worked out again in each: the same
  // values); the results are by candidate, so the decision does not depend on the threads.
  struct Candidate {
    double cost = 0.0;
    bool feasible = false;
    bool spreads = false;
    NozzleOrientation command;
  };
  auto evaluate_all = [&](const CemParameters& params, const std::vector<Eigen::Vector2d>& points,
                          bool check_sweep, bool keep_spread, std::vector<Candidate>& out) {
    out.assign(points.size(), Candidate{});
    auto one = [&](size_t i, Scratch& work) {
      Candidate& c = out[i];
      c.cost = evaluate(model_, preds, params, problem, points[i], work, &c.command, &c.feasible,
                        check_sweep);
      c.spreads = c.feasible && spreads(keep_spread, work.end_W);
    };
    if (threads_ == 1 || points.size() < 2) {
      for (size_t i = 0; i < points.size(); ++i) one(i, scratch);
      return;
    }
    const size_t runs = std::min(points.size(), static_cast<size_t>(threads_) * 4);
    parallel_for(runs, threads_, [&](size_t r) {
      Scratch work;
      for (size_t i = r * points.size() / runs; i < (r + 1) * points.size() / runs; ++i) {
        one(i, work);
      }
    });
  };
  auto scan = [&](bool keep_spread) -> std::pair<Eigen::Vector2d, double> {
    Eigen::Vector2d best = Eigen::Vector2d::Zero();
    // Points in a fixed order, ties to the first, so the result is deterministic. With the re-aim
    // predicted, the grid is ranked on the paper's prediction (one orientation instead of the
    // sweep's dozen) and the kScanShortlist cheapest are ranked again with the re-aim. The sweep
    // clearance is checked in the ranked order, only until the cheapest points it lets pass are
    // found: the same points as checking every point first, at a fraction of the checks (it
    // costs more than the paper's prediction of a point).
    CemParameters plain = p;
    plain.predict_transition = false;
    const bool rerank = p.predict_transition && problem.nozzle_now.has_value();
    const double r_max = max_stagnation_radius(model_.geometry());
    const int half = static_cast<int>(std::floor(r_max / p.scan_step_m));
    struct Point {
      double cost;
      Eigen::Vector2d s;
      NozzleOrientation command;
    };
    std::vector<Eigen::Vector2d> grid;
    for (int iy = -half; iy <= half; ++iy) {
      for (int ix = -half; ix <= half; ++ix) {
        const Eigen::Vector2d s(ix * p.scan_step_m, iy * p.scan_step_m);
        if (s.norm() <= r_max) grid.push_back(s);
      }
    }
    std::vector<Candidate> predicted;
    evaluate_all(plain, grid, /*check_sweep=*/false, keep_spread, predicted);
    std::vector<Point> ranked;
    for (size_t i = 0; i < grid.size(); ++i) {
      const Candidate& c = predicted[i];
      result.evaluations += c.feasible ? 1 : 0;
      if (c.feasible && !c.spreads) ranked.push_back({c.cost, grid[i], c.command});
    }
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const Point& a, const Point& b) { return a.cost < b.cost; });
    const size_t wanted = rerank ? kScanShortlist : 1;
    size_t kept = 0;
    for (const Point& q : ranked) {
      if (kept == wanted) break;
      if (!sweep_blocks(model_, preds, plain, problem, q.command)) ranked[kept++] = q;
    }
    ranked.resize(kept);
    double cheapest = std::numeric_limits<double>::infinity();
    for (const Point& q : ranked) {
      double c = q.cost;
      if (rerank) {
        // The clearance let q pass above (the same clearance and servos as p's).
        bool feasible = false;
        c = evaluate(model_, preds, p, problem, q.s, scratch, nullptr, &feasible,
                     /*check_sweep=*/false);
        result.evaluations += feasible ? 1 : 0;
        if (!feasible || spreads(keep_spread, scratch.end_W)) continue;
      }
      if (c < cheapest) {
        cheapest = c;
        best = q.s;
      }
      if (!rerank) break;  // ranked by the cost itself: the first is the cheapest
    }
    return {best, cheapest};
  };

  Eigen::Vector2d mu;
  Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();
  Eigen::Vector2d scan_best = Eigen::Vector2d::Zero();
  double scan_cost = std::numeric_limits<double>::infinity();
  if (p.search == CemSearch::kLine) {
    mu = Eigen::Vector2d(p.mean0_m, 0.0);
    sigma(0, 0) = p.variance0_m2;
  } else {
    mu.setZero();
    for (const auto& q : problem.positions_W) mu += q;
    mu /= static_cast<double>(m);
    sigma = Eigen::Matrix2d::Identity() * p.variance0_m2;
    if (p.scan_step_m > 0.0) {
      std::tie(scan_best, scan_cost) = scan(/*keep_spread=*/false);
      if (scan_cost < std::numeric_limits<double>::infinity()) mu = scan_best;
    }
  }

  std::vector<Eigen::Vector2d> z(n), points(n);
  std::vector<Candidate> drawn;
  std::vector<double> costs(n);
  std::vector<int> order(n);
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::Vector2d best_z = mu;
  // The spread of the feasible samples' costs: under kBlindSpread_m, no sample changed what the
  // objects do, and the elites are only the first drawn.
  double lowest_feasible = std::numeric_limits<double>::infinity();
  double highest_feasible = -std::numeric_limits<double>::infinity();
  for (int it = 0; it < p.max_iterations; ++it) {
    // Sample: x = mu + L w, L the Cholesky factor of Sigma (a 2x2 written out; Sigma is PSD).
    const double l00 = std::sqrt(std::max(0.0, sigma(0, 0)));
    const double l10 = l00 > 0.0 ? sigma(1, 0) / l00 : 0.0;
    const double l11 = std::sqrt(std::max(0.0, sigma(1, 1) - l10 * l10));
    for (int i = 0; i < n; ++i) {
      const double w0 = rng.normal();
      const double w1 = p.search == CemSearch::kPlane ? rng.normal() : 0.0;
      z[i] = mu + Eigen::Vector2d(l00 * w0, l10 * w0 + l11 * w1);
      points[i] = to_point(z[i]);
    }
    evaluate_all(p, points, /*check_sweep=*/true, /*keep_spread=*/false, drawn);
    for (int i = 0; i < n; ++i) {
      const bool feasible = drawn[i].feasible;
      costs[i] = drawn[i].cost;
      result.evaluations += feasible ? 1 : 0;
      if (feasible) {
        lowest_feasible = std::min(lowest_feasible, costs[i]);
        highest_feasible = std::max(highest_feasible, costs[i]);
      }
      if (costs[i] < best_cost) {
        best_cost = costs[i];
        best_z = z[i];
      }
    }
    // The n* cheapest refit the Gaussian (ties keep sampling order: deterministic).
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return costs[a] < costs[b]; });
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int k = 0; k < n_elite; ++k) mean += z[order[k]];
    mean /= static_cast<double>(n_elite);
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (int k = 0; k < n_elite; ++k) {
      const Eigen::Vector2d d = z[order[k]] - mean;
      cov += d * d.transpose();
    }
    cov /= static_cast<double>(n_elite);
    mu = mean;
    sigma = cov;
    result.iterations = it + 1;
    if (cem_converged(p, sigma)) {
      result.converged = true;
      break;
    }
  }

  // s* is the final mean (section V-A). Should the mean itself be infeasible (the elites straddle
  // an object's penalty disc), or cost more than the cheapest candidate seen when keep_cheapest
  // is set, that candidate stands in for it.
  NozzleOrientation orientation;
  bool feasible = false;
  Eigen::Vector2d s = to_point(mu);
  double j = evaluate(model_, preds, p, problem, s, scratch, &orientation, &feasible);
  if ((!feasible || (p.keep_cheapest && best_cost < j)) && best_cost < p.penalty) {
    s = to_point(best_z);
    j = evaluate(model_, preds, p, problem, s, scratch, &orientation, &feasible);
  }
  // A blind line search (see cem_planner.h) scans the disc when a pitch is set.
  if (p.search == CemSearch::kLine && p.scan_step_m > 0.0 &&
      !(highest_feasible - lowest_feasible >= kBlindSpread_m)) {
    // Every point at the pitch: where the model moves nothing from the ray, the pushes that do
    // are few and close to the objects, and a coarse grid's cheapest points are only its first.
    std::tie(scan_best, scan_cost) = scan(/*keep_spread=*/true);
    result.blind_scan = true;
  }
  // After a scan the decision is never worse than the scan's best point.
  if (scan_cost < p.penalty && (!feasible || scan_cost < j)) {
    s = scan_best;
    j = evaluate(model_, preds, p, problem, s, scratch, &orientation, &feasible);
  }
  if (!feasible) {
    // Nothing feasible: hold s where the nozzle can put it, as far out along the search as the
    // tilt range allows, so the rig keeps a defined orientation.
    const double r_max = 0.999 * max_stagnation_radius(model_.geometry());
    if (s.norm() > r_max) s *= r_max / s.norm();
    const AimResult aim = aim_at_stagnation(model_.geometry(), s, problem.pan_hint_rad);
    if (aim.reachable()) {
      orientation = extended_ ? compensated_command(*aim.orientation, extended_->extensions,
                                                    model_.geometry().tilt_max_rad)
                              : *aim.orientation;
    }
    j = p.penalty;
  }
  result.stagnation_W = s;
  result.orientation = orientation;
  result.cost = j;
  result.predicted_end_W.resize(m);
  for (size_t k = 0; k < m; ++k) {
    result.predicted_end_W[k] = feasible ? scratch.end_W[k] : problem.positions_W[k];
  }
  return result;
}

}  // namespace airtwin
